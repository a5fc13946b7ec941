/* SQLite results store (see results/store/store.h for the contract).
 *
 * Every write is one transaction committed before the call returns: single-row inserts run as
 * one autocommit statement, multi-row writes inside BEGIN IMMEDIATE ... COMMIT. With WAL and
 * synchronous=FULL, SQLite fsyncs the WAL at each commit, so a row reported stored survives a
 * SIGKILL or a power cut. */
#include "results/store/store.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include "results/store/backend.h"
#include "results/store/internal.h"
#include "results/store/migrations.h"
#include "results/store/rows.h"

#ifndef CSF_VERSION
#define CSF_VERSION "unknown"
#endif

/* Refuse to start a session with less free space than this: a session is a few hundred KiB,
 * and SQLite needs room for the WAL and a checkpoint. */
#define STORE_MIN_FREE_BYTES (4.0 * 1024 * 1024)
/* Size of the write probe committed (then deleted) at open, to find a full disk or quota. */
#define STORE_PROBE_BYTES (128 * 1024)

typedef struct sq_store {
    csf_store base; /* first: a csf_store * points here */
    sqlite3 *db;
    char path[1024];
    sqlite3_stmt *ins_trial, *ins_reading, *ins_frame;
    int sys_errno; /* errno of the last failed step, caught before finalize/reset can clear it */
    int claims_fd;   /* the database file for the claims' locks, opened at the first claim */
    int64_t *claims; /* sessions this handle holds */
    size_t n_claims, cap_claims;
} sq_store;

static const csf_store_ops sqlite_ops;

static sq_store *sq(csf_store *b) { return (sq_store *)b; }
static void sq_close(csf_store *base);
static csf_status sq_claim(sq_store *s, int64_t id, csf_error *err);

sqlite3 *csf_store_db(csf_store *s) { return s && s->ops == &sqlite_ops ? sq(s)->db : NULL; }

/* ---- helpers ----------------------------------------------------------------------------- */

static void copy_str(char *dst, size_t cap, const char *src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}

/* Turns an SQLite failure into a sentence that names the store file and the cause. */
static csf_status store_fail(csf_error *err, const char *path, sqlite3 *db, int sys_saved, int rc,
                             const char *what)
{
    int primary = rc & 0xff;
    int sys = sys_saved ? sys_saved : db ? sqlite3_system_errno(db) : 0;
    const char *detail = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    switch (primary) {
    case SQLITE_FULL:
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: disk full while %s (%s); free space on that disk or choose "
                             "another file with --store", path, what, detail);
    case SQLITE_READONLY:
    case SQLITE_PERM:
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: read-only, cannot write while %s (%s); make the file and "
                             "its folder writable or choose another file with --store", path, what,
                             detail);
    case SQLITE_NOTADB:
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: not a database (the file is not SQLite; it may be another "
                             "file or badly damaged); refusing to overwrite it", path);
    case SQLITE_CORRUPT:
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: database is corrupt (malformed) while %s (%s); restore it "
                             "from a backup or start a new store with --store", path, what, detail);
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: locked by another process while %s; is another csfcal "
                             "running on the same store?", path, what);
    case SQLITE_CANTOPEN:
        return csf_error_set(err, CSF_E_STORE, "store %s: cannot open (%s%s%s)", path, detail,
                             sys ? ": " : "", sys ? strerror(sys) : "");
    case SQLITE_IOERR:
        if (sys == ENOSPC || sys == EDQUOT || sys == EFBIG)
            return csf_error_set(err, CSF_E_STORE,
                                 "store %s: disk full while %s (%s); free space on that disk or "
                                 "choose another file with --store", path, what, strerror(sys));
        if (rc == SQLITE_IOERR_WRITE)
            return csf_error_set(err, CSF_E_STORE,
                                 "store %s: cannot write while %s (disk full, quota or file-size "
                                 "limit reached, or a failing disk)", path, what);
        if (sys == EROFS || sys == EACCES || sys == EPERM)
            return csf_error_set(err, CSF_E_STORE, "store %s: read-only while %s (%s)", path,
                                 what, strerror(sys));
        return csf_error_set(err, CSF_E_STORE, "store %s: input/output error while %s (%s%s%s)",
                             path, what, detail, sys ? ": " : "", sys ? strerror(sys) : "");
    case SQLITE_CONSTRAINT:
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: %s refused: %s", path, what, detail);
    default:
        return csf_error_set(err, CSF_E_STORE, "store %s: failed while %s (%s)", path, what, detail);
    }
}

static csf_status fail(sq_store *s, csf_error *err, int rc, const char *what)
{
    csf_status st = store_fail(err, s->path, s->db, s->sys_errno, rc, what);
    s->sys_errno = 0;
    return st;
}

/* SQLite records the OS error for some failures only (not for a failed write()); for an I/O
 * error the errno left by the failing call is the best account of the cause. */
static int os_errno(sqlite3 *db, int rc)
{
    int sys = sqlite3_system_errno(db);
    if (sys == 0 && (rc & 0xff) == SQLITE_IOERR) sys = errno;
    return sys;
}

/* sqlite3_step that remembers the OS error of a failure (ENOSPC, EFBIG, EROFS ...). */
static int step(sq_store *s, sqlite3_stmt *st)
{
    errno = 0;
    int rc = sqlite3_step(st);
    s->sys_errno = rc != SQLITE_ROW && rc != SQLITE_DONE ? os_errno(s->db, rc) : 0;
    return rc;
}

static int exec_s(sq_store *s, const char *sql)
{
    errno = 0;
    int rc = sqlite3_exec(s->db, sql, NULL, NULL, NULL);
    s->sys_errno = rc != SQLITE_OK ? os_errno(s->db, rc) : 0;
    return rc;
}


/* Binds a double, storing NaN as NULL (SQL has no NaN). */
static void bind_real(sqlite3_stmt *st, int i, double v)
{
    if (isnan(v)) sqlite3_bind_null(st, i);
    else sqlite3_bind_double(st, i, v);
}

static double col_real(sqlite3_stmt *st, int i)
{
    return sqlite3_column_type(st, i) == SQLITE_NULL ? NAN : sqlite3_column_double(st, i);
}

static void col_text(sqlite3_stmt *st, int i, char *dst, size_t cap)
{
    const unsigned char *t = sqlite3_column_text(st, i);
    copy_str(dst, cap, t ? (const char *)t : "");
}

static int prepare(sq_store *s, const char *sql, sqlite3_stmt **st)
{
    return sqlite3_prepare_v2(s->db, sql, -1, st, NULL);
}

/* Growable array used by the get_* functions. */
static int grow(void **buf, size_t *cap, size_t n, size_t elem)
{
    if (n < *cap) return 0;
    size_t nc = *cap ? *cap * 2 : 64;
    void *p = realloc(*buf, nc * elem);
    if (!p) return -1;
    *buf = p;
    *cap = nc;
    return 0;
}

/* One reader of many rows (the csf_store_get_* and csf_store_list_* functions): its SQL, how one
 * result row fills one element of the array, and the words for its errors. */
typedef struct {
    const char *sql;
    int binds_session;     /* the SQL's one parameter is the session id */
    size_t elem_size;
    /* Fills one zeroed element from the current row; 0, or -1 when out of memory. */
    int (*row)(sqlite3_stmt *st, void *elem, int64_t session_id);
    /* Releases what an element owns, also one the row function failed half-way (NULL: nothing). */
    void (*free_elem)(void *elem);
    const char *what;      /* failure: "store PATH: failed while <what> (...)" */
    const char *oom_what;  /* no memory: "store: out of memory <oom_what>" */
} row_query;

/* Runs q and returns its rows as one malloc'd array in *out (NULL when there are none). */
static csf_status query_rows(sq_store *s, const row_query *q, int64_t session_id, void **out,
                             size_t *n, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return csf_error_set(err, CSF_E_INVALID_ARG, "store: not open");
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, q->sql, &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, q->what);
    if (q->binds_session) sqlite3_bind_int64(st, 1, session_id);
    unsigned char *list = NULL;
    size_t cap = 0, cnt = 0;
    int oom = 0;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (grow((void **)&list, &cap, cnt, q->elem_size) < 0) {
            oom = 1;
            break;
        }
        void *elem = list + cnt++ * q->elem_size;
        memset(elem, 0, q->elem_size);
        if (q->row(st, elem, session_id) < 0) {
            oom = 1;
            break;
        }
    }
    sqlite3_finalize(st);
    if (!oom && rc == SQLITE_DONE) {
        *out = list;
        *n = cnt;
        return CSF_OK;
    }
    for (size_t i = 0; q->free_elem && i < cnt; i++) q->free_elem(list + i * q->elem_size);
    free(list);
    if (oom) return csf_error_set(err, CSF_E_NOMEM, "store: out of memory %s", q->oom_what);
    return fail(s, err, rc, q->what);
}

/* ---- open: checks before SQLite touches anything ----------------------------------------- */

static void dir_of(const char *path, char *out, size_t cap)
{
    char tmp[1024];
    copy_str(tmp, sizeof tmp, path);
    copy_str(out, cap, dirname(tmp));
}

/* /dev/null, a FIFO or a terminal: SQLite would fail later with a bare I/O error. */
static csf_status not_regular(const char *path, mode_t mode, csf_error *err)
{
    const char *what = S_ISCHR(mode) ? "a character device" : S_ISBLK(mode) ? "a block device"
                       : S_ISFIFO(mode) ? "a pipe" : S_ISSOCK(mode) ? "a socket" : "not a plain file";
    return csf_error_set(err, CSF_E_STORE, "store %s: is %s, not a database file; give the path "
                         "of a file (it is created if missing) with --store", path, what);
}

/* Read-only checks. Running as root, access() says yes to everything, so a file or folder whose
 * mode has no write bit at all is also treated as read-only: someone marked it so on purpose. */
