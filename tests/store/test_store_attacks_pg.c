/* What a station or an analyst of a lab's PostgreSQL store could try against someone else's data,
 * each tried for real against the server pg_run.sh starts, with the roles of docs/store_roles.sql
 * (argv[1]) and passwords only in a libpq password file. Every attack must fail and leave the
 * rows as they were; every wait must end with a message naming who holds the lock.
 *   locks:    the analyst takes no advisory lock (claims, schema lock); a held schema lock or table
 *             lock makes csfcal give up after CSF_STORE_LOCK_WAIT_S naming the holder; a listing
 *             never takes the schema lock;
 *   temp:     no role but the owner creates temporary tables or functions;
 *   displays: no profile history row naming another station's session; a display's current
 *             profile changes only to one the station measured;
 *   closed:   a finished session takes no trial, frame interval, threshold deletion, artifact
 *             change, participant link or state change back to running;
 *   others:   a state change of another station's session names its owner;
 *   studies:  no participant without the station's own study session; a refused participant
 *             leaves no running session, and the study report leaves such a session out;
 *   push:     what a station may still do under these rules: push a finished session of its
 *             own file to the server, twice (the second adds nothing);
 *   spool:    a station whose server went away says so once, not on every write;
 *   held:     what held before (analyst writes, COPY TO PROGRAM, pg_read_file, SET ROLE). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/config.h"
#include "studies/study_report.h"
#include "studies/study_run.h"
#include "results/store/store.h"
#include "results/store/push.h"
#include "store_test_util.h"
#include "tests/check.h"

#define CLASS "1129530929" /* 'CSF1', the class of csfcal's advisory locks */

static char g_db[64];

static void loc_as(const char *user, char *out, size_t cap)
{
    snprintf(out, cap, "postgresql:///%s?host=%s&user=%s", g_db, getenv("CSF_TEST_PG_DIR"), user);
}

static PGconn *connect_as(const char *user)
{
    char uri[1024];
    loc_as(user, uri, sizeof uri);
    PGconn *c = PQconnectdb(uri);
    if (PQstatus(c) != CONNECTION_OK) fprintf(stderr, "connect %s: %s", user, PQerrorMessage(c));
    return c;
}

/* One statement on c; 0 when the server accepted it. */
static int exec_on(PGconn *c, const char *sql)
{
    PGresult *r = PQexec(c, sql);
    int ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
    PQclear(r);
    return ok ? 0 : -1;
}

/* A statement run by hand as user on a fresh connection (what a role could try); 0 when
 * allowed, and then also 0 rows changed counts as refused (RLS hides rows silently). */
static int try_as(const char *user, const char *sql)
{
    PGconn *c = connect_as(user);
    int rc = -1;
    if (PQstatus(c) == CONNECTION_OK) {
        PGresult *r = PQexec(c, sql);
        ExecStatusType t = PQresultStatus(r);
        if (t == PGRES_TUPLES_OK) rc = 0;
        else if (t == PGRES_COMMAND_OK) rc = strcmp(PQcmdTuples(r), "0") == 0 ? -1 : 0;
        PQclear(r);
    }
    PQfinish(c);
    return rc;
}

