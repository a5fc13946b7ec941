/* Several stations on one server store, each a process of its own:
 * - stations started together on a new database all open it (the schema is made once) and
 *   share the observer, display, study and participant rows instead of failing or doubling them;
 * - every trial of every station arrives exactly once, equal to what a single station writes
 *   with the same seed;
 * - a session is claimed: a second station cannot resume one that is running elsewhere, and can
 *   once that station is killed (the server drops a dead connection's claim);
 * - the server restarted mid-session: the station says so, waits, reconnects and goes on, and no
 *   trial is lost or doubled;
 * - the server away for longer: the station keeps its trials in the local spool and goes on;
 *   they reach the server when it is back (during the session, or by a push after it, or when
 *   the next csfcal opens the store after the station was killed), once.
 * Runs on PostgreSQL only (under tests/store/pg_run.sh); on SQLite it checks nothing and says so
 * (exit 77: skipped). */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "results/store/store.h"
#include "results/store/push.h"
#include "store_test_util.h"
#include "tests/check.h"

#define STATIONS 6
#define TRIALS 60

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Waits for one byte on fd (a child saying it reached a point): pipes order the processes
 * instead of sleeps, which a loaded machine outruns. */
static int wait_byte(int fd)
{
    char c;
    return read(fd, &c, 1) == 1 ? 0 : -1;
}

/* Trials from..to-1 of session sid, each with its frame intervals, seed-determined. */
static int write_trials(csf_store *s, int64_t sid, int from, int to, uint64_t seed, int pause_us)
{
    csf_error err;
    for (int i = from; i < to; i++) {
        csf_trial t = make_trial(sid, i, seed);
        double iv[3] = {1 / 60.0, 1 / 60.0, 0.001 * i};
        if (csf_store_add_trial_frames(s, &t, iv, 3, &err) != CSF_OK) {
            fprintf(stderr, "trial %d of session %lld: %s\n", i, (long long)sid, err.msg);
            return -1;
        }
        if (pause_us) usleep((useconds_t)pause_us);
    }
    return 0;
}

/* One station of a study: shared observer/display/study names, its own participant. */
static int station(const char *loc, int w, int go_fd)
{
    char c;
    if (read(go_fd, &c, 1) < 0) return 9;
    csf_store *s = test_open_or_exit(loc, "station");
    csf_error err;
    int64_t study = 0, part = 0, sid = 0;
    if (csf_store_find_study(s, "pooled", &study, &err) != CSF_OK &&
        csf_store_create_study(s, "pooled", NULL, &study, &err) != CSF_OK &&
        csf_store_find_study(s, "pooled", &study, &err) != CSF_OK) { /* another station made it */
        fprintf(stderr, "station %d: %s\n", w, err.msg);
        return 4;
    }
    char code[16];
    snprintf(code, sizeof code, "P%02d", w);
    if (csf_store_add_participant(s, study, code, &part, &err) != CSF_OK ||
        csf_store_begin_session(s, CSF_SESSION_STUDY, code, "booth-lcd", NULL, (uint64_t)w, &sid, &err) !=
            CSF_OK ||
        csf_store_link_session_participant(s, sid, part, &err) != CSF_OK ||
        csf_store_upsert_observer(s, "shared-observer", NULL, &err) != CSF_OK) {
        fprintf(stderr, "station %d: %s\n", w, err.msg);
        return 5;
    }
    if (write_trials(s, sid, 0, TRIALS, 500 + (uint64_t)w, 0) < 0) return 6;
    if (csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err) != CSF_OK) return 7;
    csf_store_close(s);
    return 0;
}

