/* Data sets and our fits for the anchor cross-check (bench/anchors/check_psignifit.sh): studies of
 * several designs answered by the simulated observer (as bench/bench_study_coverage), each fitted
 * as `csfcal study report` does (studies/study_stats.h): ML Weibull (t, beta, lapse <= 0.06) and
 * its 95 % intervals (profile likelihood; marginal posterior with flat priors on t, log beta and
 * lapse, the report's interval).
 *
 *   usage: bench_anchor_data LEVELS.csv FITS.csv
 * LEVELS.csv: id,x_log10,n,k          (one row per level)
 * FITS.csv:   id,design,levels,trials,guess,t,beta,lapse,loglik,t_lo_profile,t_hi_profile,
 *             t_lo,t_hi,beta_lo,beta_hi  (marginal-posterior intervals) */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/observer_sim.h"
#include "studies/study_stats.h"
#include "../sim_study.h"

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: bench_anchor_data LEVELS.csv FITS.csv\n");
        return 2;
    }
    FILE *fl = fopen(argv[1], "w"), *ff = fopen(argv[2], "w");
    if (!fl || !ff) {
        perror("bench_anchor_data");
        return 1;
    }
    static const struct { const char *design; int levels, trials; } designs[] = {
        {"2afc", 6, 40}, {"2afc", 5, 20}, {"2afc", 8, 60}, {"yesno", 6, 40}};
    const double f = 2, ecc = 5;
    csf_error e;
    csf_observer_sim *o = NULL;
    if (csf_observer_sim_create("sim", 1, &o, &e) != CSF_OK) return 1;
    double t_true = log10(csf_observer_sim_threshold(o, f, ecc));
    csf_observer_sim_free(o);
    int id = 0;
    for (int d = 0; d < 4; d++)
        for (int rep = 0; rep < 5; rep++, id++) {
            int yesno = !strcmp(designs[d].design, "yesno"), nl = designs[d].levels, nt = designs[d].trials;
            if (csf_observer_sim_create("sim", 5000 + (uint64_t)id, &o, &e) != CSF_OK) return 1;
            csf_psy_level lv[8];
            uint64_t trial = 0;
            int fa = 0, n_catch = 0;
            sim_study_levels(o, &trial, f, ecc, t_true, nl, nt, yesno, nt / 3, lv, &fa, &n_catch);
            for (int i = 0; i < nl; i++) fprintf(fl, "%d,%.6f,%d,%d\n", id, lv[i].x_log10, lv[i].n, lv[i].k);
            csf_observer_sim_free(o);
            double guess = yesno ? fmin(0.5, fmax(0.001, (double)fa / n_catch)) : 0.5;
            csf_weibull_fit fit;
            double pl = NAN, ph = NAN, tl = NAN, th = NAN, bl = NAN, bh = NAN, x0, x1;
            if (csf_weibull_fit_ml(lv, (size_t)nl, guess, 0.06, &fit) != 0) continue;
            csf_weibull_profile_ci(lv, (size_t)nl, &fit, 0.06, 0.95, &pl, &ph, &x0, &x1);
            csf_weibull_marginal_ci(lv, (size_t)nl, &fit, 0.06, 0.95, &tl, &th, &bl, &bh);
            fprintf(ff, "%d,%d,%d,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", id, yesno, nl, nt,
                    guess, fit.t_log10, fit.beta, fit.lapse, fit.loglik, pl, ph, tl, th, bl, bh);
        }
    fclose(fl);
    return fclose(ff) == 0 ? 0 : 1;
}
