/* Several csfcal processes on one store (two stations of a lab on one host, or a display
 * calibration running while a report is drawn): writers wait for each other's commits instead
 * of failing, readers see consistent data, and nothing is lost. */
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "results/store/store.h"
#include "store_test_util.h"
#include "tests/check.h"

#define WRITERS 3
#define TRIALS 150

static int writer(const char *path, int w)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) != CSF_OK) {
        fprintf(stderr, "writer %d: %s\n", w, err.msg);
        return 3;
    }
    char name[16];
    snprintf(name, sizeof name, "station%d", w);
    int64_t sid = 0;
    if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, name, "lcd", NULL, (uint64_t)w, &sid, &err) !=
        CSF_OK) {
        fprintf(stderr, "writer %d: %s\n", w, err.msg);
        return 4;
    }
    for (int i = 0; i < TRIALS; i++) {
        csf_trial t = make_trial(sid, i, (uint64_t)(100 + w));
        if (csf_store_add_trial(s, &t, &err) != CSF_OK) {
            fprintf(stderr, "writer %d trial %d: %s\n", w, i, err.msg);
            return 5;
        }
        double iv[4] = {1 / 60.0, 1 / 60.0, 1 / 60.0, 1 / 60.0};
        if (csf_store_add_frame_intervals(s, sid, i, iv, 4, &err) != CSF_OK) {
            fprintf(stderr, "writer %d frames %d: %s\n", w, i, err.msg);
            return 6;
        }
        if (i % 25 == 0) { /* a reader's view in between: consistent counts */
            csf_session_info *list = NULL;
            size_t n = 0;
            if (csf_store_list_sessions(s, &list, &n, &err) != CSF_OK) return 7;
            csf_session_list_free(list, n);
        }
    }
    if (csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err) != CSF_OK) return 8;
    csf_store_close(s);
    return 0;
}

/* Several processes create the same new store at once (three stations started together on a
 * fresh lab store): every one opens it. Each waits at a pipe until all are forked, so the opens
 * really overlap; before, two of three failed with "table schema_version already exists". */
#define CREATORS 6
static void test_create_at_once(const char *dir, const char *name)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    int go[2];
    if (pipe(go) != 0) return;
    pid_t pids[CREATORS];
    for (int w = 0; w < CREATORS; w++) {
        pids[w] = fork();
        if (pids[w] == 0) {
            close(go[1]);
            char c;
            if (read(go[0], &c, 1) < 0) _exit(9);
            csf_error e;
            csf_store *cs = NULL;
            if (csf_store_open(path, &cs, &e) != CSF_OK) {
                fprintf(stderr, "creator %d: %s\n", w, e.msg);
                _exit(3);
            }
            int64_t sid = 0;
            int rc = csf_store_begin_session(cs, CSF_SESSION_OBSERVER, "station", "lcd", NULL, 1, &sid, &e) ==
                             CSF_OK
                         ? 0
                         : 4;
            csf_store_close(cs);
            _exit(rc);
        }
    }
    close(go[0]);
    close(go[1]); /* end of file: every creator's read returns at once */
    for (int w = 0; w < CREATORS; w++) {
        int status = 0;
        waitpid(pids[w], &status, 0);
        CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "creator %d status %d", w, status);
    }
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (s) {
        csf_session_info *list = NULL;
        size_t n = 0;
        CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
        CHECK_INT_EQ(n, CREATORS);
        csf_session_list_free(list, n);
        CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
        csf_store_close(s);
    }
}

int main(void)
{
    char dir[512], path[600];
    if (tmp_dir(dir, sizeof dir, "conc") < 0) return 1;
    for (int round = 0; round < 5; round++) {
        char name[32];
        snprintf(name, sizeof name, "new%d.sqlite", round);
        test_create_at_once(dir, name);
    }
    snprintf(path, sizeof path, "%s/shared.sqlite", dir);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK); /* create once, then everyone opens */
    csf_store_close(s);
    pid_t pids[WRITERS];
    for (int w = 0; w < WRITERS; w++) {
        pids[w] = fork();
        if (pids[w] == 0) _exit(writer(path, w));
    }
    for (int w = 0; w < WRITERS; w++) {
        int status = 0;
        waitpid(pids[w], &status, 0);
        CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "writer %d status %d", w, status);
    }
    s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return CHECK_RESULT();
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, WRITERS);
    for (size_t i = 0; i < n; i++) {
        CHECK_INT_EQ(list[i].n_trials, TRIALS);
        CHECK(list[i].state == CSF_SESSION_FINISHED);
        int w = list[i].observer[7] - '0';
        csf_trial *t = NULL;
        size_t nt = 0;
        CHECK_INT_EQ(csf_store_get_trials(s, list[i].id, &t, &nt, &err), CSF_OK);
        int ok = nt == TRIALS;
        for (size_t k = 0; ok && k < nt; k++) {
            csf_trial want = make_trial(list[i].id, (int)k, (uint64_t)(100 + w));
            ok = trials_equal(&t[k], &want);
        }
        CHECK_MSG(ok, "session %lld trials differ", (long long)list[i].id);
        free(t);
        double *fi = NULL;
        size_t nf = 0;
        CHECK_INT_EQ(csf_store_get_frame_intervals(s, list[i].id, &fi, &nf, &err), CSF_OK);
        CHECK_INT_EQ(nf, 4 * TRIALS);
        free(fi);
    }
    csf_session_list_free(list, n);
    csf_store_close(s);
    rm_rf(dir);
    return CHECK_RESULT();
}