static csf_status check_writable(const char *path, csf_error *err)
{
    char dir[1024];
    dir_of(path, dir, sizeof dir);
    struct stat st;
    struct statvfs vfs;
    int exists = stat(path, &st) == 0;
    if (exists && S_ISDIR(st.st_mode))
        return csf_error_set(err, CSF_E_STORE, "store %s: is a folder, not a database file", path);
    if (exists && !S_ISREG(st.st_mode)) return not_regular(path, st.st_mode, err);
    struct stat dst;
    if (stat(dir, &dst) != 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: folder %s does not exist (%s)", path, dir,
                             strerror(errno));
    if (statvfs(dir, &vfs) == 0 && (vfs.f_flag & ST_RDONLY))
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: read-only file system, results could not be saved; "
                             "choose another file with --store", path);
    if (exists && (access(path, W_OK) != 0 || (st.st_mode & 0222) == 0))
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: read-only file (permissions %03o), results could not be "
                             "saved; make it writable or choose another file with --store", path,
                             (unsigned)(st.st_mode & 0777));
    /* SQLite creates the -wal and -shm files next to the store, so the folder must be writable. */
    if (access(dir, W_OK) != 0 || (dst.st_mode & 0222) == 0)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: folder %s is read-only (permissions %03o); the store needs "
                             "to create its journal there", path, dir, (unsigned)(dst.st_mode & 0777));
    if (statvfs(dir, &vfs) == 0) {
        double free_b = (double)vfs.f_bavail * (double)vfs.f_frsize;
        if (free_b < STORE_MIN_FREE_BYTES)
            return csf_error_set(err, CSF_E_STORE,
                                 "store %s: disk full: only %.0f KiB free on the disk holding it "
                                 "(need at least %.0f KiB to start a session)", path,
                                 free_b / 1024.0, STORE_MIN_FREE_BYTES / 1024.0);
    }
    return CSF_OK;
}

/* A non-empty file must start with SQLite's magic; say so before SQLite is asked to open it. */
static csf_status check_magic(const char *path, csf_error *err)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return CSF_OK; /* does not exist yet */
    unsigned char hdr[16];
    ssize_t got = read(fd, hdr, sizeof hdr);
    close(fd);
    if (got == 0) return CSF_OK; /* empty file: becomes a new store */
    if (got != (ssize_t)sizeof hdr || memcmp(hdr, "SQLite format 3", 16) != 0)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: not a database (the file does not start with the SQLite "
                             "header; it may be another file or badly damaged); refusing to "
                             "overwrite it", path);
    return CSF_OK;
}

static int query_int(sqlite3 *db, const char *sql, int *out, int *rc_out)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK) {
        rc = sqlite3_step(st);
        if (rc == SQLITE_ROW) {
            *out = sqlite3_column_int(st, 0);
            rc = SQLITE_OK;
        } else if (rc == SQLITE_DONE) {
            rc = SQLITE_NOTFOUND;
        }
    }
    sqlite3_finalize(st);
    if (rc_out) *rc_out = rc;
    return rc == SQLITE_OK ? 0 : -1;
}

/* Version of the schema as this connection sees it now: 0 for an empty file, -1 for someone
 * else's database (tables but no schema_version). */
static int read_version(sq_store *s, int *version, int *rc)
{
    int n_tables = 0, has_version = 0;
    *version = 0;
    if (query_int(s->db, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table'", &n_tables, rc) < 0 ||
        query_int(s->db, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND "
                         "name = 'schema_version'", &has_version, rc) < 0)
        return -1;
    if (n_tables > 0 && !has_version) {
        *version = -1;
        return 0;
    }
    if (has_version && query_int(s->db, "SELECT MAX(version) FROM schema_version", version, rc) < 0)
        return -1;
    return 0;
}

/* Refuses a foreign database or a newer schema; called before anything is written, so a file
 * that is refused is left byte for byte as it was. */
static csf_status check_schema(sq_store *s, int version, csf_error *err)
{
    if (version < 0)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: an SQLite database but not a csfcal store (no "
                             "schema_version table); refusing to change it", s->path);
    if (version > CSF_STORE_SCHEMA_VERSION)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: schema version %d is newer than this csfcal understands "
                             "(%d); use a newer csfcal", s->path, version, CSF_STORE_SCHEMA_VERSION);
    return CSF_OK;
}

/* One step per transaction, and the version is read again inside it: several processes that
 * open a new or old store at once wait for each other's step and skip what is already done. */
static csf_status migrate_steps(sq_store *s, csf_error *err)
{
    for (;;) {
        int rc = exec_s(s, "BEGIN IMMEDIATE");
        if (rc != SQLITE_OK) return fail(s, err, rc, "migrating the schema");
        int v = 0;
        if (read_version(s, &v, &rc) < 0) {
            csf_status st = fail(s, err, rc, "reading the schema version");
            exec_s(s, "ROLLBACK");
            return st;
        }
        csf_status cs = check_schema(s, v, err);
        if (cs != CSF_OK || v == CSF_STORE_SCHEMA_VERSION) {
            exec_s(s, "ROLLBACK");
            return cs;
        }
        char what[64];
        snprintf(what, sizeof what, "migrating the schema from version %d to %d", v, v + 1);
        rc = exec_s(s, csf_store_migrations[v]);
        if (rc == SQLITE_OK) {
            char upd[96];
            snprintf(upd, sizeof upd, "UPDATE schema_version SET version = %d", v + 1);
            rc = exec_s(s, upd);
        }
        if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
        if (rc != SQLITE_OK) {
            csf_status st = fail(s, err, rc, what);
            exec_s(s, "ROLLBACK");
            return st;
        }
    }
}

/* Table rebuilds (v5) need foreign keys off, and that cannot change inside a transaction. */
static csf_status migrate(sq_store *s, csf_error *err)
{
    int rc = exec_s(s, "PRAGMA foreign_keys = OFF");
    if (rc != SQLITE_OK) return fail(s, err, rc, "migrating the schema");
    csf_status cs = migrate_steps(s, err);
    rc = exec_s(s, "PRAGMA foreign_keys = ON");
    if (cs == CSF_OK && rc != SQLITE_OK) cs = fail(s, err, rc, "migrating the schema");
    return cs;
}

/* Commits a real write (and removes it again) so a full disk or quota shows up now, not at
 * trial 180. Rows of a probe table leave no trace in the data tables. */
static csf_status probe_write(sq_store *s, csf_error *err)
{
    int rc = exec_s(s, "CREATE TABLE IF NOT EXISTS write_probe (id INTEGER PRIMARY KEY, content BLOB)");
    if (rc != SQLITE_OK) return fail(s, err, rc, "checking that the store can be written");
    sqlite3_stmt *st = NULL;
    rc = prepare(s, "INSERT INTO write_probe (content) VALUES (?)", &st);
    if (rc == SQLITE_OK) {
        sqlite3_bind_zeroblob(st, 1, STORE_PROBE_BYTES);
        rc = step(s, st);
        if (rc == SQLITE_DONE) rc = SQLITE_OK;
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "checking that the store can be written");
    rc = exec_s(s, "DELETE FROM write_probe");
    if (rc != SQLITE_OK) return fail(s, err, rc, "checking that the store can be written");
    return CSF_OK;
}

/* Switching to WAL needs the file to itself for a moment. When several stations open a new
 * store at once, SQLite may answer SQLITE_BUSY at once instead of calling the busy handler (it
 * does so where waiting could deadlock), so the switch is retried here for up to ~10 s. */
