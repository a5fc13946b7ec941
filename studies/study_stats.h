/* Statistics for user studies (studies/study_report.c): exact binomial intervals and tests,
 * signal-detection d' for yes/no and same/different designs, and a maximum-likelihood Weibull fit
 * with lapse and its parametric bootstrap. Pure functions of their arguments (the bootstrap draws
 * from core/rng.h with a caller's seed), no allocation beyond what is documented.
 *
 * Psychometric function (the Weibull of model/psychometric.h, x = log10 Michelson contrast):
 *   P(x) = guess + (1 - guess - lapse) (1 - exp(-10^(beta (x - t))))
 * guess is fixed by the design (0.5 in 2AFC/2IFC; in yes/no the false-alarm rate measured on
 * catch trials); t, beta and lapse are fitted. */
#ifndef CSF_STUDY_STATS_H
#define CSF_STUDY_STATS_H

#include <stddef.h>
#include <stdint.h>

/* Standard normal CDF and its inverse (|error| < 1e-9 over (1e-300, 1 - 1e-16)). */
double csf_stats_norm_cdf(double z);
double csf_stats_norm_quantile(double p);

/* Regularised incomplete beta I_x(a, b), a, b > 0, x in [0, 1]. */
double csf_stats_betainc(double a, double b, double x);

/* Exact (Clopper-Pearson) two-sided interval for k successes in n trials at confidence conf
 * (e.g. 0.95): lo = 0 when k = 0, hi = 1 when k = n. n = 0 gives [0, 1]. */
void csf_stats_clopper_pearson(int k, int n, double conf, double *lo, double *hi);

/* Exact binomial test of k successes in n against p0: one-sided P(X >= k) ("better than chance")
 * and two-sided (sum of the probabilities no larger than P(X = k)). */
double csf_stats_binom_p_greater(int k, int n, double p0);
double csf_stats_binom_p_two_sided(int k, int n, double p0);

/* Hits against false alarms, the test of a yes/no or same/different design (a person who says
 * "yes" often has many hits and as many false alarms: testing hits alone against 0.5 would call a
 * guesser able to see). Fisher's exact test of the 2x2 table (hits, misses; false alarms, correct
 * rejections), conditional on the margins: one-sided P(hits >= observed | no difference) and
 * two-sided (the sum of the tables no more probable than the one observed, as R's fisher.test).
 * At most the nominal false-positive rate at any response bias. 1 when either row is empty. */
double csf_stats_fisher_greater(int hits, int n_signal, int false_alarms, int n_noise);
double csf_stats_fisher_two_sided(int hits, int n_signal, int false_alarms, int n_noise);

/* Interval for a yes/no d' at confidence conf from the rates (corrected as for d') and the trial
 * counts: d' +- z * sqrt(h(1-h) / (n_signal phi(z(h))^2) + f(1-f) / (n_noise phi(z(f))^2))
 * (Gourevitch & Galanter 1967; Macmillan & Creelman 2005, ch. 13). NaN where d' is. */
void csf_stats_dprime_yesno_ci(double h, double f, int n_signal, int n_noise, double conf, double *lo,
                               double *hi);

/* d' from hit rate h and false-alarm rate f. Rates of 0 or 1 must be corrected by the caller
 * (the report uses the 1/(2N) rule); NaN for rates outside (0, 1).
 *   yes/no:            d' = z(h) - z(f)
 *   same/different, differencing model (roving designs; Macmillan & Creelman 2005, ch. 9):
 *     f = 2 Phi(-k / sqrt 2), h = Phi((d' - k)/sqrt 2) + Phi((-d' - k)/sqrt 2), solved for d'
 *   same/different, independent-observation model (fixed designs):
 *     p_max = Phi((z(h) - z(f)) / 2),  d' = 2 z(0.5 (1 + sqrt(2 p_max - 1)))
 * Same/different: NaN when h <= f; the report then gives the d' of the swapped rates with its
 * sign flipped (0 when h = f), so a negative d' means the same in every design: more "yes" or
 * "different" answers without a signal than with one (yes/no's z(h) - z(f) is already so). */
double csf_stats_dprime_yesno(double h, double f);
double csf_stats_dprime_sd_differencing(double h, double f);
double csf_stats_dprime_sd_independent(double h, double f);

