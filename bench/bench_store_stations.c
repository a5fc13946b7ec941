/* Several stations writing trials at once: 1, 4 and 16 processes, each with
 * its own session, each trial (with 60 frame intervals) committed durably before the next, as
 * during a session. Prints, per number of stations: durable trial commits per second over all
 * stations, and the per-trial latency (median, 99th percentile) a station sees.
 * Usage: bench_store_stations LOCATION [TRIALS_PER_STATION] [STATIONS...]
 *   LOCATION: an SQLite file (created; several processes on one file) or a server URI
 *   (postgresql://..., e.g. what tests/store/pg_run.sh puts in CSF_TEST_PG). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "results/store/store.h"

#define FRAMES 60
#define MAX_STATIONS 64

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static csf_trial trial(int64_t sid, int seq)
{
    csf_trial t;
    memset(&t, 0, sizeof t);
    t.session_id = sid;
    t.seq = seq;
    snprintf(t.method, sizeof t.method, "2afc");
    t.freq_cpd = 0.5 * pow(2.0, seq % 7);
    t.ecc_deg = 5.0 * (seq / 7 % 4);
    t.sigma_deg = 1;
    t.mean_lum_cdm2 = 50;
    t.contrast_requested = 0.001 * (1 + seq % 100);
    t.contrast_shown_mean = t.contrast_shown_max = t.contrast_requested;
    t.frames_planned = t.frames_shown = FRAMES;
    t.signal_interval = 1 + seq % 2;
    t.response = 1;
    t.rt_s = 0.5;
    t.click_x_deg = t.click_y_deg = NAN;
    t.valid = 1;
    t.n_alternatives = 2;
    return t;
}

/* One station: opens its store and session, says so, waits for the start, writes n trials,
 * sends each latency (s) down out_fd. */
static int station(const char *loc, int w, int n, int ready_fd, int go_fd, int out_fd)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(loc, &s, &err) != CSF_OK) {
        fprintf(stderr, "station %d: %s\n", w, err.msg);
        return 3;
    }
    int64_t sid = 0;
    if (csf_store_begin_session(s, CSF_SESSION_OBSERVER, "bench", "lcd", NULL, (uint64_t)w, &sid, &err) !=
        CSF_OK) {
        fprintf(stderr, "station %d: %s\n", w, err.msg);
        return 4;
    }
    char c = 'r';
    if (write(ready_fd, &c, 1) != 1 || read(go_fd, &c, 1) < 0) return 9;
    double iv[FRAMES];
    for (int k = 0; k < FRAMES; k++) iv[k] = 1 / 60.0;
    for (int i = 0; i < n; i++) {
        csf_trial t = trial(sid, i);
        double t0 = now_s();
        if (csf_store_add_trial_frames(s, &t, iv, FRAMES, &err) != CSF_OK) {
            fprintf(stderr, "station %d trial %d: %s\n", w, i, err.msg);
            return 5;
        }
        double lat = now_s() - t0;
        if (write(out_fd, &lat, sizeof lat) != sizeof lat) return 6;
    }
    csf_store_set_session_state(s, sid, CSF_SESSION_FINISHED, &err);
    csf_store_close(s);
    return 0;
}

static int run(const char *loc, int k, int n)
{
    int go[2], lat[2], ready[2];
    if (pipe(go) != 0 || pipe(lat) != 0 || pipe(ready) != 0) return -1;
    pid_t pids[MAX_STATIONS];
    for (int w = 0; w < k; w++) {
        pids[w] = fork();
        if (pids[w] == 0) {
            close(go[1]);
            close(lat[0]);
            close(ready[0]);
            _exit(station(loc, w, n, ready[1], go[0], lat[1]));
        }
    }
    close(go[0]);
    close(lat[1]);
    close(ready[1]);
    char c;
    for (int w = 0; w < k; w++) /* every station has opened its store and begun its session */
        if (read(ready[0], &c, 1) != 1) break;
    close(ready[0]);
    double t0 = now_s();
    close(go[1]);
    size_t total = (size_t)k * (size_t)n, got = 0;
    double *all = malloc(total * sizeof *all);
    while (all && got < total && read(lat[0], &all[got], sizeof all[got]) == sizeof all[got]) got++;
    double wall = now_s() - t0;
    close(lat[0]);
    int bad = 0;
    for (int w = 0; w < k; w++) {
        int status = 0;
        waitpid(pids[w], &status, 0);
        bad |= !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    if (got == 0) {
        free(all);
        return -1;
    }
    /* A station that failed (SQLite: a commit waited past the busy timeout) is part of the
     * result: the row says so and counts what was stored. */
    qsort(all, got, sizeof *all, cmp);
    printf("%8d %12zu %14.0f %12.2f %12.2f %10.2f%s\n", k, got, got / wall, 1e3 * all[got / 2],
           1e3 * all[(size_t)floor(0.99 * (double)(got - 1))], wall,
           bad || got != total ? "  a station failed (see stderr)" : "");
    free(all);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_store_stations LOCATION [TRIALS_PER_STATION] [STATIONS...]\n");
        return 2;
    }
    int n = argc > 2 ? atoi(argv[2]) : 300;
    if (n < 10) n = 10;
    int ks[16] = {1, 4, 16}, nk = 3;
    if (argc > 3) {
        nk = 0;
        for (int i = 3; i < argc && nk < 16; i++) {
            int k = atoi(argv[i]);
            if (k >= 1 && k <= MAX_STATIONS) ks[nk++] = k;
        }
    }
    char red[1024];
    csf_store_redact(argv[1], red, sizeof red);
    printf("store %s (%s), %d trials per station, %d frame intervals per trial, one transaction "
           "each\n", red, csf_store_is_server(argv[1]) ? "postgresql" : "sqlite", n, FRAMES);
    printf("%8s %12s %14s %12s %12s %10s\n", "stations", "trials", "commits/s", "median ms",
           "p99 ms", "wall s");
    for (int i = 0; i < nk; i++)
        if (run(argv[1], ks[i], n) < 0) return 1;
    return 0;
}