static int switch_to_wal(sq_store *s, char *mode, size_t mode_len)
{
    long wait_ms = 5, waited_ms = 0;
    for (;;) {
        sqlite3_stmt *st = NULL;
        int rc = prepare(s, "PRAGMA journal_mode = WAL", &st);
        if (rc == SQLITE_OK) {
            rc = step(s, st);
            if (rc == SQLITE_ROW) {
                col_text(st, 0, mode, mode_len);
                rc = SQLITE_OK;
            }
        }
        sqlite3_finalize(st);
        int busy = (rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED;
        if (!busy || waited_ms >= 10000) return rc;
        struct timespec ts = {0, wait_ms * 1000000L};
        nanosleep(&ts, NULL);
        waited_ms += wait_ms;
        if (wait_ms < 100) wait_ms *= 2;
    }
}

/* What both ways of opening refuse before touching the file. */
static csf_status check_open_args(const char *path, csf_store **out, csf_error *err)
{
    csf_error_clear(err);
    if (!out) return csf_error_set(err, CSF_E_INVALID_ARG, "store: no output pointer");
    *out = NULL;
    if (!path || !*path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: empty path (give --store PATH)");
    if (strlen(path) >= 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: path longer than 1023 characters");
    return CSF_OK;
}

/* The connection itself, set up for a file that is outside input. */
static csf_status sq_connect(sq_store *s, const char *path, csf_error *err)
{
    int rc = sqlite3_open_v2(path, &s->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE |
                             SQLITE_OPEN_NOMUTEX, NULL);
    if (rc != SQLITE_OK) return fail(s, err, rc, "opening");
    sqlite3_extended_result_codes(s->db, 1);
    /* The file is outside input: do not run functions a crafted schema might name in views or
     * triggers, and refuse writes that could corrupt it on purpose. */
    sqlite3_db_config(s->db, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, (int *)NULL);
    sqlite3_db_config(s->db, SQLITE_DBCONFIG_DEFENSIVE, 1, (int *)NULL);
    /* A second csfcal on the same store waits a little instead of failing at once. */
    sqlite3_busy_timeout(s->db, 5000);
    return CSF_OK;
}

/* Write-ahead logging, refused where the file system cannot give it, and full durability. */
static csf_status sq_use_wal(sq_store *s, const char *path, csf_error *err)
{
    char mode[16] = "";
    int rc = switch_to_wal(s, mode, sizeof mode);
    if (rc != SQLITE_OK) return fail(s, err, rc, "switching to write-ahead logging");
    if (strcmp(mode, "wal") != 0)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: cannot use write-ahead logging (journal "
                             "mode stays '%s'); is the file on a network file system?",
                             path, mode);
    rc = exec_s(s, "PRAGMA synchronous = FULL; PRAGMA foreign_keys = ON");
    if (rc != SQLITE_OK) return fail(s, err, rc, "setting durability");
    return CSF_OK;
}

/* quick_check reads every page: a malformed file is refused here rather than mid-session. */
static csf_status sq_quick_check(sq_store *s, const char *path, csf_error *err)
{
    sqlite3_stmt *st = NULL;
    char check[256] = "";
    int rc = prepare(s, "PRAGMA quick_check(1)", &st);
    if (rc == SQLITE_OK) {
        rc = step(s, st);
        if (rc == SQLITE_ROW) {
            col_text(st, 0, check, sizeof check);
            rc = SQLITE_OK;
        }
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "checking integrity");
    if (strcmp(check, "ok") != 0)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: database is corrupt (malformed: %s); "
                             "restore it from a backup or start a new store with --store",
                             path, check);
    return CSF_OK;
}

/* The inserts a session repeats for every trial, reading and frame. */
static csf_status sq_prepare_inserts(sq_store *s, csf_error *err)
{
    int rc = prepare(s,
                     "INSERT INTO trials (session_id, seq, method, freq_cpd, ecc_deg, polar_deg,"
                     " orientation_deg, sigma_deg, velocity_dps, mean_lum_cdm2, is_catch, is_practice,"
                     " contrast_requested, contrast_shown_mean, contrast_shown_max, frames_planned,"
                     " frames_shown, frames_missed, signal_interval, response, rt_s, click_x_deg,"
                     " click_y_deg, valid, flags, stored_s, n_alternatives, onset_s) VALUES (?,?,?,?,?,?,"
                     "?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                     &s->ins_trial);
    if (rc == SQLITE_OK)
        rc = prepare(s, "INSERT INTO readings (session_id, seq, channel, drive01, lum_cdm2, X_cdm2,"
                        " Y_cdm2, Z_cdm2,"
                        " t_s, status, stored_s) VALUES (?,?,?,?,?,?,?,?,?,?,?)", &s->ins_reading);
    if (rc == SQLITE_OK)
        rc = prepare(s, "INSERT INTO frame_intervals (session_id, trial_seq, idx, interval_s)"
                        " VALUES (?,?,?,?)", &s->ins_frame);
    if (rc != SQLITE_OK) return fail(s, err, rc, "preparing statements");
    return CSF_OK;
}

static csf_status sq_open_rw(const char *path, csf_store **out, csf_error *err)
{
    csf_status as = check_open_args(path, out, err);
    if (as != CSF_OK) return as;
    csf_status cs = check_writable(path, err);
    if (cs != CSF_OK) return cs;
    cs = check_magic(path, err);
    if (cs != CSF_OK) return cs;

    sq_store *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "store %s: out of memory", path);
    copy_str(s->path, sizeof s->path, path);
    s->base.ops = &sqlite_ops;
    copy_str(s->base.path, sizeof s->base.path, path);
    cs = sq_connect(s, path, err);
    if (cs != CSF_OK) goto bad;

    /* Someone else's database, or a newer csfcal's, is refused before the switch to WAL
     * below rewrites its header: a refused file stays exactly as it was. */
    int version = 0, rc = SQLITE_OK;
    if (read_version(s, &version, &rc) < 0) {
        cs = fail(s, err, rc, "reading the schema");
        goto bad;
    }
    cs = check_schema(s, version, err);
    if (cs != CSF_OK) goto bad;
    cs = sq_use_wal(s, path, err);
    if (cs != CSF_OK) goto bad;
    cs = sq_quick_check(s, path, err);
    if (cs != CSF_OK) goto bad;
    cs = migrate(s, err);
    if (cs != CSF_OK) goto bad;
    cs = probe_write(s, err);
    if (cs != CSF_OK) goto bad;
    cs = sq_prepare_inserts(s, err);
    if (cs != CSF_OK) goto bad;
    *out = &s->base;
    return CSF_OK;
bad:
    sq_close(&s->base);
    return cs;
}

/* Percent-encodes the characters that end or escape a path in an SQLite URI filename. */
static void uri_path(const char *path, char *out, size_t cap)
{
    size_t o = 0;
    for (const char *p = path; *p && o + 4 < cap; p++) {
        if (*p == '?' || *p == '#' || *p == '%') o += (size_t)snprintf(out + o, cap - o, "%%%02X", (unsigned char)*p);
        else out[o++] = *p;
    }
    out[o] = '\0';
}

static csf_status finish_readonly(sq_store *s, csf_error *err)
{
    sqlite3_extended_result_codes(s->db, 1);
    sqlite3_db_config(s->db, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, (int *)NULL);
    sqlite3_db_config(s->db, SQLITE_DBCONFIG_DEFENSIVE, 1, (int *)NULL);
    sqlite3_busy_timeout(s->db, 5000);
    char check[256] = "";
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "PRAGMA quick_check(1)", &st);
    if (rc == SQLITE_OK) {
        rc = step(s, st);
        if (rc == SQLITE_ROW) {
            col_text(st, 0, check, sizeof check);
            rc = SQLITE_OK;
        }
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "checking integrity");
    if (strcmp(check, "ok") != 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: database is corrupt (malformed: %s)",
                             s->path, check);
    int has_version = 0, version = 0;
    if (query_int(s->db, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND "
                         "name = 'schema_version'", &has_version, &rc) < 0)
        return fail(s, err, rc, "reading the schema");
    if (!has_version)
        return csf_error_set(err, CSF_E_STORE, "store %s: not a csfcal store (no schema_version "
                             "table)", s->path);
    if (query_int(s->db, "SELECT MAX(version) FROM schema_version", &version, &rc) < 0)
        return fail(s, err, rc, "reading the schema version");
    if (version > CSF_STORE_SCHEMA_VERSION)
        return csf_error_set(err, CSF_E_STORE, "store %s: schema version %d is newer than this "
                             "csfcal understands (%d); use a newer csfcal", s->path, version,
                             CSF_STORE_SCHEMA_VERSION);
    if (version < CSF_STORE_SCHEMA_VERSION)
        return csf_error_set(err, CSF_E_STORE, "store %s: schema version %d must be migrated to %d "
                             "before it can be read, which needs write access; open a writable "
                             "copy once", s->path, version, CSF_STORE_SCHEMA_VERSION);
    return CSF_OK;
}

static csf_status open_readonly_once(const char *path, csf_store **out, csf_error *err);

/* A store of an older schema on a writable file (the first listing after an upgrade) is migrated
 * by a writable open first; on read-only media it is refused with a message saying so. */
static csf_status sq_open_ro(const char *path, csf_store **out, csf_error *err)
{
    csf_status cs = open_readonly_once(path, out, err);
    if (cs != CSF_E_STORE || !err || !strstr(err->msg, "must be migrated") || access(path, W_OK) != 0)
        return cs;
    csf_store *w = NULL;
    cs = sq_open_rw(path, &w, err);
    if (w) sq_close(w);
    return cs == CSF_OK ? open_readonly_once(path, out, err) : cs;
}

static csf_status open_readonly_once(const char *path, csf_store **out, csf_error *err)
{
    csf_status as = check_open_args(path, out, err);
    if (as != CSF_OK) return as;
    struct stat stt;
    if (stat(path, &stt) != 0)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: does not exist (%s); no session has "
                             "been recorded there yet", path, strerror(errno));
    if (S_ISDIR(stt.st_mode))
        return csf_error_set(err, CSF_E_STORE, "store %s: is a folder, not a database file", path);
    if (!S_ISREG(stt.st_mode)) return not_regular(path, stt.st_mode, err);
    csf_status cs = check_magic(path, err);
    if (cs != CSF_OK) return cs;
    if (stt.st_size == 0)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: empty file, no sessions", path);
    sq_store *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "store %s: out of memory", path);
    copy_str(s->path, sizeof s->path, path);
    s->base.ops = &sqlite_ops;
    copy_str(s->base.path, sizeof s->base.path, path);
    int rc = sqlite3_open_v2(path, &s->db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, NULL);
    cs = rc == SQLITE_OK ? finish_readonly(s, err) : fail(s, err, rc, "opening");
    if (cs != CSF_OK && err && strstr(err->msg, "corrupt") == NULL && strstr(err->msg, "schema") == NULL &&
        strstr(err->msg, "csfcal store") == NULL) {
        /* A WAL store on read-only media: SQLite cannot create the -shm file next to it. Read
         * it as immutable (nothing can be writing to read-only media). */
        sqlite3_close(s->db);
        s->db = NULL;
        char uri[3200] = "file:";
        uri_path(path, uri + 5, sizeof uri - 5);
        strncat(uri, "?immutable=1", sizeof uri - strlen(uri) - 1);
        rc = sqlite3_open_v2(uri, &s->db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX, NULL);
        cs = rc == SQLITE_OK ? finish_readonly(s, err) : fail(s, err, rc, "opening read-only");
    }
    if (cs != CSF_OK) {
        sq_close(&s->base);
        return cs;
    }
    *out = &s->base;
    return CSF_OK;
}

static void sq_close(csf_store *base)
{
    sq_store *s = sq(base);
    if (!s) return;
    sqlite3_finalize(s->ins_trial);
    sqlite3_finalize(s->ins_reading);
    sqlite3_finalize(s->ins_frame);
    sqlite3_close(s->db);
    if (s->claims_fd > 0) close(s->claims_fd); /* gives back every claim of this handle */
    free(s->claims);
    free(s);
}

static int sq_schema_version(csf_store *base)
{
    sq_store *s = sq(base);
    int v = 0;
    if (!s || query_int(s->db, "SELECT MAX(version) FROM schema_version", &v, NULL) < 0) return -1;
    return v;
}

/* ---- sessions ---------------------------------------------------------------------------- */

static csf_status run_simple(sq_store *s, sqlite3_stmt *st, const char *what, csf_error *err)
{
    int rc = step(s, st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return fail(s, err, rc, what);
    return CSF_OK;
}

static csf_status upsert_named(sq_store *s, const char *table, const char *name,
                               const char *profile_id, int64_t *id, csf_error *err)
{
    char sql[256], what[64];
    snprintf(what, sizeof what, "recording a %s", table);
    sqlite3_stmt *st = NULL;
    snprintf(sql, sizeof sql, "SELECT id FROM %s WHERE name = ?", table);
    int rc = prepare(s, sql, &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, what);
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    if (rc == SQLITE_ROW) {
        int64_t found = sqlite3_column_int64(st, 0);
        sqlite3_finalize(st);
        if (id) *id = found;
        if (profile_id && !strcmp(table, "displays")) {
            rc = prepare(s, "UPDATE displays SET profile_id = ? WHERE id = ?", &st);
            if (rc != SQLITE_OK) return fail(s, err, rc, what);
            sqlite3_bind_text(st, 1, profile_id, -1, SQLITE_TRANSIENT);
            sqlite3_bind_int64(st, 2, found);
            return run_simple(s, st, what, err);
        }
        return CSF_OK;
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return fail(s, err, rc, what);
    char now[32];
    csf_store_utc_now(now);
    if (!strcmp(table, "displays")) {
        rc = prepare(s, "INSERT INTO displays (name, profile_id, created_utc) VALUES (?,?,?)", &st);
        if (rc != SQLITE_OK) return fail(s, err, rc, what);
        sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
        if (profile_id) sqlite3_bind_text(st, 2, profile_id, -1, SQLITE_TRANSIENT);
        else sqlite3_bind_null(st, 2);
        sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    } else {
        rc = prepare(s, "INSERT INTO observers (name, created_utc) VALUES (?,?)", &st);
        if (rc != SQLITE_OK) return fail(s, err, rc, what);
        sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, now, -1, SQLITE_TRANSIENT);
    }
    csf_status cs = run_simple(s, st, what, err);
    if (cs == CSF_OK && id) *id = sqlite3_last_insert_rowid(s->db);
    return cs;
}

static csf_status sq_upsert_display(csf_store *base, const char *name, const char *profile_id,
                                    int64_t *id, csf_error *err)
{
    sq_store *s = sq(base);
    csf_status cs = upsert_named(s, "displays", name, profile_id, id, err);
    if (cs != CSF_OK || !profile_id) return cs;
    /* Keep the history of profiles per display (one row per distinct profile id). */
    int64_t did = 0;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT id FROM displays WHERE name = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "recording a display profile");
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(st) == SQLITE_ROW) did = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    rc = prepare(s, "INSERT INTO display_profiles (display_id, profile_id, session_id, created_utc)"
                    " SELECT ?, ?, NULL, ? WHERE NOT EXISTS (SELECT 1 FROM display_profiles"
                    " WHERE display_id = ? AND profile_id = ?)", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "recording a display profile");
    char now[32];
    csf_store_utc_now(now);
    sqlite3_bind_int64(st, 1, did);
    sqlite3_bind_text(st, 2, profile_id, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 4, did);
    sqlite3_bind_text(st, 5, profile_id, -1, SQLITE_TRANSIENT);
    return run_simple(s, st, "recording a display profile", err);
}

