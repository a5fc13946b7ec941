/* Crash safety at the store level. A child process resumes a session (next seq = number of stored
 * trials) and writes trials in a loop, reporting each seq through a pipe only after
 * csf_store_add_trial returned CSF_OK. The parent SIGKILLs it at random moments (so also while it
 * opens the store and while a commit is being synced); some rounds the child kills itself from
 * inside SQLite's commit path (commit hook: before the commit is durable; WAL hook: after it is
 * durable but before add_trial returns). After every kill the parent checks: the file passes
 * PRAGMA integrity_check, the store opens, every reported trial is present with its exact
 * content, the stored seqs are 0..n-1 without gaps, and a trial written together with its frame
 * intervals (csf_store_add_trial_frames) has all of them or was not stored. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "results/store/store.h"
#include "results/store/internal.h"
#include "store_test_util.h"
#include "tests/check.h"

#define SEED 20261122u
#define ROUNDS 24

static int hook_countdown;

static int commit_hook_kill(void *arg)
{
    (void)arg;
    if (--hook_countdown == 0) raise(SIGKILL);
    return 0;
}

static int wal_hook_kill(void *arg, sqlite3 *db, const char *name, int pages)
{
    (void)arg, (void)db, (void)name, (void)pages;
    if (--hook_countdown == 0) raise(SIGKILL);
    return SQLITE_OK;
}

/* mode 0: plain; 1: die in the commit hook; 2: die in the WAL hook (after the sync). */
static void child(const char *path, int64_t sid, int fd, int mode, int countdown)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) != CSF_OK) {
        fprintf(stderr, "child: %s\n", err.msg);
        _exit(3);
    }
    csf_session_info info;
    if (csf_store_get_session(s, sid, &info, &err) != CSF_OK) _exit(4);
    int next = info.n_trials; /* resume point */
    csf_session_info_free(&info);
    hook_countdown = countdown;
    if (mode == 1) sqlite3_commit_hook(csf_store_db(s), commit_hook_kill, NULL);
    if (mode == 2) sqlite3_wal_hook(csf_store_db(s), wal_hook_kill, NULL);
    for (int seq = next; seq < next + 100000; seq++) {
        csf_trial t = make_trial(sid, seq, SEED);
        /* Odd trials go in with their frame intervals, in one transaction. */
        double iv[5] = {0.0166, 0.0167, 0.0168, 0.0333, 0.0167};
        csf_status st = seq % 2 ? csf_store_add_trial_frames(s, &t, iv, 5, &err)
                                : csf_store_add_trial(s, &t, &err);
        if (st != CSF_OK) {
            fprintf(stderr, "child: %s\n", err.msg);
            _exit(5);
        }
        if (write(fd, &seq, sizeof seq) != (ssize_t)sizeof seq) _exit(6);
    }
    _exit(7);
}

/* Trials stored with frames must have all 5 of them, and no frame rows may lack their trial. */
static int frames_atomic(const char *path)
{
    sqlite3 *db = NULL;
    int bad = -1;
    if (sqlite3_open(path, &db) == SQLITE_OK) {
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(db,
                "SELECT (SELECT COUNT(*) FROM trials t WHERE t.seq % 2 = 1 AND (SELECT COUNT(*) FROM"
                " frame_intervals f WHERE f.session_id = t.session_id AND f.trial_seq = t.seq) <> 5)"
                " + (SELECT COUNT(*) FROM frame_intervals f WHERE NOT EXISTS (SELECT 1 FROM trials t"
                " WHERE t.session_id = f.session_id AND t.seq = f.trial_seq))", -1, &st, NULL) == SQLITE_OK &&
            sqlite3_step(st) == SQLITE_ROW)
            bad = sqlite3_column_int(st, 0);
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return bad == 0;
}

static int integrity_ok(const char *path)
{
    sqlite3 *db = NULL;
    int ok = 0;
    if (sqlite3_open(path, &db) == SQLITE_OK) {
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &st, NULL) == SQLITE_OK &&
            sqlite3_step(st) == SQLITE_ROW)
            ok = !strcmp((const char *)sqlite3_column_text(st, 0), "ok");
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return ok;
}

