/* PostgreSQL results store through libpq (see results/store/store.h for the contract, docs/store.md
 * for a lab's set-up).
 *
 * Every write is one transaction committed before the call returns (single statements in
 * autocommit, several inside BEGIN ... COMMIT), with synchronous_commit on: the server has the
 * row in its fsynced WAL when the call returns. Credentials come only from libpq's own sources
 * (password file, service file, environment); results/store/store.c refuses a location that carries a
 * password, and every message names the location without one.
 *
 * Concurrency: ids come from identity columns; names (observers, displays) are inserted with ON
 * CONFLICT DO NOTHING and read back, so stations that record the same name at once all get its
 * one row; trials are keyed (session, seq) so a duplicate is refused, never doubled. A station
 * holds an advisory lock on each session it started or resumed (CLAIM_CLASS, id): another
 * station's state change of that session is refused while it is held, and the server drops it
 * when the station's connection ends, so the session of a crashed station can be resumed. On a
 * lab's server only the station roles and the owner may take advisory locks
 * (docs/store_roles.sql), so a read-only role cannot hold a claim or the schema lock; and no
 * wait for a lock is open-ended: the schema lock is waited for at most lock_wait_s, naming its
 * holder, and lock_timeout bounds every statement's wait for a table or row lock.
 *
 * Faults: when the connection drops (server restart, network), the call waits for the server,
 * saying so on stderr once a second, reconnects, takes its claims again and repeats the
 * transaction; a row found already stored on the repeat (its commit got through before the
 * drop) counts as stored. */
#include <errno.h>
#include <libpq-fe.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "results/store/store.h"
#include "results/store/backend.h"
#include "results/store/internal.h"
#include "results/store/migrations.h"
#include "results/store/pg_schema.h"
#include "results/store/rows.h"
#include "results/store/push.h"
#include "results/store/spool.h"

#ifndef CSF_VERSION
#define CSF_VERSION "unknown"
#endif

/* Advisory lock keys: (class, object). 'CSF1' as the class keeps them apart from other users of
 * advisory locks in the same database; object 0 serialises schema creation and migration. */
#define CLAIM_CLASS 0x43534631
#define MAX_ARGS 32

typedef struct pg_store {
    csf_store base; /* first: a csf_store * points here */
    PGconn *conn;
    char conninfo[1024];
    int readonly;
    int retrying;        /* the current transaction is a repeat after a reconnect */
    double retry_limit_s;
    double lock_wait_s;  /* the longest any statement waits for a lock another connection holds */
    int64_t *claims;     /* sessions this station holds */
    size_t n_claims, cap_claims;
    /* The local spool (an SQLite store) that keeps trials while the server is away. */
    csf_spool spool;
    double spool_after_s;  /* how long a write waits for the server before it is spooled */
    int flushing;          /* sending the spool: writes go to the server only */
    double next_try_s;     /* monotonic time of the next try to reach the server */
    int begin_unsure;      /* begin_session sent its COMMIT: the server may have the row */
    csf_session_info *known; /* sessions this station ran: what their spool copy is made from */
    size_t n_known;
    /* Studies and participants this station recorded or found: what a spooled participant link
     * names (the server's ids mean nothing in the spool). */
    struct pg_name { int64_t id, study_id; char name[256]; } *names;
    size_t n_names;
} pg_store;

static const csf_store_ops pg_ops;

static pg_store *pg(csf_store *b) { return (pg_store *)b; }
static csf_status remember(pg_store *p, int64_t id, csf_error *err);
static void recover_spool(pg_store *p);
static csf_status find_uuid(pg_store *p, const char *uuid, int64_t *id, csf_error *err);
static csf_status flush_spool(pg_store *p, double wait_s, csf_error *err);

void (*csf_store_fault_hook)(const char *point);

/* ---- parameters and results -------------------------------------------------------------- */

/* Statement parameters, text format except blobs. */
typedef struct {
    const char *v[MAX_ARGS];
    int len[MAX_ARGS], fmt[MAX_ARGS];
    char buf[MAX_ARGS][32];
    int n;
} pgargs;

static void a_txt(pgargs *a, const char *s)
{
    a->v[a->n] = s;
    a->len[a->n] = 0;
    a->fmt[a->n++] = 0;
}

static void a_i64(pgargs *a, int64_t x)
{
    snprintf(a->buf[a->n], sizeof a->buf[0], "%lld", (long long)x);
    a_txt(a, a->buf[a->n]);
}

/* NaN is stored as NULL (as on SQLite); infinities as PostgreSQL writes them. */
static void a_dbl(pgargs *a, double x)
{
    if (isnan(x)) a_txt(a, NULL);
    else if (isinf(x)) a_txt(a, x > 0 ? "Infinity" : "-Infinity");
    else {
        snprintf(a->buf[a->n], sizeof a->buf[0], "%.17g", x);
        a_txt(a, a->buf[a->n]);
    }
}

static void a_bin(pgargs *a, const void *p, size_t len)
{
    a->v[a->n] = p;
    a->len[a->n] = (int)len;
    a->fmt[a->n++] = 1;
}

static int is_null(const PGresult *r, int row, int col) { return PQgetisnull(r, row, col); }

static double g_dbl(const PGresult *r, int row, int col)
{
    return is_null(r, row, col) ? NAN : strtod(PQgetvalue(r, row, col), NULL);
}

static int64_t g_i64(const PGresult *r, int row, int col)
{
    return is_null(r, row, col) ? 0 : strtoll(PQgetvalue(r, row, col), NULL, 10);
}


static void g_txt(const PGresult *r, int row, int col, char *dst, size_t cap)
{
    snprintf(dst, cap, "%s", is_null(r, row, col) ? "" : PQgetvalue(r, row, col));
}


/* ---- errors ------------------------------------------------------------------------------ */

static const char *sqlstate(const PGresult *r)
{
    const char *s = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : NULL;
    return s ? s : "";
}

/* The server's or libpq's one-line message (without the trailing newline). */
static void message(pg_store *p, const PGresult *r, char *out, size_t cap)
{
    const char *m = r ? PQresultErrorField(r, PG_DIAG_MESSAGE_PRIMARY) : NULL;
    if (!m || !*m) m = PQerrorMessage(p->conn);
    snprintf(out, cap, "%s", m && *m ? m : "unknown error");
    size_t n = strlen(out);
    while (n > 0 && (out[n - 1] == '\n' || out[n - 1] == ' ')) out[--n] = '\0';
    for (char *c = out; *c; c++) /* libpq's messages span lines: one line per message here */
        if (*c == '\n' || *c == '\t') *c = ' ';
}

static int lost(const pg_store *p) { return PQstatus(p->conn) != CONNECTION_OK; }

/* 23xxx: a constraint refused the row (the SQLite backend's SQLITE_CONSTRAINT). */
static int constraint(const PGresult *r) { return !strncmp(sqlstate(r), "23", 2); }
static int duplicate(const PGresult *r) { return !strcmp(sqlstate(r), "23505"); }

/* After a lock wait gave up: who holds a table lock that blocks writes or reads in this
 * database (a row lock's holder is gone from pg_locks once the wait ends). The failed
 * transaction is rolled back first (its caller would anyway) so the question can be asked. */
static void table_lock_holders(pg_store *p, char *out, size_t cap)
{
    snprintf(out, cap, "another connection (see pg_locks and pg_stat_activity on the server)");
    if (PQtransactionStatus(p->conn) == PQTRANS_INERROR) PQclear(PQexec(p->conn, "ROLLBACK"));
    if (PQtransactionStatus(p->conn) != PQTRANS_IDLE) return;
    PGresult *r = PQexec(p->conn, "SELECT string_agg(DISTINCT format('login %s, program ''%s'',"
                                  " server process %s', a.usename, a.application_name, l.pid), '; ')"
                                  " FROM pg_locks l JOIN pg_stat_activity a ON a.pid = l.pid"
                                  " WHERE l.granted AND l.pid <> pg_backend_pid() AND l.locktype ="
                                  " 'relation' AND l.database = (SELECT oid FROM pg_database WHERE"
                                  " datname = current_database()) AND l.mode IN ('ShareLock',"
                                  " 'ShareRowExclusiveLock', 'ExclusiveLock', 'AccessExclusiveLock')");
    if (PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) == 1 && !is_null(r, 0, 0))
        g_txt(r, 0, 0, out, cap);
    PQclear(r);
}

static csf_status fail(pg_store *p, const PGresult *r, const char *what, csf_error *err)
{
    char msg[512];
    message(p, r, msg, sizeof msg);
    const char *st = sqlstate(r);
    if (lost(p))
        return csf_error_set(err, CSF_E_STORE, "store %s: server unreachable while %s (%s)",
                             p->base.path, what, msg);
    if (!strcmp(st, "42501") && strstr(msg, "row-level security"))
        return csf_error_set(err, CSF_E_STORE, "store %s: permission denied while %s: the row "
                             "belongs to another station's session (%s)", p->base.path, what, msg);
    if (!strcmp(st, "42501"))
        return csf_error_set(err, CSF_E_STORE, "store %s: permission denied while %s (%s); the "
                             "station's role needs the grants in docs/store_roles.sql", p->base.path,
                             what, msg);
    if (!strcmp(st, "55P03")) {
        char holders[256];
        table_lock_holders(p, holders, sizeof holders);
        return csf_error_set(err, CSF_E_STORE, "store %s: gave up after %.0f s waiting for a lock "
                             "another connection holds while %s (%s); held by %s. Try again once "
                             "it lets go (the database owner can end it with pg_terminate_backend), "
                             "or raise CSF_STORE_LOCK_WAIT_S", p->base.path, p->lock_wait_s, what,
                             msg, holders);
    }
    if (!strcmp(st, "55000"))
        return csf_error_set(err, CSF_E_STORE, "store %s: refused while %s: %s", p->base.path,
                             what, msg);
    if (!strcmp(st, "25006"))
        return csf_error_set(err, CSF_E_STORE, "store %s: opened read-only, cannot write while %s",
                             p->base.path, what);
    if (!strcmp(st, "53100"))
        return csf_error_set(err, CSF_E_STORE, "store %s: disk full on the server while %s (%s)",
                             p->base.path, what, msg);
    if (constraint(r))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store %s: %s refused: %s", p->base.path,
                             what, msg);
    return csf_error_set(err, CSF_E_STORE, "store %s: failed while %s (%s)", p->base.path, what,
                         msg);
}

/* ---- statements ---------------------------------------------------------------------------- */

/* Without arguments: PQexec, which also runs a script of several statements (the schema). */
static PGresult *run(pg_store *p, const char *sql, const pgargs *a)
{
    if (!a) return PQexec(p->conn, sql);
    return PQexecParams(p->conn, sql, a ? a->n : 0, NULL, a ? a->v : NULL, a ? a->len : NULL,
                        a ? a->fmt : NULL, 0);
}

static int ok(const PGresult *r)
{
    ExecStatusType t = PQresultStatus(r);
    return t == PGRES_COMMAND_OK || t == PGRES_TUPLES_OK;
}

/* A statement whose result only matters as success; PQclear'd here. */
static csf_status run_cmd(pg_store *p, const char *sql, const pgargs *a, const char *what,
                          csf_error *err)
{
    PGresult *r = run(p, sql, a);
    csf_status cs = ok(r) ? CSF_OK : fail(p, r, what, err);
    PQclear(r);
    return cs;
}

static void rollback(pg_store *p)
{
    if (!lost(p)) PQclear(PQexec(p->conn, "ROLLBACK"));
}

static csf_status commit(pg_store *p, const char *what, csf_error *err)
{
    return run_cmd(p, "COMMIT", NULL, what, err);
}

/* ---- connection, claims, reconnecting ------------------------------------------------------ */