static csf_status sq_upsert_observer(csf_store *base, const char *name, int64_t *id, csf_error *err)
{
    return upsert_named(sq(base), "observers", name, NULL, id, err);
}

/* The profile a session uses, in its display's history; the display's current profile only
 * when it has none (an old profile file must not replace a newer measurement). */
static csf_status link_profile(sq_store *s, const char *display, const char *profile_id,
                               csf_error *err)
{
    static const char *const sql[] = {
        "INSERT INTO display_profiles (display_id, profile_id, session_id, created_utc)"
        " SELECT id, ?2, NULL, ?3 FROM displays WHERE name = ?1 AND NOT EXISTS (SELECT 1 FROM"
        " display_profiles p WHERE p.display_id = displays.id AND p.profile_id = ?2)",
        "UPDATE displays SET profile_id = ?2 WHERE name = ?1 AND profile_id IS NULL",
    };
    char now[32];
    csf_store_utc_now(now);
    for (size_t i = 0; i < sizeof sql / sizeof sql[0]; i++) {
        sqlite3_stmt *st = NULL;
        int rc = prepare(s, sql[i], &st);
        if (rc != SQLITE_OK) return fail(s, err, rc, "recording a session's display profile");
        sqlite3_bind_text(st, 1, display, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, profile_id, -1, SQLITE_TRANSIENT);
        if (i == 0) sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
        csf_status cs = run_simple(s, st, "recording a session's display profile", err);
        if (cs != CSF_OK) return cs;
    }
    return CSF_OK;
}

static csf_status sq_begin_session(csf_store *base, const csf_store_session_new *nw, int64_t *id,
                                   csf_error *err)
{
    sq_store *s = sq(base);
    const char *kind = csf_session_kind_name(nw->kind), *observer = nw->observer, *display = nw->display;
    const char *profile_id = nw->profile_id, *settings_json = nw->settings_json;
    uint64_t seed = nw->seed;
    /* Observer and display rows are written in the same transaction as the session. */
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, "starting a session");
    csf_status cs = CSF_OK;
    if (observer && *observer) cs = upsert_named(s, "observers", observer, NULL, NULL, err);
    if (cs == CSF_OK && display && *display) cs = upsert_named(s, "displays", display, NULL, NULL, err);
    if (cs == CSF_OK && display && *display && profile_id) cs = link_profile(s, display, profile_id, err);
    sqlite3_stmt *st = NULL;
    if (cs == CSF_OK) {
        rc = prepare(s, "INSERT INTO sessions (kind, state, observer, display, settings_json, seed,"
                        " tool_version, created_utc, updated_utc, profile_id, uuid)"
                        " VALUES (?1,?10,?2,?3,?4,?5,?6,?7,?8,?9,?11)", &st);
        if (rc != SQLITE_OK) cs = fail(s, err, rc, "starting a session");
    }
    if (cs == CSF_OK) {
        char now[32];
        csf_store_utc_now(now);
        sqlite3_bind_text(st, 1, kind, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, observer ? observer : "", -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 3, display ? display : "", -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 4, settings_json ? settings_json : "{}", -1, SQLITE_TRANSIENT);
        /* Seeds are unsigned 64-bit; SQL integers are signed: stored as the same 64 bits. */
        sqlite3_bind_int64(st, 5, (sqlite3_int64)seed);
        sqlite3_bind_text(st, 6, nw->tool_version ? nw->tool_version : CSF_VERSION, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 7, nw->created_utc ? nw->created_utc : now, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 8, now, -1, SQLITE_TRANSIENT);
        if (profile_id) sqlite3_bind_text(st, 9, profile_id, -1, SQLITE_TRANSIENT);
        else sqlite3_bind_null(st, 9);
        sqlite3_bind_text(st, 10, csf_session_state_name(nw->state), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 11, nw->uuid, -1, SQLITE_TRANSIENT);
        cs = run_simple(s, st, "starting a session", err);
    }
    if (cs == CSF_OK) {
        int64_t new_id = sqlite3_last_insert_rowid(s->db);
        rc = exec_s(s, "COMMIT");
        if (rc != SQLITE_OK) {
            cs = fail(s, err, rc, "starting a session");
        } else {
            if (id) *id = new_id;
            /* A new id has no other holder; a session copied in a state other than running
             * (csf_store_push) is nobody's to hold. */
            return nw->state != CSF_SESSION_RUNNING ? CSF_OK : sq_claim(s, new_id, err);
        }
    }
    exec_s(s, "ROLLBACK");
    return cs;
}

#define SESSION_COLS CSF_STORE_SESSION_SELECT

/* The shared row mapping (results/store/rows.h) reads a statement's current row through these. */
static int cols_is_null(const csf_store_cols *c, int col)
{
    return sqlite3_column_type(c->res, col) == SQLITE_NULL;
}
static double cols_dbl(const csf_store_cols *c, int col) { return col_real(c->res, col); }
static int64_t cols_i64(const csf_store_cols *c, int col) { return sqlite3_column_int64(c->res, col); }
static const char *cols_txt(const csf_store_cols *c, int col)
{
    return (const char *)sqlite3_column_text(c->res, col);
}

static csf_store_cols cols(sqlite3_stmt *st)
{
    return (csf_store_cols){.res = st, .is_null = cols_is_null, .dbl = cols_dbl, .i64 = cols_i64,
                            .txt = cols_txt};
}

static int read_session_row(sqlite3_stmt *st, csf_session_info *o)
{
    csf_store_cols c = cols(st);
    return csf_store_row_session(&c, o);
}

static csf_status sq_get_session(csf_store *base, int64_t id, csf_session_info *out, csf_error *err)
{
    sq_store *s = sq(base);
    memset(out, 0, sizeof *out);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, SESSION_COLS " WHERE s.id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading a session");
    sqlite3_bind_int64(st, 1, id);
    rc = step(s, st);
    csf_status cs = CSF_OK;
    if (rc == SQLITE_ROW) {
        if (read_session_row(st, out) < 0) cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    } else if (rc == SQLITE_DONE) {
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", s->path, (long long)id);
    } else {
        cs = fail(s, err, rc, "reading a session");
    }
    sqlite3_finalize(st);
    return cs;
}

/* ---- session claims ---------------------------------------------------------------------
 * Two stations (or two csfcal processes) resuming one session at once would interleave their
 * trials: a session is claimed by the handle that starts or resumes it, as the PostgreSQL
 * backend does with advisory locks. The claim is an open-file-description lock on one byte of
 * the database file itself, at CLAIM_BASE + id: every name of the store (a symbolic link, a
 * hard link, a relative path) reaches the same lock, since the kernel keys it by the file, and
 * the kernel gives it back when the holder's process ends, however it ends. The bytes lie far
 * past SQLite's own lock bytes (at 1 GiB) and past any database's end, so the two never meet;
 * an OFD lock is not dropped when SQLite closes a descriptor of the same file. The same lock
 * works between machines where SQLite's own locking does (a network share with POSIX locks).
 * Who holds a claim (host, pid, time) is written for the message another station gets into
 * REALPATH-claims beside the resolved database file, CLAIM_REC bytes per session, opened without
 * following a link: a link planted there would otherwise have its target overwritten. */
#define CLAIM_REC 128
#define CLAIM_BASE ((off_t)1 << 40)
/* Keeps CLAIM_BASE + id and id * CLAIM_REC inside off_t; no store reaches it (an id past it is
 * one no session has, and the state change that follows says so). */
#define CLAIM_ID_MAX ((int64_t)1 << 54)

/* The database file, opened once for the claims' locks and kept open until the handle closes
 * (after SQLite has closed its own: closing any descriptor of the file would drop SQLite's
 * POSIX locks in this process). */
static int claims_fd(sq_store *s)
{
    if (s->claims_fd > 0) return s->claims_fd;
    int fd = open(s->path, O_RDWR | O_CLOEXEC);
    if (fd == 0) { /* never keep fd 0: 0 means "not open" here */
        int fd2 = fcntl(fd, F_DUPFD_CLOEXEC, 3);
        close(fd);
        fd = fd2;
    }
    if (fd > 0) s->claims_fd = fd;
    return fd;
}

/* PATH-claims for the holders' records, or -1 with errno (ELOOP for a link, EINVAL for
 * anything but a regular file). */
static int holders_fd(const sq_store *s, int create)
{
    /* Named after the file the store's path resolves to, so every name of it finds the records. */
    char p[PATH_MAX + 8];
    char *real = realpath(s->path, NULL);
    snprintf(p, sizeof p, "%s-claims", real ? real : s->path);
    free(real);
    int fd = open(p, O_RDWR | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | (create ? O_CREAT : 0),
                  0666);
    if (fd < 0) return -1;
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        errno = EINVAL;
        return -1;
    }
    return fd;
}

static int sq_has_claim(const sq_store *s, int64_t id)
{
    for (size_t i = 0; i < s->n_claims; i++)
        if (s->claims[i] == id) return 1;
    return 0;
}

static int claim_lock(int fd, int64_t id, short type)
{
    struct flock fl = {.l_type = type, .l_whence = SEEK_SET, .l_start = CLAIM_BASE + (off_t)id,
                       .l_len = 1};
    return fcntl(fd, F_OFD_SETLK, &fl);
}