int main(void)
{
    char dir[512], path[600];
    if (tmp_dir(dir, sizeof dir, "crash") < 0) return 1;
    snprintf(path, sizeof path, "%s/crash.sqlite", dir);
    csf_error err;
    csf_store *s = NULL;
    int64_t sid = 0;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return CHECK_RESULT();
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "sim", "sim-lcd", "{}", SEED, &sid, &err),
                 CSF_OK);
    csf_store_close(s);

    int max_reported = -1, hook_deaths = 0, kills = 0, progress_rounds = 0;
    size_t prev_n = 0;
    for (int round = 0; round < ROUNDS; round++) {
        int mode = round % 4 == 1 ? 1 : round % 4 == 3 ? 2 : 0;
        int countdown = 3 + (int)(20 * csf_rng_uniform(SEED, 100, (uint64_t)round));
        int pfd[2];
        if (pipe(pfd) != 0) return 1;
        pid_t pid = fork();
        if (pid == 0) {
            close(pfd[0]);
            child(path, sid, pfd[1], mode, countdown);
        }
        close(pfd[1]);
        if (mode == 0) {
            /* Random moment in 0..60 ms: spans the open (quick_check, probe write) and the
             * commit loop, where most time is spent inside fsync. */
            long delay_us = (long)(60000 * csf_rng_uniform(SEED, 101, (uint64_t)round));
            struct timespec ts = {0, delay_us * 1000};
            nanosleep(&ts, NULL);
            kill(pid, SIGKILL);
            kills++;
        }
        int seq;
        while (read(pfd[0], &seq, sizeof seq) == (ssize_t)sizeof seq)
            if (seq > max_reported) max_reported = seq;
        close(pfd[0]);
        int status = 0;
        waitpid(pid, &status, 0);
        CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL,
                  "round %d: child ended with status %d instead of SIGKILL", round, status);
        if (mode != 0 && WIFSIGNALED(status)) hook_deaths++;

        CHECK_MSG(integrity_ok(path), "round %d: integrity_check failed", round);
        CHECK_MSG(frames_atomic(path), "round %d: a trial lost part of its frame intervals", round);
        s = NULL;
        CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
        if (!s) {
            fprintf(stderr, "round %d: %s\n", round, err.msg);
            break;
        }
        csf_trial *t = NULL;
        size_t n = 0;
        CHECK_INT_EQ(csf_store_get_trials(s, sid, &t, &n, &err), CSF_OK);
        CHECK_MSG((long)n >= max_reported + 1, "round %d: %zu trials stored but seq %d was reported "
                  "committed", round, n, max_reported);
        int gapless = 1, intact = 1;
        for (size_t i = 0; i < n; i++) {
            if (t[i].seq != (int)i) gapless = 0;
            csf_trial want = make_trial(sid, (int)i, SEED);
            if (!trials_equal(&t[i], &want)) intact = 0;
        }
        CHECK_MSG(gapless, "round %d: stored seqs have a gap", round);
        CHECK_MSG(intact, "round %d: a stored trial differs from what was written", round);
        if (n > prev_n) progress_rounds++;
        /* A WAL-hook death happens after the commit is durable: that trial must be there even
         * though it was never reported. */
        if (mode == 2) CHECK_MSG((long)n == max_reported + 2, "round %d: WAL-hook death, %zu stored, "
                                 "last reported %d", round, n, max_reported);
        if (mode == 1) CHECK_MSG((long)n == max_reported + 1, "round %d: commit-hook death, %zu "
                                 "stored, last reported %d", round, n, max_reported);
        if (mode != 0) max_reported = (int)n - 1;
        prev_n = n;
        free(t);
        csf_store_close(s);
    }
    fprintf(stderr, "%d random kills, %d kills inside commit, %zu trials stored, %d rounds made "
            "progress\n", kills, hook_deaths, prev_n, progress_rounds);
    CHECK_INT_EQ(hook_deaths, ROUNDS / 2);
    CHECK(progress_rounds >= ROUNDS / 2);
    rm_rf(dir);
    return CHECK_RESULT();
}