static int has_claim(const pg_store *p, int64_t id)
{
    for (size_t i = 0; i < p->n_claims; i++)
        if (p->claims[i] == id) return 1;
    return 0;
}

static void drop_claim(pg_store *p, int64_t id)
{
    for (size_t i = 0; i < p->n_claims; i++)
        if (p->claims[i] == id) p->claims[i] = p->claims[--p->n_claims];
}

static int add_claim(pg_store *p, int64_t id)
{
    if (has_claim(p, id)) return 0;
    if (p->n_claims == p->cap_claims) {
        size_t nc = p->cap_claims ? 2 * p->cap_claims : 8;
        int64_t *c = realloc(p->claims, nc * sizeof *c);
        if (!c) return -1;
        p->claims = c;
        p->cap_claims = nc;
    }
    p->claims[p->n_claims++] = id;
    return 0;
}

/* Takes session id's advisory lock; *held = 0 when another station has it. */
static csf_status try_claim(pg_store *p, int64_t id, int *held, csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, CLAIM_CLASS);
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT pg_try_advisory_lock($1::int, ($2::bigint % 2147483647)::int)", &a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "claiming a session", err);
    else *held = PQgetvalue(r, 0, 0)[0] == 't';
    PQclear(r);
    if (cs == CSF_OK && *held && add_claim(p, id) < 0)
        cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory claiming a session");
    return cs;
}

static void release_claim(pg_store *p, int64_t id)
{
    if (!has_claim(p, id)) return;
    pgargs a = {0};
    a_i64(&a, CLAIM_CLASS);
    a_i64(&a, id);
    PQclear(run(p, "SELECT pg_advisory_unlock($1::int, ($2::bigint % 2147483647)::int)", &a));
    drop_claim(p, id);
}

/* What every connection sets first: durable commits, and no writes on a read-only store. */
static csf_status setup_connection(pg_store *p, csf_error *err)
{
    csf_status cs = run_cmd(p, "SET synchronous_commit = on", NULL, "connecting", err);
    /* No statement waits silently for a lock another connection holds: it gives up and says so. */
    char sql[64];
    long wait_ms = (long)(p->lock_wait_s * 1000.0);
    snprintf(sql, sizeof sql, "SET lock_timeout = %ld", wait_ms > 0 ? wait_ms : 1); /* 0: no limit */
    if (cs == CSF_OK) cs = run_cmd(p, sql, NULL, "connecting", err);
    if (cs == CSF_OK && p->readonly)
        cs = run_cmd(p, "SET default_transaction_read_only = on", NULL, "connecting", err);
    return cs;
}

/* After a reconnect: the claims went with the old connection; take them again. A claim someone
 * else took meanwhile is a session this station must not go on writing. */
static csf_status reclaim_all(pg_store *p, csf_error *err)
{
    int64_t *ids = p->n_claims ? malloc(p->n_claims * sizeof *ids) : NULL;
    size_t n = p->n_claims;
    if (n && !ids) return csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    if (n) memcpy(ids, p->claims, n * sizeof *ids);
    p->n_claims = 0;
    csf_status cs = CSF_OK;
    for (size_t i = 0; i < n && cs == CSF_OK; i++) {
        int held = 0;
        cs = try_claim(p, ids[i], &held, err);
        if (cs == CSF_OK && !held)
            cs = csf_error_set(err, CSF_E_STORE, "store %s: session %lld was claimed by another "
                               "station while the server was unreachable", p->base.path,
                               (long long)ids[i]);
    }
    free(ids);
    return cs;
}

/* Waits for the server after the connection dropped: one try a second, a line on stderr each
 * time when say (the person at the station sees why the next stimulus is late), for limit_s.
 * While rows are spooled each write tries once more without a line: the station said so once. */
static csf_status reconnect(pg_store *p, double limit_s, int say, csf_error *err)
{
    char msg[512];
    message(p, NULL, msg, sizeof msg);
    double waited_s = 0.0;
    for (;;) {
        if (say)
            fprintf(stderr, "csfcal: store %s: connection to the server lost (%s); retrying "
                            "(%.0f s of %.0f s)\n", p->base.path, msg, waited_s, limit_s);
        PQreset(p->conn);
        if (!lost(p)) {
            csf_status cs = setup_connection(p, err);
            if (cs == CSF_OK) cs = reclaim_all(p, err);
            if (cs == CSF_OK && say) fprintf(stderr, "csfcal: store %s: reconnected\n", p->base.path);
            return cs;
        }
        message(p, NULL, msg, sizeof msg);
        if (waited_s >= limit_s)
            return csf_error_set(err, CSF_E_STORE, "store %s: server unreachable for %.0f s (%s); "
                                 "the session can be resumed with --resume once it is back",
                                 p->base.path, waited_s, msg);
        sleep(1);
        waited_s += 1.0;
    }
}

/* Runs one transaction (call), and again after a reconnect when the connection dropped. */
#define RETRY(p, err, call)                                                                  \
    do {                                                                                     \
        (p)->retrying = 0;                                                                   \
        for (;;) {                                                                           \
            csf_status cs_ = (call);                                                         \
            if (cs_ == CSF_OK || !lost(p)) return cs_;                                       \
            csf_status rs_ = reconnect((p), (p)->retry_limit_s, 1, (err));                                          \
            if (rs_ != CSF_OK) return rs_;                                                   \
            (p)->retrying = 1;                                                               \
        }                                                                                    \
    } while (0)

/* ---- rows --------------------------------------------------------------------------------- */

typedef struct {
    const char *sql;
    int binds_session;
    size_t elem_size;
    int (*row)(const PGresult *r, int i, void *elem, int64_t session_id);
    void (*free_elem)(void *elem);
    const char *what;
} row_query;

static csf_status query_rows_once(pg_store *p, const row_query *q, int64_t session_id, void **out,
                                  size_t *n, csf_error *err)
{
    pgargs a = {0};
    if (q->binds_session) a_i64(&a, session_id);
    PGresult *r = run(p, q->sql, &a);
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        csf_status cs = fail(p, r, q->what, err);
        PQclear(r);
        return cs;
    }
    int rows = PQntuples(r);
    unsigned char *list = rows ? calloc((size_t)rows, q->elem_size) : NULL;
    int i = 0;
    while (list && i < rows && q->row(r, i, list + (size_t)i * q->elem_size, session_id) == 0) i++;
    PQclear(r);
    if (i < rows) {
        for (int k = 0; list && q->free_elem && k <= i && k < rows; k++)
            q->free_elem(list + (size_t)k * q->elem_size);
        free(list);
        return csf_error_set(err, CSF_E_NOMEM, "store: out of memory %s", q->what);
    }
    *out = list;
    *n = (size_t)rows;
    return CSF_OK;
}

static csf_status query_rows(pg_store *p, const row_query *q, int64_t session_id, void **out,
                             size_t *n, csf_error *err)
{
    RETRY(p, err, query_rows_once(p, q, session_id, out, n, err));
}

/* One integer from a one-row query; CSF_E_NOT_FOUND when there is no row. */
static csf_status query_i64(pg_store *p, const char *sql, const pgargs *a, int64_t *v,
                            const char *what, csf_error *err)
{
    PGresult *r = run(p, sql, a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, what, err);
    else if (PQntuples(r) == 0) cs = CSF_E_NOT_FOUND;
    else *v = g_i64(r, 0, 0);
    PQclear(r);
    return cs;
}

/* ---- open ----------------------------------------------------------------------------------- */

/* Who holds advisory lock (CLAIM_CLASS, object): login, program, server process and since when,
 * as pg_locks and pg_stat_activity show it to every role (the start times of another login's
 * connection are shown only to roles with pg_read_all_stats: "since ?" otherwise). */
static void lock_holder(pg_store *p, int64_t object, char *out, size_t cap, long *pid)
{
    *pid = 0;
    pgargs a = {0};
    a_i64(&a, CLAIM_CLASS);
    a_i64(&a, object);
    PGresult *r = run(p, "SELECT a.usename, a.application_name, l.pid, COALESCE(to_char(COALESCE("
                         "a.xact_start, a.backend_start) AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS\"Z\"'),"
                         " '?') FROM pg_locks l LEFT JOIN pg_stat_activity a ON a.pid = l.pid"
                         " WHERE l.locktype = 'advisory' AND l.granted AND l.classid ="
                         " $1::bigint::oid AND l.objid = ($2::bigint % 2147483647)::oid AND"
                         " l.objsubid = 2 LIMIT 1", &a);
    if (PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) == 1) {
        char who[80], app[80], since[40];
        g_txt(r, 0, 0, who, sizeof who);
        g_txt(r, 0, 1, app, sizeof app);
        g_txt(r, 0, 3, since, sizeof since);
        *pid = (long)g_i64(r, 0, 2);
        snprintf(out, cap, "login %s, program '%s', server process %ld, since %s", who[0] ? who : "?",
                 app, *pid, since);
    } else {
        snprintf(out, cap, "a connection that has let go of it since");
    }
    PQclear(r);
}

/* The schema lock, inside the open transaction, waited for at most lock_wait_s: a connection
 * that holds it (a station's csfcal migrating, or anyone holding it by hand) is named once on
 * stderr, and named again in the refusal when it does not let go. */
static csf_status schema_lock(pg_store *p, csf_error *err)
{
    const char *what = "locking the schema";
    double waited_s = 0.0;
    char holder[256] = "";
    long pid = 0;
    for (;;) {
        pgargs a = {0};
        a_i64(&a, CLAIM_CLASS);
        PGresult *r = run(p, "SELECT pg_try_advisory_xact_lock($1::int, 0)", &a);
        csf_status cs = PQresultStatus(r) == PGRES_TUPLES_OK ? CSF_OK : fail(p, r, what, err);
        int got = cs == CSF_OK && PQgetvalue(r, 0, 0)[0] == 't';
        PQclear(r);
        if (cs != CSF_OK || got) return cs;
        lock_holder(p, 0, holder, sizeof holder, &pid);
        if (waited_s >= p->lock_wait_s)
            return csf_error_set(err, CSF_E_STORE, "store %s: gave up after %.0f s waiting for the "
                                 "schema lock, held by %s; once that connection ends (the database "
                                 "owner can end it with pg_terminate_backend) try again",
                                 p->base.path, waited_s, holder);
        if (waited_s == 0.0)
            fprintf(stderr, "csfcal: store %s: waiting up to %.0f s for the schema lock, held by %s\n",
                    p->base.path, p->lock_wait_s, holder);
        usleep(200000);
        waited_s += 0.2;
    }
}

typedef struct {
    int64_t has, tables, version;
} schema_state;

static csf_status read_schema_state(pg_store *p, schema_state *ss, csf_error *err)
{
    const char *what = "reading the schema";
    *ss = (schema_state){0};
    csf_status cs = query_i64(p, "SELECT COUNT(*) FROM information_schema.tables WHERE table_schema"
                                 " = current_schema() AND table_name = 'schema_version'", NULL,
                              &ss->has, what, err);
    if (cs == CSF_OK)
        cs = query_i64(p, "SELECT COUNT(*) FROM information_schema.tables WHERE table_schema ="
                          " current_schema()", NULL, &ss->tables, what, err);
    if (cs == CSF_OK && ss->has)
        cs = query_i64(p, "SELECT MAX(version) FROM schema_version", NULL, &ss->version, what, err);
    if (cs == CSF_OK && !ss->has && ss->tables > 0)
        cs = csf_error_set(err, CSF_E_STORE, "store %s: the database has tables but is not a csfcal "
                           "store (no schema_version table); refusing to change it", p->base.path);
    if (cs == CSF_OK && ss->version > CSF_STORE_SCHEMA_VERSION)
        cs = csf_error_set(err, CSF_E_STORE, "store %s: schema version %lld, this csfcal reads %d; "
                           "use a csfcal of that version", p->base.path, (long long)ss->version,
                           CSF_STORE_SCHEMA_VERSION);
    return cs;
}

