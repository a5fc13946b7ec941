/* Session claims, on SQLite and (under tests/store/pg_run.sh) PostgreSQL:
 * two stations, each a process of its own, must never write one session at once.
 * - a second station resuming a session another holds is refused, with a message that names
 *   the holder (station and process) and says how to take over when it is stale;
 * - two stations resuming one paused session at the same moment: exactly one gets it;
 * - the holder killed: its claim goes with it, and the session can be resumed;
 * - on a server, a hung holder's claim is taken over as the refusal says (the database owner
 *   ends its connection).
 * No sleeps as synchronisation: pipes order the processes; the one wait that cannot be a pipe
 * (the server noticing a dead connection) polls up to a deadline. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "results/store/store.h"
#include "store_test_util.h"
#include "tests/check.h"

static char loc[1024];

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* A holds a session it started; B is refused with the holder named; A killed, B resumes. */
static void test_holder_named(void)
{
    int ready[2], hold[2];
    if (pipe(ready) != 0 || pipe(hold) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        close(hold[1]);
        csf_store *s = test_open_or_exit(loc, "station A");
        csf_error err;
        int64_t sid = 0;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "held", "lcd", NULL, 5, &sid, &err) != CSF_OK)
            _exit(4);
        csf_trial t = make_trial(sid, 0, 5);
        if (csf_store_add_trial(s, &t, &err) != CSF_OK) _exit(5);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid) _exit(6);
        char c;
        if (read(hold[0], &c, 1) < 0) _exit(7); /* holds the claim until killed */
        _exit(8);
    }
    close(ready[1]);
    close(hold[0]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    close(ready[0]);

    csf_store *b = test_open_or_exit(loc, "station B");
    csf_error err;
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "in use by another station");
    if (test_pg()) {
        CHECK_STR_CONTAINS(err.msg, "login csfcal_admin");
        CHECK_STR_CONTAINS(err.msg, "pg_terminate_backend(");
    } else {
        char host[64] = "", want[96];
        gethostname(host, sizeof host);
        host[sizeof host - 1] = '\0';
        snprintf(want, sizeof want, "%s, csfcal process %ld", host, (long)a);
        CHECK_STR_CONTAINS(err.msg, want);
        snprintf(want, sizeof want, "kill %ld on %s", (long)a, host);
        CHECK_STR_CONTAINS(err.msg, want);
    }
    /* Another station may not end it either. */
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_ABORTED, &err), CSF_E_STORE);

    kill(a, SIGKILL);
    int status = 0;
    waitpid(a, &status, 0);
    CHECK(WIFSIGNALED(status));
    close(hold[1]);
    /* SQLite: the kernel dropped the lock with the process. A server notices the closed socket
     * a little later: poll up to a deadline. */
    csf_status cs = CSF_E_STORE;
    double deadline = now_s() + 60.0;
    while ((cs = csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err)) != CSF_OK && test_pg() &&
           now_s() < deadline)
        usleep(50000);
    CHECK_INT_EQ(cs, CSF_OK);
    csf_trial t = make_trial(sid, 1, 5);
    CHECK_INT_EQ(csf_store_add_trial(b, &t, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    csf_store_close(b);
}

/* PostgreSQL: a station that hangs (stopped, its connection open) keeps its claim; the refusal
 * says how the database owner takes it over, and doing just that lets another station resume. */
static void test_take_over_hung(void)
{
    int ready[2];
    if (pipe(ready) != 0) return;
    pid_t a = fork();
    if (a == 0) {
        close(ready[0]);
        csf_store *s = test_open_or_exit(loc, "station A");
        csf_error err;
        int64_t sid = 0;
        if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "hung", "lcd", NULL, 7, &sid, &err) != CSF_OK)
            _exit(4);
        if (write(ready[1], &sid, sizeof sid) != sizeof sid) _exit(6);
        pause();
        _exit(8);
    }
    close(ready[1]);
    int64_t sid = 0;
    CHECK(read(ready[0], &sid, sizeof sid) == sizeof sid);
    close(ready[0]);
    kill(a, SIGSTOP); /* hung: the process is there, its connection open */
    csf_store *b = test_open_or_exit(loc, "station B");
    csf_error err;
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err), CSF_E_STORE);
    const char *say = strstr(err.msg, "SELECT pg_terminate_backend(");
    CHECK_MSG(say != NULL, "no way to take over in: %s", err.msg);
    long backend = 0;
    if (say) sscanf(say, "SELECT pg_terminate_backend(%ld)", &backend);
    CHECK(backend > 0);
    char sql[96];
    snprintf(sql, sizeof sql, "SELECT pg_terminate_backend(%ld)", backend);
    CHECK_INT_EQ(test_pg_admin("csfcal", sql), 0);
    csf_status cs = CSF_E_STORE;
    double deadline = now_s() + 60.0;
    while ((cs = csf_store_set_session_state(b, sid, CSF_SESSION_RUNNING, &err)) != CSF_OK &&
           now_s() < deadline)
        usleep(50000);
    CHECK_INT_EQ(cs, CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(b, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    csf_store_close(b);
    kill(a, SIGKILL);
    int status = 0;
    waitpid(a, &status, 0);
}

/* Two stations resume one paused session at the same moment: one gets it, the other is
 * refused; each keeps what it got until told to close. */
static void test_resume_race(void)
{
    csf_store *s = test_open_or_exit(loc, "setup");
    csf_error err;
    int64_t sid = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "raced", "lcd", NULL, 6, &sid, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(s, sid, CSF_SESSION_PAUSED, &err), CSF_OK);
    csf_store_close(s);

    enum { N = 4 };
    int go[2], done[2], results[2];
    if (pipe(go) != 0 || pipe(done) != 0 || pipe(results) != 0) return;
    pid_t pids[N];
    for (int w = 0; w < N; w++) {
        pids[w] = fork();
        if (pids[w] == 0) {
            close(go[1]);
            close(done[1]);
            close(results[0]);
            csf_store *st = test_open_or_exit(loc, "racer");
            char c;
            if (read(go[0], &c, 1) < 0) _exit(9);
            csf_error e;
            char r = csf_store_set_session_state(st, sid, CSF_SESSION_RUNNING, &e) == CSF_OK ? 'y'
                     : strstr(e.msg, "in use by another station")                            ? 'n'
                                                                                             : '?';
            if (r == '?') fprintf(stderr, "racer: %s\n", e.msg);
            if (write(results[1], &r, 1) != 1) _exit(9);
            if (read(done[0], &c, 1) < 0) _exit(9); /* hold until all have answered */
            csf_store_close(st);
            _exit(0);
        }
    }
    close(go[0]);
    close(done[0]);
    close(results[1]);
    close(go[1]); /* all at once */
    int yes = 0, no = 0;
    for (int w = 0; w < N; w++) {
        char r = 0;
        CHECK(read(results[0], &r, 1) == 1);
        yes += r == 'y';
        no += r == 'n';
    }
    close(done[1]);
    for (int w = 0; w < N; w++) {
        int status = 0;
        waitpid(pids[w], &status, 0);
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    close(results[0]);
    CHECK_INT_EQ(yes, 1);
    CHECK_INT_EQ(no, N - 1);
}


/* SQLite: a claim belongs to the file, not to the name it was opened by. A session held
 * through the store's own path is refused to a handle that opened the store through a symbolic
 * link (`sessions abort 3 --store link.sqlite` once aborted a running session this way), or
 * through a relative path to it. (A hard link is no way in: SQLite refuses to open a database
 * file with more than one link.) */
static void test_claim_by_file(const char *dir)
{
    char sym[1024], rel[1024];
    snprintf(sym, sizeof sym, "%s/sym.sqlite", dir);
    snprintf(rel, sizeof rel, "%s/./sub/../lab.sqlite", dir);
    CHECK(symlink(loc, sym) == 0);
    char sub[1024];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    CHECK(mkdir(sub, 0700) == 0);
    csf_store *a = test_open_or_exit(loc, "holder");
    csf_error err;
    int64_t sid = 0;
    CHECK_INT_EQ(csf_store_begin_session(a, CSF_SESSION_OBSERVER, "held", "lcd", NULL, 5, &sid, &err),
                 CSF_OK);
    /* The aliases are tried from another process, as a second station would. */
    int res[2];
    CHECK(pipe(res) == 0);
    pid_t p = fork();
    if (p == 0) {
        close(res[0]);
        int out[2] = {0, 0};
        const char *names[2] = {sym, rel};
        for (int i = 0; i < 2; i++) {
            csf_store *b = test_open_or_exit(names[i], "alias");
            csf_error e;
            csf_status cs = csf_store_set_session_state(b, sid, CSF_SESSION_ABORTED, &e);
            out[i] = cs == CSF_E_STORE && strstr(e.msg, "in use by another station") != NULL;
            csf_store_close(b);
        }
        if (write(res[1], out, sizeof out) != sizeof out) _exit(2);
        _exit(0);
    }
    close(res[1]);
    int out[2] = {0, 0};
    CHECK(read(res[0], out, sizeof out) == sizeof out);
    close(res[0]);
    waitpid(p, NULL, 0);
    CHECK_MSG(out[0], "a symbolic link to the store aborted a session another process holds");
    CHECK_MSG(out[1], "another path to the store aborted a session another process holds");
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(a, sid, &si, &err), CSF_OK);
    CHECK_MSG(si.state == CSF_SESSION_RUNNING, "state %s", si.state_text);
    csf_session_info_free(&si);
    CHECK_INT_EQ(csf_store_set_session_state(a, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    csf_store_close(a);
    unlink(sym);
    rmdir(sub);
}

/* SQLite: a symbolic link planted at STORE-claims is not written through (its target once had
 * bytes 128-255 overwritten); the claim is refused with the reason, and the target is intact. */
static void test_planted_claims_link(const char *dir)
{
    char store[1024], claims[1100], victim[1024];
    snprintf(store, sizeof store, "%s/planted.sqlite", dir);
    snprintf(claims, sizeof claims, "%s-claims", store);
    snprintf(victim, sizeof victim, "%s/victim.txt", dir);
    FILE *f = fopen(victim, "w");
    CHECK(f != NULL);
    for (int i = 0; f && i < 64; i++) fputs("untouchable\n", f);
    if (f) fclose(f);
    CHECK(symlink(victim, claims) == 0);
    csf_store *s = test_open_or_exit(store, "planted");
    csf_error err;
    int64_t sid = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "x", "lcd", NULL, 5, &sid, &err),
                 CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "symbolic link or not a regular file");
    csf_store_close(s);
    char buf[1024] = "";
    f = fopen(victim, "r");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f) fclose(f);
    CHECK(n == 64 * 12 && strstr(buf, "station=") == NULL);
    unlink(claims);
    unlink(victim);
}

int main(void)
{
    test_pg_require();
    char dir[512];
    if (tmp_dir(dir, sizeof dir, "claims") < 0) return 1;
    if (test_store_location(dir, "lab.sqlite", loc, sizeof loc) < 0) return 1;
    test_holder_named();
    test_resume_race();
    if (test_pg()) test_take_over_hung();
    else {
        test_claim_by_file(dir);
        test_planted_claims_link(dir);
    }
    rm_rf(dir);
    return CHECK_RESULT();
}