/* The refusal for a claim another process holds, naming it from its record when there is one. */
static csf_status claim_refused(const sq_store *s, int64_t id, csf_error *err)
{
    char rec[CLAIM_REC + 1] = "", host[64] = "?", since[32] = "?";
    long pid = 0;
    int hfd = holders_fd(s, 0);
    if (hfd >= 0) {
        ssize_t got = pread(hfd, rec, CLAIM_REC, (off_t)(id * CLAIM_REC));
        rec[got > 0 ? got : 0] = '\0';
        close(hfd);
    }
    if (sscanf(rec, "station=%63s pid=%ld since=%31s", host, &pid, since) < 2)
        return csf_error_set(err, CSF_E_STORE, "store %s: session %lld is in use by another "
                             "csfcal process, which holds its claim (it left no record of who it "
                             "is in %s-claims). Two stations must not write one session. The "
                             "claim ends with that process; resume again when it has ended",
                             s->path, (long long)id, s->path);
    return csf_error_set(err, CSF_E_STORE, "store %s: session %lld is in use by another "
                         "station: %s, csfcal process %ld, since %s, holds its claim. Two "
                         "stations must not write one session. The claim ends with that "
                         "process (a crashed or killed csfcal has none); if it hangs, end it "
                         "(kill %ld on %s) and resume again", s->path, (long long)id, host,
                         pid, since, pid, host);
}

/* Writes who holds session id's claim into its record. */
static csf_status write_holder(const sq_store *s, int64_t id, csf_error *err)
{
    int hfd = holders_fd(s, 1);
    if (hfd < 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: cannot use %s-claims to record who "
                             "holds session %lld: %s%s", s->path, s->path, (long long)id,
                             strerror(errno), errno == ELOOP || errno == EINVAL
                             ? " (it is a symbolic link or not a regular file: csfcal does not "
                               "write through it; remove it)" : "");
    char host[64] = "", now[32], rec[CLAIM_REC];
    if (gethostname(host, sizeof host) != 0 || !host[0]) snprintf(host, sizeof host, "unknown");
    host[sizeof host - 1] = '\0';
    for (char *c = host; *c; c++)
        if (*c == ' ') *c = '_';
    csf_store_utc_now(now);
    memset(rec, ' ', sizeof rec);
    int n = snprintf(rec, sizeof rec, "station=%s pid=%ld since=%s\n", host, (long)getpid(), now);
    if (n > 0 && n < (int)sizeof rec) rec[n] = ' ';
    rec[sizeof rec - 1] = '\n';
    if (pwrite(hfd, rec, sizeof rec, (off_t)(id * CLAIM_REC)) != (ssize_t)sizeof rec) {
        /* Only the message for another station is lost: the lock holds. */
    }
    close(hfd);
    return CSF_OK;
}

/* Takes session id's claim, or says who holds it and what to do. */
static csf_status sq_claim(sq_store *s, int64_t id, csf_error *err)
{
    if (sq_has_claim(s, id) || id <= 0 || id >= CLAIM_ID_MAX) return CSF_OK;
    int fd = claims_fd(s);
    if (fd < 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: cannot open it to claim session %lld (%s)",
                             s->path, (long long)id, strerror(errno));
    if (claim_lock(fd, id, F_WRLCK) != 0) {
        if (errno != EAGAIN && errno != EACCES)
            return csf_error_set(err, CSF_E_STORE, "store %s: cannot claim session %lld (%s)",
                                 s->path, (long long)id, strerror(errno));
        return claim_refused(s, id, err);
    }
    csf_status ws = write_holder(s, id, err);
    if (ws != CSF_OK) {
        claim_lock(fd, id, F_UNLCK);
        return ws;
    }
    if (s->n_claims == s->cap_claims) {
        size_t nc = s->cap_claims ? 2 * s->cap_claims : 8;
        int64_t *c = realloc(s->claims, nc * sizeof *c);
        if (!c) {
            claim_lock(fd, id, F_UNLCK);
            return csf_error_set(err, CSF_E_NOMEM, "store: out of memory claiming a session");
        }
        s->claims = c;
        s->cap_claims = nc;
    }
    s->claims[s->n_claims++] = id;
    return CSF_OK;
}

static void sq_release(sq_store *s, int64_t id)
{
    for (size_t i = 0; i < s->n_claims; i++)
        if (s->claims[i] == id) {
            claim_lock(s->claims_fd, id, F_UNLCK);
            s->claims[i] = s->claims[--s->n_claims];
            return;
        }
}

/* A state change needs the session's claim (as on a server): resuming takes it, one held by
 * another station is refused; a state other than running gives it back. */
static csf_status sq_set_session_state(csf_store *base, int64_t id, csf_session_state state, csf_error *err)
{
    sq_store *s = sq(base);
    csf_status cls = sq_claim(s, id, err);
    if (cls != CSF_OK) return cls;
    if (state != CSF_SESSION_RUNNING) sq_release(s, id); /* also when the change fails */
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "UPDATE sessions SET state = ?, updated_utc = ? WHERE id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "changing a session's state");
    char now[32];
    csf_store_utc_now(now);
    sqlite3_bind_text(st, 1, csf_session_state_name(state), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, now, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 3, id);
    csf_status cs = run_simple(s, st, "changing a session's state", err);
    if (cs == CSF_OK && sqlite3_changes(s->db) == 0)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", s->path, (long long)id);
    return cs;
}

/* ---- person time -------------------------------------------------------------------------
 * A session's person time only grows: each run adds its own, and a copy from another store
 * raises it to the copy's total, so a second push adds nothing. A finished or aborted session is
 * closed: its person time stays as it is, as its rows do on a lab's server. */

/* Why an update of session id's person time changed no row: the session is missing or closed,
 * or it already has total_s or more (a raise with nothing to do; total_s NaN for an addition). */
static csf_status person_unchanged(sq_store *s, int64_t id, double total_s, csf_error *err)
{
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT state, person_s FROM sessions WHERE id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading a session's person time");
    sqlite3_bind_int64(st, 1, id);
    rc = step(s, st);
    char state[16] = "";
    double have_s = NAN;
    if (rc == SQLITE_ROW) {
        col_text(st, 0, state, sizeof state);
        have_s = col_real(st, 1);
    }
    sqlite3_finalize(st);
    if (rc == SQLITE_DONE)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", s->path, (long long)id);
    if (rc != SQLITE_ROW) return fail(s, err, rc, "reading a session's person time");
    if (have_s >= total_s) return CSF_OK;
    csf_session_state now_state = csf_session_state_from_name(state);
    if (csf_session_state_closed(now_state)) return csf_store_person_time_closed(err, s->path, id, now_state);
    return csf_error_set(err, CSF_E_STORE,
                         "store %s: the person time of session %lld did not "
                         "change",
                         s->path, (long long)id);
}

/* total_s NaN: add seconds; else raise to total_s. */
static csf_status sq_person_time(sq_store *s, int64_t id, double seconds, double total_s, csf_error *err)
{
    const char *what = "storing a session's person time";
    int add = isnan(total_s);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s,
                     add ? "UPDATE sessions SET person_s = COALESCE(person_s, 0) + ?1"
                           " WHERE id = ?2 AND state IN ('running', 'paused')"
                         : "UPDATE sessions SET person_s = ?1 WHERE id = ?2"
                           " AND state IN ('running', 'paused')"
                           " AND (person_s IS NULL OR person_s < ?1)",
                     &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, what);
    sqlite3_bind_double(st, 1, add ? seconds : total_s);
    sqlite3_bind_int64(st, 2, id);
    csf_status cs = run_simple(s, st, what, err);
    if (cs == CSF_OK && sqlite3_changes(s->db) == 0) cs = person_unchanged(s, id, total_s, err);
    return cs;
}

static csf_status sq_add_person_time(csf_store *base, int64_t id, double seconds, csf_error *err)
{
    return sq_person_time(sq(base), id, seconds, NAN, err);
}

static csf_status sq_raise_person_time(csf_store *base, int64_t id, double total_s, csf_error *err)
{
    return sq_person_time(sq(base), id, 0.0, total_s, err);
}

static int session_row(sqlite3_stmt *st, void *elem, int64_t session_id)
{
    (void)session_id;
    return read_session_row(st, elem);
}

static void session_elem_free(void *elem) { csf_session_info_free(elem); }

static csf_status sq_list_sessions(csf_store *base, csf_session_info **out, size_t *n, csf_error *err)
{
    sq_store *s = sq(base);
    static const row_query q = {
        .sql = SESSION_COLS " ORDER BY s.id", .elem_size = sizeof(csf_session_info),
        .row = session_row, .free_elem = session_elem_free,
        .what = "listing sessions", .oom_what = "listing sessions"};
    return query_rows(s, &q, 0, (void **)out, n, err);
}

static csf_status sq_session_times(csf_store *base, int64_t id, char created_utc[32],
                                   char updated_utc[32], csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT created_utc, updated_utc,"
                        " (SELECT MAX(stored_s) FROM trials WHERE session_id = s.id),"
                        " (SELECT MAX(stored_s) FROM readings WHERE session_id = s.id)"
                        " FROM sessions s WHERE id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading session times");
    sqlite3_bind_int64(st, 1, id);
    rc = step(s, st);
    if (rc != SQLITE_ROW) {
        sqlite3_finalize(st);
        if (rc == SQLITE_DONE)
            return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", s->path, (long long)id);
        return fail(s, err, rc, "reading session times");
    }
    char created[32], updated[32];
    col_text(st, 0, created, sizeof created);
    col_text(st, 1, updated, sizeof updated);
    /* ISO 8601 strings of one format compare like the times they name. */
    for (int c = 2; c <= 3; c++) {
        double t = col_real(st, c);
        char u[32];
        if (csf_store_format_unix(t, u)) {
            if (strcmp(u, updated) > 0) copy_str(updated, sizeof updated, u);
        }
    }
    sqlite3_finalize(st);
    if (created_utc) copy_str(created_utc, 32, created);
    if (updated_utc) copy_str(updated_utc, 32, updated);
    return CSF_OK;
}

/* ---- readings ---------------------------------------------------------------------------- */

static csf_status sq_add_reading(csf_store *base, const csf_reading *r, csf_error *err)
{
    sq_store *s = sq(base);
    if (!s->ins_reading)
        return csf_error_set(err, CSF_E_STORE, "store %s: opened read-only, cannot store a reading", s->path);
    sqlite3_stmt *st = s->ins_reading;
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
    sqlite3_bind_int64(st, 1, r->session_id);
    sqlite3_bind_int(st, 2, r->seq);
    sqlite3_bind_text(st, 3, r->channel, -1, SQLITE_TRANSIENT);
    sqlite3_bind_double(st, 4, r->drive01);
    bind_real(st, 5, r->lum_cdm2);
    if (r->has_xyz) {
        bind_real(st, 6, r->X);
        bind_real(st, 7, r->Y);
        bind_real(st, 8, r->Z);
    }
    bind_real(st, 9, isnan(r->t_s) ? 0.0 : r->t_s);
    sqlite3_bind_text(st, 10, csf_reading_status_name(r->status), -1, SQLITE_TRANSIENT);
    sqlite3_bind_double(st, 11, csf_store_unix_now_s());
    int rc = step(s, st);
    sqlite3_reset(st);
    if (rc == SQLITE_DONE) return CSF_OK;
    if ((rc & 0xff) == SQLITE_CONSTRAINT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: reading %d of session %lld refused "
                             "(session unknown or seq already stored): %s", s->path, r->seq,
                             (long long)r->session_id, sqlite3_errmsg(s->db));
    return fail(s, err, rc, "storing a photometer reading");
}

