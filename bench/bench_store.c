/* Results store benchmark: durable commits per second (each trial/reading committed and synced
 * before the call returns, as during a session) and the cost of opening, listing and loading a
 * store that holds 100,000 trials. Usage: bench_store [DIR] [N_DURABLE] (DIR default $TMPDIR or
 * /tmp: put it on the disk the real store lives on, since fsync speed is the point). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "results/plot.h"
#include "core/rng.h"
#include "results/store/store.h"
#include "results/store/export.h"
#include "results/store/internal.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static csf_trial trial(int64_t sid, int seq)
{
    csf_trial t;
    memset(&t, 0, sizeof t);
    t.session_id = sid;
    t.seq = seq;
    snprintf(t.method, sizeof t.method, "fade");
    t.freq_cpd = 0.5 * pow(2.0, seq % 7);
    t.ecc_deg = 5.0 * (seq / 7 % 4);
    t.orientation_deg = 90;
    t.sigma_deg = 1;
    t.mean_lum_cdm2 = 50;
    t.contrast_requested = pow(10.0, -3 + 2 * csf_rng_uniform(1, 1, (uint64_t)seq));
    t.contrast_shown_mean = t.contrast_requested;
    t.contrast_shown_max = t.contrast_requested;
    t.frames_planned = t.frames_shown = 60;
    t.response = 1;
    t.rt_s = 0.5 + csf_rng_uniform(1, 2, (uint64_t)seq);
    t.click_x_deg = t.click_y_deg = NAN;
    t.valid = 1;
    return t;
}

static void die(const csf_error *err)
{
    fprintf(stderr, "bench_store: %s\n", err->msg);
    exit(1);
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    const char *base = argc > 1 ? argv[1] : getenv("TMPDIR");
    if (!base || !*base) base = "/tmp";
    int n_durable = argc > 2 ? atoi(argv[2]) : 2000;
    if (n_durable < 10) n_durable = 10;
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s/bench-store-XXXXXX", base);
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(path, sizeof path, "%s/bench.sqlite", dir);
    csf_error err;
    csf_store *s = NULL;

    printf("%-52s %14s %10s\n", "measure", "value", "unit");
    printf("%-52s %14s %10s\n", "-------", "-----", "----");

    /* 1. Durable commits: one trial per commit, as a session does. */
    double t0 = now_s();
    if (csf_store_open(path, &s, &err) != CSF_OK) die(&err);
    double t_open_empty = now_s() - t0;
    int64_t sid = 0;
    if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "bench", "bench", NULL, 1, &sid, &err) != CSF_OK)
        die(&err);
    double *lat = malloc((size_t)n_durable * sizeof *lat);
    t0 = now_s();
    for (int i = 0; i < n_durable; i++) {
        csf_trial t = trial(sid, i);
        double a = now_s();
        if (csf_store_add_trial(s, &t, &err) != CSF_OK) die(&err);
        lat[i] = now_s() - a;
    }
    double t_trials = now_s() - t0;
    qsort(lat, (size_t)n_durable, sizeof *lat, cmp);
    double p50 = lat[n_durable / 2], p99 = lat[(int)(0.99 * (n_durable - 1))];
    /* Frame intervals: 60 per trial in one transaction. */
    double iv[60];
    for (int k = 0; k < 60; k++) iv[k] = 1 / 60.0;
    int n_fi = n_durable / 4;
    t0 = now_s();
    for (int i = 0; i < n_fi; i++)
        if (csf_store_add_frame_intervals(s, sid, i, iv, 60, &err) != CSF_OK) die(&err);
    double t_fi = now_s() - t0;
    csf_store_close(s);
    printf("%-52s %14.1f %10s\n", "open (create) empty store", 1000 * t_open_empty, "ms");
    printf("%-52s %14.0f %10s\n", "durable trial commits (1 trial per commit)", n_durable / t_trials, "commits/s");
    printf("%-52s %14.3f %10s\n", "  add_trial latency, median", 1000 * p50, "ms");
    printf("%-52s %14.3f %10s\n", "  add_trial latency, 99th percentile", 1000 * p99, "ms");
    printf("%-52s %14.0f %10s\n", "durable frame-interval commits (60 per commit)", n_fi / t_fi, "commits/s");
    free(lat);
    unlink(path);

    /* 2. A store with 100,000 trials (loaded in bulk, one transaction per 10,000). */
    const int N = 100000;
    if (csf_store_open(path, &s, &err) != CSF_OK) die(&err);
    if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "bulk", "bench", NULL, 2, &sid, &err) != CSF_OK)
        die(&err);
    t0 = now_s();
    for (int i = 0; i < N; i++) {
        if (i % 10000 == 0) sqlite3_exec(csf_store_db(s), "BEGIN", NULL, NULL, NULL);
        csf_trial t = trial(sid, i);
        if (csf_store_add_trial(s, &t, &err) != CSF_OK) die(&err);
        if (i % 10000 == 9999) sqlite3_exec(csf_store_db(s), "COMMIT", NULL, NULL, NULL);
    }
    double t_bulk = now_s() - t0;
    csf_store_close(s);
    struct stat st;
    stat(path, &st);
    printf("%-52s %14.0f %10s\n", "bulk insert (10,000 trials per transaction)", N / t_bulk, "trials/s");
    printf("%-52s %14.1f %10s\n", "store file size with 100,000 trials", st.st_size / 1048576.0, "MiB");

    double best_open = INFINITY, best_list = INFINITY, best_load = INFINITY, best_exp = INFINITY;
    size_t n_loaded = 0;
    for (int rep = 0; rep < 3; rep++) {
        t0 = now_s();
        if (csf_store_open(path, &s, &err) != CSF_OK) die(&err);
        double a = now_s() - t0;
        csf_session_info *list = NULL;
        size_t n = 0;
        t0 = now_s();
        if (csf_store_list_sessions(s, &list, &n, &err) != CSF_OK) die(&err);
        double b = now_s() - t0;
        csf_session_list_free(list, n);
        csf_trial *tr = NULL;
        t0 = now_s();
        if (csf_store_get_trials(s, sid, &tr, &n_loaded, &err) != CSF_OK) die(&err);
        double c = now_s() - t0;
        free(tr);
        FILE *null_out = fopen("/dev/null", "w");
        t0 = now_s();
        if (csf_store_export(s, sid, CSF_TABLE_TRIALS, CSF_EXPORT_CSV, null_out, &err) != CSF_OK) die(&err);
        double d = now_s() - t0;
        fclose(null_out);
        csf_store_close(s);
        best_open = a < best_open ? a : best_open;
        best_list = b < best_list ? b : best_list;
        best_load = c < best_load ? c : best_load;
        best_exp = d < best_exp ? d : best_exp;
    }
    if (n_loaded != (size_t)N) fprintf(stderr, "bench_store: loaded %zu trials, expected %d\n", n_loaded, N);
    printf("%-52s %14.1f %10s\n", "open store with 100,000 trials (incl. quick_check)", 1000 * best_open, "ms");
    printf("%-52s %14.1f %10s\n", "list sessions (with trial counts)", 1000 * best_list, "ms");
    printf("%-52s %14.1f %10s\n", "load all 100,000 trials (get_trials, by seq)", 1000 * best_load, "ms");
    printf("%-52s %14.1f %10s\n", "export 100,000 trials as CSV (to /dev/null)", 1000 * best_exp, "ms");
    printf("(best of 3 for the 100,000-trial figures; store in %s)\n", dir);
    unlink(path);
    char side[700];
    snprintf(side, sizeof side, "%s-wal", path);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", path);
    unlink(side);
    rmdir(dir);
    return 0;
}