/* Interval for a same/different d' at confidence conf, from the corrected rates and the trial
 * counts, in the report's signed reading (negative: the swapped rates' d', negated).
 *   differencing model: the profile-likelihood interval (Cox & Hinkley 1974, ch. 9): the signed
 *     d' values whose likelihood, maximised over the criterion k, is within z^2/2 of the maximum
 *     (1.92 at 95 %). Near d' = 0 the hit rate moves with d'^2, so a delta-method (Wald)
 *     interval there is as wide as the slope is flat; the likelihood's own interval is not.
 *     An end that does not reach the cutoff is +-CSF_SD_DPRIME_LIMIT.
 *   independent-observation model: its d' is a monotone function of z(h) - z(f), so the ends are
 *     that function of the ends of the yes/no interval of z(h) - z(f) (Gourevitch & Galanter
 *     1967), negative ends read through the sign convention.
 * NaN for rates outside (0, 1) or empty counts. */
#define CSF_SD_DPRIME_LIMIT 10.0
void csf_stats_dprime_sd_ci(double h, double f, int n_signal, int n_noise, int differencing, double conf,
                            double *lo, double *hi);

/* ---- Weibull fit --------------------------------------------------------------------------- */

typedef struct {
    double x_log10;  /* level */
    int n, k;        /* trials, successes ("correct" or "yes") */
} csf_psy_level;

typedef struct {
    double t_log10, beta, lapse, guess;
    double loglik;
    int converged;
} csf_weibull_fit;

/* Limits of the fit (the parameters a study can identify): beta in [0.5, 20], lapse in
 * [0, max_lapse] (0.06 by default in the report), t within the data's range +- 1 log10. */
#define CSF_FIT_BETA_MIN 0.5
#define CSF_FIT_BETA_MAX 20.0

/* ML fit of t, beta and lapse (guess fixed) to binomial data at n_levels levels: a grid over t
 * (the data's range +- 1 log10), beta and lapse finds the global peak's basin, and Nelder-Mead on
 * a bounded reparameterisation, started there and from a few other points, polishes it. Returns 0, or -1 when
 * there is nothing to fit (no trials, or fewer than 2 distinct levels). */
int csf_weibull_fit_ml(const csf_psy_level *lv, size_t n_levels, double guess, double max_lapse,
                       csf_weibull_fit *out);

/* Parametric bootstrap: n_boot data sets drawn from fit at the same levels and trial counts,
 * each refitted; percentile intervals (conf, e.g. 0.95) for t and beta. Returns the number of
 * refits that succeeded. */
int csf_weibull_bootstrap(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit,
                          double max_lapse, int n_boot, uint64_t seed, double conf,
                          double *t_lo, double *t_hi, double *beta_lo, double *beta_hi);

/* Profile-likelihood intervals for t and beta: the values whose likelihood, maximised over the two
 * other parameters, is within z^2/2 of the maximum (z the normal quantile at (1 + conf)/2; 1.92
 * log-likelihood units at 95 %), i.e. a likelihood-ratio test inverted (Cox & Hinkley 1974,
 * ch. 9; Venzon & Moolgavkar 1988). An end that does not reach the cutoff inside the fit's
 * limits (t within the data's range +- 1 log10, beta in [0.5, 20]) is that limit. Returns 0 (or
 * 1-2: a profile point beat the fit and the intervals are around the better maximum), or -1. */
int csf_weibull_profile_ci(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit, double max_lapse,
                           double conf, double *t_lo, double *t_hi, double *beta_lo, double *beta_hi);

/* Marginal-posterior (credible) intervals for t and beta, the report's intervals: the posterior
 * under flat priors on t (within the data's range +- 1 log10), on the width 1/beta (beta in
 * [0.5, 20]; psignifit 4's default width prior is flat too) and on the lapse (over [0,
 * max_lapse]), summed on a grid over the other parameters, and its (1 - conf)/2 and
 * (1 + conf)/2 quantiles: the interval psignifit 4 gives (Schuett, Harmeling, Macke & Wichmann
 * 2016, Vision Res. 122:105-123); with the same priors and limits it matches psignifit's to a few
 * thousandths of a log unit (bench/anchors/). Integrating over the slope, instead of maximising
 * (profile likelihood) or plugging in the fit (parametric bootstrap), keeps the threshold interval
 * near its nominal coverage although the ML slope of a small study is biased steep (Wichmann &
 * Hill 2001a); a prior flat in log beta gave 92 % at 6 levels x 40 trials, flat in width 94 %
 * (BENCHMARKS.md, bench/bench_study_coverage). Returns 0, or -1 on bad arguments or no memory. */
int csf_weibull_marginal_ci(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit, double max_lapse,
                            double conf, double *t_lo, double *t_hi, double *beta_lo, double *beta_hi);

#endif