/* First column of the first row of sql, read as the server's superuser. */
static long long admin_int(const char *sql)
{
    char uri[1024];
    loc_as("csfcal_admin", uri, sizeof uri);
    return test_query_int(NULL, uri, sql);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int run_roles(const char *file)
{
    FILE *f = fopen(file, "rb");
    if (!f) return -1;
    static char sql[65536];
    size_t n = fread(sql, 1, sizeof sql - 1, f);
    fclose(f);
    sql[n] = '\0';
    return test_pg_admin(g_db, sql);
}

/* As README sets a lab up: a database owned by an ordinary login (csfcal_owner, no superuser,
 * no CREATEROLE) that creates the schema with csfcal; the roles script run by the superuser; two
 * stations and an analyst; passwords only in PGPASSFILE. */
static int setup(const char *roles_sql)
{
    char owner[1024];
    if (test_store_location("", "", owner, sizeof owner) != 0) return -1;
    sscanf(owner, "postgresql:///%63[^?]", g_db);
    char pass[600];
    snprintf(pass, sizeof pass, "%s/pgpass", getenv("CSF_TEST_PG_DIR"));
    FILE *f = fopen(pass, "w");
    if (!f) return -1;
    fprintf(f, "*:*:*:booth1:pw-booth-one\n*:*:*:booth2:pw-booth-two\n*:*:*:alice:pw-alice\n"
               "*:*:*:csfcal_owner:pw-owner\n");
    fclose(f);
    chmod(pass, 0600);
    setenv("PGPASSFILE", pass, 1);
    setenv("CSF_STORE_LOCK_WAIT_S", "1", 1);
    char sql[256];
    test_pg_admin(g_db, "DO $$ BEGIN IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname ="
                        " 'csfcal_owner') THEN CREATE ROLE csfcal_owner LOGIN PASSWORD 'pw-owner';"
                        " END IF; END $$");
    snprintf(sql, sizeof sql, "ALTER DATABASE %s OWNER TO csfcal_owner", g_db);
    CHECK_INT_EQ(test_pg_admin(g_db, sql), 0);
    loc_as("csfcal_owner", owner, sizeof owner);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(owner, &s, &err), CSF_OK); /* csfcal sessions init */
    csf_store_close(s);
    CHECK_INT_EQ(run_roles(roles_sql), 0);
    CHECK_INT_EQ(run_roles(roles_sql), 0); /* safe to run again */
    test_pg_admin(g_db, "DO $$ BEGIN IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'booth1')"
                        " THEN CREATE ROLE booth1 LOGIN PASSWORD 'pw-booth-one' IN ROLE csf_station;"
                        " CREATE ROLE booth2 LOGIN PASSWORD 'pw-booth-two' IN ROLE csf_station;"
                        " CREATE ROLE alice LOGIN PASSWORD 'pw-alice' IN ROLE csf_analyst; END IF; END $$");
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM pg_tables WHERE tablename = 'sessions' AND"
                           " tableowner = 'csfcal_owner'"), 1);
    return 0;
}

static csf_store *open_as(const char *user, int readonly)
{
    char uri[1024];
    loc_as(user, uri, sizeof uri);
    csf_store *s = NULL;
    csf_error err;
    csf_status st = readonly ? csf_store_open_readonly(uri, &s, &err) : csf_store_open(uri, &s, &err);
    if (st != CSF_OK) fprintf(stderr, "open as %s: %s\n", user, err.msg);
    return s;
}

/* A session of store s with n trials, each with frame intervals. */
static int64_t session_with_trials(csf_store *s, int n)
{
    int64_t sid = 0;
    csf_error err;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "p", "booth-lcd", NULL, 1, &sid, &err),
                 CSF_OK);
    for (int i = 0; i < n; i++) {
        csf_trial t = make_trial(sid, i, 1);
        double iv[3] = {0.0166, 0.0167, 0.0168};
        CHECK_INT_EQ(csf_store_add_trial_frames(s, &t, iv, 3, &err), CSF_OK);
    }
    return sid;
}

/* ---- locks ---------------------------------------------------------------------------------- */

