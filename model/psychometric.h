/* Psychometric functions for contrast detection, in x = log10 Michelson contrast (a Weibull):
 *
 *   P(x) = guess + (1 - guess - lapse) * F(x),   F(x) = 1 - exp(-10^(beta * (x - t)))
 *
 * t is the threshold in log10 contrast. 2AFC: guess = 0.5 (P(t) = 81.6 % with lapse 0); yes/no
 * detection: guess = the false-alarm rate. Used by the simulated observer (devices/observer_sim),
 * by the fade and 2AFC procedures, and by the joint Bayesian method (calib/method_bayes.c) for its
 * likelihood. All functions are pure (no state, no allocation) except the threshold grid below.
 *
 * Fade-in model (a grating whose log contrast rises over a ramp): the observer detects at the
 * first frame whose contrast crosses a latent threshold drawn once per trial from F. Equivalently
 * the per-frame hazard is h_k = 1 - S(x_k)/S(x_max_before), S = 1 - F, over the running maximum
 * of the contrast shown, so the probability of having detected by a frame equals F at the highest
 * contrast shown so far (frames that lost contrast add nothing). csf_psy_fade_hazard gives h_k. */
#ifndef CSF_PSYCHOMETRIC_H
#define CSF_PSYCHOMETRIC_H

#include <stddef.h>

typedef struct {
    double t_log10;   /* threshold, log10 Michelson contrast */
    double beta;      /* slope (per log10 unit); grating detection 3-3.5 */
    double guess;     /* gamma: 0.5 in 2AFC, false-alarm rate in yes/no */
    double lapse;     /* lambda: 0.01-0.04 */
} csf_weibull;

/* F(x): the core detection probability in [0,1] (no guess, no lapse). */
double csf_psy_core(double x_log10, double t_log10, double beta);

/* Full P(x) with guess and lapse. */
double csf_psy_p(const csf_weibull *w, double x_log10);
double csf_psy_p4(double x_log10, double t_log10, double beta, double guess, double lapse);

/* log P(response | x): response 1 = "yes"/correct, 0 = "no"/wrong. Never -inf: the probability
 * is clamped to [1e-12, 1 - 1e-12] so a single lapse cannot zero a posterior. */
double csf_psy_loglik(const csf_weibull *w, double x_log10, int response);

/* Inverse: the x at which P(x) = p. Returns NAN when p is outside (guess, 1 - lapse). */
double csf_psy_inverse(const csf_weibull *w, double p);

/* Fade-in hazard (see the model above): probability of detecting at a frame whose contrast is
 * x_now, given no detection while the running maximum of the contrast was x_prev_max (use
 * -INFINITY before the first frame). 0 when x_now <= x_prev_max. Lapse and guess are NOT in it:
 * the simulated observer adds lapses (missed stimulus) and false alarms as separate events. */
double csf_psy_fade_hazard(double x_prev_max, double x_now, double t_log10, double beta);

/* ---- One threshold, whatever the task (docs/observer-calibration.md) ----------------------------
 *
 * The table's threshold t is the contrast at which the person's sensitivity index d' reaches
 * CSF_PSY_DPRIME_CRITERION, d' = CSF_PSY_DPRIME_CRITERION * 10^(k (x - t)) (a power-law contrast
 * transducer, Legge & Foley 1980), and d' is the task-independent quantity of signal-detection
 * theory (Green & Swets 1966; Macmillan & Creelman 2005): the same person has the same d' in two
 * intervals, in four places and in yes/no. The criterion is the d' at which two-interval
 * P(correct) is 1 - e^-1/2 = 81.6 %, where the Weibull above puts its t, so a two-interval
 * table means what it meant before. Each task maps d' to its own probability:
 *   two intervals: the Weibull above (guess 1/2) with slope beta; a Weibull fitted to the
 *     SDT 2AFC function has beta = CSF_PSY_WEIBULL_PER_K * k (Pelli 1987; May & Solomon 2013,
 *     Theorem 2), and puts t within 0.01/k log10 of the d' criterion;
 *   m places (m >= 3): P = lapse' / m + (1 - lapse') Pc_m(d'), Pc_m the max rule's proportion
 *     correct (csf_psy_sdt_pc_mafc), k = beta / CSF_PSY_WEIBULL_PER_K, lapse' = lapse m / (m - 1)
 *     so the upper asymptote is 1 - lapse as in the Weibull. (A Weibull with guess 1/4 would put
 *     its t at d' = 1.58, 0.094 / k log10 above the two-interval one.) */