/* A read-only connection never changes the schema, so it never takes the schema lock: a
 * listing cannot be kept waiting by it. */
static csf_status check_schema_readonly(pg_store *p, const schema_state *ss, csf_error *err)
{
    if (!ss->has)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no csfcal store in that database yet; "
                             "no session has been recorded there", p->base.path);
    if (ss->version != CSF_STORE_SCHEMA_VERSION)
        return csf_error_set(err, CSF_E_STORE, "store %s: schema version %lld must be migrated to %d "
                             "before it can be read; open it once with a role that may change the "
                             "schema", p->base.path, (long long)ss->version, CSF_STORE_SCHEMA_VERSION);
    return CSF_OK;
}

/* Creates the schema in an empty database, or migrates the one there, under the schema lock
 * (stations started together on a new database wait for each other), reading its state again
 * once the lock is held. */
static csf_status create_or_migrate(pg_store *p, schema_state *ss, csf_error *err)
{
    const char *what = "creating the schema";
    csf_status cs = schema_lock(p, err);
    if (cs == CSF_OK) cs = read_schema_state(p, ss, err);
    if (cs == CSF_OK && !ss->has) cs = run_cmd(p, csf_store_pg_schema_v5, NULL, what, err);
    if (cs == CSF_OK && !ss->has) ss->version = 5;
    /* The migrations after version 5: the same SQL as on SQLite, or its server form where the
     * types differ. */
    while (cs == CSF_OK && ss->version >= 5 && ss->version < CSF_STORE_SCHEMA_VERSION) {
        char upd[80];
        snprintf(upd, sizeof upd, "UPDATE schema_version SET version = %lld",
                 (long long)ss->version + 1);
        const char *step = csf_store_migrations_pg[ss->version] ? csf_store_migrations_pg[ss->version]
                                                                : csf_store_migrations[ss->version];
        cs = run_cmd(p, step, NULL, "migrating the schema", err);
        if (cs == CSF_OK) cs = run_cmd(p, upd, NULL, "migrating the schema", err);
        ss->version++;
    }
    if (cs == CSF_OK && ss->version != CSF_STORE_SCHEMA_VERSION)
        cs = csf_error_set(err, CSF_E_STORE, "store %s: schema version %lld, this csfcal reads %d; "
                           "use a csfcal of that version", p->base.path, (long long)ss->version,
                           CSF_STORE_SCHEMA_VERSION);
    return cs;
}

/* Checks the schema, creating or migrating it when a writable connection finds it missing or
 * old. A current schema is only read, without the lock. */
static csf_status ensure_schema(pg_store *p, csf_error *err)
{
    const char *what = "creating the schema";
    schema_state ss;
    csf_status cs = run_cmd(p, "BEGIN", NULL, what, err);
    if (cs == CSF_OK) cs = read_schema_state(p, &ss, err);
    int current = cs == CSF_OK && ss.has && ss.version == CSF_STORE_SCHEMA_VERSION;
    if (cs == CSF_OK && !current && p->readonly) cs = check_schema_readonly(p, &ss, err);
    else if (cs == CSF_OK && !current) cs = create_or_migrate(p, &ss, err);
    if (cs == CSF_OK) return commit(p, what, err);
    rollback(p);
    return cs;
}

/* A server that does not fsync cannot keep the promise a stored trial makes. */
static csf_status check_durable(pg_store *p, csf_error *err)
{
    PGresult *r = run(p, "SHOW fsync", NULL);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "checking durability", err);
    else if (strcmp(PQgetvalue(r, 0, 0), "on") != 0)
        cs = csf_error_set(err, CSF_E_STORE, "store %s: the server runs with fsync = off, so a "
                           "committed trial can be lost in a crash; turn fsync on", p->base.path);
    PQclear(r);
    return cs;
}

/* The server's notices (NOTICE, not errors) would land among the procedure's messages. */
static void quiet(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

/* Seconds from the environment (CSF_STORE_RETRY_S, CSF_STORE_SPOOL_AFTER_S), else def_s. */
static double env_seconds(const char *name, double def_s)
{
    const char *e = getenv(name);
    char *end = NULL;
    double v = e ? strtod(e, &end) : NAN;
    return e && end != e && *end == '\0' && v >= 0 && v <= 86400 ? v : def_s;
}

csf_status csf_store_pg_open(const char *conninfo, int readonly, csf_store **out, csf_error *err)
{
    pg_store *p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    p->base.ops = &pg_ops;
    csf_store_redact(conninfo, p->base.path, sizeof p->base.path);
    snprintf(p->conninfo, sizeof p->conninfo, "%s", conninfo);
    p->readonly = readonly;
    p->retry_limit_s = env_seconds("CSF_STORE_RETRY_S", 120.0);
    p->spool_after_s = env_seconds("CSF_STORE_SPOOL_AFTER_S", 5.0);
    p->lock_wait_s = env_seconds("CSF_STORE_LOCK_WAIT_S", 10.0);
    csf_spool_init(&p->spool, p->base.path);
    /* dbname last: what the location says wins over these defaults. */
    const char *keys[] = {"application_name", "connect_timeout", "dbname", NULL};
    const char *vals[] = {"csfcal", "10", conninfo, NULL};
    p->conn = PQconnectdbParams(keys, vals, 1);
    csf_status cs = CSF_OK;
    if (!p->conn) {
        cs = csf_error_set(err, CSF_E_NOMEM, "store %s: out of memory connecting", p->base.path);
    } else if (PQstatus(p->conn) != CONNECTION_OK) {
        char msg[512];
        message(p, NULL, msg, sizeof msg);
        cs = csf_error_set(err, CSF_E_STORE, "store %s: cannot connect to the server (%s); start "
                           "the server or run on a local store (--store FILE) and copy it later "
                           "with csfcal sessions push --to LOCATION", p->base.path, msg);
    }
    if (cs == CSF_OK) PQsetNoticeProcessor(p->conn, quiet, NULL);
    if (cs == CSF_OK) cs = setup_connection(p, err);
    if (cs == CSF_OK && !readonly) cs = check_durable(p, err);
    if (cs == CSF_OK) cs = ensure_schema(p, err);
    if (cs == CSF_OK && !readonly) recover_spool(p);
    if (cs != CSF_OK) {
        pg_ops.close(&p->base);
        return cs;
    }
    *out = &p->base;
    return CSF_OK;
}

static void pg_close(csf_store *b)
{
    pg_store *p = pg(b);
    if (p->spool.spooling) {
        csf_error e;
        p->flushing = 1;
        if (flush_spool(p, p->retry_limit_s, &e) != CSF_OK)
            fprintf(stderr,
                    "csfcal: store %s: %d writes (trials, readings, state changes) are only "
                    "in the local spool %s; send them when the server is back with: csfcal "
                    "sessions push --store '%s' --to '%s'\n",
                    p->base.path, p->spool.n_spooled, p->spool.path, p->spool.path, p->base.path);
    }
    csf_spool_close(&p->spool);
    for (size_t i = 0; i < p->n_known; i++) csf_session_info_free(&p->known[i]);
    free(p->known);
    free(p->names);
    if (p->conn) PQfinish(p->conn); /* ends the connection: the server drops its claims */
    free(p->claims);
    free(p);
}

static int pg_schema_version(csf_store *b)
{
    pg_store *p = pg(b);
    int64_t v = -1;
    return query_i64(p, "SELECT MAX(version) FROM schema_version", NULL, &v, "", NULL) == CSF_OK
               ? (int)v : -1;
}

/* ---- displays and observers ------------------------------------------------------------- */

/* Records a name (observers, displays) and returns its id: ON CONFLICT makes stations that
 * record the same name at once share one row instead of one of them failing. */
static csf_status upsert_name(pg_store *p, const char *table, const char *name, int64_t *id,
                              csf_error *err)
{
    char sql[160], now[32], what[48];
    csf_store_utc_now(now);
    snprintf(what, sizeof what, "recording a %s", table);
    snprintf(sql, sizeof sql, "INSERT INTO %s (name, created_utc) VALUES ($1, $2)"
             " ON CONFLICT (name) DO NOTHING", table);
    pgargs a = {0};
    a_txt(&a, name);
    a_txt(&a, now);
    csf_status cs = run_cmd(p, sql, &a, what, err);
    if (cs != CSF_OK || !id) return cs;
    snprintf(sql, sizeof sql, "SELECT id FROM %s WHERE name = $1", table);
    a.n = 1;
    cs = query_i64(p, sql, &a, id, what, err);
    return cs == CSF_E_NOT_FOUND ? fail(p, NULL, what, err) : cs;
}

/* The display's profile history gets one row per distinct profile id. */
static csf_status add_profile_history(pg_store *p, const char *display, const char *profile_id,
                                      csf_error *err)
{
    char now[32];
    csf_store_utc_now(now);
    pgargs a = {0};
    a_txt(&a, display);
    a_txt(&a, profile_id);
    a_txt(&a, now);
    return run_cmd(p, "INSERT INTO display_profiles (display_id, profile_id, session_id, created_utc)"
                      " SELECT id, $2, NULL, $3 FROM displays WHERE name = $1 AND NOT EXISTS"
                      " (SELECT 1 FROM display_profiles q WHERE q.display_id = displays.id"
                      " AND q.profile_id = $2)", &a, "recording a display profile", err);
}

static csf_status upsert_display_once(pg_store *p, const char *name, const char *profile_id,
                                      int64_t *id, csf_error *err)
{
    csf_status cs = run_cmd(p, "BEGIN", NULL, "recording a display", err);
    if (cs == CSF_OK) cs = upsert_name(p, "displays", name, id, err);
    if (cs == CSF_OK && profile_id) {
        pgargs a = {0};
        a_txt(&a, profile_id);
        a_txt(&a, name);
        cs = run_cmd(p, "UPDATE displays SET profile_id = $1 WHERE name = $2", &a,
                     "recording a display", err);
        if (cs == CSF_OK) cs = add_profile_history(p, name, profile_id, err);
    }
    if (cs == CSF_OK) return commit(p, "recording a display", err);
    rollback(p);
    return cs;
}

static csf_status pg_upsert_display(csf_store *b, const char *name, const char *profile_id,
                                    int64_t *id, csf_error *err)
{
    pg_store *p = pg(b);
    RETRY(p, err, upsert_display_once(p, name, profile_id, id, err));
}

static csf_status pg_upsert_observer(csf_store *b, const char *name, int64_t *id, csf_error *err)
{
    pg_store *p = pg(b);
    RETRY(p, err, upsert_name(p, "observers", name, id, err));
}

static csf_status pg_display_profile_id(csf_store *b, const char *display, char *out, size_t cap,
                                        csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_txt(&a, display);
    PGresult *r = run(p, "SELECT profile_id FROM displays WHERE name = $1 AND profile_id IS NOT NULL", &a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading a display's profile", err);
    else if (PQntuples(r) == 0)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no profile recorded for display '%s'",
                           p->base.path, display);
    else g_txt(r, 0, 0, out, cap);
    PQclear(r);
    return cs;
}

/* ---- sessions ------------------------------------------------------------------------------ */

/* The session's row, with its claim taken inside the same transaction (an advisory lock taken
 * in a transaction is held by the connection after COMMIT): a drop before COMMIT leaves nothing
 * on the server. A repeat after a drop looks for the uuid first: a COMMIT that got through
 * before the drop already made the session, and a second row would be a phantom. */
static csf_status begin_once(pg_store *p, const csf_store_session_new *nw, int64_t *id,
                             csf_error *err)
{
    const char *what = "starting a session";
    const char *kind = csf_session_kind_name(nw->kind), *observer = nw->observer, *display = nw->display;
    const char *profile_id = nw->profile_id, *settings_json = nw->settings_json;
    uint64_t seed = nw->seed;
    int64_t new_id = 0;
    int held = 0;
    if (p->retrying) {
        csf_status fs = find_uuid(p, nw->uuid, &new_id, err);
        if (fs == CSF_OK) {
            csf_status cs = try_claim(p, new_id, &held, err);
            if (cs == CSF_OK) cs = remember(p, new_id, err);
            if (cs == CSF_OK && id) *id = new_id;
            return cs;
        }
        if (fs != CSF_E_NOT_FOUND) return fs;
        csf_error_clear(err);
    }
    csf_status cs = run_cmd(p, "BEGIN", NULL, what, err);
    if (cs == CSF_OK && observer && *observer) cs = upsert_name(p, "observers", observer, NULL, err);
    if (cs == CSF_OK && display && *display) cs = upsert_name(p, "displays", display, NULL, err);
    if (cs == CSF_OK && display && *display && profile_id) {
        cs = add_profile_history(p, display, profile_id, err);
        pgargs a = {0};
        a_txt(&a, profile_id);
        a_txt(&a, display);
        if (cs == CSF_OK)
            cs = run_cmd(p, "UPDATE displays SET profile_id = $1 WHERE name = $2 AND profile_id"
                            " IS NULL", &a, what, err);
    }
    char now[32];
    csf_store_utc_now(now);
    pgargs a = {0};
    a_txt(&a, kind);
    a_txt(&a, observer ? observer : "");
    a_txt(&a, display ? display : "");
    a_txt(&a, settings_json ? settings_json : "{}");
    a_i64(&a, (int64_t)seed); /* unsigned 64 bits stored as the same signed 64 bits */
    a_txt(&a, nw->tool_version ? nw->tool_version : CSF_VERSION);
    a_txt(&a, nw->created_utc ? nw->created_utc : now);
    a_txt(&a, profile_id);
    a_txt(&a, csf_session_state_name(nw->state));
    a_txt(&a, nw->uuid);
    a_txt(&a, now);
    /* station: the login, which the row-level policies of docs/store_roles.sql compare with. */
    if (cs == CSF_OK)
        cs = query_i64(p, "INSERT INTO sessions (kind, state, observer, display, settings_json, seed,"
                          " tool_version, created_utc, updated_utc, profile_id, uuid, station)"
                          " VALUES ($1, $9, $2, $3, $4, $5, $6, $7, $11, $8, $10, current_user)"
                          " RETURNING id", &a, &new_id, what, err);
    if (cs == CSF_OK) cs = try_claim(p, new_id, &held, err);
    if (cs == CSF_OK) {
        p->begin_unsure = 1; /* from here the row may be on the server whatever we hear back */
        cs = commit(p, what, err);
    }
    if (cs != CSF_OK) {
        rollback(p);
        return cs;
    }
    if (csf_store_fault_hook) csf_store_fault_hook("session_committed");
    cs = remember(p, new_id, err);
    if (cs == CSF_OK && id) *id = new_id;
    return cs;
}

static csf_status pg_begin_session(csf_store *b, const csf_store_session_new *nw, int64_t *id,
                                   csf_error *err)
{
    pg_store *p = pg(b);
    p->retrying = 0;
    p->begin_unsure = 0;
    for (;;) {
        csf_status cs = begin_once(p, nw, id, err);
        if (cs == CSF_OK || !lost(p)) return cs;
        csf_status rs = reconnect(p, p->retry_limit_s, 1, err);
        if (rs != CSF_OK) {
            /* the server may have the row: the spool keeps its uuid, aborted, so that the next
             * csfcal that reaches the server marks the server's copy aborted (recover_spool) */
            if (p->begin_unsure) csf_spool_unsure_begin(&p->spool, nw);
            return rs;
        }
        p->retrying = 1;
    }
}

static csf_status pg_find_session_uuid(csf_store *b, const char *uuid, int64_t *id, csf_error *err)
{
    return find_uuid(pg(b), uuid, id, err);
}

static csf_status find_uuid(pg_store *p, const char *uuid, int64_t *id, csf_error *err)
{
    pgargs a = {0};
    a_txt(&a, uuid);
    return query_i64(p, "SELECT id FROM sessions WHERE uuid = $1", &a, id, "finding a session", err);
}

#define SESSION_COLS CSF_STORE_SESSION_SELECT

/* The shared row mapping (results/store/rows.h) reads row c->row of a result through these. */
static int cols_is_null(const csf_store_cols *c, int col) { return is_null(c->res, c->row, col); }
static double cols_dbl(const csf_store_cols *c, int col) { return g_dbl(c->res, c->row, col); }
static int64_t cols_i64(const csf_store_cols *c, int col) { return g_i64(c->res, c->row, col); }
static const char *cols_txt(const csf_store_cols *c, int col)
{
    return is_null(c->res, c->row, col) ? NULL : PQgetvalue(c->res, c->row, col);
}

static csf_store_cols cols(const PGresult *r, int i)
{
    return (csf_store_cols){.res = (PGresult *)r, .row = i, .is_null = cols_is_null,
                            .dbl = cols_dbl, .i64 = cols_i64, .txt = cols_txt};
}

static int session_row(const PGresult *r, int i, void *elem, int64_t session_id)
{
    (void)session_id;
    csf_store_cols c = cols(r, i);
    return csf_store_row_session(&c, elem);
}

static void session_free(void *elem) { csf_session_info_free(elem); }

static csf_status pg_get_session(csf_store *b, int64_t id, csf_session_info *out, csf_error *err)
{
    pg_store *p = pg(b);
    static const row_query q = {.sql = SESSION_COLS " WHERE s.id = $1", .binds_session = 1,
                                .elem_size = sizeof(csf_session_info), .row = session_row,
                                .free_elem = session_free, .what = "reading a session"};
    void *list = NULL;
    size_t n = 0;
    csf_status cs = query_rows(p, &q, id, &list, &n, err);
    if (cs != CSF_OK) return cs;
    if (n == 0)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path,
                             (long long)id);
    *out = *(csf_session_info *)list;
    free(list);
    return CSF_OK;
}