static void test_analyst_takes_no_lock(int64_t sid)
{
    static const char *const fns[] = {
        "pg_advisory_lock(" CLASS ", 0)", "pg_try_advisory_lock(" CLASS ", 0)",
        "pg_advisory_lock_shared(" CLASS ", 0)", "pg_try_advisory_lock_shared(" CLASS ", 0)",
        "pg_advisory_xact_lock(" CLASS ", 0)", "pg_try_advisory_xact_lock(" CLASS ", 0)",
        "pg_advisory_xact_lock_shared(" CLASS ", 0)", "pg_try_advisory_xact_lock_shared(" CLASS ", 0)",
        "pg_advisory_lock(4851020977389043712)", "pg_try_advisory_lock_shared(1)",
        "pg_advisory_xact_lock(1)", "pg_try_advisory_xact_lock_shared(1)"};
    for (size_t i = 0; i < sizeof fns / sizeof fns[0]; i++) {
        char sql[160];
        snprintf(sql, sizeof sql, "SELECT %s", fns[i]);
        CHECK_MSG(try_as("alice", sql) != 0, "analyst may run %s", sql);
    }
    /* Nor a row or table lock a station's write would wait for. */
    static const char *const row_locks[] = {
        "SELECT id FROM sessions FOR UPDATE", "SELECT id FROM sessions FOR KEY SHARE",
        "SELECT seq FROM trials FOR SHARE", "BEGIN; LOCK TABLE trials IN SHARE MODE; COMMIT",
        "BEGIN; LOCK TABLE sessions IN EXCLUSIVE MODE; COMMIT"};
    for (size_t i = 0; i < sizeof row_locks / sizeof row_locks[0]; i++) {
        CHECK_MSG(try_as("alice", row_locks[i]) != 0, "analyst may run %s", row_locks[i]);
        CHECK_MSG(try_as("csfcal_admin", row_locks[i]) == 0, "owner may not run %s", row_locks[i]);
    }
    char sql[160];
    snprintf(sql, sizeof sql, "SELECT pg_try_advisory_lock_shared(" CLASS ", %lld)", (long long)sid);
    CHECK(try_as("alice", sql) != 0);
    snprintf(sql, sizeof sql, "SELECT pg_try_advisory_lock(" CLASS ", %lld)", (long long)sid);
    CHECK(try_as("booth2", sql) == 0); /* stations still may (booth1's csfcal holds this one) */
}

/* A station holding the schema lock by hand: a new store's creation gives up after the limit,
 * naming the holder; reading (a listing) never waits for it. */
static void test_schema_lock_wait(void)
{
    PGconn *hold = connect_as("booth2");
    CHECK_INT_EQ(exec_on(hold, "SET application_name = 'holder-by-hand'"), 0);
    CHECK_INT_EQ(exec_on(hold, "SELECT pg_advisory_lock(" CLASS ", 0)"), 0);

    csf_store *ro = NULL;
    double t0 = now_s();
    ro = open_as("alice", 1);
    CHECK(ro != NULL);
    csf_session_info *list = NULL;
    size_t n = 0;
    csf_error err;
    if (ro) CHECK_INT_EQ(csf_store_list_sessions(ro, &list, &n, &err), CSF_OK);
    csf_session_list_free(list, n);
    csf_store_close(ro);
    CHECK_MSG(now_s() - t0 < 0.9, "listing took %.1f s under a held schema lock", now_s() - t0);

    /* A database without the schema yet: creating it needs the lock, which booth2 holds there. */
    char sql[160], fresh[80], uri[1024];
    snprintf(fresh, sizeof fresh, "%s_fresh", g_db);
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", fresh);
    CHECK_INT_EQ(test_pg_admin("csfcal", sql), 0);
    snprintf(uri, sizeof uri, "postgresql:///%s?host=%s&user=booth2", fresh, getenv("CSF_TEST_PG_DIR"));
    PGconn *hold2 = PQconnectdb(uri);
    CHECK_INT_EQ(exec_on(hold2, "SET application_name = 'holder-by-hand'"), 0);
    CHECK_INT_EQ(exec_on(hold2, "SELECT pg_advisory_lock(" CLASS ", 0)"), 0);
    snprintf(uri, sizeof uri, "postgresql:///%s?host=%s&user=booth1", fresh, getenv("CSF_TEST_PG_DIR"));
    csf_store *s = NULL;
    t0 = now_s();
    CHECK_INT_EQ(csf_store_open(uri, &s, &err), CSF_E_STORE);
    double took_s = now_s() - t0;
    CHECK_MSG(took_s >= 0.9 && took_s < 5.0, "gave up after %.1f s, limit 1 s", took_s);
    CHECK_STR_CONTAINS(err.msg, "gave up after");
    CHECK_STR_CONTAINS(err.msg, "schema lock");
    CHECK_STR_CONTAINS(err.msg, "login booth2");
    CHECK_STR_CONTAINS(err.msg, "holder-by-hand");
    CHECK_STR_CONTAINS(err.msg, "server process ");
    csf_store_close(s);
    PQfinish(hold2);
    PQfinish(hold);
}

/* A table lock held by someone else: statements give up after the limit with a message, the
 * listing included (it never hangs silently). */
