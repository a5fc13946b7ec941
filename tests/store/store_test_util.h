/* Helpers shared by the store tests: temporary folders and a filled-in trial. */
#ifndef CSF_STORE_TEST_UTIL_H
#define CSF_STORE_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <libpq-fe.h>
#include <sqlite3.h>

#include "core/rng.h"
#include "results/store/store.h"
#include "results/store/internal.h"

/* Makes a fresh folder under $TMPDIR (or /tmp); path written to dir. */
static inline int tmp_dir(char *dir, size_t cap, const char *tag)
{
    const char *base = getenv("TMPDIR");
    snprintf(dir, cap, "%s/csfstore-%s-XXXXXX", base && *base ? base : "/tmp", tag);
    return mkdtemp(dir) ? 0 : -1;
}

static inline void rm_rf(const char *dir)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "warning: could not remove %s\n", dir);
}

/* A whole file, NUL-terminated, malloc'd (NULL when it cannot be read); its length in *len. */
static inline char *test_read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = buf ? fread(buf, 1, (size_t)n, f) : 0;
    if (buf) buf[got] = '\0';
    fclose(f);
    if (len) *len = got;
    return buf;
}

/* SQL run on an SQLite file directly, past the store (fixtures of old schemas, foreign files,
 * damage); SQLite's result code (SQLITE_OK = 0), the message on stderr when it failed. */
static inline int test_sqlite_exec(const char *path, const char *sql)
{
    sqlite3 *db = NULL;
    int rc = sqlite3_open(path, &db);
    char *msg = NULL;
    if (rc == SQLITE_OK) rc = sqlite3_exec(db, sql, NULL, NULL, &msg);
    if (rc != SQLITE_OK) fprintf(stderr, "sql failed: %s\n", msg ? msg : sqlite3_errmsg(db));
    sqlite3_free(msg);
    sqlite3_close(db);
    return rc;
}

/* The backend under test: CSF_TEST_BACKEND=postgresql (set by meson for the *_pg tests, which
 * run inside tests/store/pg_run.sh) runs the test against a real server; SQLite otherwise. */
static inline int test_pg(void)
{
    const char *b = getenv("CSF_TEST_BACKEND");
    return b && !strcmp(b, "postgresql");
}

/* A PostgreSQL test without pg_run.sh around it has no server: that is a skip, not a pass. */
static inline void test_pg_require(void)
{
    if (test_pg() && (!getenv("CSF_TEST_PG") || !getenv("CSF_TEST_PG_DIR"))) {
        fprintf(stderr, "SKIP: no test server (run through tests/store/pg_run.sh)\n");
        exit(77);
    }
}

/* Runs one SQL command on the test server as its superuser; 0 on success. */
static inline int test_pg_admin(const char *db, const char *sql)
{
    char uri[1024];
    snprintf(uri, sizeof uri, "postgresql:///%s?host=%s&user=csfcal_admin", db,
             getenv("CSF_TEST_PG_DIR"));
    PGconn *c = PQconnectdb(uri);
    int ok = PQstatus(c) == CONNECTION_OK;
    if (ok) {
        PGresult *r = PQexec(c, sql);
        ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
        if (!ok) fprintf(stderr, "test server: %s: %s", sql, PQerrorMessage(c));
        PQclear(r);
    }
    PQfinish(c);
    return ok ? 0 : -1;
}

/* A fresh store location named name: dir/name for SQLite; for PostgreSQL a new empty database
 * (one per location, so tests do not see each other's rows) and its URI. */
static inline int test_store_location(const char *dir, const char *name, char *out, size_t cap)
{
    if (!test_pg()) {
        snprintf(out, cap, "%s/%s", dir, name);
        return 0;
    }
    static int n = 0;
    char db[64], sql[128];
    snprintf(db, sizeof db, "t%d_%d", (int)getpid(), n++);
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", db);
    if (test_pg_admin("csfcal", sql) < 0) return -1;
    snprintf(out, cap, "postgresql:///%s?host=%s&user=csfcal_admin", db, getenv("CSF_TEST_PG_DIR"));
    return 0;
}

/* First column of the first row of sql as an integer, read on the side (not through the store
 * interface), from either backend; -1 on any failure. */
static inline long long test_query_int(csf_store *s, const char *location, const char *sql)
{
    long long v = -1;
    if (csf_store_db(s)) {
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(csf_store_db(s), sql, -1, &st, NULL) == SQLITE_OK &&
            sqlite3_step(st) == SQLITE_ROW)
            v = sqlite3_column_int64(st, 0);
        sqlite3_finalize(st);
        return v;
    }
    PGconn *c = PQconnectdb(location);
    PGresult *r = PQstatus(c) == CONNECTION_OK ? PQexec(c, sql) : NULL;
    if (r && PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) > 0)
        v = strtoll(PQgetvalue(r, 0, 0), NULL, 10);
    PQclear(r);
    PQfinish(c);
    return v;
}