/* The refusal a second station gets: who holds the claim (the server shows every role the
 * login and server process of a connection, nothing more) and how to take it over when that
 * station is gone but its connection lingers (a station cut off from the network: the server
 * notices only when TCP keepalive gives up). */
static csf_status claimed_elsewhere(pg_store *p, int64_t id, csf_error *err)
{
    char holder[256], since[40] = "?";
    long pid = 0;
    lock_holder(p, id, holder, sizeof holder, &pid);
    /* The session's last state change is when that station started or resumed it: every role
     * may read it, unlike the connection's start time. */
    pgargs a = {0};
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT updated_utc FROM sessions WHERE id = $1", &a);
    if (PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) == 1) g_txt(r, 0, 0, since, sizeof since);
    PQclear(r);
    return csf_error_set(err, CSF_E_STORE, "store %s: session %lld is in use by another station: "
                         "%s, holds its claim (running since %s). Two stations must not write one "
                         "session. The claim ends with that station's connection (a crashed "
                         "csfcal's goes when the server notices); if the station is gone and its "
                         "connection lingers, the database owner can end it with SELECT "
                         "pg_terminate_backend(%ld); then resume again", p->base.path,
                         (long long)id, holder, since, pid);
}

/* A state change that changed no row: the session is missing, or it belongs to another
 * station (row-level security hides it from this login's UPDATE). */
static csf_status state_unchanged(pg_store *p, int64_t id, csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT station FROM sessions WHERE id = $1", &a);
    char owner[80] = "";
    int found = PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) == 1;
    if (found) g_txt(r, 0, 0, owner, sizeof owner);
    PQclear(r);
    if (!found)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path,
                             (long long)id);
    return csf_error_set(err, CSF_E_STORE, "store %s: session %lld belongs to another station "
                         "(login %s); a station changes only the sessions it started, so ask at "
                         "that station or the database owner", p->base.path, (long long)id,
                         owner[0] ? owner : "?");
}

/* A state change needs the session's claim: a station resuming a session takes it, and one
 * that another station holds is refused (two stations never run one session). A state other
 * than running gives the claim back. */
static csf_status set_state_once(pg_store *p, int64_t id, csf_session_state state, csf_error *err)
{
    int held = has_claim(p, id);
    csf_status cs = held ? CSF_OK : try_claim(p, id, &held, err);
    if (cs != CSF_OK) return cs;
    if (!held) return claimed_elsewhere(p, id, err);
    char now[32];
    csf_store_utc_now(now);
    pgargs a = {0};
    a_txt(&a, csf_session_state_name(state));
    a_txt(&a, now);
    a_i64(&a, id);
    PGresult *r = run(p, "UPDATE sessions SET state = $1, updated_utc = $2 WHERE id = $3", &a);
    if (!ok(r)) cs = fail(p, r, "changing a session's state", err);
    else if (!strcmp(PQcmdTuples(r), "0")) cs = state_unchanged(p, id, err);
    PQclear(r);
    if (cs == CSF_OK && state == CSF_SESSION_RUNNING) cs = remember(p, id, err);
    if (cs != CSF_OK || state != CSF_SESSION_RUNNING) release_claim(p, id);
    return cs;
}

static csf_status pg_list_sessions(csf_store *b, csf_session_info **out, size_t *n, csf_error *err)
{
    static const row_query q = {.sql = SESSION_COLS " ORDER BY s.id",
                                .elem_size = sizeof(csf_session_info), .row = session_row,
                                .free_elem = session_free, .what = "listing sessions"};
    return query_rows(pg(b), &q, 0, (void **)out, n, err);
}

static csf_status pg_session_times(csf_store *b, int64_t id, char created_utc[32],
                                   char updated_utc[32], csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT created_utc, updated_utc,"
                         " (SELECT MAX(stored_s) FROM trials WHERE session_id = s.id),"
                         " (SELECT MAX(stored_s) FROM readings WHERE session_id = s.id)"
                         " FROM sessions s WHERE id = $1", &a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading session times", err);
    else if (PQntuples(r) == 0)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path,
                           (long long)id);
    if (cs == CSF_OK) {
        char created[32], updated[32], u[32];
        g_txt(r, 0, 0, created, sizeof created);
        g_txt(r, 0, 1, updated, sizeof updated);
        for (int c = 2; c <= 3; c++)
            if (csf_store_format_unix(g_dbl(r, 0, c), u) && strcmp(u, updated) > 0)
                snprintf(updated, sizeof updated, "%s", u);
        if (created_utc) snprintf(created_utc, 32, "%s", created);
        if (updated_utc) snprintf(updated_utc, 32, "%s", updated);
    }
    PQclear(r);
    return cs;
}

/* ---- spooling ----------------------------------------------------------------------------
 * When the server cannot be reached within spool_after_s, a write of a session this station runs
 * goes to the local spool (results/store/spool.c) and the procedure goes on. Each later write
 * first tries the server again (at most every 5 s) and, once it answers, sends the spooled rows
 * before the new one. */

static const csf_session_info *known(const pg_store *p, int64_t id)
{
    for (size_t i = 0; i < p->n_known; i++)
        if (p->known[i].id == id) return &p->known[i];
    return NULL;
}

/* Keeps what a spool copy of session id is made from (read while the server is there). */
static csf_status remember(pg_store *p, int64_t id, csf_error *err)
{
    if (known(p, id)) return CSF_OK;
    csf_session_info *k = realloc(p->known, (p->n_known + 1) * sizeof *k);
    if (!k) return csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    p->known = k;
    static const row_query q = {.sql = SESSION_COLS " WHERE s.id = $1", .binds_session = 1,
                                .elem_size = sizeof(csf_session_info), .row = session_row,
                                .free_elem = session_free, .what = "reading a session"};
    void *list = NULL;
    size_t n = 0;
    csf_status cs = query_rows_once(p, &q, id, &list, &n, err);
    if (cs == CSF_OK && n == 1) p->known[p->n_known++] = *(csf_session_info *)list;
    free(list);
    return cs;
}