static void test_table_lock_wait(int64_t sid)
{
    csf_store *s1 = open_as("booth1", 0), *ro = open_as("alice", 1);
    PGconn *own = connect_as("csfcal_admin");
    CHECK_INT_EQ(exec_on(own, "SET application_name = 'lab-maintenance'"), 0);
    CHECK_INT_EQ(exec_on(own, "BEGIN"), 0);
    CHECK_INT_EQ(exec_on(own, "LOCK TABLE sessions, trials IN ACCESS EXCLUSIVE MODE"), 0);
    csf_error err;
    csf_session_info *list = NULL;
    size_t n = 0;
    double t0 = now_s();
    if (ro) CHECK(csf_store_list_sessions(ro, &list, &n, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "gave up after 1 s waiting for a lock");
    CHECK_STR_CONTAINS(err.msg, "held by login csfcal_admin, program 'lab-maintenance'");
    CHECK_MSG(now_s() - t0 < 5.0, "listing waited %.1f s", now_s() - t0);
    csf_trial t = make_trial(sid, 100, 1);
    if (s1) CHECK(csf_store_add_trial(s1, &t, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "waiting for a lock");
    CHECK_STR_CONTAINS(err.msg, "held by login csfcal_admin");
    exec_on(own, "ROLLBACK");
    PQfinish(own);
    csf_store_close(ro);
    csf_store_close(s1);
}

/* ---- temporary objects ------------------------------------------------------------------------ */

static void test_no_temp(void)
{
    static const char *const users[] = {"alice", "booth1"};
    for (int i = 0; i < 2; i++) {
        CHECK_MSG(try_as(users[i], "CREATE TEMP TABLE x (a int)") != 0, "%s made a temp table", users[i]);
        CHECK_MSG(try_as(users[i], "CREATE FUNCTION pg_temp.f() RETURNS int LANGUAGE sql AS 'SELECT 1'") != 0,
                  "%s made a pg_temp function", users[i]);
    }
}

/* ---- displays ---------------------------------------------------------------------------------- */

static void test_displays(int64_t sid1, int64_t sid2)
{
    char sql[512];
    test_pg_admin(g_db, "INSERT INTO displays (name, profile_id, created_utc) VALUES ('default',"
                        " 'lab-profile', 'x') ON CONFLICT (name) DO UPDATE SET profile_id = 'lab-profile'");
    long long before = admin_int("SELECT COUNT(*) FROM display_profiles");
    snprintf(sql, sizeof sql, "INSERT INTO display_profiles (display_id, profile_id, session_id,"
             " created_utc) SELECT id, 'forged', %lld, 'x' FROM displays WHERE name = 'default'",
             (long long)sid2);
    CHECK(try_as("booth1", sql) != 0); /* naming booth2's session */
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM display_profiles"), before);
    CHECK(try_as("booth1", "UPDATE displays SET profile_id = 'forged' WHERE name = 'default'") != 0);
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM displays WHERE name = 'default' AND profile_id ="
                           " 'lab-profile'"), 1);
    /* What a station may do: a profile its own session measured becomes current. */
    csf_store *s1 = open_as("booth1", 0);
    const char *prof = "csfcal-display-profile 1\nid = booth1-measured\ndisplay = default\n";
    csf_error err;
    if (s1) CHECK_INT_EQ(csf_store_add_artifact(s1, sid1, "profile", NULL, prof, strlen(prof), &err), CSF_OK);
    csf_store_close(s1);
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM displays WHERE name = 'default' AND profile_id ="
                           " 'booth1-measured'"), 1);
}

/* ---- closed sessions ---------------------------------------------------------------------------- */

