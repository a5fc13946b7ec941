/* THE KILL/RESUME TEST. Runs `csfcal observer calibrate` (simulated observer, small budget) as a
 * child process and SIGKILLs it at pseudo-random moments many times, resuming each time with
 * --resume until it finishes. Then checks against an uninterrupted run with the same seed:
 *   - the threshold tables are equal node for node (and metadata except the date),
 *   - the stored trials are identical field by field, seq 0..n-1 with no gap or duplicate,
 *   - the number of stored trials never went down across a kill (no committed trial lost).
 * Cases: fade; 2afc with two intervals (--afc 2); bayes with four places shown at once away from
 * the fovea (--afc 4): the resumed plan has the same layout, place and answer for every trial.
 * argv[1] = path of the csfcal executable. */
#include <math.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "results/csflut/csflut.h"
#include "core/rng.h"
#include "results/store/store.h"
#include "tests/check.h"

static const char *csfcal;
static char dir[] = "/tmp/csfcal-killtest-XXXXXX";

static const char *afc_arg = "4";
static const char *vel_arg = NULL; /* --velocities of the case (NULL: static gratings) */

static pid_t spawn_n(const char *method, const char *store, const char *out, int resume, const char *trials)
{
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        char rid[16];
        snprintf(rid, sizeof rid, "%d", resume);
        const char *args[32] = {csfcal, "observer", "calibrate", "--observer", "sim", "--seed", "7",
                                "--method", method, "--freqs", "0.5,1,4,8", "--eccs", "0,5,10",
                                "--trials", trials, "--practice", "2", "--store", store, "--out", out,
                                "--quiet", "--headless", "--afc", afc_arg};
        int n = 25;
        if (vel_arg) {
            args[n++] = "--velocities";
            args[n++] = vel_arg;
        }
        if (resume) {
            args[n++] = "--resume";
            args[n++] = rid;
        }
        args[n] = NULL;
        execv(csfcal, (char *const *)args);
        _exit(127);
    }
    return pid;
}

static pid_t spawn(const char *method, const char *store, const char *out, int resume)
{
    return spawn_n(method, store, out, resume, strcmp(method, "fade") == 0 ? "90" : "70");
}

static double seconds_since(const struct timespec *t0)
{
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return (double)(t1.tv_sec - t0->tv_sec) + (t1.tv_nsec - t0->tv_nsec) * 1e-9;
}

static int wait_exit(pid_t pid)
{
    int status;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* 1 when session 1 is finished: a kill that lands after the table was written and the session
 * marked finished, but before the process exits, leaves nothing to resume. */
static int session_finished(const char *store)
{
    csf_store *s;
    csf_error err;
    if (access(store, F_OK) != 0 || csf_store_open(store, &s, &err) != CSF_OK) return 0;
    csf_session_info info;
    int done = 0;
    if (csf_store_get_session(s, 1, &info, &err) == CSF_OK) {
        done = info.state == CSF_SESSION_FINISHED;
        csf_session_info_free(&info);
    }
    csf_store_close(s);
    return done;
}

/* Number of trials stored in session 1, or -1 when there is no session yet. */
static int stored_trials(const char *store, csf_trial **out, size_t *n)
{
    csf_store *s;
    csf_error err;
    if (access(store, F_OK) != 0) return -1;
    if (csf_store_open(store, &s, &err) != CSF_OK) {
        fprintf(stderr, "reopen after kill failed: %s\n", err.msg);
        return -2;
    }
    csf_session_info info;
    int rc = -1;
    if (csf_store_get_session(s, 1, &info, &err) == CSF_OK) {
        csf_session_info_free(&info);
        csf_trial *t = NULL;
        size_t m = 0;
        if (csf_store_get_trials(s, 1, &t, &m, &err) == CSF_OK) {
            rc = (int)m;
            if (out) {
                *out = t;
                *n = m;
            } else {
                free(t);
            }
        }
    }
    csf_store_close(s);
    return rc;
}

static int same_double(double a, double b)
{
    return a == b || (isnan(a) && isnan(b));
}

static void compare_trials(const csf_trial *a, const csf_trial *b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        CHECK_INT_EQ(a[i].seq, (int)i);
        CHECK_INT_EQ(b[i].seq, (int)i);
        int same = a[i].is_catch == b[i].is_catch && a[i].is_practice == b[i].is_practice &&
                   a[i].response == b[i].response && a[i].valid == b[i].valid &&
                   a[i].signal_interval == b[i].signal_interval && a[i].frames_shown == b[i].frames_shown &&
                   a[i].n_alternatives == b[i].n_alternatives && same_double(a[i].freq_cpd, b[i].freq_cpd) &&
                   same_double(a[i].ecc_deg, b[i].ecc_deg) && same_double(a[i].polar_deg, b[i].polar_deg) &&
                   same_double(a[i].velocity_dps, b[i].velocity_dps) &&
                   same_double(a[i].contrast_requested, b[i].contrast_requested) &&
                   same_double(a[i].contrast_shown_max, b[i].contrast_shown_max) &&
                   same_double(a[i].rt_s, b[i].rt_s) && same_double(a[i].click_x_deg, b[i].click_x_deg) &&
                   strcmp(a[i].flags, b[i].flags) == 0;
        CHECK_MSG(same, "trial %zu differs: rt %.17g vs %.17g, contrast %.17g vs %.17g, resp %d vs %d", i,
                  a[i].rt_s, b[i].rt_s, a[i].contrast_shown_max, b[i].contrast_shown_max, a[i].response,
                  b[i].response);
    }
}