/* The spool's copy of server session sid (made on first use). */
static csf_status spool_session(pg_store *p, int64_t sid, int64_t *lsid, csf_error *err)
{
    const csf_session_info *k = known(p, sid);
    if (!k || !k->uuid[0])
        return csf_error_set(err, CSF_E_STORE, "store %s: server unreachable, and session %lld was "
                             "not started or resumed by this station, so it cannot be spooled",
                             p->base.path, (long long)sid);
    return csf_spool_session(&p->spool, k, lsid, err);
}

typedef csf_spool_write write_op;

static csf_status to_server(pg_store *p, const write_op *w, csf_error *err);
static csf_status put_thresholds_once(pg_store *p, int64_t session_id,
                                      const csf_threshold_row *rows, size_t n, csf_error *err);
static csf_status add_artifact_once(pg_store *p, int64_t session_id, const char *kind,
                                    const char *path, const void *blob, size_t len, csf_error *err);
static csf_status link_once(pg_store *p, int64_t session_id, int64_t participant_id,
                            csf_error *err);

/* Studies (is_participant 0) and participants (1) by id, as this station recorded them. */
static const struct pg_name *find_name(const pg_store *p, int64_t id, int is_participant)
{
    for (size_t i = 0; i < p->n_names; i++)
        if (p->names[i].id == id && (p->names[i].study_id != 0) == is_participant)
            return &p->names[i];
    return NULL;
}

static void note_name(pg_store *p, int64_t id, int64_t study_id, const char *name)
{
    if (find_name(p, id, study_id != 0)) return;
    struct pg_name *nn = realloc(p->names, (p->n_names + 1) * sizeof *nn);
    if (!nn) return; /* only a spooled link would miss it, and it says so */
    p->names = nn;
    nn[p->n_names].id = id;
    nn[p->n_names].study_id = study_id;
    snprintf(nn[p->n_names].name, sizeof nn[p->n_names].name, "%s", name);
    p->n_names++;
}

static csf_status to_spool(pg_store *p, const write_op *w, csf_error *err)
{
    int64_t lsid = 0;
    csf_status cs = spool_session(p, w->sid, &lsid, err);
    if (cs != CSF_OK) return cs;
    write_op named = *w;
    if (w->kind == CSF_SPOOL_LINK) {
        const struct pg_name *pt = find_name(p, w->participant_id, 1);
        const struct pg_name *st = pt ? find_name(p, pt->study_id, 0) : NULL;
        if (!st)
            return csf_error_set(err, CSF_E_STORE,
                                 "store %s: server unreachable, and participant "
                                 "%lld was not recorded by this station, so the link cannot be "
                                 "spooled",
                                 p->base.path, (long long)w->participant_id);
        named.study = st->name;
        named.code = pt->name;
    }
    return csf_spool_put(&p->spool, lsid, &named, err);
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Sends what the spool holds of this station's sessions; CSF_OK when the server has it all. */
static csf_status flush_spool(pg_store *p, double wait_s, csf_error *err)
{
    if (lost(p)) {
        if (wait_s <= 0.0 && mono_s() < p->next_try_s)
            return csf_error_set(err, CSF_E_STORE, "store %s: server unreachable", p->base.path);
        p->next_try_s = mono_s() + 5.0;
        csf_status rs = reconnect(p, wait_s, wait_s > 0.0, err);
        if (rs != CSF_OK) return rs;
    }
    return csf_spool_send(&p->spool, &p->base, p->known, p->n_known, err);
}

/* A start the server got but its station never heard of (csf_spool_unsure_begin): the spool has
 * it aborted and empty; the server's copy, still running with no rows, becomes aborted too. A
 * session someone resumed and wrote to is left alone. 1 when it was marked. */
static int abort_phantom(csf_store *b, const csf_session_info *local, int64_t sid)
{
    pg_store *p = pg(b);
    if (local->state != CSF_SESSION_ABORTED || local->n_trials || local->n_readings) return 0;
    csf_session_info si;
    csf_error e;
    if (pg_get_session(&p->base, sid, &si, &e) != CSF_OK) return 0;
    int phantom = si.state == CSF_SESSION_RUNNING && !si.n_trials && !si.n_readings;
    csf_session_info_free(&si);
    return phantom && set_state_once(p, sid, CSF_SESSION_ABORTED, &e) == CSF_OK;
}

/* A station that died while the server was away left rows in its spool that nobody sent. They
 * go to the server when the next csfcal opens it, before a procedure reads the trials it
 * resumes from (a resume without them would number new trials over them). Only sessions this
 * server has (by uuid) are sent; the state of each stays as the server has it. A failure is
 * said on stderr and does not stop the open: the rows stay in the spool. */
static void recover_spool(pg_store *p)
{
    p->flushing = 1;
    csf_spool_recover(&p->spool, &p->base, abort_phantom);
    p->flushing = 0;
}

/* A write of a session this station runs: to the server; after a drop, a short wait for it;
 * then to the spool. While rows are spooled, the server gets them first once it is back. */
static csf_status write_or_spool(pg_store *p, const write_op *w, csf_error *err)
{
    if (p->flushing) return to_server(p, w, err);
    if (p->spool.spooling) {
        csf_error e2;
        p->flushing = 1;
        csf_status fs = flush_spool(p, 0.0, &e2);
        p->flushing = 0;
        if (fs != CSF_OK) return lost(p) ? to_spool(p, w, err) : csf_error_set(err, fs, "%s", e2.msg);
    }
    p->retrying = 0;
    for (;;) {
        csf_status cs = to_server(p, w, err);
        if (cs == CSF_OK || !lost(p)) return cs;
        csf_error e2;
        csf_status rs = reconnect(p, p->spool_after_s, 1, &e2);
        if (rs != CSF_OK) return lost(p) ? to_spool(p, w, err) : csf_error_set(err, rs, "%s", e2.msg);
        p->retrying = 1;
    }
}

static csf_status pg_set_session_state(csf_store *b, int64_t id, csf_session_state state, csf_error *err)
{
    pg_store *p = pg(b);
    if (!known(p, id)) RETRY(p, err, set_state_once(p, id, state, err)); /* a claim to take */
    write_op w = {.kind = CSF_SPOOL_STATE, .sid = id, .state = state};
    return write_or_spool(p, &w, err);
}

/* ---- person time ---------------------------------------------------------------------------
 * Sent as the total the session has after the write, not as the amount added: a repeat after a
 * dropped connection whose first COMMIT got through finds the total there and adds nothing, and
 * the spool keeps the same total. The total is the server's value (while it is away: the one
 * this station last knew) plus the addition; the station holds the session's claim, so no other
 * station changes it in between. */

/* Why an update of session id's person time to total_s changed no row: the session is missing,
 * closed, another station's (row-level security hides it from this login's UPDATE), or already
 * at total_s (or past it, for a copy's raise: exact 0). */
static csf_status person_unchanged(pg_store *p, int64_t id, double total_s, int exact, csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT state, person_s FROM sessions WHERE id = $1", &a);
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        csf_status cs = fail(p, r, "reading a session's person time", err);
        PQclear(r);
        return cs;
    }
    int found = PQntuples(r) == 1;
    char state[16] = "";
    double have_s = found ? g_dbl(r, 0, 1) : NAN;
    if (found) g_txt(r, 0, 0, state, sizeof state);
    PQclear(r);
    if (!found)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path, (long long)id);
    /* Read back as text: equal to the last bits only where the server writes floats exactly
     * (extra_float_digits >= 1, PostgreSQL 12's default), so a rounding's width is allowed. */
    if (fabs(have_s - total_s) <= 1e-12 * fmax(1.0, total_s) || (!exact && have_s > total_s)) return CSF_OK;
    csf_session_state now_state = csf_session_state_from_name(state);
    if (csf_session_state_closed(now_state))
        return csf_store_person_time_closed(err, p->base.path, id, now_state);
    if (have_s > total_s)
        return csf_error_set(err, CSF_E_STORE,
                             "store %s: session %lld has %.17g s of person time "
                             "on the server, not the %.17g s this station expected after its "
                             "addition: another connection changed it; nothing was added",
                             p->base.path, (long long)id, have_s, total_s);
    return state_unchanged(p, id, err);
}

static csf_status person_once(pg_store *p, int64_t id, double total_s, int exact, csf_error *err)
{
    pgargs a = {0};
    a_dbl(&a, total_s);
    a_i64(&a, id);
    PGresult *r = run(p,
                      "UPDATE sessions SET person_s = $1 WHERE id = $2"
                      " AND state IN ('running', 'paused')"
                      " AND (person_s IS NULL OR person_s < $1)",
                      &a);
    csf_status cs = CSF_OK;
    if (!ok(r)) cs = fail(p, r, "storing a session's person time", err);
    else if (!strcmp(PQcmdTuples(r), "0")) cs = person_unchanged(p, id, total_s, exact, err);
    PQclear(r);
    return cs;
}

static csf_status read_person_once(pg_store *p, int64_t id, double *have_s, csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, id);
    PGresult *r = run(p, "SELECT person_s FROM sessions WHERE id = $1", &a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading a session's person time", err);
    else if (PQntuples(r) == 0)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path, (long long)id);
    else *have_s = g_dbl(r, 0, 0);
    PQclear(r);
    return cs;
}

static csf_status read_person(pg_store *p, int64_t id, double *have_s, csf_error *err)
{
    RETRY(p, err, read_person_once(p, id, have_s, err));
}

static csf_session_info *known_mut(pg_store *p, int64_t id)
{
    for (size_t i = 0; i < p->n_known; i++)
        if (p->known[i].id == id) return &p->known[i];
    return NULL;
}

/* The session's person time before an addition: the server's while it answers and holds all
 * this station wrote (this station holds the claim, so it stays so until the addition), else
 * what this station last knew of a session it runs (the spool may hold the newer total). */
static csf_status person_before(pg_store *p, int64_t id, double *have_s, csf_error *err)
{
    const csf_session_info *k = known(p, id);
    if (!k) return read_person(p, id, have_s, err);
    csf_error e2;
    if (p->spool.spooling || lost(p) || read_person_once(p, id, have_s, &e2) != CSF_OK) *have_s = k->person_s;
    return CSF_OK;
}

static csf_status pg_add_person_time(csf_store *b, int64_t id, double seconds, csf_error *err)
{
    pg_store *p = pg(b);
    double have_s = NAN;
    csf_status cs = person_before(p, id, &have_s, err);
    if (cs != CSF_OK) return cs;
    write_op w = {.kind = CSF_SPOOL_PERSON,
                  .sid = id,
                  .person_exact = 1,
                  .person_s = (isnan(have_s) ? 0.0 : have_s) + seconds};
    cs = write_or_spool(p, &w, err);
    csf_session_info *km = known_mut(p, id);
    if (cs == CSF_OK && km) km->person_s = w.person_s;
    return cs;
}

static csf_status pg_raise_person_time(csf_store *b, int64_t id, double total_s, csf_error *err)
{
    pg_store *p = pg(b);
    write_op w = {.kind = CSF_SPOOL_PERSON, .sid = id, .person_s = total_s};
    csf_status cs = write_or_spool(p, &w, err);
    csf_session_info *km = known_mut(p, id);
    if (cs == CSF_OK && km && !(km->person_s >= total_s)) km->person_s = total_s;
    return cs;
}

/* ---- readings ------------------------------------------------------------------------------ */

