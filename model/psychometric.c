/* Weibull psychometric function in log10 contrast, likelihoods, a 1-D threshold grid posterior
 * and a maximum-likelihood threshold fit. See psychometric.h for the model. */
#include "model/psychometric.h"

#include <math.h>
#include <stdlib.h>

#define P_FLOOR 1e-12

double csf_psy_core(double x_log10, double t_log10, double beta)
{
    if (isnan(x_log10) || isnan(t_log10)) return 0.0;
    if (x_log10 == -INFINITY || t_log10 == INFINITY) return 0.0;
    double e = beta * (x_log10 - t_log10);
    if (e > 3.0) return 1.0; /* 10^3 in the exponent: exp(-1000) is 0 in double */
    /* -expm1(-y) keeps precision for tiny y far below threshold. */
    return -expm1(-pow(10.0, e));
}

double csf_psy_p4(double x_log10, double t_log10, double beta, double guess, double lapse)
{
    return guess + (1.0 - guess - lapse) * csf_psy_core(x_log10, t_log10, beta);
}

double csf_psy_p(const csf_weibull *w, double x_log10)
{
    return csf_psy_p4(x_log10, w->t_log10, w->beta, w->guess, w->lapse);
}

static double clamp_p(double p)
{
    if (!(p > P_FLOOR)) return P_FLOOR;
    if (p > 1.0 - P_FLOOR) return 1.0 - P_FLOOR;
    return p;
}

double csf_psy_loglik(const csf_weibull *w, double x_log10, int response)
{
    double p = clamp_p(csf_psy_p(w, x_log10));
    return response ? log(p) : log1p(-p);
}

double csf_psy_inverse(const csf_weibull *w, double p)
{
    double span = 1.0 - w->guess - w->lapse;
    if (!(span > 0) || !(p > w->guess) || !(p < 1.0 - w->lapse)) return NAN;
    double f = (p - w->guess) / span;           /* F(x) */
    double y = -log1p(-f);                      /* 10^(beta (x - t)) */
    return w->t_log10 + log10(y) / w->beta;
}

double csf_psy_fade_hazard(double x_prev_max, double x_now, double t_log10, double beta)
{
    if (!(x_now > x_prev_max)) return 0.0;
    /* log survival: log S(x) = -10^(beta (x - t)); hazard = 1 - S(now)/S(prev). */
    double ls_now = (x_now == -INFINITY) ? 0.0 : -pow(10.0, fmin(beta * (x_now - t_log10), 300.0));
    double ls_prev = (x_prev_max == -INFINITY) ? 0.0 : -pow(10.0, fmin(beta * (x_prev_max - t_log10), 300.0));
    double h = -expm1(ls_now - ls_prev);
    if (h < 0) h = 0;
    if (h > 1) h = 1;
    return h;
}

/* ---- task-independent threshold -------------------------------------------------------------- */

static double std_phi(double x) { return exp(-0.5 * x * x) / sqrt(2.0 * M_PI); }
static double std_Phi(double x) { return 0.5 * erfc(-x / sqrt(2.0)); }

/* Composite Simpson over [min(-9, d-9), max(9, d+9)]: the integrand is smooth and outside that
 * range below 1e-18, so 2000 panels are far inside 1e-9. */
double csf_psy_sdt_pc_mafc(double dprime, int m)
{
    if (m < 2 || m > 64 || isnan(dprime)) return NAN;
    if (dprime > 40) return 1.0;
    double lo = fmin(-9.0, dprime - 9.0), hi = fmax(9.0, dprime + 9.0);
    const int n = 2000;
    double h = (hi - lo) / n, s = 0;
    for (int i = 0; i <= n; i++) {
        double x = lo + i * h;
        double w = (i == 0 || i == n) ? 1 : (i & 1) ? 4 : 2;
        s += w * std_phi(x - dprime) * pow(std_Phi(x), m - 1);
    }
    double p = s * h / 3;
    return p > 1 ? 1 : p;
}

/* Pc_m(d') on d' in [0, AFC_TAB_DMAX], built on first use per m (methods call it per grid node
 * and trial; the integral costs 2000 evaluations). Linear interpolation: |Pc''| < 0.5, so the
 * error is below 0.5 * h^2 / 8 = 1e-6. Not thread-safe on first use; nothing here runs threads. */
#define AFC_TAB_N 4001
#define AFC_TAB_DMAX 12.0
#define AFC_TAB_MMAX 8
static double afc_tab[AFC_TAB_MMAX + 1][AFC_TAB_N];
static int afc_tab_ready[AFC_TAB_MMAX + 1];