/* Every trial of a session is there once, in order, equal to the seed's; frames too. */
static void check_session(csf_store *s, int64_t sid, uint64_t seed, int n)
{
    csf_error err;
    csf_trial *t = NULL;
    size_t nt = 0;
    CHECK_INT_EQ(csf_store_get_trials(s, sid, &t, &nt, &err), CSF_OK);
    CHECK_INT_EQ(nt, n);
    int same = nt == (size_t)n;
    for (size_t k = 0; same && k < nt; k++) {
        csf_trial want = make_trial(sid, (int)k, seed);
        same = t[k].seq == (int)k && trials_equal(&t[k], &want);
    }
    CHECK_MSG(same, "session %lld: trials differ from the single-station run", (long long)sid);
    free(t);
    double *fi = NULL;
    size_t nf = 0;
    CHECK_INT_EQ(csf_store_get_frame_intervals(s, sid, &fi, &nf, &err), CSF_OK);
    CHECK_INT_EQ(nf, 3 * (size_t)n);
    free(fi);
}

static void test_many_stations(const char *loc)
{
    int go[2];
    if (pipe(go) != 0) return;
    pid_t pids[STATIONS];
    for (int w = 0; w < STATIONS; w++) {
        pids[w] = fork();
        if (pids[w] == 0) {
            close(go[1]);
            _exit(station(loc, w, go[0]));
        }
    }
    close(go[0]);
    close(go[1]); /* all start at once, on a database with no schema yet */
    for (int w = 0; w < STATIONS; w++) {
        int status = 0;
        waitpid(pids[w], &status, 0);
        CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "station %d status %d", w, status);
    }
    csf_store *s = test_open_or_exit(loc, "check");
    csf_error err;
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, STATIONS);
    for (size_t i = 0; i < n; i++) {
        int w = atoi(list[i].observer + 1);
        CHECK(list[i].state == CSF_SESSION_FINISHED);
        check_session(s, list[i].id, 500 + (uint64_t)w, TRIALS);
    }
    csf_session_list_free(list, n);
    CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM studies"), 1);
    CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM participants"), STATIONS);
    CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM displays WHERE name = 'booth-lcd'"), 1);
    CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM observers WHERE name = 'shared-observer'"), 1);
    CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM session_participants"), STATIONS);
    csf_store_close(s);
}

/* A station runs a session slowly; another tries to resume it and is refused; the first is
 * killed mid-session; now the second resumes where the stored trials end and finishes it. */
static void test_claim_and_kill(const char *loc)
{
    int ready[2];
    if (pipe(ready) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        csf_store *s = test_open_or_exit(loc, "station A");
        csf_error err;
        int64_t sid = 0;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "claimed", "lcd", NULL, 77, &sid, &err) !=
            CSF_OK)
            _exit(4);
        if (write_trials(s, sid, 0, 10, 77, 0) < 0) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid) _exit(6);
        write_trials(s, sid, 10, 100000, 77, 20000); /* until killed */
        _exit(7);
    }
    close(ready[1]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    close(ready[0]);

    csf_store *b = test_open_or_exit(loc, "station B");
    csf_error err;
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "in use by another station");
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_ABORTED, &err), CSF_E_STORE);
    kill(a, SIGKILL); /* mid-session: it writes a trial every 20 ms */
    int status = 0;
    waitpid(a, &status, 0);
    CHECK(WIFSIGNALED(status));
    /* The server notices the dead connection soon after on a unix socket, later on a loaded
     * machine: poll up to a deadline. */
    csf_status cs = CSF_E_STORE;
    double deadline = now_s() + 60.0;
    while ((cs = csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err)) != CSF_OK &&
           now_s() < deadline)
        usleep(50000);
    CHECK_INT_EQ(cs, CSF_OK);
    csf_trial *t = NULL;
    size_t nt = 0;
    CHECK_INT_EQ(csf_store_get_trials(b, sid, &t, &nt, &err), CSF_OK);
    free(t);
    CHECK(nt >= 10);
    CHECK_INT_EQ(write_trials(b, sid, (int)nt, TRIALS, 77, 0), 0);
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    check_session(b, sid, 77, TRIALS);
    csf_store_close(b);
}

/* The server restarts while a station writes: it waits, says so, reconnects, and every trial
 * is there once. */