static void compare_tables(const char *pa, const char *pb)
{
    csflut_table *a = NULL, *b = NULL;
    CHECK(csflut_open_file(pa, &a) == CSFLUT_OK);
    CHECK(csflut_open_file(pb, &b) == CSFLUT_OK);
    if (!a || !b) {
        csflut_close(a);
        csflut_close(b);
        return;
    }
    CHECK(csflut_node_count(a) == csflut_node_count(b));
    size_t n = csflut_node_count(a);
    const double *ta = csflut_raw_thresholds(a), *tb = csflut_raw_thresholds(b);
    int equal = 0;
    for (size_t i = 0; i < n; i++) equal += ta[i] == tb[i];
    CHECK_MSG(equal == (int)n, "%d of %zu thresholds equal", equal, n);
    const double *sa = csflut_stderr_log10(a), *sb = csflut_stderr_log10(b);
    for (size_t i = 0; sa && sb && i < n; i++) CHECK(same_double(sa[i], sb[i]));
    CHECK(strcmp(csflut_observer(a), csflut_observer(b)) == 0);
    CHECK(strcmp(csflut_method(a), csflut_method(b)) == 0);
    CHECK_INT_EQ(csflut_trials(a), csflut_trials(b));
    csflut_close(a);
    csflut_close(b);
}