static csf_status add_reading_once(pg_store *p, const csf_reading *rd, csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, rd->session_id);
    a_i64(&a, rd->seq);
    a_txt(&a, rd->channel);
    a_dbl(&a, rd->drive01);
    a_dbl(&a, rd->lum_cdm2);
    a_dbl(&a, rd->has_xyz ? rd->X : NAN);
    a_dbl(&a, rd->has_xyz ? rd->Y : NAN);
    a_dbl(&a, rd->has_xyz ? rd->Z : NAN);
    a_dbl(&a, isnan(rd->t_s) ? 0.0 : rd->t_s);
    a_txt(&a, csf_reading_status_name(rd->status));
    a_dbl(&a, csf_store_unix_now_s());
    PGresult *r = run(p, "INSERT INTO readings (session_id, seq, channel, drive01, lum_cdm2, X_cdm2,"
                         " Y_cdm2, Z_cdm2, t_s, status, stored_s)"
                         " VALUES ($1,$2,$3,$4,$5,$6,$7,$8,$9,$10,$11)", &a);
    csf_status cs = CSF_OK;
    if (ok(r) || (p->retrying && duplicate(r))) cs = CSF_OK; /* a repeat whose first commit got through */
    else if (constraint(r))
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "store %s: reading %d of session %lld refused "
                           "(session unknown or seq already stored): %s", p->base.path, rd->seq,
                           (long long)rd->session_id, PQresultErrorField(r, PG_DIAG_MESSAGE_PRIMARY));
    else cs = fail(p, r, "storing a photometer reading", err);
    PQclear(r);
    return cs;
}

static csf_status pg_add_reading(csf_store *b, const csf_reading *rd, csf_error *err)
{
    write_op w = {.kind = CSF_SPOOL_READING, .sid = rd->session_id, .r = rd};
    return write_or_spool(pg(b), &w, err);
}

static int reading_row(const PGresult *r, int i, void *elem, int64_t session_id)
{
    csf_store_cols c = cols(r, i);
    csf_store_row_reading(&c, session_id, elem);
    return 0;
}

static csf_status pg_get_readings(csf_store *b, int64_t session_id, csf_reading **out, size_t *n,
                                  csf_error *err)
{
    static const row_query q = {
        .sql = "SELECT " CSF_STORE_READING_COLS " FROM readings WHERE session_id = $1 ORDER BY seq",
        .binds_session = 1, .elem_size = sizeof(csf_reading), .row = reading_row,
        .what = "reading photometer readings"};
    return query_rows(pg(b), &q, session_id, (void **)out, n, err);
}

/* ---- trials and frames ------------------------------------------------------------------- */

static void trial_args(pgargs *a, const csf_trial *t)
{
    a_i64(a, t->session_id);
    a_i64(a, t->seq);
    a_txt(a, t->method);
    a_dbl(a, t->freq_cpd);
    a_dbl(a, t->ecc_deg);
    a_dbl(a, isnan(t->polar_deg) ? 0.0 : t->polar_deg);
    a_dbl(a, isnan(t->orientation_deg) ? 0.0 : t->orientation_deg);
    a_dbl(a, isnan(t->sigma_deg) ? 0.0 : t->sigma_deg);
    a_dbl(a, isnan(t->velocity_dps) ? 0.0 : t->velocity_dps);
    a_dbl(a, isnan(t->mean_lum_cdm2) ? 0.0 : t->mean_lum_cdm2);
    a_i64(a, t->is_catch != 0);
    a_i64(a, t->is_practice != 0);
    a_dbl(a, t->contrast_requested);
    a_dbl(a, t->contrast_shown_mean);
    a_dbl(a, t->contrast_shown_max);
    a_i64(a, t->frames_planned);
    a_i64(a, t->frames_shown);
    a_i64(a, t->frames_missed);
    a_i64(a, t->signal_interval);
    a_i64(a, t->response);
    a_dbl(a, t->rt_s);
    a_dbl(a, t->click_x_deg);
    a_dbl(a, t->click_y_deg);
    a_i64(a, t->valid != 0);
    a_txt(a, t->flags);
    a_dbl(a, csf_store_unix_now_s());
    a_i64(a, t->n_alternatives);
    a_dbl(a, t->has_onset ? t->onset_s : NAN);
}

/* Frame intervals of one trial in one statement (one round trip however many frames). */
static csf_status insert_frames(pg_store *p, int64_t session_id, int trial_seq,
                                const double *interval_s, int n, csf_error *err)
{
    size_t cap = (size_t)n * 26 + 3;
    char *arr = malloc(cap);
    if (!arr) return csf_error_set(err, CSF_E_NOMEM, "store: out of memory storing frame intervals");
    size_t o = 0;
    arr[o++] = '{';
    for (int i = 0; i < n; i++)
        o += (size_t)snprintf(arr + o, cap - o, "%s%.17g", i ? "," : "",
                              isfinite(interval_s[i]) ? interval_s[i] : 0.0);
    snprintf(arr + o, cap - o, "}");
    pgargs a = {0};
    a_i64(&a, session_id);
    a_i64(&a, trial_seq);
    a_txt(&a, arr);
    PGresult *r = run(p, "INSERT INTO frame_intervals (session_id, trial_seq, idx, interval_s)"
                         " SELECT $1, $2, u.i - 1, u.v FROM unnest($3::double precision[])"
                         " WITH ORDINALITY AS u(v, i)", &a);
    free(arr);
    csf_status cs = CSF_OK;
    if (ok(r) || (p->retrying && duplicate(r))) cs = CSF_OK;
    else if (constraint(r))
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "store %s: frame intervals of trial %d of "
                           "session %lld refused (session unknown or already stored)",
                           p->base.path, trial_seq, (long long)session_id);
    else cs = fail(p, r, "storing frame intervals", err);
    PQclear(r);
    return cs;
}

static csf_status add_trial_once(pg_store *p, const csf_trial *t, const double *iv, int n,
                                 csf_error *err)
{
    csf_status cs = n > 0 ? run_cmd(p, "BEGIN", NULL, "storing a trial", err) : CSF_OK;
    pgargs a = {0};
    trial_args(&a, t);
    PGresult *r =
        cs == CSF_OK
            ? run(p,
                  "INSERT INTO trials (session_id, seq, method, freq_cpd,"
                  " ecc_deg, polar_deg, orientation_deg, sigma_deg, velocity_dps, mean_lum_cdm2, is_catch,"
                  " is_practice, contrast_requested, contrast_shown_mean, contrast_shown_max, frames_planned,"
                  " frames_shown, frames_missed, signal_interval, response, rt_s, click_x_deg, click_y_deg,"
                  " valid, flags, stored_s, n_alternatives, onset_s) VALUES ($1,$2,$3,$4,$5,$6,$7,$8,$9,$10,"
                  "$11,$12,$13,$14,$15,$16,$17,$18,$19,$20,$21,$22,$23,$24,$25,$26,$27,$28)",
                  &a)
            : NULL;
    int repeat_done = r && p->retrying && duplicate(r);
    if (cs == CSF_OK && !ok(r) && !repeat_done)
        cs = constraint(r)
            ? csf_error_set(err, CSF_E_INVALID_ARG, "store %s: trial %d of session %lld refused "
                            "(session unknown or seq already stored): %s", p->base.path, t->seq,
                            (long long)t->session_id, PQresultErrorField(r, PG_DIAG_MESSAGE_PRIMARY))
            : fail(p, r, "storing a trial", err);
    PQclear(r);
    if (repeat_done) { /* the whole transaction got through before the drop */
        rollback(p);
        return CSF_OK;
    }
    if (cs == CSF_OK && n > 0) cs = insert_frames(p, t->session_id, t->seq, iv, n, err);
    if (cs == CSF_OK && n > 0) cs = commit(p, "storing a trial", err);
    if (cs != CSF_OK && n > 0) rollback(p);
    return cs;
}

static csf_status pg_add_trial_frames(csf_store *b, const csf_trial *t, const double *iv, int n,
                                      csf_error *err)
{
    write_op w = {.kind = CSF_SPOOL_TRIAL, .sid = t->session_id, .t = t, .iv = iv, .n = n};
    return write_or_spool(pg(b), &w, err);
}

static int trial_row(const PGresult *r, int i, void *elem, int64_t session_id)
{
    csf_store_cols c = cols(r, i);
    csf_store_row_trial(&c, session_id, elem);
    return 0;
}

static csf_status pg_get_trials(csf_store *b, int64_t session_id, csf_trial **out, size_t *n,
                                csf_error *err)
{
    static const row_query q = {
        .sql = "SELECT " CSF_STORE_TRIAL_COLS " FROM trials WHERE session_id = $1 ORDER BY seq",
        .binds_session = 1, .elem_size = sizeof(csf_trial), .row = trial_row,
        .what = "reading trials"};
    return query_rows(pg(b), &q, session_id, (void **)out, n, err);
}

static csf_status pg_add_frame_intervals(csf_store *b, int64_t session_id, int trial_seq,
                                         const double *interval_s, int n, csf_error *err)
{
    write_op w = {.kind = CSF_SPOOL_FRAMES, .sid = session_id, .seq = trial_seq, .iv = interval_s, .n = n};
    return write_or_spool(pg(b), &w, err);
}

static csf_status to_server(pg_store *p, const write_op *w, csf_error *err)
{
    switch (w->kind) {
    case CSF_SPOOL_TRIAL: return add_trial_once(p, w->t, w->iv, w->n, err);
    case CSF_SPOOL_READING: return add_reading_once(p, w->r, err);
    case CSF_SPOOL_FRAMES: return insert_frames(p, w->sid, w->seq, w->iv, w->n, err);
    case CSF_SPOOL_THRESHOLDS: return put_thresholds_once(p, w->sid, w->rows, w->n_rows, err);
    case CSF_SPOOL_ARTIFACT: return add_artifact_once(p, w->sid, w->art_kind, w->path, w->blob, w->len, err);
    case CSF_SPOOL_LINK: return link_once(p, w->sid, w->participant_id, err);
    case CSF_SPOOL_PERSON: return person_once(p, w->sid, w->person_s, w->person_exact, err);
    default: return set_state_once(p, w->sid, w->state, err);
    }
}

static int interval_row(const PGresult *r, int i, void *elem, int64_t session_id)
{
    (void)session_id;
    *(double *)elem = g_dbl(r, i, 0);
    return 0;
}

static csf_status pg_get_frame_intervals(csf_store *b, int64_t session_id, double **out, size_t *n,
                                         csf_error *err)
{
    static const row_query q = {
        .sql = "SELECT interval_s FROM frame_intervals WHERE session_id = $1 ORDER BY trial_seq, idx",
        .binds_session = 1, .elem_size = sizeof(double), .row = interval_row,
        .what = "reading frame intervals"};
    return query_rows(pg(b), &q, session_id, (void **)out, n, err);
}

/* ---- thresholds ------------------------------------------------------------------------------ */

static int threshold_row(const PGresult *r, int i, void *elem, int64_t session_id)
{
    (void)session_id;
    csf_store_cols c = cols(r, i);
    csf_store_row_threshold(&c, elem);
    return 0;
}

static const row_query threshold_query = {
    .sql = "SELECT " CSF_STORE_THRESHOLD_COLS " FROM thresholds WHERE session_id = $1"
           " ORDER BY lum_cdm2, velocity_dps, ecc_deg, freq_cpd",
    .binds_session = 1, .elem_size = sizeof(csf_threshold_row), .row = threshold_row,
    .what = "reading thresholds"};

static int same_value(double a, double b) { return (isnan(a) && isnan(b)) || a == b; }

static int same_threshold(const csf_threshold_row *a, const csf_threshold_row *b)
{
    return same_value(a->freq_cpd, b->freq_cpd) && same_value(a->ecc_deg, b->ecc_deg) &&
           same_value(isnan(a->velocity_dps) ? 0.0 : a->velocity_dps, b->velocity_dps) &&
           same_value(isnan(a->lum_cdm2) ? 0.0 : a->lum_cdm2, b->lum_cdm2) &&
           same_value(a->threshold, b->threshold) &&
           same_value(a->stderr_log10, b->stderr_log10) && a->n_trials == b->n_trials;
}