/* Opens the store at loc or ends this (forked) process with status 3, saying why: a station's
 * open in the multi-process tests. */
static inline csf_store *test_open_or_exit(const char *loc, const char *who)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(loc, &s, &err) != CSF_OK) {
        fprintf(stderr, "%s: %s\n", who, err.msg);
        _exit(3);
    }
    return s;
}

/* A trial whose every field depends on (seed, seq), so a wrong column shows up as a mismatch. */
static inline csf_trial make_trial(int64_t session_id, int seq, uint64_t seed)
{
    csf_trial t;
    memset(&t, 0, sizeof t);
    t.session_id = session_id;
    t.seq = seq;
    snprintf(t.method, sizeof t.method, "%s", seq % 2 ? "fade" : "2afc");
    t.freq_cpd = 0.5 + 20.0 * csf_rng_uniform(seed, 1, (uint64_t)seq);
    t.ecc_deg = 30.0 * csf_rng_uniform(seed, 2, (uint64_t)seq);
    t.polar_deg = 360.0 * csf_rng_uniform(seed, 3, (uint64_t)seq);
    t.orientation_deg = 180.0 * csf_rng_uniform(seed, 4, (uint64_t)seq);
    t.sigma_deg = 0.5 + csf_rng_uniform(seed, 5, (uint64_t)seq);
    t.velocity_dps = 4.0 * csf_rng_uniform(seed, 6, (uint64_t)seq);
    t.mean_lum_cdm2 = 50.0 + seq % 7;
    t.is_catch = seq % 11 == 3;
    t.is_practice = seq < 2;
    t.contrast_requested = pow(10.0, -3.0 + 2.0 * csf_rng_uniform(seed, 7, (uint64_t)seq));
    t.contrast_shown_mean = t.contrast_requested * 0.99;
    t.contrast_shown_max = t.contrast_requested * 1.01;
    t.frames_planned = 30 + seq % 5;
    t.frames_missed = seq % 13 == 0 ? 2 : 0;
    t.frames_shown = t.frames_planned - t.frames_missed;
    t.signal_interval = seq % 2 ? 0 : 1 + seq % 3 % 2;
    t.response = seq % 3 == 0;
    t.rt_s = seq % 17 == 5 ? NAN : 0.3 + csf_rng_uniform(seed, 8, (uint64_t)seq);
    t.click_x_deg = seq % 4 == 0 ? NAN : 10.0 * csf_rng_normal(seed, 9, (uint64_t)seq);
    t.click_y_deg = seq % 4 == 0 ? NAN : 10.0 * csf_rng_normal(seed, 10, (uint64_t)seq);
    t.valid = t.frames_missed == 0;
    snprintf(t.flags, sizeof t.flags, "%s", t.frames_missed ? "missed_frames,late" : "");
    t.has_onset = seq % 5 != 1; /* some trials keep no onset (stored NULL) */
    t.onset_s = t.has_onset ? 2.5 * seq + csf_rng_uniform(seed, 11, (uint64_t)seq) : 0.0;
    return t;
}

static inline int same_double(double a, double b)
{
    return (isnan(a) && isnan(b)) || a == b;
}

static inline int trials_equal(const csf_trial *a, const csf_trial *b)
{
    return a->session_id == b->session_id && a->seq == b->seq && !strcmp(a->method, b->method) &&
           same_double(a->freq_cpd, b->freq_cpd) && same_double(a->ecc_deg, b->ecc_deg) &&
           same_double(a->polar_deg, b->polar_deg) && same_double(a->orientation_deg, b->orientation_deg) &&
           same_double(a->sigma_deg, b->sigma_deg) && same_double(a->velocity_dps, b->velocity_dps) &&
           same_double(a->mean_lum_cdm2, b->mean_lum_cdm2) && a->is_catch == b->is_catch &&
           a->is_practice == b->is_practice && same_double(a->contrast_requested, b->contrast_requested) &&
           same_double(a->contrast_shown_mean, b->contrast_shown_mean) &&
           same_double(a->contrast_shown_max, b->contrast_shown_max) &&
           a->frames_planned == b->frames_planned && a->frames_shown == b->frames_shown &&
           a->frames_missed == b->frames_missed && a->signal_interval == b->signal_interval &&
           a->response == b->response && same_double(a->rt_s, b->rt_s) &&
           same_double(a->click_x_deg, b->click_x_deg) && same_double(a->click_y_deg, b->click_y_deg) &&
           a->valid == b->valid && !strcmp(a->flags, b->flags) && a->has_onset == b->has_onset &&
           same_double(a->onset_s, b->onset_s);
}

#endif