static void test_server_restart(const char *loc)
{
    int ready[2];
    if (pipe(ready) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        csf_store *s = test_open_or_exit(loc, "station");
        csf_error err;
        int64_t sid = 0;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "restart", "lcd", NULL, 91, &sid, &err) !=
            CSF_OK)
            _exit(4);
        if (write_trials(s, sid, 0, 5, 91, 0) < 0) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid) _exit(6); /* some trials in */
        if (write_trials(s, sid, 5, TRIALS, 91, 30000) < 0) _exit(5);
        if (csf_store_add_person_time(s, sid, 75.5, &err) != CSF_OK) _exit(8);
        if (csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err) != CSF_OK) _exit(7);
        csf_store_close(s);
        _exit(0);
    }
    close(ready[1]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    close(ready[0]);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "'%s' restart '%s'", getenv("CSF_TEST_PG_RUN"), getenv("CSF_TEST_PG_DIR"));
    CHECK_INT_EQ(system(cmd), 0);
    int status = 0;
    waitpid(a, &status, 0);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "station status %d", status);
    csf_store *s = test_open_or_exit(loc, "check");
    check_session(s, sid, 91, TRIALS);
    csf_session_info si;
    csf_error err;
    CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
    CHECK(si.state == CSF_SESSION_FINISHED);
    CHECK_NEAR(si.person_s, 75.5, 0);
    csf_session_info_free(&si);
    csf_store_close(s);
}

static void run_pg(const char *what)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "'%s' %s '%s'", getenv("CSF_TEST_PG_RUN"), what, getenv("CSF_TEST_PG_DIR"));
    CHECK_INT_EQ(system(cmd), 0);
}

static long long spool_trials(const char *spool)
{
    csf_store *s = NULL;
    csf_error err;
    if (csf_store_open_readonly(spool, &s, &err) != CSF_OK) return -1;
    long long n = test_query_int(s, spool, "SELECT COUNT(*) FROM trials");
    csf_store_close(s);
    return n;
}

/* The server stops mid-session: trials go to the spool and the station goes on without waiting
 * for the server; when it is back the spooled trials are sent, every one once. Pipes mark the
 * points: trials 0-4 stored, server stopped, trials 5-19 written (spooled), server started. */
static void test_server_away(const char *loc, const char *spool)
{
    int ready[2], stopped[2], spooled[2], started[2];
    if (pipe(ready) != 0 || pipe(stopped) != 0 || pipe(spooled) != 0 || pipe(started) != 0) return;
    setenv("CSF_STORE_SPOOL", spool, 1);
    setenv("CSF_STORE_SPOOL_AFTER_S", "1", 1);
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        close(stopped[1]);
        close(spooled[0]);
        close(started[1]);
        csf_store *s = test_open_or_exit(loc, "station");
        csf_error err;
        int64_t sid = 0;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "away", "lcd", NULL, 93, &sid, &err) != CSF_OK)
            _exit(4);
        if (write_trials(s, sid, 0, 5, 93, 0) < 0) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid || wait_byte(stopped[0]) < 0) _exit(6);
        if (write_trials(s, sid, 5, 20, 93, 0) < 0) _exit(5);
        if (write(spooled[1], "s", 1) != 1 || wait_byte(started[0]) < 0) _exit(6);
        if (write_trials(s, sid, 20, TRIALS, 93, 10000) < 0) _exit(5);
        if (csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err) != CSF_OK) _exit(7);
        csf_store_close(s);
        _exit(0);
    }
    close(ready[1]);
    close(stopped[0]);
    close(spooled[1]);
    close(started[0]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    run_pg("stop");
    CHECK(write(stopped[1], "g", 1) == 1);
    CHECK(wait_byte(spooled[0]) == 0); /* 15 trials written with the server away */
    CHECK(spool_trials(spool) >= 15);
    run_pg("start");
    CHECK(write(started[1], "g", 1) == 1);
    int status = 0;
    waitpid(a, &status, 0);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "station status %d", status);
    csf_store *s = test_open_or_exit(loc, "check");
    check_session(s, sid, 93, TRIALS);
    csf_session_info si;
    csf_error err;
    CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
    CHECK(si.state == CSF_SESSION_FINISHED);
    csf_session_info_free(&si);
    csf_store_close(s);
    close(ready[0]);
    close(stopped[1]);
    close(spooled[0]);
    close(started[1]);
}

