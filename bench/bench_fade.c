/* Accuracy of the fade-in method (and the per-cell 2AFC Psi method beside it) against the
 * simulated observer's truth: RMS error of log10 threshold over the visible cells of the default
 * 6 x 4 grid (0.5-16 cpd x 0, 5, 10, 20 deg), per trial budget, over seeds; plus cells whose
 * visibility came out wrong. The procedures run against the simulated observer frame by frame at
 * 60 Hz on the planned ramp (tests/observer/sim_loop.h), without the presenter: the session's
 * wall time is measured separately with csfcal itself (see BENCHMARKS.md).
 * Usage: bench_fade [--seeds N] [--budgets A,B,...] [--table FILE.csv | --observer SPEC] [--fade-anchors S]
 * --observer: any simulated person (devices/observer_sim spec); --fade-anchors: the fade method's
 * anchor share (0 = none; default: the method's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/procedure.h"
#include "model/observer_sim.h"
#include "tests/observer/sim_loop.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
    int n_seeds = 20;
    int budgets[16] = {60, 120, 240, 480}, n_budgets = 4;
    const char *table = NULL, *observer = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--seeds") == 0 && i + 1 < argc) n_seeds = atoi(argv[++i]);
        else if (strcmp(argv[i], "--table") == 0 && i + 1 < argc) table = argv[++i];
        else if (strcmp(argv[i], "--observer") == 0 && i + 1 < argc) observer = argv[++i];
        else if (strcmp(argv[i], "--fade-anchors") == 0 && i + 1 < argc) {
            double a = atof(argv[++i]);
            sim_loop_fade_anchor_share = a > 0 ? a : -1;
        }
        else if (strcmp(argv[i], "--budgets") == 0 && i + 1 < argc) {
            n_budgets = 0;
            for (char *s = strtok(argv[++i], ","); s && n_budgets < 16; s = strtok(NULL, ","))
                budgets[n_budgets++] = atoi(s);
        } else {
            fprintf(stderr, "usage: bench_fade [--seeds N] [--budgets A,B,...] [--table FILE.csv | --observer SPEC] "
                            "[--fade-anchors S]\n");
            return 2;
        }
    }
    if (n_seeds < 1 || n_seeds > 1000) return 2;
    char spec[1200];
    if (observer) snprintf(spec, sizeof spec, "%s", observer);
    else snprintf(spec, sizeof spec, table ? "sim:table=%s" : "sim", table ? table : "");
    csf_cell cells[24];
    int n = 0;
    const double eccs[4] = {0, 5, 10, 20};
    for (int e = 0; e < 4; e++)
        for (int f = 0; f < 6; f++) cells[n++] = (csf_cell){0.5 * pow(32.0, f / 5.0), eccs[e], 0};
    printf("observer: %s, %d seeds, default 6 x 4 grid\n", spec, n_seeds);
    printf("| trials | fade RMS | wrong | trials used | ms/run | 2afc RMS | wrong | ms/run |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const char *methods[2] = {"fade", "2afc"};
    for (int b = 0; b < n_budgets; b++) {
        double rms[2], ms[2], used[2];
        int wrong[2];
        for (int m = 0; m < 2; m++) {
            const csf_procedure_ops *ops = csf_procedure_find(methods[m]);
            double se2 = 0, t_total = 0, used_total = 0;
            int nv = 0, nw = 0;
            for (int s = 1; s <= n_seeds; s++) {
                csf_observer_sim *o;
                csf_error err;
                if (csf_observer_sim_create(spec, (uint64_t)s * 7919, &o, &err) != CSF_OK) {
                    fprintf(stderr, "bench_fade: %s\n", err.msg);
                    return 1;
                }
                csf_procedure_setup set = sim_loop_setup(cells, n, budgets[b], (uint64_t)s, ops->task);
                set.max_contrast = 0.98;
                csf_cell_estimate est[24];
                double t0 = now_s();
                used_total += sim_loop_run(ops, &set, o, est);
                t_total += now_s() - t0;
                for (int k = 0; k < n; k++) {
                    double truth = csf_observer_sim_threshold(o, cells[k].freq_cpd, cells[k].ecc_deg);
                    int vis_true = isfinite(truth) && truth < set.max_contrast;
                    int vis_est = isfinite(est[k].threshold);
                    if (vis_true != vis_est) nw++;
                    if (!vis_true) continue;
                    double e = log10(vis_est ? est[k].threshold : set.max_contrast) - log10(truth);
                    se2 += e * e;
                    nv++;
                }
                csf_observer_sim_free(o);
            }
            rms[m] = sqrt(se2 / nv);
            wrong[m] = nw;
            ms[m] = 1000 * t_total / n_seeds;
            used[m] = used_total / n_seeds;
        }
        printf("| %d | %.3f | %d | %.0f | %.1f | %.3f | %d | %.1f |\n", budgets[b], rms[0], wrong[0], used[0],
               ms[0], rms[1], wrong[1], ms[1]);
    }
    return 0;
}