/* d' at the table's threshold: sqrt(2) Phi^-1(1 - e^-1 / 2). */
#define CSF_PSY_DPRIME_CRITERION 1.2734322744392470
/* Weibull slope of the SDT two-interval function per unit of transducer exponent (Pelli 1987). */
#define CSF_PSY_WEIBULL_PER_K 1.247

/* How tables state the definition (csflut metadata: appended to the method string, which older
 * readers show as text; docs/csflut.md). */
#define CSF_PSY_THRESHOLD_DEFINITION "threshold d'=1.2734 (2AFC 81.6%, SDT)"

/* P(correct) of the max rule in m-AFC (2 <= m <= 64) at d' (numeric integral, |error| < 1e-9). */
double csf_psy_sdt_pc_mafc(double dprime, int m);
/* P(correct) at log10 contrast x with m alternatives (m = 2: the Weibull with guess 1/2; m >= 3:
 * the SDT m-AFC function above, from a table built on first use, |error| < 1e-6), for the table's
 * threshold t, Weibull-equivalent slope beta and lapse. NAN for m outside 2-8. */
double csf_psy_p_afc(double x_log10, double t_log10, double beta, double lapse, int m);

/* ---- Threshold grid posterior (1-D, per cell): QUEST+/Psi style adaptive procedures ---------- */

/* A posterior over t_log10 on a fixed regular grid, slope/guess/lapse fixed. Storage is caller
 * owned or from csf_psy_grid_init (then free with csf_psy_grid_free). log_post is unnormalised. */
typedef struct {
    int n;
    double t_lo, t_step;   /* grid: t_i = t_lo + i * t_step */
    double *log_post;
    double beta, guess, lapse;
    int n_alt;             /* 0 (from init): the Weibull with guess; >= 3: csf_psy_p_afc with m = n_alt */
} csf_psy_grid;

/* Allocates an n-point grid over [t_lo, t_hi] with a Gaussian prior (mean, sd in log10; sd <= 0
 * or infinite = flat). Returns 0, or -1 on bad arguments / no memory. */
int csf_psy_grid_init(csf_psy_grid *g, int n, double t_lo, double t_hi, double prior_mean,
                      double prior_sd, double beta, double guess, double lapse);
void csf_psy_grid_free(csf_psy_grid *g);
/* P(yes/correct) at x for threshold t under the grid's model (its Weibull, or n_alt places). */
double csf_psy_grid_p(const csf_psy_grid *g, double x_log10, double t_log10);
/* Bayes update with one trial. */
void csf_psy_grid_update(csf_psy_grid *g, double x_log10, int response);
/* Posterior mean and sd of t_log10. */
void csf_psy_grid_moments(const csf_psy_grid *g, double *mean, double *sd);
/* Posterior probability that t_log10 > t_cut (e.g. the contrast ceiling: "not visible"). */
double csf_psy_grid_prob_above(const csf_psy_grid *g, double t_cut);
/* Expected posterior entropy after a trial at x (Psi method, Kontsevich & Tyler 1999). */
double csf_psy_grid_expected_entropy(const csf_psy_grid *g, double x_log10);
/* x among n_x candidates on [x_lo, x_hi] minimising expected entropy. */
double csf_psy_grid_best_x(const csf_psy_grid *g, double x_lo, double x_hi, int n_x);

/* ---- Maximum-likelihood fit of t for fixed slope/guess/lapse ----------------------------------- */

typedef struct {
    double x_log10;
    int response;      /* 1 yes/correct, 0 no/wrong */
} csf_psy_obs;

/* ML estimate of t over [t_lo, t_hi] (grid + golden refinement) and its standard error from the
 * observed Fisher information (NAN when the data are flat, e.g. all one response).
 * Returns 0, -1 on bad arguments (n < 1). */
int csf_psy_fit_t(const csf_psy_obs *obs, size_t n, double beta, double guess, double lapse,
                  double t_lo, double t_hi, double *t_hat, double *se_log10);

#endif