/* The server goes away and the session ends before it is back: the trials stay in the spool;
 * the next csfcal to open the store sends them (not the state), and the push the station
 * printed sends the state and nothing twice. */
static void test_spool_then_push(const char *loc, const char *spool)
{
    int ready[2], cont[2];
    if (pipe(ready) != 0 || pipe(cont) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        close(cont[1]);
        setenv("CSF_STORE_RETRY_S", "1", 1);
        csf_store *s = test_open_or_exit(loc, "station");
        csf_error err;
        int64_t sid = 0;
        char c;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "pushed", "lcd", NULL, 94, &sid, &err) != CSF_OK)
            _exit(4);
        if (write_trials(s, sid, 0, 10, 94, 0) < 0) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid || read(cont[0], &c, 1) != 1) _exit(6);
        if (write_trials(s, sid, 10, 25, 94, 0) < 0) _exit(5);
        if (csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err) != CSF_OK) _exit(7);
        csf_store_close(s);
        _exit(0);
    }
    close(ready[1]);
    close(cont[0]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    run_pg("stop");
    CHECK(write(cont[1], "g", 1) == 1);
    int status = 0;
    waitpid(a, &status, 0);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "station status %d", status);
    run_pg("start");
    csf_store *s = test_open_or_exit(loc, "check"), *sp = NULL;
    csf_error err;
    CHECK_INT_EQ(csf_store_open(spool, &sp, &err), CSF_OK);
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
    int64_t lsid = 0;
    CHECK_INT_EQ(test_query_int(sp, spool, "SELECT COUNT(*) FROM sessions"), 2);
    char q[160];
    snprintf(q, sizeof q, "SELECT id FROM sessions WHERE uuid = '%s'", si.uuid);
    lsid = test_query_int(sp, spool, q);
    csf_session_info_free(&si);
    csf_push_counts c;
    check_session(s, sid, 94, 25); /* sent by the open */
    CHECK_INT_EQ(csf_store_push_session(sp, s, lsid, &c, &err), CSF_OK);
    CHECK_INT_EQ(c.trials_sent, 0);
    CHECK_INT_EQ(c.trials_present, 15); /* the spool holds trials 10-24 */
    CHECK_INT_EQ(c.dest_id, sid);
    check_session(s, sid, 94, 25);
    CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
    CHECK(si.state == CSF_SESSION_FINISHED);
    csf_session_info_free(&si);
    csf_store_close(sp);
    csf_store_close(s);
}

/* A station killed while its trials were only in the spool: the next csfcal to open the store
 * sends them before anything reads the session (a resume then continues after them), and does
 * not claim the session or change its state on the way. */