static int reading_row(sqlite3_stmt *st, void *elem, int64_t session_id)
{
    csf_store_cols c = cols(st);
    csf_store_row_reading(&c, session_id, elem);
    return 0;
}

static csf_status sq_get_readings(csf_store *base, int64_t session_id, csf_reading **out, size_t *n,
                                  csf_error *err)
{
    sq_store *s = sq(base);
    static const row_query q = {
        .sql = "SELECT " CSF_STORE_READING_COLS " FROM readings WHERE session_id = ? ORDER BY seq",
        .binds_session = 1, .elem_size = sizeof(csf_reading), .row = reading_row,
        .what = "reading photometer readings", .oom_what = "reading readings"};
    return query_rows(s, &q, session_id, (void **)out, n, err);
}

/* ---- trials ------------------------------------------------------------------------------ */

/* Arguments are checked in results/store/store.c; a store opened read-only has no insert statement. */
static csf_status check_trial(sq_store *s, const csf_trial *t, csf_error *err)
{
    (void)t;
    if (!s->ins_trial)
        return csf_error_set(err, CSF_E_STORE, "store %s: opened read-only, cannot store a trial", s->path);
    return CSF_OK;
}

/* One trial row; SQLITE_OK or the failing step's code. */
static int insert_trial(sq_store *s, const csf_trial *t)
{
    sqlite3_stmt *st = s->ins_trial;
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
    int i = 1;
    sqlite3_bind_int64(st, i++, t->session_id);
    sqlite3_bind_int(st, i++, t->seq);
    sqlite3_bind_text(st, i++, t->method, -1, SQLITE_TRANSIENT);
    bind_real(st, i++, t->freq_cpd);
    bind_real(st, i++, t->ecc_deg);
    sqlite3_bind_double(st, i++, isnan(t->polar_deg) ? 0.0 : t->polar_deg);
    sqlite3_bind_double(st, i++, isnan(t->orientation_deg) ? 0.0 : t->orientation_deg);
    sqlite3_bind_double(st, i++, isnan(t->sigma_deg) ? 0.0 : t->sigma_deg);
    sqlite3_bind_double(st, i++, isnan(t->velocity_dps) ? 0.0 : t->velocity_dps);
    sqlite3_bind_double(st, i++, isnan(t->mean_lum_cdm2) ? 0.0 : t->mean_lum_cdm2);
    sqlite3_bind_int(st, i++, t->is_catch != 0);
    sqlite3_bind_int(st, i++, t->is_practice != 0);
    bind_real(st, i++, t->contrast_requested);
    bind_real(st, i++, t->contrast_shown_mean);
    bind_real(st, i++, t->contrast_shown_max);
    sqlite3_bind_int(st, i++, t->frames_planned);
    sqlite3_bind_int(st, i++, t->frames_shown);
    sqlite3_bind_int(st, i++, t->frames_missed);
    sqlite3_bind_int(st, i++, t->signal_interval);
    sqlite3_bind_int(st, i++, t->response);
    bind_real(st, i++, t->rt_s);
    bind_real(st, i++, t->click_x_deg);
    bind_real(st, i++, t->click_y_deg);
    sqlite3_bind_int(st, i++, t->valid != 0);
    sqlite3_bind_text(st, i++, t->flags, -1, SQLITE_TRANSIENT);
    sqlite3_bind_double(st, i++, csf_store_unix_now_s());
    sqlite3_bind_int(st, i++, t->n_alternatives);
    bind_real(st, i++, t->has_onset ? t->onset_s : NAN);
    int rc = step(s, st);
    sqlite3_reset(st);
    return rc == SQLITE_DONE ? SQLITE_OK : rc;
}

static csf_status trial_failed(sq_store *s, const csf_trial *t, int rc, csf_error *err)
{
    if ((rc & 0xff) == SQLITE_CONSTRAINT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: trial %d of session %lld refused "
                             "(session unknown or seq already stored): %s", s->path, t->seq,
                             (long long)t->session_id, sqlite3_errmsg(s->db));
    return fail(s, err, rc, "storing a trial");
}

/* Frame interval rows of one trial inside the caller's transaction. */
static int insert_frames(sq_store *s, int64_t session_id, int trial_seq, const double *interval_s, int n)
{
    sqlite3_stmt *st = s->ins_frame;
    int rc = SQLITE_OK;
    for (int i = 0; i < n && rc == SQLITE_OK; i++) {
        sqlite3_reset(st);
        sqlite3_bind_int64(st, 1, session_id);
        sqlite3_bind_int(st, 2, trial_seq);
        sqlite3_bind_int(st, 3, i);
        sqlite3_bind_double(st, 4, isfinite(interval_s[i]) ? interval_s[i] : 0.0);
        rc = step(s, st);
        rc = rc == SQLITE_DONE ? SQLITE_OK : rc;
    }
    sqlite3_reset(st);
    return rc;
}

static csf_status sq_add_trial_frames(csf_store *base, const csf_trial *t, const double *interval_s,
                                      int n, csf_error *err)
{
    sq_store *s = sq(base);
    csf_error_clear(err);
    csf_status cs = check_trial(s, t, err);
    if (cs != CSF_OK) return cs;
    if (n == 0) { /* one row: one autocommit statement */
        int rc1 = insert_trial(s, t);
        return rc1 == SQLITE_OK ? CSF_OK : trial_failed(s, t, rc1, err);
    }
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, "storing a trial");
    rc = insert_trial(s, t);
    if (rc != SQLITE_OK) {
        cs = trial_failed(s, t, rc, err);
        exec_s(s, "ROLLBACK");
        return cs;
    }
    rc = insert_frames(s, t->session_id, t->seq, interval_s, n);
    if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
    if (rc != SQLITE_OK) {
        cs = fail(s, err, rc, "storing a trial's frame intervals");
        exec_s(s, "ROLLBACK");
        return cs;
    }
    return CSF_OK;
}

static int trial_row(sqlite3_stmt *st, void *elem, int64_t session_id)
{
    csf_store_cols c = cols(st);
    csf_store_row_trial(&c, session_id, elem);
    return 0;
}

static csf_status sq_get_trials(csf_store *base, int64_t session_id, csf_trial **out, size_t *n,
                                csf_error *err)
{
    sq_store *s = sq(base);
    static const row_query q = {
        .sql = "SELECT " CSF_STORE_TRIAL_COLS " FROM trials WHERE session_id = ? ORDER BY seq",
        .binds_session = 1, .elem_size = sizeof(csf_trial), .row = trial_row,
        .what = "reading trials", .oom_what = "reading trials"};
    return query_rows(s, &q, session_id, (void **)out, n, err);
}

static csf_status sq_add_frame_intervals(csf_store *base, int64_t session_id, int trial_seq,
                                         const double *interval_s, int n, csf_error *err)
{
    sq_store *s = sq(base);
    if (!s->ins_frame)
        return csf_error_set(err, CSF_E_STORE, "store %s: opened read-only, cannot store frame intervals", s->path);
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, "storing frame intervals");
    rc = insert_frames(s, session_id, trial_seq, interval_s, n);
    if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
    if (rc != SQLITE_OK) {
        csf_status cs = (rc & 0xff) == SQLITE_CONSTRAINT
            ? csf_error_set(err, CSF_E_INVALID_ARG, "store %s: frame intervals of trial %d of "
                            "session %lld refused (session unknown or already stored)", s->path,
                            trial_seq, (long long)session_id)
            : fail(s, err, rc, "storing frame intervals");
        exec_s(s, "ROLLBACK");
        return cs;
    }
    return CSF_OK;
}

static int interval_row(sqlite3_stmt *st, void *elem, int64_t session_id)
{
    (void)session_id;
    *(double *)elem = sqlite3_column_double(st, 0);
    return 0;
}

static csf_status sq_get_frame_intervals(csf_store *base, int64_t session_id, double **out, size_t *n,
                                         csf_error *err)
{
    sq_store *s = sq(base);
    static const row_query q = {
        .sql = "SELECT interval_s FROM frame_intervals WHERE session_id = ? ORDER BY trial_seq, idx",
        .binds_session = 1, .elem_size = sizeof(double), .row = interval_row,
        .what = "reading frame intervals", .oom_what = "reading frame intervals"};
    return query_rows(s, &q, session_id, (void **)out, n, err);
}

/* ---- thresholds -------------------------------------------------------------------------- */

static csf_status sq_put_thresholds(csf_store *base, int64_t session_id, const csf_threshold_row *rows,
                                    size_t n, csf_error *err)
{
    sq_store *s = sq(base);
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, "storing thresholds");
    sqlite3_stmt *st = NULL;
    int exists = 0;
    rc = prepare(s, "SELECT COUNT(*) FROM sessions WHERE id = ?", &st);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, session_id);
        if (sqlite3_step(st) == SQLITE_ROW) exists = sqlite3_column_int(st, 0);
        sqlite3_finalize(st);
        st = NULL;
    }
    if (rc == SQLITE_OK && !exists) {
        exec_s(s, "ROLLBACK");
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", s->path,
                             (long long)session_id);
    }
    if (rc == SQLITE_OK) rc = prepare(s, "DELETE FROM thresholds WHERE session_id = ?", &st);
    if (rc == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, session_id);
        rc = step(s, st);
        rc = rc == SQLITE_DONE ? SQLITE_OK : rc;
        sqlite3_finalize(st);
        st = NULL;
    }
    if (rc == SQLITE_OK)
        rc = prepare(s, "INSERT INTO thresholds (session_id, freq_cpd, ecc_deg, velocity_dps, lum_cdm2,"
                        " threshold_michelson, stderr_log10, n_trials) VALUES (?,?,?,?,?,?,?,?)", &st);
    for (size_t i = 0; i < n && rc == SQLITE_OK; i++) {
        const csf_threshold_row *r = &rows[i];
        sqlite3_reset(st);
        sqlite3_bind_int64(st, 1, session_id);
        bind_real(st, 2, r->freq_cpd);
        bind_real(st, 3, r->ecc_deg);
        sqlite3_bind_double(st, 4, isnan(r->velocity_dps) ? 0.0 : r->velocity_dps);
        sqlite3_bind_double(st, 5, isnan(r->lum_cdm2) ? 0.0 : r->lum_cdm2);
        /* INFINITY (never visible) is a valid IEEE value in SQLite and PostgreSQL alike. */
        bind_real(st, 6, r->threshold);
        bind_real(st, 7, r->stderr_log10);
        sqlite3_bind_int(st, 8, r->n_trials);
        rc = step(s, st);
        rc = rc == SQLITE_DONE ? SQLITE_OK : rc;
    }
    sqlite3_finalize(st);
    if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
    if (rc != SQLITE_OK) {
        csf_status cs = fail(s, err, rc, "storing thresholds");
        exec_s(s, "ROLLBACK");
        return cs;
    }
    return CSF_OK;
}