static double sdt_pc_fast(double dprime, int m)
{
    if (!afc_tab_ready[m]) {
        for (int i = 0; i < AFC_TAB_N; i++)
            afc_tab[m][i] = csf_psy_sdt_pc_mafc(AFC_TAB_DMAX * i / (AFC_TAB_N - 1), m);
        afc_tab_ready[m] = 1;
    }
    if (!(dprime > 0)) return afc_tab[m][0];
    double u = dprime / AFC_TAB_DMAX * (AFC_TAB_N - 1);
    if (u >= AFC_TAB_N - 1) return afc_tab[m][AFC_TAB_N - 1];
    int i = (int)u;
    double a = u - i;
    return afc_tab[m][i] * (1 - a) + afc_tab[m][i + 1] * a;
}

double csf_psy_p_afc(double x_log10, double t_log10, double beta, double lapse, int m)
{
    if (m == 2) return csf_psy_p4(x_log10, t_log10, beta, 0.5, lapse);
    if (m < 3 || m > AFC_TAB_MMAX || isnan(x_log10) || isnan(t_log10)) return NAN;
    double l = lapse * m / (m - 1.0);
    if (l > 1) l = 1;
    double d = 0;
    if (x_log10 != -INFINITY && t_log10 != INFINITY) {
        double e = beta / CSF_PSY_WEIBULL_PER_K * (x_log10 - t_log10);
        d = e > 2.0 ? AFC_TAB_DMAX : CSF_PSY_DPRIME_CRITERION * pow(10.0, e);
    }
    return l / m + (1 - l) * sdt_pc_fast(d, m);
}

/* The grid's P: the Weibull with its guess, or the m-place function. */
double csf_psy_grid_p(const csf_psy_grid *g, double x_log10, double t_log10)
{
    if (g->n_alt >= 3) return csf_psy_p_afc(x_log10, t_log10, g->beta, g->lapse, g->n_alt);
    return csf_psy_p4(x_log10, t_log10, g->beta, g->guess, g->lapse);
}

/* ---- grid posterior ------------------------------------------------------------------------- */

int csf_psy_grid_init(csf_psy_grid *g, int n, double t_lo, double t_hi, double prior_mean,
                      double prior_sd, double beta, double guess, double lapse)
{
    if (!g || n < 2 || n > 100000 || !(t_hi > t_lo) || !isfinite(t_lo) || !isfinite(t_hi) ||
        !(beta > 0) || !(guess >= 0) || !(lapse >= 0) || !(guess + lapse < 1))
        return -1;
    g->log_post = malloc((size_t)n * sizeof *g->log_post);
    if (!g->log_post) return -1;
    g->n = n;
    g->t_lo = t_lo;
    g->t_step = (t_hi - t_lo) / (n - 1);
    g->beta = beta;
    g->guess = guess;
    g->lapse = lapse;
    g->n_alt = 0;
    int flat = !(prior_sd > 0) || !isfinite(prior_sd) || !isfinite(prior_mean);
    for (int i = 0; i < n; i++) {
        double t = t_lo + i * g->t_step;
        double z = flat ? 0.0 : (t - prior_mean) / prior_sd;
        g->log_post[i] = -0.5 * z * z;
    }
    return 0;
}

void csf_psy_grid_free(csf_psy_grid *g)
{
    if (!g) return;
    free(g->log_post);
    g->log_post = NULL;
    g->n = 0;
}

void csf_psy_grid_update(csf_psy_grid *g, double x_log10, int response)
{
    double mx = -INFINITY;
    for (int i = 0; i < g->n; i++) {
        double p = clamp_p(csf_psy_grid_p(g, x_log10, g->t_lo + i * g->t_step));
        g->log_post[i] += response ? log(p) : log1p(-p);
        if (g->log_post[i] > mx) mx = g->log_post[i];
    }
    /* Renormalise the log scale so repeated updates never underflow. */
    for (int i = 0; i < g->n; i++) g->log_post[i] -= mx;
}

/* Normalised posterior weights into w (n values); returns the max log posterior. */
static void grid_weights(const csf_psy_grid *g, double *w)
{
    double mx = -INFINITY, s = 0;
    for (int i = 0; i < g->n; i++)
        if (g->log_post[i] > mx) mx = g->log_post[i];
    for (int i = 0; i < g->n; i++) {
        w[i] = exp(g->log_post[i] - mx);
        s += w[i];
    }
    for (int i = 0; i < g->n; i++) w[i] /= s;
}

void csf_psy_grid_moments(const csf_psy_grid *g, double *mean, double *sd)
{
    double mx = -INFINITY;
    for (int i = 0; i < g->n; i++)
        if (g->log_post[i] > mx) mx = g->log_post[i];
    double s = 0, s1 = 0, s2 = 0;
    for (int i = 0; i < g->n; i++) {
        double w = exp(g->log_post[i] - mx), t = g->t_lo + i * g->t_step;
        s += w;
        s1 += w * t;
        s2 += w * t * t;
    }
    double m = s1 / s, v = s2 / s - m * m;
    if (mean) *mean = m;
    if (sd) *sd = sqrt(v > 0 ? v : 0);
}