/* 1 when the session already has exactly these thresholds (in any order): replacing them would
 * change nothing, and a lab's server refuses any change to a finished session, so a second push
 * of one must not try. */
static int thresholds_stored(pg_store *p, int64_t session_id, const csf_threshold_row *rows,
                             size_t n)
{
    void *list = NULL;
    size_t have = 0;
    csf_error e;
    if (query_rows_once(p, &threshold_query, session_id, &list, &have, &e) != CSF_OK) return 0;
    const csf_threshold_row *h = list;
    int same = have == n;
    for (size_t i = 0; same && i < n; i++) {
        int found = 0;
        for (size_t k = 0; !found && k < have; k++) found = same_threshold(&rows[i], &h[k]);
        same = found;
    }
    free(list);
    return same;
}


static csf_status put_thresholds_once(pg_store *p, int64_t session_id, const csf_threshold_row *rows,
                                      size_t n, csf_error *err)
{
    const char *what = "storing thresholds";
    if (n > 0 && thresholds_stored(p, session_id, rows, n)) return CSF_OK;
    csf_status cs = run_cmd(p, "BEGIN", NULL, what, err);
    pgargs s = {0};
    a_i64(&s, session_id);
    int64_t exists = 0;
    if (cs == CSF_OK)
        cs = query_i64(p, "SELECT COUNT(*) FROM sessions WHERE id = $1", &s, &exists, what, err);
    if (cs == CSF_OK && !exists)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no session %lld", p->base.path,
                           (long long)session_id);
    if (cs == CSF_OK) cs = run_cmd(p, "DELETE FROM thresholds WHERE session_id = $1", &s, what, err);
    for (size_t i = 0; i < n && cs == CSF_OK; i++) {
        pgargs a = {0};
        a_i64(&a, session_id);
        a_dbl(&a, rows[i].freq_cpd);
        a_dbl(&a, rows[i].ecc_deg);
        a_dbl(&a, isnan(rows[i].velocity_dps) ? 0.0 : rows[i].velocity_dps);
        a_dbl(&a, isnan(rows[i].lum_cdm2) ? 0.0 : rows[i].lum_cdm2);
        a_dbl(&a, rows[i].threshold);
        a_dbl(&a, rows[i].stderr_log10);
        a_i64(&a, rows[i].n_trials);
        cs = run_cmd(p, "INSERT INTO thresholds (session_id, freq_cpd, ecc_deg, velocity_dps,"
                        " lum_cdm2, threshold_michelson, stderr_log10, n_trials)"
                        " VALUES ($1,$2,$3,$4,$5,$6,$7,$8)", &a, what, err);
    }
    if (cs == CSF_OK) return commit(p, what, err);
    rollback(p);
    return cs;
}

static csf_status pg_put_thresholds(csf_store *b, int64_t session_id, const csf_threshold_row *rows,
                                    size_t n, csf_error *err)
{
    pg_store *p = pg(b);
    if (!known(p, session_id)) RETRY(p, err, put_thresholds_once(p, session_id, rows, n, err));
    write_op w = {.kind = CSF_SPOOL_THRESHOLDS, .sid = session_id, .rows = rows, .n_rows = n};
    return write_or_spool(p, &w, err);
}

static csf_status pg_get_thresholds(csf_store *b, int64_t session_id, csf_threshold_row **out,
                                    size_t *n, csf_error *err)
{
    return query_rows(pg(b), &threshold_query, session_id, (void **)out, n, err);
}

/* ---- artifacts ------------------------------------------------------------------------------ */

/* Value of a "key = value" line in the first 4 KiB of a display profile text; "" when absent. */
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

/* A display profile stored by a session becomes that display's current profile, with history. */
static csf_status record_profile(pg_store *p, int64_t session_id, const void *blob, size_t len,
                                 csf_error *err)
{
    const char magic[] = "csfcal-display-profile";
    if (!blob || len < sizeof magic || memcmp(blob, magic, sizeof magic - 1) != 0) return CSF_OK;
    char id[128], display[256], now[32];
    profile_key(blob, len, "id", id, sizeof id);
    profile_key(blob, len, "display", display, sizeof display);
    if (!id[0] || !display[0]) return CSF_OK;
    csf_store_utc_now(now);
    const char *what = "recording a display profile";
    pgargs a = {0};
    a_txt(&a, display);
    a_txt(&a, id);
    a_txt(&a, now);
    /* The history row first: on a lab's server a station may make a display's current profile
     * only one its own session measured (docs/store_roles.sql), and this row is what says so. */
    csf_status cs = run_cmd(p, "INSERT INTO displays (name, profile_id, created_utc) VALUES"
                               " ($1, $2, $3) ON CONFLICT (name) DO NOTHING", &a, what, err);
    a_i64(&a, session_id);
    if (cs == CSF_OK)
        cs = run_cmd(p, "INSERT INTO display_profiles (display_id, profile_id, session_id,"
                        " created_utc) SELECT id, $2, $4, $3 FROM displays WHERE name = $1",
                     &a, what, err);
    a.n = 2;
    if (cs == CSF_OK)
        cs = run_cmd(p, "UPDATE displays SET profile_id = $2 WHERE name = $1 AND profile_id IS"
                        " DISTINCT FROM $2", &a, what, err);
    return cs;
}

/* The writer of a file and the code that produced its bytes may each record it: the second call
 * completes the first call's row (see csf_store_add_artifact). */
static csf_status complete_half_record(pg_store *p, int64_t session_id, const char *kind,
                                       const char *path, const void *blob, size_t len,
                                       int *merged, csf_error *err)
{
    *merged = 0;
    int has_path = path && *path;
    if (has_path == (blob != NULL)) return CSF_OK;
    pgargs a = {0};
    a_i64(&a, session_id);
    a_txt(&a, kind);
    if (has_path) a_txt(&a, path);
    else {
        a_bin(&a, blob, len);
        a_i64(&a, (int64_t)len);
    }
    PGresult *r = run(p, has_path
        ? "UPDATE artifacts SET path = $3 WHERE id = (SELECT id FROM artifacts WHERE"
          " session_id = $1 AND kind = $2 AND path = '' AND content IS NOT NULL"
          " ORDER BY id DESC LIMIT 1)"
        : "UPDATE artifacts SET content = $3, size_bytes = $4 WHERE id = (SELECT id"
          " FROM artifacts WHERE session_id = $1 AND kind = $2 AND path <> ''"
          " AND content IS NULL ORDER BY id DESC LIMIT 1)", &a);
    csf_status cs = ok(r) ? CSF_OK : fail(p, r, "storing an artifact", err);
    if (cs == CSF_OK) *merged = strcmp(PQcmdTuples(r), "0") != 0;
    PQclear(r);
    return cs;
}

static csf_status add_artifact_once(pg_store *p, int64_t session_id, const char *kind,
                                    const char *path, const void *blob, size_t len, csf_error *err)
{
    const char *what = "storing an artifact";
    if (p->retrying) { /* a repeat whose first COMMIT got through must not add a second row */
        pgargs q = {0};
        a_i64(&q, session_id);
        a_txt(&q, kind);
        a_txt(&q, path ? path : "");
        if (blob) a_bin(&q, blob, len);
        else a_txt(&q, NULL);
        int64_t have = 0;
        csf_status qs = query_i64(p, "SELECT COUNT(*) FROM artifacts WHERE session_id = $1 AND"
                                     " kind = $2 AND ($3 = '' OR path = $3) AND ($4::bytea IS NULL"
                                     " OR content = $4::bytea)", &q, &have, what, err);
        if (qs != CSF_OK || have > 0) return qs;
    }
    csf_status cs = run_cmd(p, "BEGIN", NULL, what, err);
    int merged = 0;
    if (cs == CSF_OK) cs = complete_half_record(p, session_id, kind, path, blob, len, &merged, err);
    if (cs == CSF_OK && !merged) {
        char now[32];
        csf_store_utc_now(now);
        pgargs a = {0};
        a_i64(&a, session_id);
        a_txt(&a, kind);
        a_txt(&a, path ? path : "");
        a_i64(&a, (int64_t)len);
        if (blob) a_bin(&a, blob, len);
        else a_txt(&a, NULL);
        a_txt(&a, now);
        PGresult *r = run(p, "INSERT INTO artifacts (session_id, kind, path, size_bytes, content,"
                             " created_utc) VALUES ($1,$2,$3,$4,$5,$6)", &a);
        if (!ok(r))
            cs = constraint(r) ? csf_error_set(err, CSF_E_NOT_FOUND, "store %s: artifact refused: "
                                               "no session %lld", p->base.path, (long long)session_id)
                               : fail(p, r, what, err);
        PQclear(r);
    }
    if (cs == CSF_OK && !strcmp(kind, "profile")) cs = record_profile(p, session_id, blob, len, err);
    if (cs == CSF_OK) return commit(p, what, err);
    rollback(p);
    return cs;
}

static csf_status pg_add_artifact(csf_store *b, int64_t session_id, const char *kind,
                                  const char *path, const void *blob, size_t len, csf_error *err)
{
    pg_store *p = pg(b);
    if (!known(p, session_id))
        RETRY(p, err, add_artifact_once(p, session_id, kind, path, blob, len, err));
    write_op w = {.kind = CSF_SPOOL_ARTIFACT,
                  .sid = session_id,
                  .art_kind = kind,
                  .path = path,
                  .blob = blob,
                  .len = len};
    return write_or_spool(p, &w, err);
}

static csf_status pg_get_artifact(csf_store *b, int64_t session_id, const char *kind, void **blob,
                                  size_t *len, char *path_out, size_t path_len, csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_i64(&a, session_id);
    a_txt(&a, kind);
    /* Binary results: the bytes as stored, no hex decoding. */
    PGresult *r = PQexecParams(p->conn, "SELECT content, path FROM artifacts WHERE session_id ="
                               " $1::bigint AND kind = $2::text ORDER BY CASE WHEN content IS NULL"
                               " THEN 1 ELSE 0 END, id DESC LIMIT 1",
                               a.n, NULL, a.v, a.len, a.fmt, 1);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading an artifact", err);
    else if (PQntuples(r) == 0)
        cs = csf_error_set(err, CSF_E_NOT_FOUND, "store %s: session %lld has no '%s' artifact",
                           p->base.path, (long long)session_id, kind);
    if (cs == CSF_OK) {
        size_t nb = is_null(r, 0, 0) ? 0 : (size_t)PQgetlength(r, 0, 0);
        unsigned char *copy = malloc(nb + 1);
        if (!copy) cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory reading an artifact");
        else {
            if (nb) memcpy(copy, PQgetvalue(r, 0, 0), nb);
            copy[nb] = '\0';
            *blob = copy;
            *len = nb;
            if (path_out && path_len) {
                size_t pl = (size_t)PQgetlength(r, 0, 1);
                if (pl >= path_len) pl = path_len - 1;
                memcpy(path_out, PQgetvalue(r, 0, 1), pl);
                path_out[pl] = '\0';
            }
        }
    }
    PQclear(r);
    return cs;
}

/* ---- studies and participants ---------------------------------------------------------------- */

static csf_status pg_create_study(csf_store *b, const char *name, const char *design_json,
                                  int64_t *id, csf_error *err)
{
    pg_store *p = pg(b);
    char now[32];
    csf_store_utc_now(now);
    pgargs a = {0};
    a_txt(&a, name);
    a_txt(&a, design_json ? design_json : "{}");
    a_txt(&a, now);
    PGresult *r = run(p, "INSERT INTO studies (name, design_json, created_utc) VALUES ($1,$2,$3)"
                         " RETURNING id", &a);
    csf_status cs = CSF_OK;
    if (duplicate(r))
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "store %s: a study named '%s' already exists",
                           p->base.path, name);
    else if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "creating a study", err);
    else {
        note_name(p, g_i64(r, 0, 0), 0, name);
        if (id) *id = g_i64(r, 0, 0);
    }
    PQclear(r);
    return cs;
}