static int threshold_row(sqlite3_stmt *st, void *elem, int64_t session_id)
{
    (void)session_id;
    csf_store_cols c = cols(st);
    csf_store_row_threshold(&c, elem);
    return 0;
}

static csf_status sq_get_thresholds(csf_store *base, int64_t session_id, csf_threshold_row **out,
                                    size_t *n, csf_error *err)
{
    sq_store *s = sq(base);
    static const row_query q = {
        .sql = "SELECT " CSF_STORE_THRESHOLD_COLS " FROM thresholds WHERE session_id = ?"
        " ORDER BY lum_cdm2, velocity_dps, ecc_deg, freq_cpd",
        .binds_session = 1, .elem_size = sizeof(csf_threshold_row), .row = threshold_row,
        .what = "reading thresholds", .oom_what = "reading thresholds"};
    return query_rows(s, &q, session_id, (void **)out, n, err);
}

/* ---- artifacts --------------------------------------------------------------------------- */

/* Value of a "key = value" line in the header of a display profile text (docs/display-profile.md),
 * looked for in the first 4 KiB only; "" when absent. */
static void profile_key(const char *text, size_t len, const char *key, char *out, size_t cap)
{
    out[0] = '\0';
    size_t lim = len < 4096 ? len : 4096, kl = strlen(key);
    for (size_t i = 0; i < lim; i++) {
        if ((i == 0 || text[i - 1] == '\n') && i + kl + 3 <= lim && memcmp(text + i, key, kl) == 0 &&
            memcmp(text + i + kl, " = ", 3) == 0) {
            size_t j = i + kl + 3, o = 0;
            while (j < lim && text[j] != '\n' && text[j] != '\r' && text[j] != '\0' && o + 1 < cap)
                out[o++] = text[j++];
            out[o] = '\0';
            return;
        }
    }
}

/* A display profile written by a session is also recorded as that display's current profile. */
static int record_profile(sq_store *s, int64_t session_id, const void *blob, size_t len)
{
    const char *text = blob;
    const char magic[] = "csfcal-display-profile";
    if (!blob || len < sizeof magic || memcmp(text, magic, sizeof magic - 1) != 0) return SQLITE_OK;
    char id[128], display[256];
    profile_key(text, len, "id", id, sizeof id);
    profile_key(text, len, "display", display, sizeof display);
    if (!id[0] || !display[0]) return SQLITE_OK;
    char now[32];
    csf_store_utc_now(now);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "INSERT INTO displays (name, profile_id, created_utc) SELECT ?, ?, ?"
                        " WHERE NOT EXISTS (SELECT 1 FROM displays WHERE name = ?)", &st);
    if (rc != SQLITE_OK) return rc;
    sqlite3_bind_text(st, 1, display, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, id, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, display, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return rc;
    rc = prepare(s, "UPDATE displays SET profile_id = ? WHERE name = ?", &st);
    if (rc != SQLITE_OK) return rc;
    sqlite3_bind_text(st, 1, id, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, display, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return rc;
    rc = prepare(s, "INSERT INTO display_profiles (display_id, profile_id, session_id, created_utc)"
                    " SELECT id, ?, ?, ? FROM displays WHERE name = ?", &st);
    if (rc != SQLITE_OK) return rc;
    sqlite3_bind_text(st, 1, id, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 2, session_id);
    sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, display, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? SQLITE_OK : rc;
}

/* The writer of a file and the code that produced its bytes may each record it (display
 * calibrate stores the profile text, then the command that saved it the path): the second call
 * completes the first call's row. *merged = 1 when a row was completed. */
static int complete_half_record(sq_store *s, int64_t session_id, const char *kind,
                                const char *path, const void *blob, size_t len, int *merged)
{
    *merged = 0;
    int has_path = path && *path;
    if (has_path == (blob != NULL)) return SQLITE_OK; /* a whole record, or nothing to add */
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, has_path
                     ? "UPDATE artifacts SET path = ?3 WHERE id = (SELECT id FROM artifacts WHERE"
                       " session_id = ?1 AND kind = ?2 AND path = '' AND content IS NOT NULL"
                       " ORDER BY id DESC LIMIT 1)"
                     : "UPDATE artifacts SET content = ?3, size_bytes = ?4 WHERE id = (SELECT id"
                       " FROM artifacts WHERE session_id = ?1 AND kind = ?2 AND path <> ''"
                       " AND content IS NULL ORDER BY id DESC LIMIT 1)", &st);
    if (rc != SQLITE_OK) return rc;
    sqlite3_bind_int64(st, 1, session_id);
    sqlite3_bind_text(st, 2, kind, -1, SQLITE_TRANSIENT);
    if (has_path) {
        sqlite3_bind_text(st, 3, path, -1, SQLITE_TRANSIENT);
    } else {
        sqlite3_bind_blob64(st, 3, blob, len, SQLITE_STATIC);
        sqlite3_bind_int64(st, 4, (sqlite3_int64)len);
    }
    rc = step(s, st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return rc;
    *merged = sqlite3_changes(s->db) > 0;
    return SQLITE_OK;
}

static csf_status sq_add_artifact(csf_store *base, int64_t session_id, const char *kind,
                                  const char *path, const void *blob, size_t len, csf_error *err)
{
    sq_store *s = sq(base);
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, "storing an artifact");
    int merged = 0;
    rc = complete_half_record(s, session_id, kind, path, blob, len, &merged);
    sqlite3_stmt *st = NULL;
    if (rc == SQLITE_OK && !merged)
        rc = prepare(s, "INSERT INTO artifacts (session_id, kind, path, size_bytes, content, created_utc)"
                        " VALUES (?,?,?,?,?,?)", &st);
    if (rc == SQLITE_OK && !merged) {
        char now[32];
        csf_store_utc_now(now);
        sqlite3_bind_int64(st, 1, session_id);
        sqlite3_bind_text(st, 2, kind, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 3, path ? path : "", -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(st, 4, (sqlite3_int64)len);
        if (blob) sqlite3_bind_blob64(st, 5, blob, len, SQLITE_STATIC);
        else sqlite3_bind_null(st, 5);
        sqlite3_bind_text(st, 6, now, -1, SQLITE_TRANSIENT);
        rc = step(s, st);
        rc = rc == SQLITE_DONE ? SQLITE_OK : rc;
    }
    sqlite3_finalize(st);
    if (rc == SQLITE_OK && !strcmp(kind, "profile")) rc = record_profile(s, session_id, blob, len);
    if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
    if (rc == SQLITE_OK) return CSF_OK;
    csf_status cs = (rc & 0xff) == SQLITE_CONSTRAINT
        ? csf_error_set(err, CSF_E_NOT_FOUND, "store %s: artifact refused: no session %lld",
                        s->path, (long long)session_id)
        : fail(s, err, rc, "storing an artifact");
    exec_s(s, "ROLLBACK");
    return cs;
}

static csf_status sq_display_profile_id(csf_store *base, const char *display, char *out, size_t cap,
                                        csf_error *err)
{
    sq_store *s = sq(base);
    out[0] = '\0';
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT profile_id FROM displays WHERE name = ? AND profile_id IS NOT NULL", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading a display's profile");
    sqlite3_bind_text(st, 1, display, -1, SQLITE_TRANSIENT);
    rc = sqlite3_step(st);
    csf_status cs = CSF_OK;
    if (rc == SQLITE_ROW) col_text(st, 0, out, cap);
    else if (rc == SQLITE_DONE)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no profile recorded for display '%s'",
                           s->path, display);
    else cs = fail(s, err, rc, "reading a display's profile");
    sqlite3_finalize(st);
    return cs;
}

static csf_status sq_get_artifact(csf_store *base, int64_t session_id, const char *kind,
                                  void **blob, size_t *len, char *path_out, size_t path_len,
                                  csf_error *err)
{
    sq_store *s = sq(base);
    *blob = NULL;
    *len = 0;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT content, path FROM artifacts WHERE session_id = ? AND kind = ?"
                        " ORDER BY CASE WHEN content IS NULL THEN 1 ELSE 0 END, id DESC LIMIT 1", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading an artifact");
    sqlite3_bind_int64(st, 1, session_id);
    sqlite3_bind_text(st, 2, kind, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    if (rc == SQLITE_DONE) {
        sqlite3_finalize(st);
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: session %lld has no '%s' artifact",
                             s->path, (long long)session_id, kind);
    }
    if (rc != SQLITE_ROW) {
        sqlite3_finalize(st);
        return fail(s, err, rc, "reading an artifact");
    }
    int nb = sqlite3_column_bytes(st, 0);
    const void *p = sqlite3_column_blob(st, 0);
    /* One spare NUL byte so text artifacts (profiles) can be parsed as strings. */
    unsigned char *copy = malloc((size_t)nb + 1);
    if (!copy) {
        sqlite3_finalize(st);
        return csf_error_set(err, CSF_E_NOMEM, "store: out of memory reading an artifact");
    }
    if (nb > 0 && p) memcpy(copy, p, (size_t)nb);
    copy[nb] = '\0';
    if (path_out && path_len) col_text(st, 1, path_out, path_len);
    sqlite3_finalize(st);
    *blob = copy;
    *len = (size_t)nb;
    return CSF_OK;
}

/* ---- studies and participants ------------------------------------------------------------ */

static csf_status sq_create_study(csf_store *base, const char *name, const char *design_json,
                                  int64_t *id, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "INSERT INTO studies (name, design_json, created_utc) VALUES (?,?,?)", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "creating a study");
    char now[32];
    csf_store_utc_now(now);
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, design_json ? design_json : "{}", -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    sqlite3_finalize(st);
    if ((rc & 0xff) == SQLITE_CONSTRAINT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: a study named '%s' already exists",
                             s->path, name);
    if (rc != SQLITE_DONE) return fail(s, err, rc, "creating a study");
    if (id) *id = sqlite3_last_insert_rowid(s->db);
    return CSF_OK;
}