static void test_closed(void)
{
    csf_store *s1 = open_as("booth1", 0);
    if (!s1) return;
    int64_t sid = session_with_trials(s1, 3);
    csf_error err;
    csf_threshold_row th = {.freq_cpd = 2, .ecc_deg = 5, .threshold = 0.01, .stderr_log10 = 0.1,
                            .n_trials = 3};
    CHECK_INT_EQ(csf_store_put_thresholds(s1, sid, &th, 1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s1, sid, "csflut", "t.csflut", "table", 5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s1, sid, 42.5, &err), CSF_OK); /* the station's grant */
    CHECK_INT_EQ(csf_store_set_session_state(s1, sid, CSF_SESSION_FINISHED, &err), CSF_OK);

    char sql[512], q[256];
    snprintf(sql, sizeof sql, "INSERT INTO trials SELECT session_id, 50, method, freq_cpd, ecc_deg,"
             " polar_deg, orientation_deg, sigma_deg, mean_lum_cdm2, is_catch, is_practice,"
             " contrast_requested, contrast_shown_mean, contrast_shown_max, frames_planned,"
             " frames_shown, frames_missed, signal_interval, response, rt_s, valid, velocity_dps,"
             " click_x_deg, click_y_deg, flags, stored_s, n_alternatives FROM trials WHERE"
             " session_id = %lld AND seq = 0", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    csf_trial t = make_trial(sid, 3, 1);
    CHECK(csf_store_add_trial(s1, &t, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "closed");
    snprintf(sql, sizeof sql, "INSERT INTO frame_intervals VALUES (%lld, 0, 99, 0.5)", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    snprintf(sql, sizeof sql, "UPDATE artifacts SET content = 'evil' WHERE session_id = %lld", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    snprintf(sql, sizeof sql, "DELETE FROM thresholds WHERE session_id = %lld", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    snprintf(sql, sizeof sql, "UPDATE sessions SET state = 'running' WHERE id = %lld", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    CHECK(csf_store_set_session_state(s1, sid, CSF_SESSION_RUNNING, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "closed");
    /* The owner is held to it too (a repair disables the trigger on purpose). */
    CHECK(try_as("csfcal_owner", sql) != 0);
    /* Its person time too: through csfcal, and by hand past it (the trigger). */
    CHECK_INT_EQ(csf_store_add_person_time(s1, sid, 10.0, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "finished and closed");
    snprintf(sql, sizeof sql, "UPDATE sessions SET person_s = 9999 WHERE id = %lld", (long long)sid);
    CHECK(try_as("booth1", sql) != 0);
    CHECK(try_as("csfcal_owner", sql) != 0);
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions WHERE id = %lld AND person_s = 42.5",
             (long long)sid);
    CHECK_INT_EQ(admin_int(q), 1);

    snprintf(q, sizeof q, "SELECT COUNT(*) FROM trials WHERE session_id = %lld", (long long)sid);
    CHECK_INT_EQ(admin_int(q), 3);
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM frame_intervals WHERE session_id = %lld", (long long)sid);
    CHECK_INT_EQ(admin_int(q), 9);
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM thresholds WHERE session_id = %lld", (long long)sid);
    CHECK_INT_EQ(admin_int(q), 1);
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM artifacts WHERE session_id = %lld AND content ="
             " 'table'::bytea", (long long)sid);
    CHECK_INT_EQ(admin_int(q), 1);
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions WHERE id = %lld AND state = 'finished'", (long long)sid);
    CHECK_INT_EQ(admin_int(q), 1);
    /* A file written from it afterwards (a report plot) is still recorded. */
    CHECK_INT_EQ(csf_store_add_artifact(s1, sid, "plot", "p.png", "png", 3, &err), CSF_OK);
    csf_store_close(s1);
}

/* ---- another station's session ------------------------------------------------------------------ */

static void test_others_session(int64_t sid1)
{
    csf_store *s1 = open_as("booth1", 0), *s2 = open_as("booth2", 0);
    if (!s1 || !s2) return;
    csf_error err;
    CHECK_INT_EQ(csf_store_set_session_state(s1, sid1, CSF_SESSION_RUNNING, &err), CSF_OK);
    /* While booth1 runs it: refused, naming the holder and since when it runs. */
    CHECK_INT_EQ(csf_store_set_session_state(s2, sid1, CSF_SESSION_PAUSED, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "in use by another station: login booth1, program 'csfcal'");
    CHECK_STR_CONTAINS(err.msg, "running since 20");
    CHECK_INT_EQ(csf_store_set_session_state(s1, sid1, CSF_SESSION_PAUSED, &err), CSF_OK);
    csf_store_close(s1);
    CHECK_INT_EQ(csf_store_set_session_state(s2, sid1, CSF_SESSION_ABORTED, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "belongs to another station");
    CHECK_STR_CONTAINS(err.msg, "login booth1");
    char q[160];
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions WHERE id = %lld AND state = 'paused'", (long long)sid1);
    CHECK_INT_EQ(admin_int(q), 1);
    CHECK_INT_EQ(csf_store_set_session_state(s2, 999999, CSF_SESSION_ABORTED, &err), CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(err.msg, "no session 999999");
    csf_trial t = make_trial(sid1, 40, 1);
    CHECK(csf_store_add_trial(s2, &t, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "another station");
    /* nor its person time, through csfcal or by hand */
    CHECK_INT_EQ(csf_store_add_person_time(s2, sid1, 30.0, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "belongs to another station");
    char sql[160];
    snprintf(sql, sizeof sql, "UPDATE sessions SET person_s = 30 WHERE id = %lld", (long long)sid1);
    CHECK(try_as("booth2", sql) != 0); /* row-level security: it changes no row */
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions WHERE id = %lld AND person_s IS NULL",
             (long long)sid1);
    CHECK_INT_EQ(admin_int(q), 1);
    csf_store_close(s2);
}

/* ---- studies -------------------------------------------------------------------------------------- */

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

static csf_status run_study(const char *conf, const char *user, const char *participant, csf_error *e)
{
    char uri[1024];
    loc_as(user, uri, sizeof uri);
    csf_config cfg;
    csf_config_defaults(&cfg);
    csf_study_run_options o;
    memset(&o, 0, sizeof o);
    o.cfg = &cfg;
    o.study_path = conf;
    o.participant = participant;
    o.observer_spec = "sim";
    o.store_path = uri;
    o.headless = 1;
    o.quiet = 1;
    csf_study_run_result res;
    return csf_study_run(&o, &res, e);
}

static void test_studies(void)
{
    char dir[512], conf[600], csv[600];
    CHECK_INT_EQ(tmp_dir(dir, sizeof dir, "attacks"), 0);
    snprintf(conf, sizeof conf, "%s/tiny.conf", dir);
    snprintf(csv, sizeof csv, "%s/tiny.csv", dir);
    write_text(conf, "name = tiny\ndesign = 2afc\nconditions = tiny.csv\ntrials_per_condition = 2\n"
                     "blocks = 1\npractice_trials = 0\nfixation_s = 0\nstimulus_s = 0.05\n"
                     "response_window_s = 0\niti_s = 0\nfeedback = no\nseed = 7\nbootstrap = 0\n");
    write_text(csv, "label,stimulus,freq_cpd,contrast,ecc_deg,polar_deg,sigma_deg,curve\n"
                    "a,gabor,2,0.05,5,0,1,\nb,gabor,2,0.1,5,0,1,\n");
    csf_error e;
    csf_status st = run_study(conf, "booth1", "P01", &e);
    CHECK_MSG(st == CSF_OK, "study run P01: %s", e.msg);
    /* A station takes no participant code by hand: it has no study session waiting for one. */
    CHECK(try_as("booth1", "INSERT INTO participants (study_id, code, created_utc) SELECT id, 'P09',"
                           " 'x' FROM studies WHERE name = 'tiny'") != 0);
    CHECK(try_as("booth2", "INSERT INTO participants (study_id, code, created_utc) SELECT id, 'P09',"
                           " 'x' FROM studies WHERE name = 'tiny'") != 0);
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM participants WHERE code = 'P09'"), 0);
    /* Nor another code while a study session of its own waits for its participant. */
    csf_store *s1 = open_as("booth1", 0);
    int64_t waiting = 0;
    if (s1)
        CHECK_INT_EQ(csf_store_begin_session(s1, CSF_SESSION_STUDY, "P20", "", NULL, 1, &waiting, &e),
                     CSF_OK);
    CHECK(try_as("booth1", "INSERT INTO participants (study_id, code, created_utc) SELECT id, 'P21',"
                           " 'x' FROM studies WHERE name = 'tiny'") != 0);
    CHECK(try_as("booth1", "INSERT INTO participants (study_id, code, created_utc) SELECT id, 'P20',"
                           " 'x' FROM studies WHERE name = 'tiny'") == 0); /* its own: allowed */
    if (s1) CHECK_INT_EQ(csf_store_set_session_state(s1, waiting, CSF_SESSION_ABORTED, &e), CSF_OK);
    csf_store_close(s1);
    /* A code taken some other way (an older csfcal, the superuser or the owner by hand): the
     * run is refused, and the session it began is not left running. */
    test_pg_admin(g_db, "INSERT INTO participants (study_id, code, created_utc) SELECT id, 'P09', 'x'"
                        " FROM studies WHERE name = 'tiny'");
    st = run_study(conf, "booth2", "P09", &e);
    CHECK(st != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "P09");
    CHECK_INT_EQ(admin_int("SELECT COUNT(*) FROM sessions WHERE kind = 'study' AND state = 'running'"), 0);
    /* A phantom as an older csfcal left it (running, no study files) does not stop the report. */
    test_pg_admin(g_db, "INSERT INTO sessions (kind, state, settings_json, seed, tool_version,"
                        " created_utc, updated_utc, station) VALUES ('study', 'running',"
                        " '{\"study\":\"tiny\",\"participant\":\"P10\"}', 1, 'old', 'x', 'x', 'booth2')");
    st = run_study(conf, "booth2", "P02", &e);
    CHECK_MSG(st == CSF_OK, "study run P02: %s", e.msg);
    char uri[1024];
    loc_as("alice", uri, sizeof uri);
    csf_study_report *r = NULL;
    st = csf_study_report_build(uri, "tiny", 0, 0, &r, &e);
    CHECK_MSG(st == CSF_OK, "study report: %s", e.msg);
    if (r) CHECK_INT_EQ(r->n_sessions, 2);
    csf_study_report_free(r);
    rm_rf(dir);
}

/* ---- a station's own finished work, pushed ------------------------------------------------------ */

static void test_push_finished(void)
{
    char dir[512], file[600];
    CHECK_INT_EQ(tmp_dir(dir, sizeof dir, "attacks-push"), 0);
    snprintf(file, sizeof file, "%s/local.sqlite", dir);
    csf_store *src = NULL, *dst = open_as("booth1", 0);
    csf_error err;
    CHECK_INT_EQ(csf_store_open(file, &src, &err), CSF_OK);
    if (!src || !dst) return;
    int64_t sid = session_with_trials(src, 4);
    csf_threshold_row th = {.freq_cpd = 4, .ecc_deg = 0, .threshold = 0.02, .stderr_log10 = 0.1,
                            .n_trials = 4};
    CHECK_INT_EQ(csf_store_put_thresholds(src, sid, &th, 1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(src, sid, "csflut", "t.csflut", "table", 5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(src, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    for (int round = 0; round < 2; round++) {
        csf_push_counts c;
        csf_status st = csf_store_push_session(src, dst, sid, &c, &err);
        CHECK_MSG(st == CSF_OK, "push %d: %s", round, err.msg);
        CHECK_INT_EQ(c.trials_sent, round ? 0 : 4);
        CHECK_INT_EQ(c.artifacts_sent, round ? 0 : 1);
        char q[200];
        snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions s WHERE id = %lld AND state = 'finished'"
                 " AND station = 'booth1' AND (SELECT COUNT(*) FROM thresholds WHERE session_id ="
                 " s.id) = 1", (long long)c.dest_id);
        CHECK_INT_EQ(admin_int(q), 1);
    }
    csf_store_close(dst);
    csf_store_close(src);
    rm_rf(dir);
}

/* ---- what held before ---------------------------------------------------------------------------- */

static void test_held(void)
{
    static const char *const sql[] = {
        "UPDATE trials SET response = 0", "DELETE FROM sessions", "DELETE FROM trials",
        "INSERT INTO observers (name, created_utc) VALUES ('x', 'y')", "DROP TABLE trials",
        "COPY (SELECT 1) TO PROGRAM 'true'", "SELECT pg_read_file('/etc/passwd')",
        "SET ROLE csfcal_admin", "SET ROLE booth2", "CREATE TABLE x (a int)"};
    for (size_t i = 0; i < sizeof sql / sizeof sql[0]; i++) {
        CHECK_MSG(try_as("alice", sql[i]) != 0, "analyst: %s", sql[i]);
        if (i != 3) CHECK_MSG(try_as("booth1", sql[i]) != 0, "station: %s", sql[i]);
    }
    CHECK(try_as("alice", "SELECT COUNT(*) FROM trials") == 0);
}

/* ---- a station without its server ------------------------------------------------------------------ */

static void server(const char *what)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "'%s' %s '%s'", getenv("CSF_TEST_PG_RUN"), what, getenv("CSF_TEST_PG_DIR"));
    CHECK_INT_EQ(system(cmd), 0);
}

static int count_lines(const char *text, const char *needle)
{
    int n = 0;
    for (const char *p = text; p && (p = strstr(p, needle)); p += strlen(needle)) n++;
    return n;
}

/* Seven writes over seven seconds with the server stopped: the wait for it is announced (one line
 * a second for CSF_STORE_SPOOL_AFTER_S), then the spool once; the later tries to reach the
 * server, one every 5 s, say nothing. */
static void test_spool_says_once(void)
{
    char loc[1024], dir[512], spool[600], log[600];
    CHECK_INT_EQ(test_store_location("", "", loc, sizeof loc), 0);
    CHECK_INT_EQ(tmp_dir(dir, sizeof dir, "attacks-spool"), 0);
    snprintf(spool, sizeof spool, "%s/spool.sqlite", dir);
    snprintf(log, sizeof log, "%s/stderr.txt", dir);
    setenv("CSF_STORE_SPOOL", spool, 1);
    setenv("CSF_STORE_SPOOL_AFTER_S", "1", 1);
    csf_store *s = NULL;
    csf_error err;
    CHECK_INT_EQ(csf_store_open(loc, &s, &err), CSF_OK);
    if (!s) return;
    int64_t sid = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "p", "d", NULL, 1, &sid, &err), CSF_OK);
    server("stop");
    fflush(stderr);
    int saved = dup(2), fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 2);
    close(fd);
    for (int i = 0; i < 7; i++) {
        csf_trial t = make_trial(sid, i, 1);
        CHECK_INT_EQ(csf_store_add_trial(s, &t, &err), CSF_OK);
        sleep(1);
    }
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    server("start");
    csf_trial t = make_trial(sid, 7, 1);
    CHECK_INT_EQ(csf_store_add_trial(s, &t, &err), CSF_OK);
    csf_store_close(s);
    size_t len = 0;
    char *text = test_read_file(log, &len);
    CHECK(text != NULL);
    CHECK_INT_EQ(count_lines(text, "keeping what is measured in the local spool"), 1);
    CHECK_INT_EQ(count_lines(text, "(0 s of 0 s)"), 0);
    CHECK_MSG(count_lines(text, "connection to the server lost") <= 2, "stderr:\n%s", text ? text : "");
    free(text);
    char q[160];
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM trials WHERE session_id = %lld", (long long)sid);
    CHECK_INT_EQ(test_query_int(NULL, loc, q), 8);
    unsetenv("CSF_STORE_SPOOL_AFTER_S");
    rm_rf(dir);
}

int main(int argc, char **argv)
{
    if (!test_pg()) {
        fprintf(stderr, "SKIP: the attacks on a lab's server run under tests/store/pg_run.sh\n");
        return 77;
    }
    test_pg_require();
    if (argc < 2) {
        fprintf(stderr, "usage: test_store_attacks_pg ROLES.sql\n");
        return 2;
    }
    if (setup(argv[1]) != 0) return 1;
    csf_store *s1 = open_as("booth1", 0), *s2 = open_as("booth2", 0);
    if (!s1 || !s2) return 1;
    int64_t sid1 = session_with_trials(s1, 2), sid2 = session_with_trials(s2, 1);
    csf_store_close(s2);
    test_analyst_takes_no_lock(sid1);
    test_schema_lock_wait();
    test_table_lock_wait(sid1);
    test_no_temp();
    test_displays(sid1, sid2);
    csf_store_close(s1);
    test_closed();
    test_others_session(sid1);
    test_studies();
    test_push_finished();
    test_held();
    test_spool_says_once();
    return CHECK_RESULT();
}