static void test_crash_while_away(const char *loc)
{
    int ready[2], cont[2], spooled[2];
    if (pipe(ready) != 0 || pipe(cont) != 0 || pipe(spooled) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        close(cont[1]);
        close(spooled[0]);
        csf_store *s = test_open_or_exit(loc, "station");
        csf_error err;
        int64_t sid = 0;
        char c;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "crashed", "lcd", NULL, 95, &sid, &err) !=
            CSF_OK)
            _exit(4);
        if (write_trials(s, sid, 0, 10, 95, 0) < 0) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid || read(cont[0], &c, 1) != 1) _exit(6);
        if (write_trials(s, sid, 10, 20, 95, 0) < 0) _exit(5);
        if (write(spooled[1], "s", 1) != 1) _exit(6);
        pause(); /* killed here, with ten trials only in the spool */
        _exit(7);
    }
    close(ready[1]);
    close(cont[0]);
    close(spooled[1]);
    int64_t sid = 0;
    char c;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    run_pg("stop");
    CHECK(write(cont[1], "g", 1) == 1);
    CHECK(read(spooled[0], &c, 1) == 1);
    kill(a, SIGKILL);
    int status = 0;
    waitpid(a, &status, 0);
    run_pg("start");
    csf_store *s = test_open_or_exit(loc, "next run"); /* sends what the spool holds */
    check_session(s, sid, 95, 20);
    csf_session_info si;
    csf_error err;
    CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
    CHECK(si.state == CSF_SESSION_RUNNING);
    csf_session_info_free(&si);
    csf_store *other = test_open_or_exit(loc, "another station");
    CHECK_INT_EQ(csf_store_set_session_state(other, sid, CSF_SESSION_RUNNING, &err), CSF_OK); /* unclaimed */
    CHECK_INT_EQ(write_trials(other, sid, 20, 25, 95, 0), 0); /* the resume goes on after them */
    CHECK_INT_EQ(csf_store_set_session_state(other, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    check_session(other, sid, 95, 25);
    csf_store_close(other);
    csf_store_close(s);
}

/* Everything a session writes while the server is away goes to the spool, not only trials:
 * thresholds, artifacts (two of one kind, and a path-only record completed by its bytes), person
 * time and the study participant link. Once the server is back (here: at close) all of it arrives, once;
 * the next open, which sends the spool again, adds nothing. */
static void test_away_results(const char *loc)
{
    setenv("CSF_STORE_RETRY_S", "2", 1);
    csf_store *s = test_open_or_exit(loc, "station");
    csf_error err;
    int64_t study = 0, part = 0, sid = 0;
    CHECK_INT_EQ(csf_store_create_study(s, "away-study", "{\"d\":1}", &study, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_participant(s, study, "A1", &part, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_STUDY, "A1", "lcd", NULL, 98, &sid, &err), CSF_OK);
    CHECK_INT_EQ(write_trials(s, sid, 0, 3, 98, 0), 0);
    CHECK_INT_EQ(csf_store_add_person_time(s, sid, 100.0, &err), CSF_OK); /* on the server */
    run_pg("stop");
    CHECK_INT_EQ(csf_store_add_person_time(s, sid, 50.5, &err), CSF_OK); /* spooled */
    CHECK_INT_EQ(csf_store_link_session_participant(s, sid, part, &err), CSF_OK);
    CHECK_INT_EQ(write_trials(s, sid, 3, 6, 98, 0), 0);
    csf_threshold_row rows[2] = {{4.0, 0.0, 0.0, 50.0, 0.004, 0.05, 30},
                                 {8.0, 0.0, 0.0, 50.0, 0.009, 0.07, 30}};
    CHECK_INT_EQ(csf_store_put_thresholds(s, sid, rows, 2, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, sid, "plot", "/tmp/a.png", "PNG1", 4, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, sid, "plot", "/tmp/b.png", "PNG22", 5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, sid, "csflut", "/tmp/a.csflut", NULL, 0, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, sid, "csflut", NULL, "LUT", 3, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    run_pg("start");
    csf_store_close(s); /* sends the spool */
    setenv("CSF_STORE_RETRY_S", "60", 1);
    for (int round = 0; round < 2; round++) { /* round 1: the open sends the spool again */
        s = test_open_or_exit(loc, "check");
        check_session(s, sid, 98, 6);
        char q[200];
        snprintf(q, sizeof q, "SELECT COUNT(*) FROM thresholds WHERE session_id = %lld", (long long)sid);
        CHECK_INT_EQ(test_query_int(s, loc, q), 2);
        snprintf(q, sizeof q, "SELECT COUNT(*) FROM artifacts WHERE session_id = %lld", (long long)sid);
        CHECK_INT_EQ(test_query_int(s, loc, q), 3);
        snprintf(q, sizeof q, "SELECT COUNT(*) FROM artifacts WHERE session_id = %lld AND kind ="
                 " 'csflut' AND path = '/tmp/a.csflut' AND content = 'LUT'", (long long)sid);
        CHECK_INT_EQ(test_query_int(s, loc, q), 1);
        snprintf(q, sizeof q, "SELECT participant_id FROM session_participants WHERE session_id = %lld",
                 (long long)sid);
        CHECK_INT_EQ(test_query_int(s, loc, q), part);
        CHECK_INT_EQ(test_query_int(s, loc, "SELECT COUNT(*) FROM participants WHERE code = 'A1'"), 1);
        csf_session_info si;
        CHECK_INT_EQ(csf_store_get_session(s, sid, &si, &err), CSF_OK);
        CHECK(si.state == CSF_SESSION_FINISHED);
        CHECK_NEAR(si.person_s, 150.5, 0); /* both runs' parts, the spooled one sent once */
        csf_session_info_free(&si);
        csf_store_close(s);
    }
}

/* The fault hook of results/store/internal.h: at the named point, once, run pg_run.sh with
 * the action (restart: the server comes back; stop: it stays away). */
static const char *hook_action;
static int hook_fired;

static void drop_at_commit(const char *point)
{
    if (hook_fired || !hook_action || strcmp(point, "session_committed") != 0) return;
    hook_fired = 1;
    run_pg(hook_action);
}

static long long count_sessions(csf_store *s, const char *loc, const char *observer,
                                const char *state)
{
    char q[256];
    snprintf(q, sizeof q, "SELECT COUNT(*) FROM sessions WHERE observer = '%s'%s%s%s", observer,
             state ? " AND state = '" : "", state ? state : "", state ? "'" : "");
    return test_query_int(s, loc, q);
}

/* The connection drops right after the server committed a new session, before the station has
 * used it. Back within the retry limit: the station finds its session by uuid and goes on with
 * it (no second, empty row). Away for longer: begin fails, and the next csfcal to reach the
 * server marks the row it may have left aborted, so no phantom running session is listed. */
static void test_begin_drop(const char *loc)
{
    csf_store_fault_hook = drop_at_commit;
    hook_action = "restart";
    hook_fired = 0;
    csf_store *s = test_open_or_exit(loc, "station");
    csf_error err;
    int64_t sid = 0;
    CHECK_INT_EQ(
        csf_store_begin_session(s, CSF_SESSION_OBSERVER, "dropped-begin", "lcd", NULL, 96, &sid, &err),
        CSF_OK);
    CHECK(hook_fired);
    CHECK_INT_EQ(write_trials(s, sid, 0, 5, 96, 0), 0);
    CHECK_INT_EQ(count_sessions(s, loc, "dropped-begin", NULL), 1);
    check_session(s, sid, 96, 5);
    csf_store_close(s);

    setenv("CSF_STORE_RETRY_S", "1", 1);
    hook_action = "stop";
    hook_fired = 0;
    s = test_open_or_exit(loc, "station");
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "phantom", "lcd", NULL, 97, &sid, &err),
                 CSF_E_STORE);
    CHECK(hook_fired);
    csf_store_close(s);
    csf_store_fault_hook = NULL;
    setenv("CSF_STORE_RETRY_S", "60", 1);
    run_pg("start");
    s = test_open_or_exit(loc, "next run");
    CHECK_INT_EQ(count_sessions(s, loc, "phantom", NULL), 1);
    CHECK_INT_EQ(count_sessions(s, loc, "phantom", "aborted"), 1);
    csf_store_close(s);
}

int main(void)
{
    if (!test_pg()) {
        fprintf(stderr, "SKIP: several stations need a server store (CSF_TEST_BACKEND=postgresql)\n");
        return 77;
    }
    test_pg_require();
    setenv("CSF_STORE_RETRY_S", "60", 1);
    char loc[1024];
    if (test_store_location("", "", loc, sizeof loc) < 0) return 1;
    test_many_stations(loc);
    test_claim_and_kill(loc);
    test_server_restart(loc);
    char dir[512], spool[600];
    if (tmp_dir(dir, sizeof dir, "spool") < 0) return 1;
    snprintf(spool, sizeof spool, "%s/spool.sqlite", dir);
    test_server_away(loc, spool);
    test_spool_then_push(loc, spool);
    test_crash_while_away(loc);
    test_begin_drop(loc);
    test_away_results(loc);
    rm_rf(dir);
    return CHECK_RESULT();
}