static csf_status sq_find_study(csf_store *base, const char *name, int64_t *id, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT id FROM studies WHERE name = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "finding a study");
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    csf_status cs = CSF_OK;
    if (rc == SQLITE_ROW) {
        if (id) *id = sqlite3_column_int64(st, 0);
    } else if (rc == SQLITE_DONE) {
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no study named '%s'", s->path, name);
    } else {
        cs = fail(s, err, rc, "finding a study");
    }
    sqlite3_finalize(st);
    return cs;
}

static csf_status sq_add_participant(csf_store *base, int64_t study_id, const char *code,
                                     int64_t *id, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "INSERT INTO participants (study_id, code, created_utc) VALUES (?,?,?)", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "adding a participant");
    char now[32];
    csf_store_utc_now(now);
    sqlite3_bind_int64(st, 1, study_id);
    sqlite3_bind_text(st, 2, code, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    sqlite3_finalize(st);
    if ((rc & 0xff) == SQLITE_CONSTRAINT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: participant '%s' refused (study %lld "
                             "unknown or code already used in it)", s->path, code, (long long)study_id);
    if (rc != SQLITE_DONE) return fail(s, err, rc, "adding a participant");
    if (id) *id = sqlite3_last_insert_rowid(s->db);
    return CSF_OK;
}

static csf_status sq_count_participants(csf_store *base, int64_t study_id, int *n, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT COUNT(*) FROM participants WHERE study_id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "counting participants");
    sqlite3_bind_int64(st, 1, study_id);
    rc = step(s, st);
    if (rc == SQLITE_ROW) *n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? CSF_OK : fail(s, err, rc, "counting participants");
}

static csf_status sq_link_session_participant(csf_store *base, int64_t session_id,
                                              int64_t participant_id, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "INSERT INTO session_participants (session_id, participant_id) VALUES (?,?)", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "linking a session to a participant");
    sqlite3_bind_int64(st, 1, session_id);
    sqlite3_bind_int64(st, 2, participant_id);
    rc = step(s, st);
    sqlite3_finalize(st);
    if ((rc & 0xff) == SQLITE_CONSTRAINT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: session %lld cannot be linked to "
                             "participant %lld (unknown, or already linked)", s->path,
                             (long long)session_id, (long long)participant_id);
    return rc == SQLITE_DONE ? CSF_OK : fail(s, err, rc, "linking a session to a participant");
}

static csf_status sq_list_artifacts(csf_store *base, int64_t session_id, csf_store_artifact **out,
                                    size_t *n, csf_error *err)
{
    sq_store *s = sq(base);
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT kind, path, content FROM artifacts WHERE session_id = ? ORDER BY id", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "listing artifacts");
    sqlite3_bind_int64(st, 1, session_id);
    csf_store_artifact *list = NULL;
    size_t cnt = 0, cap = 0;
    csf_status cs = CSF_OK;
    while (cs == CSF_OK && (rc = step(s, st)) == SQLITE_ROW) {
        if (grow((void **)&list, &cap, cnt, sizeof *list) < 0) {
            cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory listing artifacts");
            break;
        }
        csf_store_artifact *a = &list[cnt];
        memset(a, 0, sizeof *a);
        col_text(st, 0, a->kind, sizeof a->kind);
        col_text(st, 1, a->path, sizeof a->path);
        if (sqlite3_column_type(st, 2) != SQLITE_NULL) {
            size_t nb = (size_t)sqlite3_column_bytes(st, 2);
            const void *b = sqlite3_column_blob(st, 2);
            a->blob = malloc(nb + 1);
            if (!a->blob) cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory listing artifacts");
            else if (nb) memcpy(a->blob, b, nb);
            a->len = nb;
        }
        cnt++;
    }
    if (cs == CSF_OK && rc != SQLITE_DONE) cs = fail(s, err, rc, "listing artifacts");
    sqlite3_finalize(st);
    if (cs != CSF_OK) {
        csf_store_artifacts_free(list, cnt);
        return cs;
    }
    *out = list;
    *n = cnt;
    return CSF_OK;
}

static csf_status sq_session_participant(csf_store *base, int64_t session_id, char study[256],
                                         char **design_json, char code[64], csf_error *err)
{
    sq_store *s = sq(base);
    *design_json = NULL;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT st.name, st.design_json, p.code FROM session_participants sp"
                        " JOIN participants p ON p.id = sp.participant_id"
                        " JOIN studies st ON st.id = p.study_id WHERE sp.session_id = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading a session's participant");
    sqlite3_bind_int64(st, 1, session_id);
    rc = step(s, st);
    csf_status cs = CSF_OK;
    if (rc == SQLITE_ROW) {
        col_text(st, 0, study, 256);
        const unsigned char *d = sqlite3_column_text(st, 1);
        *design_json = strdup(d ? (const char *)d : "{}");
        col_text(st, 2, code, 64);
        if (!*design_json) cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    } else if (rc == SQLITE_DONE) {
        cs = CSF_E_NOT_FOUND;
    } else {
        cs = fail(s, err, rc, "reading a session's participant");
    }
    sqlite3_finalize(st);
    return cs;
}

static csf_status sq_link_named(csf_store *base, int64_t session_id, const char *study,
                                const char *design_json, const char *code, csf_error *err)
{
    sq_store *s = sq(base);
    static const char *const sql[] = {
        "INSERT INTO studies (name, design_json, created_utc) VALUES (?1, ?2, ?3)"
        " ON CONFLICT DO NOTHING",
        "INSERT INTO participants (study_id, code, created_utc) SELECT id, ?4, ?3 FROM studies"
        " WHERE name = ?1 ON CONFLICT DO NOTHING",
        "INSERT INTO session_participants (session_id, participant_id) SELECT ?5, p.id FROM"
        " participants p JOIN studies st ON st.id = p.study_id WHERE st.name = ?1 AND"
        " p.code = ?4 ON CONFLICT DO NOTHING",
    };
    const char *what = "linking a session to a participant";
    int rc = exec_s(s, "BEGIN IMMEDIATE");
    if (rc != SQLITE_OK) return fail(s, err, rc, what);
    char now[32];
    csf_store_utc_now(now);
    for (size_t i = 0; rc == SQLITE_OK && i < sizeof sql / sizeof sql[0]; i++) {
        sqlite3_stmt *st = NULL;
        rc = prepare(s, sql[i], &st);
        if (rc != SQLITE_OK) break;
        sqlite3_bind_text(st, 1, study, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, design_json ? design_json : "{}", -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 3, now, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 4, code, -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(st, 5, session_id);
        rc = step(s, st);
        sqlite3_finalize(st);
        rc = rc == SQLITE_DONE ? SQLITE_OK : rc;
    }
    if (rc == SQLITE_OK) rc = exec_s(s, "COMMIT");
    if (rc == SQLITE_OK) return CSF_OK;
    csf_status cs = fail(s, err, rc, what);
    exec_s(s, "ROLLBACK");
    return cs;
}

static csf_status sq_find_session_uuid(csf_store *base, const char *uuid, int64_t *id,
                                       csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT id FROM sessions WHERE uuid = ?", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "finding a session");
    sqlite3_bind_text(st, 1, uuid, -1, SQLITE_TRANSIENT);
    rc = step(s, st);
    if (rc == SQLITE_ROW) *id = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    if (rc == SQLITE_ROW) return CSF_OK;
    return rc == SQLITE_DONE ? CSF_E_NOT_FOUND : fail(s, err, rc, "finding a session");
}

static csf_status sq_set_session_uuid(csf_store *base, int64_t id, const char *uuid, csf_error *err)
{
    sq_store *s = sq(base);
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "UPDATE sessions SET uuid = ? WHERE id = ? AND uuid IS NULL", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "giving a session its uuid");
    sqlite3_bind_text(st, 1, uuid, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 2, id);
    return run_simple(s, st, "giving a session its uuid", err);
}

static csf_status sq_get_trial_frames(csf_store *base, int64_t session_id, int trial_seq,
                                      double **out, size_t *n, csf_error *err)
{
    sq_store *s = sq(base);
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    int rc = prepare(s, "SELECT interval_s FROM frame_intervals WHERE session_id = ? AND"
                        " trial_seq = ? ORDER BY idx", &st);
    if (rc != SQLITE_OK) return fail(s, err, rc, "reading frame intervals");
    sqlite3_bind_int64(st, 1, session_id);
    sqlite3_bind_int(st, 2, trial_seq);
    size_t cap = 0;
    while ((rc = step(s, st)) == SQLITE_ROW) {
        if (grow((void **)out, &cap, *n, sizeof **out) < 0) {
            sqlite3_finalize(st);
            free(*out);
            *out = NULL;
            *n = 0;
            return csf_error_set(err, CSF_E_NOMEM, "store: out of memory reading frame intervals");
        }
        (*out)[(*n)++] = sqlite3_column_double(st, 0);
    }
    sqlite3_finalize(st);
    if (rc == SQLITE_DONE) return CSF_OK;
    free(*out);
    *out = NULL;
    *n = 0;
    return fail(s, err, rc, "reading frame intervals");
}

static const csf_store_ops sqlite_ops = {
    .name = "sqlite",
    .close = sq_close,
    .schema_version = sq_schema_version,
    .begin_session = sq_begin_session,
    .find_session_uuid = sq_find_session_uuid,
    .set_session_uuid = sq_set_session_uuid,
    .get_trial_frames = sq_get_trial_frames,
    .get_session = sq_get_session,
    .set_session_state = sq_set_session_state,
    .list_sessions = sq_list_sessions,
    .add_person_time = sq_add_person_time,
    .raise_person_time = sq_raise_person_time,
    .session_times = sq_session_times,
    .add_reading = sq_add_reading,
    .get_readings = sq_get_readings,
    .add_trial_frames = sq_add_trial_frames,
    .get_trials = sq_get_trials,
    .add_frame_intervals = sq_add_frame_intervals,
    .get_frame_intervals = sq_get_frame_intervals,
    .put_thresholds = sq_put_thresholds,
    .get_thresholds = sq_get_thresholds,
    .add_artifact = sq_add_artifact,
    .get_artifact = sq_get_artifact,
    .upsert_display = sq_upsert_display,
    .display_profile_id = sq_display_profile_id,
    .upsert_observer = sq_upsert_observer,
    .create_study = sq_create_study,
    .find_study = sq_find_study,
    .add_participant = sq_add_participant,
    .count_participants = sq_count_participants,
    .link_session_participant = sq_link_session_participant,
    .list_artifacts = sq_list_artifacts,
    .session_participant = sq_session_participant,
    .link_named = sq_link_named,
};

csf_status csf_store_sqlite_open(const char *path, int readonly, csf_store **out, csf_error *err)
{
    return readonly ? sq_open_ro(path, out, err) : sq_open_rw(path, out, err);
}