static csf_status pg_find_study(csf_store *b, const char *name, int64_t *id, csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_txt(&a, name);
    int64_t v = 0;
    csf_status cs = query_i64(p, "SELECT id FROM studies WHERE name = $1", &a, &v, "finding a study", err);
    if (cs == CSF_E_NOT_FOUND)
        return csf_error_set(err, CSF_E_NOT_FOUND, "store %s: no study named '%s'", p->base.path, name);
    if (cs == CSF_OK) note_name(p, v, 0, name);
    if (cs == CSF_OK && id) *id = v;
    return cs;
}

static csf_status pg_add_participant(csf_store *b, int64_t study_id, const char *code, int64_t *id,
                                     csf_error *err)
{
    pg_store *p = pg(b);
    char now[32];
    csf_store_utc_now(now);
    pgargs a = {0};
    a_i64(&a, study_id);
    a_txt(&a, code);
    a_txt(&a, now);
    PGresult *r = run(p, "INSERT INTO participants (study_id, code, created_utc) VALUES ($1,$2,$3)"
                         " RETURNING id", &a);
    csf_status cs = CSF_OK;
    if (constraint(r))
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "store %s: participant '%s' refused (study %lld "
                           "unknown or code already used in it)", p->base.path, code,
                           (long long)study_id);
    else if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "adding a participant", err);
    else {
        note_name(p, g_i64(r, 0, 0), study_id, code);
        if (id) *id = g_i64(r, 0, 0);
    }
    PQclear(r);
    return cs;
}

static csf_status pg_count_participants(csf_store *b, int64_t study_id, int *n, csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_i64(&a, study_id);
    int64_t v = 0;
    csf_status cs = query_i64(p, "SELECT COUNT(*) FROM participants WHERE study_id = $1", &a, &v,
                              "counting participants", err);
    if (cs == CSF_OK) *n = (int)v;
    return cs;
}

static csf_status link_once(pg_store *p, int64_t session_id, int64_t participant_id,
                            csf_error *err)
{
    pgargs a = {0};
    a_i64(&a, session_id);
    a_i64(&a, participant_id);
    PGresult *r = run(p, "INSERT INTO session_participants (session_id, participant_id) VALUES ($1,$2)", &a);
    csf_status cs = CSF_OK;
    if (ok(r) || (p->retrying && duplicate(r))) cs = CSF_OK;
    else if (constraint(r))
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "store %s: session %lld cannot be linked to "
                           "participant %lld (unknown, or already linked)", p->base.path,
                           (long long)session_id, (long long)participant_id);
    else cs = fail(p, r, "linking a session to a participant", err);
    PQclear(r);
    return cs;
}

static csf_status pg_link_session_participant(csf_store *b, int64_t session_id,
                                              int64_t participant_id, csf_error *err)
{
    pg_store *p = pg(b);
    if (!known(p, session_id)) RETRY(p, err, link_once(p, session_id, participant_id, err));
    write_op w = {.kind = CSF_SPOOL_LINK, .sid = session_id, .participant_id = participant_id};
    return write_or_spool(p, &w, err);
}

static csf_status pg_list_artifacts(csf_store *b, int64_t session_id, csf_store_artifact **out,
                                    size_t *n, csf_error *err)
{
    pg_store *p = pg(b);
    *out = NULL;
    *n = 0;
    pgargs a = {0};
    a_i64(&a, session_id);
    /* Binary results: the bytes as stored. */
    PGresult *r = PQexecParams(p->conn, "SELECT kind, path, content FROM artifacts WHERE"
                               " session_id = $1::bigint ORDER BY id", a.n, NULL, a.v, a.len,
                               a.fmt, 1);
    csf_status cs = CSF_OK;
    int rows = PQntuples(r);
    csf_store_artifact *list = NULL;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "listing artifacts", err);
    else if (rows > 0 && !(list = calloc((size_t)rows, sizeof *list)))
        cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory listing artifacts");
    int i = 0;
    /* list is set whenever cs is CSF_OK and rows > 0; tested too, for the analyzer, which does
     * not follow fail() far enough to see that it never returns CSF_OK */
    for (; cs == CSF_OK && list && i < rows; i++) {
        csf_store_artifact *o = &list[i];
        g_txt(r, i, 0, o->kind, sizeof o->kind);
        size_t pl = (size_t)PQgetlength(r, i, 1);
        if (pl >= sizeof o->path) pl = sizeof o->path - 1;
        memcpy(o->path, PQgetvalue(r, i, 1), pl);
        o->path[pl] = '\0';
        if (is_null(r, i, 2)) continue;
        o->len = (size_t)PQgetlength(r, i, 2);
        if (!(o->blob = malloc(o->len + 1)))
            cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory listing artifacts");
        else if (o->len) memcpy(o->blob, PQgetvalue(r, i, 2), o->len);
    }
    PQclear(r);
    if (cs != CSF_OK) {
        csf_store_artifacts_free(list, list ? (size_t)rows : 0);
        return cs;
    }
    *out = list;
    *n = (size_t)rows;
    return CSF_OK;
}

static csf_status pg_session_participant(csf_store *b, int64_t session_id, char study[256],
                                         char **design_json, char code[64], csf_error *err)
{
    pg_store *p = pg(b);
    *design_json = NULL;
    pgargs a = {0};
    a_i64(&a, session_id);
    PGresult *r = run(p, "SELECT st.name, st.design_json, p.code FROM session_participants sp"
                         " JOIN participants p ON p.id = sp.participant_id"
                         " JOIN studies st ON st.id = p.study_id WHERE sp.session_id = $1", &a);
    csf_status cs = CSF_OK;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading a session's participant", err);
    else if (PQntuples(r) == 0) cs = CSF_E_NOT_FOUND;
    else {
        g_txt(r, 0, 0, study, 256);
        *design_json = strdup(is_null(r, 0, 1) ? "{}" : PQgetvalue(r, 0, 1));
        g_txt(r, 0, 2, code, 64);
        if (!*design_json) cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory");
    }
    PQclear(r);
    return cs;
}

static csf_status link_named_once(pg_store *p, int64_t session_id, const char *study,
                                  const char *design_json, const char *code, csf_error *err)
{
    static const char *const sql[] = {
        "INSERT INTO studies (name, design_json, created_utc) VALUES ($1, $2, $3)"
        " ON CONFLICT DO NOTHING",
        /* Rows already there are not proposed again: a lab's server checks every proposed row
         * (a participant only for a session of this station, nothing added to a closed one). */
        "INSERT INTO participants (study_id, code, created_utc) SELECT id, $4, $3 FROM studies"
        " WHERE name = $1 AND NOT EXISTS (SELECT 1 FROM participants q WHERE q.study_id ="
        " studies.id AND q.code = $4) ON CONFLICT DO NOTHING",
        "INSERT INTO session_participants (session_id, participant_id) SELECT $5, p.id FROM"
        " participants p JOIN studies st ON st.id = p.study_id WHERE st.name = $1 AND"
        " p.code = $4 AND NOT EXISTS (SELECT 1 FROM session_participants q WHERE q.session_id"
        " = $5) ON CONFLICT DO NOTHING",
    };
    const char *what = "linking a session to a participant";
    char now[32];
    csf_store_utc_now(now);
    csf_status cs = run_cmd(p, "BEGIN", NULL, what, err);
    for (size_t i = 0; cs == CSF_OK && i < sizeof sql / sizeof sql[0]; i++) {
        pgargs a = {0};
        a_txt(&a, study);
        a_txt(&a, design_json ? design_json : "{}");
        a_txt(&a, now);
        a_txt(&a, code);
        a_i64(&a, session_id);
        /* Types given: a statement need not use every parameter. text x4, int8. */
        static const Oid types[] = {25, 25, 25, 25, 20};
        PGresult *r = PQexecParams(p->conn, sql[i], a.n, types, a.v, a.len, a.fmt, 0);
        cs = ok(r) ? CSF_OK : fail(p, r, what, err);
        PQclear(r);
    }
    if (cs == CSF_OK) return commit(p, what, err);
    rollback(p);
    return cs;
}

static csf_status pg_link_named(csf_store *b, int64_t session_id, const char *study,
                                const char *design_json, const char *code, csf_error *err)
{
    pg_store *p = pg(b);
    RETRY(p, err, link_named_once(p, session_id, study, design_json, code, err));
}

static csf_status pg_set_session_uuid(csf_store *b, int64_t id, const char *uuid, csf_error *err)
{
    pg_store *p = pg(b);
    pgargs a = {0};
    a_txt(&a, uuid);
    a_i64(&a, id);
    return run_cmd(p, "UPDATE sessions SET uuid = $1 WHERE id = $2 AND uuid IS NULL", &a,
                   "giving a session its uuid", err);
}

static csf_status pg_get_trial_frames(csf_store *b, int64_t session_id, int trial_seq,
                                      double **out, size_t *n, csf_error *err)
{
    pg_store *p = pg(b);
    *out = NULL;
    *n = 0;
    pgargs a = {0};
    a_i64(&a, session_id);
    a_i64(&a, trial_seq);
    PGresult *r = run(p, "SELECT interval_s FROM frame_intervals WHERE session_id = $1 AND"
                         " trial_seq = $2 ORDER BY idx", &a);
    csf_status cs = CSF_OK;
    int rows = PQntuples(r);
    if (PQresultStatus(r) != PGRES_TUPLES_OK) cs = fail(p, r, "reading frame intervals", err);
    else if (rows > 0 && !(*out = malloc((size_t)rows * sizeof **out)))
        cs = csf_error_set(err, CSF_E_NOMEM, "store: out of memory reading frame intervals");
    for (int i = 0; cs == CSF_OK && i < rows; i++) (*out)[i] = g_dbl(r, i, 0);
    if (cs == CSF_OK) *n = (size_t)rows;
    PQclear(r);
    return cs;
}

static const csf_store_ops pg_ops = {
    .name = "postgresql",
    .close = pg_close,
    .schema_version = pg_schema_version,
    .begin_session = pg_begin_session,
    .find_session_uuid = pg_find_session_uuid,
    .set_session_uuid = pg_set_session_uuid,
    .get_trial_frames = pg_get_trial_frames,
    .get_session = pg_get_session,
    .set_session_state = pg_set_session_state,
    .list_sessions = pg_list_sessions,
    .add_person_time = pg_add_person_time,
    .raise_person_time = pg_raise_person_time,
    .session_times = pg_session_times,
    .add_reading = pg_add_reading,
    .get_readings = pg_get_readings,
    .add_trial_frames = pg_add_trial_frames,
    .get_trials = pg_get_trials,
    .add_frame_intervals = pg_add_frame_intervals,
    .get_frame_intervals = pg_get_frame_intervals,
    .put_thresholds = pg_put_thresholds,
    .get_thresholds = pg_get_thresholds,
    .add_artifact = pg_add_artifact,
    .get_artifact = pg_get_artifact,
    .upsert_display = pg_upsert_display,
    .display_profile_id = pg_display_profile_id,
    .upsert_observer = pg_upsert_observer,
    .create_study = pg_create_study,
    .find_study = pg_find_study,
    .add_participant = pg_add_participant,
    .count_participants = pg_count_participants,
    .link_session_participant = pg_link_session_participant,
    .list_artifacts = pg_list_artifacts,
    .session_participant = pg_session_participant,
    .link_named = pg_link_named,
};
