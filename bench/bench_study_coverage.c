/* Coverage of the study report's intervals (issue 14 item 4, nominal 95 %): many simulated
 * studies of one design, each analysed as `csfcal study report` does (calib/study_report.c ->
 * results/study_stats.h), counting how often the interval holds the simulated observer's truth.
 *
 * Design (examples/studies/contrast_2afc: one curve): six fixed contrasts 0.15 log10 apart
 * around the threshold, N trials each, two-alternative forced choice. Answers come from the
 * simulated observer (devices/observer_sim.h, csf_observer_sim_2afc: its Weibull with lapse,
 * slope 3.5 and lapse 0.02 by default), at 2 cpd and 5 deg, where its true threshold is t.
 * Per study: ML Weibull fit (t, beta, lapse <= 0.06) and a B-sample parametric bootstrap; counts
 * the 95 % percentile intervals of t and beta that hold the truth, and the exact Clopper-Pearson
 * intervals of each level's proportion correct that hold the observer's P(correct) there.
 *
 *   usage: bench_study_coverage [STUDIES=200] [TRIALS_PER_LEVEL=40] [BOOT=200] [OBSERVER_SPEC=sim] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "devices/observer_sim.h"
#include "results/study_stats.h"

#define LEVELS 6

int main(int argc, char **argv)
{
    int studies = argc > 1 ? atoi(argv[1]) : 200;
    int per_level = argc > 2 ? atoi(argv[2]) : 40;
    int boot = argc > 3 ? atoi(argv[3]) : 200;
    const char *spec = argc > 4 ? argv[4] : "sim";
    if (studies < 1 || per_level < 1 || boot < 2) {
        fprintf(stderr, "usage: bench_study_coverage [STUDIES] [TRIALS_PER_LEVEL] [BOOT] [OBSERVER_SPEC]\n");
        return 2;
    }
    const double f = 2, ecc = 5;
    csf_observer_sim *truth = NULL;
    csf_error e;
    if (csf_observer_sim_create(spec, 1, &truth, &e) != CSF_OK) {
        fprintf(stderr, "%s\n", e.msg);
        return 2;
    }
    const csf_observer_sim_params *tp = csf_observer_sim_params_get(truth);
    double t_true = log10(csf_observer_sim_threshold(truth, f, ecc));
    double beta_true = tp->slope, lapse_true = tp->lapse;
    csf_observer_sim_free(truth);

    int cov_t = 0, cov_b = 0, cov_cp = 0, n_cp = 0, fitted = 0;
    double sum_t = 0, sum_w = 0;
    clock_t c0 = clock();
    for (int s = 0; s < studies; s++) {
        /* each study a new participant: a new seed, so new answers */
        csf_observer_sim *o = NULL;
        if (csf_observer_sim_create(spec, 1000 + (uint64_t)s, &o, &e) != CSF_OK) return 1;
        csf_psy_level lv[LEVELS];
        uint64_t trial = 0;
        for (int i = 0; i < LEVELS; i++) {
            lv[i].x_log10 = t_true - 0.45 + 0.15 * i;
            lv[i].n = per_level;
            lv[i].k = 0;
            double c = pow(10.0, lv[i].x_log10);
            for (int j = 0; j < per_level; j++, trial++) {
                int target = (int)(trial & 1);
                double shown[2] = {0, 0}, rt;
                shown[target] = c;
                lv[i].k += csf_observer_sim_2afc(o, trial, f, ecc, shown, &rt) == target;
            }
            double lo, hi;
            csf_stats_clopper_pearson(lv[i].k, lv[i].n, 0.95, &lo, &hi);
            double p = 0.5 + (0.5 - lapse_true) * (1 - exp(-pow(10.0, beta_true * (lv[i].x_log10 - t_true))));
            cov_cp += lo <= p && p <= hi;
            n_cp++;
        }
        csf_observer_sim_free(o);
        csf_weibull_fit fit;
        if (csf_weibull_fit_ml(lv, LEVELS, 0.5, 0.06, &fit) != 0) continue;
        double tl, th, bl, bh;
        if (csf_weibull_bootstrap(lv, LEVELS, &fit, 0.06, boot, 77 + (uint64_t)s, 0.95, &tl, &th, &bl, &bh) < 2)
            continue;
        fitted++;
        sum_t += fit.t_log10 - t_true;
        sum_w += th - tl;
        cov_t += tl <= t_true && t_true <= th;
        cov_b += bl <= beta_true && beta_true <= bh;
    }
    double secs = (double)(clock() - c0) / CLOCKS_PER_SEC;
    printf("observer %s at %g cpd, %g deg: true t %.3f log10, beta %.2f, lapse %.3f\n", spec, f, ecc, t_true,
           beta_true, lapse_true);
    printf("%d studies x %d levels x %d trials, bootstrap %d (%.1f s CPU)\n", studies, LEVELS, per_level, boot, secs);
    printf("| interval | nominal | coverage | studies |\n|---|---|---|---|\n");
    printf("| threshold t, bootstrap percentile | 95 %% | %.1f %% | %d |\n", 100.0 * cov_t / fitted, fitted);
    printf("| slope beta, bootstrap percentile | 95 %% | %.1f %% | %d |\n", 100.0 * cov_b / fitted, fitted);
    printf("| P(correct) per level, Clopper-Pearson | >= 95 %% | %.1f %% | %d levels |\n", 100.0 * cov_cp / n_cp, n_cp);
    printf("mean t error %+.4f log10, mean t interval width %.3f log10\n", sum_t / fitted, sum_w / fitted);
    return 0;
}