double csf_psy_grid_prob_above(const csf_psy_grid *g, double t_cut)
{
    double mx = -INFINITY;
    for (int i = 0; i < g->n; i++)
        if (g->log_post[i] > mx) mx = g->log_post[i];
    double s = 0, a = 0;
    for (int i = 0; i < g->n; i++) {
        double w = exp(g->log_post[i] - mx);
        s += w;
        if (g->t_lo + i * g->t_step > t_cut) a += w;
    }
    return a / s;
}

static double entropy_of(const double *w, int n)
{
    double h = 0;
    for (int i = 0; i < n; i++)
        if (w[i] > 0) h -= w[i] * log(w[i]);
    return h;
}

double csf_psy_grid_expected_entropy(const csf_psy_grid *g, double x_log10)
{
    int n = g->n;
    double *w = malloc((size_t)n * 3 * sizeof *w);
    if (!w) return INFINITY;
    double *w1 = w + n, *w0 = w + 2 * n;
    grid_weights(g, w);
    double p1 = 0;
    for (int i = 0; i < n; i++) {
        double p = clamp_p(csf_psy_grid_p(g, x_log10, g->t_lo + i * g->t_step));
        w1[i] = w[i] * p;
        w0[i] = w[i] * (1 - p);
        p1 += w1[i];
    }
    double p0 = 1 - p1;
    for (int i = 0; i < n; i++) {
        w1[i] /= p1;
        w0[i] /= p0;
    }
    double h = p1 * entropy_of(w1, n) + p0 * entropy_of(w0, n);
    free(w);
    return h;
}

double csf_psy_grid_best_x(const csf_psy_grid *g, double x_lo, double x_hi, int n_x)
{
    if (n_x < 2) return x_lo;
    double best = x_lo, best_h = INFINITY;
    for (int k = 0; k < n_x; k++) {
        double x = x_lo + (x_hi - x_lo) * k / (n_x - 1);
        double h = csf_psy_grid_expected_entropy(g, x);
        if (h < best_h - 1e-12) {
            best_h = h;
            best = x;
        }
    }
    return best;
}

/* ---- ML fit ---------------------------------------------------------------------------------- */

static double total_loglik(const csf_psy_obs *obs, size_t n, double t, double beta, double guess,
                           double lapse)
{
    csf_weibull w = {t, beta, guess, lapse};
    double s = 0;
    for (size_t i = 0; i < n; i++) s += csf_psy_loglik(&w, obs[i].x_log10, obs[i].response);
    return s;
}

int csf_psy_fit_t(const csf_psy_obs *obs, size_t n, double beta, double guess, double lapse,
                  double t_lo, double t_hi, double *t_hat, double *se_log10)
{
    if (!obs || n < 1 || !(t_hi > t_lo) || !(beta > 0)) return -1;
    const int n_grid = 121;
    double step = (t_hi - t_lo) / (n_grid - 1), best_t = t_lo, best_l = -INFINITY;
    for (int i = 0; i < n_grid; i++) {
        double t = t_lo + i * step, l = total_loglik(obs, n, t, beta, guess, lapse);
        if (l > best_l) {
            best_l = l;
            best_t = t;
        }
    }
    /* Golden-section refinement in the bracket around the best grid point. */
    double a = fmax(t_lo, best_t - step), b = fmin(t_hi, best_t + step);
    const double gr = 0.6180339887498949;
    double c = b - gr * (b - a), d = a + gr * (b - a);
    double fc = total_loglik(obs, n, c, beta, guess, lapse), fd = total_loglik(obs, n, d, beta, guess, lapse);
    for (int it = 0; it < 40; it++) {
        if (fc > fd) {
            b = d; d = c; fd = fc;
            c = b - gr * (b - a);
            fc = total_loglik(obs, n, c, beta, guess, lapse);
        } else {
            a = c; c = d; fc = fd;
            d = a + gr * (b - a);
            fd = total_loglik(obs, n, d, beta, guess, lapse);
        }
    }
    double t = 0.5 * (a + b);
    if (total_loglik(obs, n, t, beta, guess, lapse) < best_l) t = best_t;
    *t_hat = t;
    if (se_log10) {
        double h = 0.01;
        double l0 = total_loglik(obs, n, t, beta, guess, lapse);
        double lp = total_loglik(obs, n, t + h, beta, guess, lapse);
        double lm = total_loglik(obs, n, t - h, beta, guess, lapse);
        double curv = -(lp - 2 * l0 + lm) / (h * h);
        *se_log10 = (curv > 1e-9 && t > t_lo + step && t < t_hi - step) ? 1.0 / sqrt(curv) : NAN;
    }
    return 0;
}