/* afc: the --afc value ("2" or "4"); want_four: the session must have four-place trials. */
static void run_case(const char *method, const char *afc, uint64_t seed, int n_kills, int want_four)
{
    afc_arg = afc;
    if (vel_arg) afc = "4v"; /* the files' names */
    char ref_store[512], ref_out[512], store[512], out[512];
    snprintf(ref_store, sizeof ref_store, "%s/ref-%s-%s.sqlite", dir, method, afc);
    snprintf(ref_out, sizeof ref_out, "%s/ref-%s-%s.csflut", dir, method, afc);
    snprintf(store, sizeof store, "%s/kill-%s-%s.sqlite", dir, method, afc);
    snprintf(out, sizeof out, "%s/kill-%s-%s.csflut", dir, method, afc);

    char probe_store[512], probe_out[512];
    snprintf(probe_store, sizeof probe_store, "%s/probe-%s-%s.sqlite", dir, method, afc);
    snprintf(probe_out, sizeof probe_out, "%s/probe-%s-%s.csflut", dir, method, afc);
    struct timespec t0;
    /* Start-up cost (EGL, shaders, store) from a one-trial run; then the whole run. */
    clock_gettime(CLOCK_MONOTONIC, &t0);
    wait_exit(spawn_n(method, probe_store, probe_out, 0, "1"));
    double startup_s = seconds_since(&t0);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    CHECK_INT_EQ(wait_exit(spawn(method, ref_store, ref_out, 0)), 0);
    double full_s = seconds_since(&t0);
    int ref_n = stored_trials(ref_store, NULL, NULL);

    int kills = 0, progressed_kills = 0, prev = -1, lost = 0, attempts = 0, rc = -1;
    while (attempts < 200) {
        attempts++;
        int have = stored_trials(store, NULL, NULL);
        pid_t pid = spawn(method, store, out, have >= 0 ? 1 : 0);
        if (kills < n_kills) {
            /* Kill at a random point of the trial/commit cycle: wait until the store's WAL file
             * has changed k times (k random 6..13; start-up makes a few changes, then each trial
             * two: its row and its frame intervals), then a random 0-15 ms more; every sixth
             * kill or so lands during start-up instead. Progress-based, so a loaded machine does not
             * turn kills into finished runs. */
            char wal[600];
            snprintf(wal, sizeof wal, "%s-wal", store);
            int target = 6 + (int)(8 * csf_rng_uniform(seed, 1, (uint64_t)attempts));
            int during_startup = csf_rng_uniform(seed, 3, (uint64_t)attempts) < 0.17;
            /* On a loaded machine the child runs ahead while this process waits for the CPU, so a
             * kill can land several trials later than planned and the run could finish before
             * every kill was made: once fewer than two trials per remaining kill are left, the
             * remaining kills land during start-up (they still test recovery: a half-opened
             * session must resume as if nothing happened). */
            if (have >= 0 && ref_n - have < 2 * (n_kills - kills) + 2) during_startup = 1;
            struct stat st0;
            long long last = -1;
            if (stat(wal, &st0) == 0) last = (long long)st0.st_size * 1000003LL + st0.st_mtim.tv_nsec;
            int changes = 0, finished = 0, status = 0;
            struct timespec t_start;
            clock_gettime(CLOCK_MONOTONIC, &t_start);
            double startup_wait = startup_s * 0.8 * csf_rng_uniform(seed, 4, (uint64_t)attempts);
            for (;;) {
                if (waitpid(pid, &status, WNOHANG) == pid) {
                    finished = 1;
                    break;
                }
                if (during_startup && seconds_since(&t_start) >= startup_wait) break;
                struct stat sw;
                if (stat(wal, &sw) == 0) {
                    long long sig = (long long)sw.st_size * 1000003LL + sw.st_mtim.tv_nsec;
                    if (sig != last) {
                        last = sig;
                        /* A resumed run can start faster than the probe did (warm caches), and
                         * with one or two trials left it could then finish inside the timed
                         * wait: a start-up kill also lands at the run's first store write, so a
                         * run never completes before its planned kill (CI saw 10 of 12 kills). */
                        if (during_startup || ++changes >= target) break;
                    }
                }
                if (seconds_since(&t_start) > 60) break;
                struct timespec ms = {0, 1000000};
                nanosleep(&ms, NULL);
            }
            if (finished) {
                int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
                if (code == 0) {
                    rc = 0;
                    break;
                }
                fprintf(stderr, "run exited with %d before the kill\n", code);
                CHECK(0);
                break;
            }
            double extra_s = 15e-3 * csf_rng_uniform(seed, 2, (uint64_t)attempts);
            struct timespec d = {0, during_startup ? 0 : (long)(extra_s * 1e9)};
            nanosleep(&d, NULL);
            kill(pid, SIGKILL);
            int st = wait_exit(pid);
            if (st == 128 + SIGKILL) kills++;
            if (st == 0 || session_finished(store)) {
                rc = 0;
                break;
            }
            int now = stored_trials(store, NULL, NULL);
            CHECK(now != -2);
            if (now >= 0 && prev >= 0 && now < prev) lost = 1;
            if (now > prev && prev >= 0) progressed_kills++;
            if (now >= 0) prev = now;
        } else {
            rc = wait_exit(pid);
            break;
        }
    }
    fprintf(stderr, "%s --afc %s: start-up %.2f s, uninterrupted run %.2f s (%d trials stored); %d SIGKILLs (%d after new trials were stored), %d starts\n",
            method, afc, startup_s, full_s, ref_n, kills, progressed_kills, attempts);
    CHECK_INT_EQ(rc, 0);
    CHECK(kills >= n_kills);
    CHECK(progressed_kills >= 3);
    CHECK_MSG(!lost, "a committed trial disappeared after a kill");

    csf_trial *ta = NULL, *tb = NULL;
    size_t na = 0, nb = 0;
    CHECK(stored_trials(ref_store, &ta, &na) > 0);
    CHECK(stored_trials(store, &tb, &nb) > 0);
    CHECK_INT_EQ(na, nb);
    if (na == nb) compare_trials(ta, tb, na);
    /* The layout: fade trials are yes/no or two-interval anchors; forced-choice trials are two-interval at
     * the fovea and (want_four) four-place at 5 and 10 deg, in both runs alike. */
    int n_four = 0, bad_layout = 0;
    for (size_t i = 0; i < nb; i++) {
        int m = tb[i].n_alternatives;
        if (strcmp(method, "fade") == 0) bad_layout += m != 0 && m != 2; /* yes/no, or its two-interval anchors */
        else if (tb[i].ecc_deg == 0 || !want_four) bad_layout += m != 2;
        else bad_layout += m != 4;
        if (m == 4) {
            n_four++;
            bad_layout += tb[i].signal_interval < 1 || tb[i].signal_interval > 4 || tb[i].response < 1 ||
                          tb[i].response > 4;
        }
    }
    CHECK_MSG(bad_layout == 0, "%s --afc %s: %d trials with the wrong layout or answer", method, afc, bad_layout);
    if (want_four) CHECK_MSG(n_four >= 10, "%s --afc %s: only %d four-place trials", method, afc, n_four);
    free(ta);
    free(tb);
    compare_tables(ref_out, out);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_kill_resume CSFCAL\n");
        return 2;
    }
    csfcal = argv[1];
    if (!mkdtemp(dir)) return 2;
    run_case("fade", "4", 11, 12, 0);
    run_case("2afc", "2", 12, 12, 0);
    run_case("bayes", "4", 13, 12, 1);
    /* a drifting grid: the direction of each trial's drift and the cells the 60 Hz display cannot
     * show (8 cpd at 6 deg/s) must come back the same after every kill */
    vel_arg = "0,6";
    run_case("bayes", "4", 14, 8, 1);
    if (CHECK_RESULT() == 0) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
        return 0;
    }
    fprintf(stderr, "files kept in %s\n", dir);
    return 1;
}
