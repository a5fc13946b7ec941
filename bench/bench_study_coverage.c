/* Coverage of the study report's intervals (nominal 95 %): many simulated
 * studies of one design, each analysed as `csfcal study report` does (studies/study_report.c ->
 * studies/study_stats.h), counting how often each interval holds the simulated observer's truth.
 *
 * Design (after examples/studies/contrast_2afc and yes_no: one curve): LEVELS fixed contrasts
 * 0.15 log10 apart around the threshold (from t - 0.45), N trials each. Answers come from the
 * simulated observer (model/observer_sim.h; slope 3.5, lapse 0.02 by default) at 2 cpd and
 * 5 deg, where its true threshold is t:
 *   2afc:  csf_observer_sim_2afc (its Weibull with guess 1/2 and lapse);
 *   yesno: its fade-in model fed a constant contrast for 0.3 s then 1.5 s of blank at 60 Hz, as
 *          `csfcal study run` does; a quarter of the trials are catch trials (nothing shown), and
 *          the fit's guess rate is their false-alarm rate, as in the report. Its P(yes) is then
 *          a Weibull with the same t, guess = the spontaneous press rate and lapse * (1 - guess).
 * Per study: ML Weibull fit (t, beta, lapse <= 0.06) and three 95 % intervals: the
 * marginal-posterior interval under flat priors (what the report gives), the profile-likelihood
 * interval, and the B-sample parametric-bootstrap percentile interval (what it gave before); and the exact Clopper-Pearson interval of each
 * level's proportion against the observer's probability there. Coverage is printed with its
 * binomial standard error sqrt(p (1 - p) / n) and the exact 95 % interval of the rate.
 *
 *   usage: bench_study_coverage [STUDIES=200] [TRIALS_PER_LEVEL=40] [BOOT=200] [LEVELS=6]
 *                               [DESIGN=2afc|yesno] [OBSERVER_SPEC=sim]
 * BOOT = 0 skips the bootstrap (the profile interval alone is fast). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/observer_sim.h"
#include "studies/study_stats.h"
#include "sim_study.h"

#define MAX_LEVELS 32

typedef struct {
    int hit, n;
    double width;
} tally;

static void add(tally *t, double lo, double hi, double truth)
{
    if (!isfinite(lo) || !isfinite(hi)) return;
    t->n++;
    t->hit += lo <= truth && truth <= hi;
    t->width += hi - lo;
}

static void row(const char *name, const tally *t, const char *unit)
{
    if (!t->n) return;
    double p = (double)t->hit / t->n, lo, hi;
    csf_stats_clopper_pearson(t->hit, t->n, 0.95, &lo, &hi);
    printf("| %s | 95 %% | %.1f %% ± %.1f | [%.1f, %.1f] %% | %d | %.3f %s |\n", name, 100 * p,
           100 * sqrt(p * (1 - p) / t->n), 100 * lo, 100 * hi, t->n, t->width / t->n, unit);
}

int main(int argc, char **argv)
{
    int studies = argc > 1 ? atoi(argv[1]) : 200;
    int per_level = argc > 2 ? atoi(argv[2]) : 40;
    int boot = argc > 3 ? atoi(argv[3]) : 200;
    int levels = argc > 4 ? atoi(argv[4]) : 6;
    const char *design = argc > 5 ? argv[5] : "2afc";
    const char *spec = argc > 6 ? argv[6] : "sim";
    int yesno = !strcmp(design, "yesno");
    if (studies < 1 || per_level < 1 || (boot != 0 && boot < 2) || levels < 3 || levels > MAX_LEVELS ||
        (!yesno && strcmp(design, "2afc"))) {
        fprintf(stderr, "usage: bench_study_coverage [STUDIES] [TRIALS_PER_LEVEL] [BOOT (0 or >= 2)] "
                        "[LEVELS 3-%d] [2afc|yesno] [OBSERVER_SPEC]\n", MAX_LEVELS);
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
    /* yes/no: a press before or without a detection (false alarm or anticipation) is the guess */
    double spont = 1 - (1 - tp->fa) * (1 - tp->anticip);
    double guess_true = yesno ? spont : 0.5, lapse_eff = yesno ? lapse_true * (1 - spont) : lapse_true;
    csf_observer_sim_free(truth);
    /* yes/no: catch trials are a quarter of all (catch_fraction = 0.25), per level as the report
     * pools them into one false-alarm rate per curve */
    int catch_per_level = yesno ? per_level / 3 : 0;

    tally prof_t = {0}, prof_b = {0}, mg_t = {0}, mg_b = {0}, pct_t = {0}, pct_b = {0}, cp = {0};
    int fitted = 0, lapse_at_0 = 0, lapse_at_max = 0;
    double sum_t = 0, sum_b = 0;
    clock_t c0 = clock();
    for (int s = 0; s < studies; s++) {
        /* each study a new participant: a new seed, so new answers */
        csf_observer_sim *o = NULL;
        if (csf_observer_sim_create(spec, 1000 + (uint64_t)s, &o, &e) != CSF_OK) return 1;
        csf_psy_level lv[MAX_LEVELS];
        uint64_t trial = 0;
        int fa = 0, n_catch = 0;
        sim_study_levels(o, &trial, f, ecc, t_true, levels, per_level, yesno, catch_per_level, lv, &fa, &n_catch);
        for (int i = 0; i < levels; i++) {
            double lo, hi;
            csf_stats_clopper_pearson(lv[i].k, lv[i].n, 0.95, &lo, &hi);
            double p = guess_true + (1 - guess_true - lapse_eff) *
                                        (1 - exp(-pow(10.0, beta_true * (lv[i].x_log10 - t_true))));
            add(&cp, lo, hi, p);
        }
        csf_observer_sim_free(o);
        double guess = 0.5;
        if (yesno) guess = fmin(0.5, fmax(0.001, (double)fa / n_catch)); /* as studies/study_report.c */
        csf_weibull_fit fit;
        if (csf_weibull_fit_ml(lv, (size_t)levels, guess, 0.06, &fit) != 0) continue;
        fitted++;
        sum_t += fit.t_log10 - t_true;
        sum_b += fit.beta;
        lapse_at_0 += fit.lapse < 1e-4;
        lapse_at_max += fit.lapse > 0.06 - 1e-4;
        double tl, th, bl, bh;
        if (csf_weibull_profile_ci(lv, (size_t)levels, &fit, 0.06, 0.95, &tl, &th, &bl, &bh) >= 0) {
            add(&prof_t, tl, th, t_true);
            add(&prof_b, bl, bh, beta_true);
        }
        if (csf_weibull_marginal_ci(lv, (size_t)levels, &fit, 0.06, 0.95, &tl, &th, &bl, &bh) >= 0) {
            add(&mg_t, tl, th, t_true);
            add(&mg_b, bl, bh, beta_true);
        }
        if (boot && csf_weibull_bootstrap(lv, (size_t)levels, &fit, 0.06, boot, 77 + (uint64_t)s, 0.95, &tl, &th,
                                          &bl, &bh) >= 2) {
            add(&pct_t, tl, th, t_true);
            add(&pct_b, bl, bh, beta_true);
        }
    }
    double secs = (double)(clock() - c0) / CLOCKS_PER_SEC;
    printf("observer %s at %g cpd, %g deg: true t %.3f log10, beta %.2f, lapse %.3f; %s", spec, f, ecc, t_true,
           beta_true, lapse_true, yesno ? "yes/no" : "2afc");
    if (yesno) printf(" (guess %.4f, effective lapse %.4f; %d catch trials per level)", guess_true, lapse_eff,
                      catch_per_level);
    printf("\n%d studies x %d levels x %d trials, bootstrap %d (%.1f s CPU)\n", studies, levels, per_level, boot,
           secs);
    printf("| interval | nominal | coverage ± s.e. | exact 95 %% CI of the rate | intervals | mean width |\n"
           "|---|---|---|---|---|---|\n");
    row("threshold t, profile likelihood", &prof_t, "log10");
    row("threshold t, marginal posterior", &mg_t, "log10");
    row("threshold t, bootstrap percentile", &pct_t, "log10");
    row("slope beta, profile likelihood", &prof_b, "");
    row("slope beta, marginal posterior", &mg_b, "");
    row("slope beta, bootstrap percentile", &pct_b, "");
    row("P(correct) per level, Clopper-Pearson", &cp, "");
    printf("mean t error %+.4f log10; mean fitted beta %.2f (true %.2f); lapse fitted at 0 in %d, at 0.06 in %d "
           "of %d\n", sum_t / fitted, sum_b / fitted, beta_true, lapse_at_0, lapse_at_max, fitted);
    return 0;
}
