/* Statistics for user studies (see study_stats.h). */
#include "studies/study_stats.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

double csf_stats_norm_cdf(double z)
{
    return 0.5 * erfc(-z / sqrt(2.0));
}

/* Acklam's rational approximation, then one Halley step on erfc (full double precision). */
double csf_stats_norm_quantile(double p)
{
    if (!(p > 0) || !(p < 1)) return p == 0 ? -INFINITY : p == 1 ? INFINITY : NAN;
    static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                               1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                               6.680131188771972e+01, -1.328068155288572e+01};
    static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                               -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
    static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                               3.754408661907416e+00};
    double q, x;
    if (p < 0.02425) {
        q = sqrt(-2 * log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    } else if (p > 1 - 0.02425) {
        q = sqrt(-2 * log1p(-p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    } else {
        q = p - 0.5;
        double r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
    }
    double e = csf_stats_norm_cdf(x) - p;
    double u = e * sqrt(2 * M_PI) * exp(x * x / 2);
    return x - u / (1 + x * u / 2);
}

/* Continued fraction for I_x(a, b) (modified Lentz), valid for x < (a + 1)/(a + b + 2). */
static double betacf(double a, double b, double x)
{
    const double tiny = 1e-300;
    double c = 1, d = 1 - (a + b) * x / (a + 1);
    if (fabs(d) < tiny) d = tiny;
    d = 1 / d;
    double h = d;
    for (int m = 1; m <= 1000; m++) {
        double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((a + m2 - 1) * (a + m2));
        d = 1 + aa * d;
        if (fabs(d) < tiny) d = tiny;
        c = 1 + aa / c;
        if (fabs(c) < tiny) c = tiny;
        d = 1 / d;
        h *= d * c;
        aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1));
        d = 1 + aa * d;
        if (fabs(d) < tiny) d = tiny;
        c = 1 + aa / c;
        if (fabs(c) < tiny) c = tiny;
        d = 1 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1) < 1e-15) break;
    }
    return h;
}

double csf_stats_betainc(double a, double b, double x)
{
    if (x <= 0) return 0;
    if (x >= 1) return 1;
    double lbt = lgamma(a + b) - lgamma(a) - lgamma(b) + a * log(x) + b * log1p(-x);
    if (x < (a + 1) / (a + b + 2)) return exp(lbt) * betacf(a, b, x) / a;
    return 1 - exp(lbt) * betacf(b, a, 1 - x) / b;
}

/* x with I_x(a, b) = p, by bisection (monotone; 200 halvings reach double precision). */
static double beta_quantile(double a, double b, double p)
{
    double lo = 0, hi = 1;
    for (int i = 0; i < 200 && hi - lo > 1e-16; i++) {
        double mid = 0.5 * (lo + hi);
        if (csf_stats_betainc(a, b, mid) < p) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

void csf_stats_clopper_pearson(int k, int n, double conf, double *lo, double *hi)
{
    double alpha = 1 - conf;
    if (n <= 0 || k < 0 || k > n) {
        *lo = 0;
        *hi = 1;
        return;
    }
    *lo = k == 0 ? 0 : beta_quantile(k, n - k + 1, alpha / 2);
    *hi = k == n ? 1 : beta_quantile(k + 1, n - k, 1 - alpha / 2);
}

static double binom_logpmf(int k, int n, double p)
{
    if (p <= 0) return k == 0 ? 0 : -INFINITY;
    if (p >= 1) return k == n ? 0 : -INFINITY;
    return lgamma(n + 1.0) - lgamma(k + 1.0) - lgamma(n - k + 1.0) + k * log(p) + (n - k) * log1p(-p);
}

double csf_stats_binom_p_greater(int k, int n, double p0)
{
    if (n <= 0 || k <= 0) return 1;
    if (k > n) return 0;
    /* P(X >= k) = I_p0(k, n - k + 1) */
    return csf_stats_betainc(k, n - k + 1, p0);
}

double csf_stats_binom_p_two_sided(int k, int n, double p0)
{
    if (n <= 0) return 1;
    double lk = binom_logpmf(k, n, p0);
    double sum = 0;
    /* relative tolerance as R's binom.test, so ties in floating point count as equal */
    for (int i = 0; i <= n; i++) {
        double li = binom_logpmf(i, n, p0);
        if (li <= lk + 1e-7 * fabs(lk) + 1e-12) sum += exp(li);
    }
    return sum > 1 ? 1 : sum;
}

/* log P(hits = a) for the hypergeometric of the 2x2 table with margins n_signal, n_noise and
 * a + b = yes answers in all. */
static double hyper_logpmf(int a, int n_signal, int n_noise, int yes)
{
    return lgamma(n_signal + 1.0) - lgamma(a + 1.0) - lgamma(n_signal - a + 1.0) + lgamma(n_noise + 1.0) -
           lgamma(yes - a + 1.0) - lgamma(n_noise - (yes - a) + 1.0) - lgamma(n_signal + n_noise + 1.0) +
           lgamma(yes + 1.0) + lgamma(n_signal + n_noise - yes + 1.0);
}

/* Sums the hypergeometric over hits in [from, to]; with only_at_most, only the tables no more
 * probable than log-probability lk. */
static double fisher_sum(int n_signal, int n_noise, int yes, int from, int to, int only_at_most, double lk)
{
    double sum = 0;
    for (int a = from; a <= to; a++) {
        double la = hyper_logpmf(a, n_signal, n_noise, yes);
        if (!only_at_most || la <= lk + 1e-7 * fabs(lk) + 1e-12) sum += exp(la);
    }
    return sum > 1 ? 1 : sum;
}

double csf_stats_fisher_greater(int hits, int n_signal, int false_alarms, int n_noise)
{
    if (n_signal <= 0 || n_noise <= 0 || hits < 0 || false_alarms < 0 || hits > n_signal ||
        false_alarms > n_noise)
        return 1;
    int yes = hits + false_alarms;
    int a_max = yes < n_signal ? yes : n_signal;
    return fisher_sum(n_signal, n_noise, yes, hits, a_max, 0, 0);
}

double csf_stats_fisher_two_sided(int hits, int n_signal, int false_alarms, int n_noise)
{
    if (n_signal <= 0 || n_noise <= 0 || hits < 0 || false_alarms < 0 || hits > n_signal ||
        false_alarms > n_noise)
        return 1;
    int yes = hits + false_alarms;
    int a_min = yes > n_noise ? yes - n_noise : 0, a_max = yes < n_signal ? yes : n_signal;
    return fisher_sum(n_signal, n_noise, yes, a_min, a_max, 1, hyper_logpmf(hits, n_signal, n_noise, yes));
}

void csf_stats_dprime_yesno_ci(double h, double f, int n_signal, int n_noise, double conf, double *lo,
                               double *hi)
{
    *lo = *hi = NAN;
    double d = csf_stats_dprime_yesno(h, f);
    if (isnan(d) || n_signal <= 0 || n_noise <= 0 || !(conf > 0 && conf < 1)) return;
    double zh = csf_stats_norm_quantile(h), zf = csf_stats_norm_quantile(f);
    double ph = exp(-0.5 * zh * zh) / sqrt(2 * M_PI), pf = exp(-0.5 * zf * zf) / sqrt(2 * M_PI);
    double var = h * (1 - h) / (n_signal * ph * ph) + f * (1 - f) / (n_noise * pf * pf);
    double half = csf_stats_norm_quantile(0.5 * (1 + conf)) * sqrt(var);
    *lo = d - half;
    *hi = d + half;
}

double csf_stats_dprime_yesno(double h, double f)
{
    if (!(h > 0 && h < 1 && f > 0 && f < 1)) return NAN;
    return csf_stats_norm_quantile(h) - csf_stats_norm_quantile(f);
}

static double sd_diff_hit(double dp, double k)
{
    return csf_stats_norm_cdf((dp - k) / M_SQRT2) + csf_stats_norm_cdf((-dp - k) / M_SQRT2);
}

double csf_stats_dprime_sd_differencing(double h, double f)
{
    if (!(h > 0 && h < 1 && f > 0 && f < 1) || h <= f) return NAN;
    double k = -M_SQRT2 * csf_stats_norm_quantile(f / 2);
    /* the hit rate rises monotonically from f (d' = 0) towards 1 */
    double lo = 0, hi = 1;
    while (sd_diff_hit(hi, k) < h && hi < 64) hi *= 2;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        if (sd_diff_hit(mid, k) < h) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

double csf_stats_dprime_sd_independent(double h, double f)
{
    if (!(h > 0 && h < 1 && f > 0 && f < 1) || h <= f) return NAN;
    double pmax = csf_stats_norm_cdf((csf_stats_norm_quantile(h) - csf_stats_norm_quantile(f)) / 2);
    return 2 * csf_stats_norm_quantile(0.5 * (1 + sqrt(2 * pmax - 1)));
}

/* Log-likelihood of rates (h, f) over (n_signal, n_noise) trials under the differencing model
 * at a signed d' s and criterion k: s >= 0 predicts "different" to different pairs at
 * sd_diff_hit(s, k) and to same pairs at 2 Phi(-k / sqrt 2); s < 0 swaps the two, the report's
 * reading of a negative d' (more "different" to same pairs than to different ones). */
static double sd_diff_loglik(double s, double k, double h, double f, int n_signal, int n_noise)
{
    double pf = 2 * csf_stats_norm_cdf(-k / M_SQRT2), ph = sd_diff_hit(fabs(s), k);
    if (s < 0) {
        double t = ph;
        ph = pf;
        pf = t;
    }
    ph = fmin(fmax(ph, 1e-15), 1 - 1e-15);
    pf = fmin(fmax(pf, 1e-15), 1 - 1e-15);
    return n_signal * (h * log(ph) + (1 - h) * log1p(-ph)) + n_noise * (f * log(pf) + (1 - f) * log1p(-pf));
}

/* The likelihood at s maximised over the criterion k: a grid finds the peak's bracket, golden
 * section refines it (the likelihood is unimodal in k for a fixed s). */
static double sd_diff_profile(double s, double h, double f, int n_signal, int n_noise)
{
    const double k_max = 12;
    int best = 1;
    double best_ll = -INFINITY;
    for (int i = 1; i <= 24; i++) {
        double ll = sd_diff_loglik(s, k_max * i / 24, h, f, n_signal, n_noise);
        if (ll > best_ll) {
            best_ll = ll;
            best = i;
        }
    }
    double a = k_max * (best - 1) / 24, b = k_max * (best + 1) / 24, g = 0.5 * (sqrt(5.0) - 1);
    for (int i = 0; i < 40; i++) { /* the bracket shrinks to 1e-9 */
        double c = b - g * (b - a), d = a + g * (b - a);
        if (sd_diff_loglik(s, c, h, f, n_signal, n_noise) > sd_diff_loglik(s, d, h, f, n_signal, n_noise))
            b = d;
        else a = c;
    }
    return fmax(best_ll, sd_diff_loglik(s, 0.5 * (a + b), h, f, n_signal, n_noise));
}

/* The end of the profile-likelihood interval between s_in (inside) and s_out: where the
 * deviance from the saturated fit crosses cut; s_out when it never does. */
static double sd_diff_end(double s_in, double s_out, double sat, double cut, double h, double f, int ns,
                          int nn)
{
    if (sat - sd_diff_profile(s_out, h, f, ns, nn) <= cut) return s_out;
    for (int i = 0; i < 40; i++) { /* to 1e-11 of the limits' span */
        double mid = 0.5 * (s_in + s_out);
        if (sat - sd_diff_profile(mid, h, f, ns, nn) <= cut) s_in = mid;
        else s_out = mid;
    }
    return 0.5 * (s_in + s_out);
}

/* The independent-observation d' as a function of z(h) - z(f), odd so that a negative argument
 * gives the negated d' of the swapped rates. */
static double sd_indep_of_z(double dz)
{
    double pmax = csf_stats_norm_cdf(fabs(dz) / 2);
    double d = 2 * csf_stats_norm_quantile(0.5 * (1 + sqrt(fmax(0, 2 * pmax - 1))));
    return dz < 0 ? -d : d;
}

void csf_stats_dprime_sd_ci(double h, double f, int n_signal, int n_noise, int differencing, double conf,
                            double *lo, double *hi)
{
    *lo = *hi = NAN;
    if (!(h > 0 && h < 1 && f > 0 && f < 1) || n_signal <= 0 || n_noise <= 0 || !(conf > 0 && conf < 1))
        return;
    if (!differencing) {
        double zl, zh;
        csf_stats_dprime_yesno_ci(h, f, n_signal, n_noise, conf, &zl, &zh);
        *lo = sd_indep_of_z(zl);
        *hi = sd_indep_of_z(zh);
        return;
    }
    double s_hat = h == f  ? 0
                   : h > f ? csf_stats_dprime_sd_differencing(h, f)
                           : -csf_stats_dprime_sd_differencing(f, h);
    double z = csf_stats_norm_quantile(0.5 * (1 + conf));
    /* the model reaches any pair of rates, so the maximum is the saturated likelihood */
    double sat = n_signal * (h * log(h) + (1 - h) * log1p(-h)) + n_noise * (f * log(f) + (1 - f) * log1p(-f));
    *lo = sd_diff_end(s_hat, -CSF_SD_DPRIME_LIMIT, sat, 0.5 * z * z, h, f, n_signal, n_noise);
    *hi = sd_diff_end(s_hat, CSF_SD_DPRIME_LIMIT, sat, 0.5 * z * z, h, f, n_signal, n_noise);
}

/* ---- Weibull fit ----------------------------------------------------------------------------- */

typedef struct {
    const csf_psy_level *lv;
    size_t n;
    double guess, max_lapse;
    int fix;         /* profile fits: -1 none; 0 t or 1 u held at `fixed`, the other two free */
    double fixed;
} fit_ctx;

/* Unconstrained (t, u, v) -> (t, beta, lapse): beta = clamp(exp u), lapse = max_lapse logistic(v). */
static void unpack(const fit_ctx *c, const double *q, double *t, double *beta, double *lapse)
{
    *t = q[0];
    double b = exp(q[1]);
    *beta = b < CSF_FIT_BETA_MIN ? CSF_FIT_BETA_MIN : b > CSF_FIT_BETA_MAX ? CSF_FIT_BETA_MAX : b;
    *lapse = c->max_lapse > 0 ? c->max_lapse / (1 + exp(-q[2])) : 0;
}

static double weibull_p(double x, double t, double beta, double guess, double lapse)
{
    return guess + (1 - guess - lapse) * (1 - exp(-pow(10.0, beta * (x - t))));
}

static double negloglik_full(const fit_ctx *c, const double *q)
{
    double t, beta, lapse;
    unpack(c, q, &t, &beta, &lapse);
    double nll = 0;
    for (size_t i = 0; i < c->n; i++) {
        double p = weibull_p(c->lv[i].x_log10, t, beta, c->guess, lapse);
        if (p < 1e-12) p = 1e-12;
        if (p > 1 - 1e-12) p = 1 - 1e-12;
        nll -= c->lv[i].k * log(p) + (c->lv[i].n - c->lv[i].k) * log1p(-p);
    }
    /* keep beta's raw parameter from wandering where the clamp makes the surface flat */
    double excess = fabs(q[1]) > 4 ? fabs(q[1]) - 4 : 0;
    return nll + excess * excess;
}

/* The simplex's point: (t, u, v), or the two free ones of a profile fit. */
static double negloglik(const fit_ctx *c, const double *q)
{
    if (c->fix < 0) return negloglik_full(c, q);
    double full[3];
    if (c->fix == 0) {
        full[0] = c->fixed;
        full[1] = q[0];
    } else {
        full[0] = q[0];
        full[1] = c->fixed;
    }
    full[2] = q[1];
    return negloglik_full(c, full);
}

/* Nelder-Mead simplex in d <= 3 dimensions; q holds the start and returns the minimum. */
static double nelder_mead(const fit_ctx *c, int d, double *q, const double *step, int max_iter, int *conv)
{
    enum { DM = 3 };
    double s[DM + 1][DM], f[DM + 1];
    size_t row = (size_t)d * sizeof(double);
    for (int i = 0; i <= d; i++) {
        memcpy(s[i], q, row);
        if (i > 0) s[i][i - 1] += step[i - 1];
        f[i] = negloglik(c, s[i]);
    }
    *conv = 0;
    for (int it = 0; it < max_iter; it++) {
        /* order: best first */
        for (int i = 1; i <= d; i++)
            for (int j = i; j > 0 && f[j] < f[j - 1]; j--) {
                double tf = f[j];
                f[j] = f[j - 1];
                f[j - 1] = tf;
                double tmp[DM];
                memcpy(tmp, s[j], row);
                memcpy(s[j], s[j - 1], row);
                memcpy(s[j - 1], tmp, row);
            }
        if (fabs(f[d] - f[0]) < 1e-10 * (1 + fabs(f[0]))) {
            *conv = 1;
            break;
        }
        double cen[DM] = {0, 0, 0}, xr[DM], xe[DM], xc[DM];
        for (int i = 0; i < d; i++)
            for (int j = 0; j < d; j++) cen[j] += s[i][j] / d;
        for (int j = 0; j < d; j++) xr[j] = cen[j] + (cen[j] - s[d][j]);
        double fr = negloglik(c, xr);
        if (fr < f[0]) {
            for (int j = 0; j < d; j++) xe[j] = cen[j] + 2 * (cen[j] - s[d][j]);
            double fe = negloglik(c, xe);
            if (fe < fr) {
                memcpy(s[d], xe, row);
                f[d] = fe;
            } else {
                memcpy(s[d], xr, row);
                f[d] = fr;
            }
        } else if (fr < f[d - 1]) {
            memcpy(s[d], xr, row);
            f[d] = fr;
        } else {
            int outside = fr < f[d];
            for (int j = 0; j < d; j++)
                xc[j] = outside ? cen[j] + 0.5 * (xr[j] - cen[j]) : cen[j] + 0.5 * (s[d][j] - cen[j]);
            double fc = negloglik(c, xc);
            if (fc < (outside ? fr : f[d])) {
                memcpy(s[d], xc, row);
                f[d] = fc;
            } else {
                for (int i = 1; i <= d; i++) {
                    for (int j = 0; j < d; j++) s[i][j] = s[0][j] + 0.5 * (s[i][j] - s[0][j]);
                    f[i] = negloglik(c, s[i]);
                }
            }
        }
    }
    int best = 0;
    for (int i = 1; i <= d; i++)
        if (f[i] < f[best]) best = i;
    memcpy(q, s[best], row);
    return f[best];
}

/* A grid over t in [xmin - 1, xmax + 1] (the limits the fit keeps t to), beta log-spaced over its
 * limits and three lapses. A steep peak is narrow in t and a shallow one wide, so the best point
 * of each of GRID_BANDS slope bands is kept (q[band]), each to be polished on its own. */
#define GRID_BANDS 4
static void grid_search(const fit_ctx *c, double xmin, double xmax, double q[GRID_BANDS][3],
                        double f_best[GRID_BANDS])
{
    enum { N_T = 161, N_BETA = 24 };
    static const double lapse_v[3] = {-3.0, 0.0, 3.0};
    for (int band = 0; band < GRID_BANDS; band++) f_best[band] = INFINITY;
    for (int j = 0; j < N_BETA; j++) {
        int band = j * GRID_BANDS / N_BETA;
        double u = log(CSF_FIT_BETA_MIN) + (log(CSF_FIT_BETA_MAX) - log(CSF_FIT_BETA_MIN)) * j / (N_BETA - 1);
        for (int i = 0; i < N_T; i++)
            for (int k = 0; k < (c->max_lapse > 0 ? 3 : 1); k++) {
                double cand[3] = {xmin - 1 + (xmax - xmin + 2) * i / (N_T - 1), u, lapse_v[k]};
                double f = negloglik(c, cand);
                if (f < f_best[band]) {
                    f_best[band] = f;
                    memcpy(q[band], cand, sizeof cand);
                }
            }
    }
}

int csf_weibull_fit_ml(const csf_psy_level *lv, size_t n_levels, double guess, double max_lapse,
                       csf_weibull_fit *out)
{
    memset(out, 0, sizeof *out);
    out->t_log10 = out->beta = out->lapse = NAN;
    out->guess = guess;
    if (!lv || n_levels < 2 || !(guess >= 0 && guess < 1) || !(max_lapse >= 0 && max_lapse < 0.5)) return -1;
    double xmin = INFINITY, xmax = -INFINITY;
    int ntot = 0;
    for (size_t i = 0; i < n_levels; i++) {
        if (lv[i].n <= 0) continue;
        ntot += lv[i].n;
        if (lv[i].x_log10 < xmin) xmin = lv[i].x_log10;
        if (lv[i].x_log10 > xmax) xmax = lv[i].x_log10;
    }
    if (ntot == 0 || !(xmax > xmin)) return -1;
    fit_ctx c = {lv, n_levels, guess, max_lapse, -1, 0};
    double best_f = INFINITY, best_q[3] = {0, 0, 0};
    int best_conv = 0;
    /* starting grid: threshold across the data, three slopes, small lapse */
    static const double betas[] = {1.5, 3.0, 6.0};
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 3; j++) {
            double q[3] = {xmin + (xmax - xmin) * i / 4.0, log(betas[j]), -2.0};
            double step[3] = {0.1 + 0.2 * (xmax - xmin), 0.4, 1.0};
            int conv;
            double fq = nelder_mead(&c, 3, q, step, 600, &conv);
            if (fq < best_f) {
                best_f = fq;
                memcpy(best_q, q, sizeof q);
                best_conv = conv;
            }
        }
    /* The simplex starts above can all settle on a local optimum of a two-peak surface (a steep
     * slope through one level against a shallow one through all): a grid over everything the
     * data identify finds the better peak, and a simplex polishes it. */
    double grid_q[GRID_BANDS][3], grid_f[GRID_BANDS];
    grid_search(&c, xmin, xmax, grid_q, grid_f);
    for (int band = 0; band < GRID_BANDS; band++) {
        if (!(grid_f[band] < INFINITY)) continue;
        double gstep[3] = {0.05, 0.2, 0.5};
        int gconv;
        double gf = nelder_mead(&c, 3, grid_q[band], gstep, 600, &gconv);
        if (gf < best_f) {
            best_f = gf;
            memcpy(best_q, grid_q[band], sizeof best_q);
            best_conv = gconv;
        }
    }
    /* restart from the best point: Nelder-Mead can stall on a ridge */
    double step[3] = {0.05, 0.2, 0.5};
    int conv;
    double fq = nelder_mead(&c, 3, best_q, step, 600, &conv);
    if (fq <= best_f) {
        best_f = fq;
        best_conv = conv;
    }
    unpack(&c, best_q, &out->t_log10, &out->beta, &out->lapse);
    /* the threshold is identified only near the data */
    if (out->t_log10 < xmin - 1) out->t_log10 = xmin - 1;
    if (out->t_log10 > xmax + 1) out->t_log10 = xmax + 1;
    out->loglik = -best_f;
    out->converged = best_conv;
    return 0;
}

static int binom_draw(csf_rng *r, int n, double p)
{
    int k = 0;
    for (int i = 0; i < n; i++) k += csf_rng_next_uniform(r) < p;
    return k;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double quantile_sorted(const double *v, int n, double p)
{
    double pos = p * (n - 1);
    int i = (int)floor(pos);
    if (i >= n - 1) return v[n - 1];
    double w = pos - i;
    return v[i] * (1 - w) + v[i + 1] * w;
}

/* n_boot data sets drawn from the Weibull (t, beta, lapse, guess) at the data's levels and trial
 * counts, each refitted: the refits' t and beta into ts, bs. Returns how many succeeded. */
static int boot_draws(const csf_psy_level *lv, size_t n_levels, double t, double beta, double lapse, double guess,
                      double max_lapse, int n_boot, csf_rng *r, csf_psy_level *sim, double *ts, double *bs)
{
    int ok = 0;
    for (int b = 0; b < n_boot; b++) {
        for (size_t i = 0; i < n_levels; i++) {
            sim[i] = lv[i];
            sim[i].k = binom_draw(r, lv[i].n, weibull_p(lv[i].x_log10, t, beta, guess, lapse));
        }
        csf_weibull_fit f;
        if (csf_weibull_fit_ml(sim, n_levels, guess, max_lapse, &f) == 0) {
            ts[ok] = f.t_log10;
            bs[ok] = f.beta;
            ok++;
        }
    }
    return ok;
}

int csf_weibull_bootstrap(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit,
                          double max_lapse, int n_boot, uint64_t seed, double conf,
                          double *t_lo, double *t_hi, double *beta_lo, double *beta_hi)
{
    *t_lo = *t_hi = *beta_lo = *beta_hi = NAN;
    if (n_boot < 2 || n_levels < 2 || !isfinite(fit->t_log10)) return 0;
    csf_psy_level *sim = malloc(n_levels * sizeof *sim);
    double *ts = malloc((size_t)n_boot * sizeof *ts), *bs = malloc((size_t)n_boot * sizeof *bs);
    int ok = 0;
    if (sim && ts && bs) {
        csf_rng r;
        csf_rng_init(&r, seed, 0xB0075);
        ok = boot_draws(lv, n_levels, fit->t_log10, fit->beta, fit->lapse, fit->guess, max_lapse, n_boot,
                        &r, sim, ts, bs);
        if (ok >= 2) {
            qsort(ts, (size_t)ok, sizeof *ts, cmp_double);
            qsort(bs, (size_t)ok, sizeof *bs, cmp_double);
            double a = (1 - conf) / 2;
            *t_lo = quantile_sorted(ts, ok, a);
            *t_hi = quantile_sorted(ts, ok, 1 - a);
            *beta_lo = quantile_sorted(bs, ok, a);
            *beta_hi = quantile_sorted(bs, ok, 1 - a);
        }
    }
    free(sim);
    free(ts);
    free(bs);
    return ok;
}


/* ---- profile likelihood ---------------------------------------------------------------------- */

/* Maximum log likelihood with parameter c->fix held at c->fixed; q (the two free raw parameters)
 * is the warm start and returns the optimum. Several starts: the surface of a 6-level study has
 * ridges (slope against lapse) where one simplex stalls. */
static double profile_max(const fit_ctx *c, double *q, const double *q_fit)
{
    double starts[4][2] = {{q[0], q[1]}, {q_fit[0], q_fit[1]}, {0, -2}, {0, -2}};
    if (c->fix == 0) {
        starts[2][0] = log(1.5);
        starts[3][0] = log(6.0);
    } else {
        starts[2][0] = q_fit[0] - 0.2;
        starts[3][0] = q_fit[0] + 0.2;
    }
    double best = INFINITY, best_q[2] = {q[0], q[1]};
    for (int i = 0; i < 4; i++) {
        double w[2] = {starts[i][0], starts[i][1]};
        double step[2] = {c->fix == 0 ? 0.4 : 0.1, 1.0};
        int conv;
        double f = nelder_mead(c, 2, w, step, 400, &conv);
        if (f < best) {
            best = f;
            memcpy(best_q, w, sizeof w);
        }
    }
    double step[2] = {c->fix == 0 ? 0.1 : 0.03, 0.3};
    int conv;
    double f = nelder_mead(c, 2, best_q, step, 400, &conv);
    if (f < best) best = f;
    memcpy(q, best_q, sizeof best_q);
    return -best;
}

/* One end of the interval: walks from the estimate in direction dir until the deviance passes
 * crit (or the limit is reached), then bisects. *ll_max is raised when a profile point beats
 * the fit (the full fit stalled); the caller then starts again. */
static double profile_end(fit_ctx *c, double est, double dir, double limit, double first_step, double crit,
                          const double *q_fit, double *ll_max, int *better, double *q_better)
{
    double q[2] = {q_fit[0], q_fit[1]};
    double inside = est, h = first_step;
    *better = 0;
    for (;;) {
        double x = inside + dir * h;
        if ((x - limit) * dir >= 0) x = limit;
        c->fixed = x;
        double qq[2] = {q[0], q[1]};
        double ll = profile_max(c, qq, q_fit);
        if (ll > *ll_max + 1e-6) {
            *ll_max = ll;
            *better = 1;
            /* the full parameter vector of the better point */
            q_better[c->fix] = x;
            q_better[c->fix == 0 ? 1 : 0] = qq[0];
            q_better[2] = qq[1];
            return NAN;
        }
        if (2 * (*ll_max - ll) > crit) break;
        inside = x;
        memcpy(q, qq, sizeof q);
        if (x == limit) return limit;
        h *= 1.6;
    }
    double outside = inside + dir * h;
    if ((outside - limit) * dir > 0) outside = limit;
    while (fabs(outside - inside) > 2e-4) {
        double mid = 0.5 * (inside + outside);
        c->fixed = mid;
        double qq[2] = {q[0], q[1]};
        double ll = profile_max(c, qq, q_fit);
        if (2 * (*ll_max - ll) > crit) outside = mid;
        else {
            inside = mid;
            memcpy(q, qq, sizeof q);
        }
    }
    return 0.5 * (inside + outside);
}

/* The fit's raw parameters (t, log beta, logit of lapse / max_lapse); a lapse at 0 (or at its
 * maximum) sits at a finite logit. */
static void raw_of_fit(const csf_weibull_fit *fit, double max_lapse, double *q3)
{
    double v = max_lapse > 0 ? fit->lapse / max_lapse : 0.5;
    v = v < 1e-9 ? -20 : v > 1 - 1e-9 ? 20 : log(v / (1 - v));
    q3[0] = fit->t_log10;
    q3[1] = log(fit->beta);
    q3[2] = v;
}

static int data_range(const csf_psy_level *lv, size_t n_levels, double *xmin, double *xmax)
{
    *xmin = INFINITY;
    *xmax = -INFINITY;
    for (size_t i = 0; i < n_levels; i++) {
        if (lv[i].n <= 0) continue;
        if (lv[i].x_log10 < *xmin) *xmin = lv[i].x_log10;
        if (lv[i].x_log10 > *xmax) *xmax = lv[i].x_log10;
    }
    return *xmax > *xmin;
}

/* Profile intervals with a deviance cutoff per end: crit[0], crit[1] for t's lower and upper
 * ends, crit[2], crit[3] for beta's. */
static int profile_ci(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit, double max_lapse,
                      const double *crit, double *t_lo, double *t_hi, double *beta_lo, double *beta_hi)
{
    *t_lo = *t_hi = *beta_lo = *beta_hi = NAN;
    double xmin, xmax;
    if (!lv || n_levels < 2 || !isfinite(fit->t_log10) || !data_range(lv, n_levels, &xmin, &xmax)) return -1;
    fit_ctx c = {lv, n_levels, fit->guess, max_lapse, -1, 0};
    double q3[3];
    raw_of_fit(fit, max_lapse, q3);
    double u_lo = log(CSF_FIT_BETA_MIN), u_hi = log(CSF_FIT_BETA_MAX);
    if (q3[1] < u_lo) q3[1] = u_lo;
    if (q3[1] > u_hi) q3[1] = u_hi;
    double ll_max = -negloglik_full(&c, q3);
    for (int pass = 0; pass < 3; pass++) {
        int better = 0;
        double qt[2] = {q3[1], q3[2]}, qb[2] = {q3[0], q3[2]}, ul = NAN, uh = NAN;
        c.fix = 0;
        *t_lo = profile_end(&c, q3[0], -1, xmin - 1, 0.02, crit[0], qt, &ll_max, &better, q3);
        if (!better) *t_hi = profile_end(&c, q3[0], +1, xmax + 1, 0.02, crit[1], qt, &ll_max, &better, q3);
        c.fix = 1;
        if (!better) ul = profile_end(&c, q3[1], -1, u_lo, 0.05, crit[2], qb, &ll_max, &better, q3);
        if (!better) uh = profile_end(&c, q3[1], +1, u_hi, 0.05, crit[3], qb, &ll_max, &better, q3);
        if (!better) {
            *beta_lo = exp(ul);
            *beta_hi = exp(uh);
            return pass;
        }
        /* a profile point beat the fit (the fit's simplex stalled on a ridge): the intervals are
         * drawn around the better maximum, found again from that point */
    }
    *t_lo = *t_hi = *beta_lo = *beta_hi = NAN;
    return -1;
}

int csf_weibull_profile_ci(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit, double max_lapse,
                           double conf, double *t_lo, double *t_hi, double *beta_lo, double *beta_hi)
{
    *t_lo = *t_hi = *beta_lo = *beta_hi = NAN;
    if (!(conf > 0 && conf < 1)) return -1;
    double z = csf_stats_norm_quantile(0.5 + conf / 2), crit[4] = {z * z, z * z, z * z, z * z};
    return profile_ci(lv, n_levels, fit, max_lapse, crit, t_lo, t_hi, beta_lo, beta_hi);
}

/* ---- marginal posterior ---------------------------------------------------------------------- */

/* Grid: log beta over [0.5, 20] in 48 steps (8 %), lapse over [0, max_lapse] in 13 (the posterior
 * is smooth in the lapse; it is summed out per (t, beta)); t first over the whole range the fit
 * allows in 121 steps, then again in 241 steps over the part that holds all but 1e-9 of the
 * mass (a 0.1 log10 interval gets some 0.001 log10 steps). */
#define MG_NT1 121
#define MG_NT 241
#define MG_NU 48
#define MG_NL 13

/* Unnormalised marginals of t (n_t points over [t0, t1]) and u = log beta on the grid. */
static int marginals(const csf_psy_level *lv, size_t n_levels, double guess, double max_lapse, double t0,
                     double t1, int n_t, double *mt, double *mu)
{
    double u0 = log(CSF_FIT_BETA_MIN), u1 = log(CSF_FIT_BETA_MAX);
    double (*ll)[MG_NU] = malloc((size_t)n_t * sizeof *ll);
    if (!ll) return -1;
    double mx = -INFINITY;
    for (int i = 0; i < n_t; i++) {
        double t = t0 + (t1 - t0) * i / (n_t - 1);
        for (int j = 0; j < MG_NU; j++) {
            double u = u0 + (u1 - u0) * j / (MG_NU - 1), beta = exp(u);
            double lmx = -INFINITY, lk[MG_NL];
            for (int l = 0; l < MG_NL; l++) {
                double lapse = max_lapse * l / (MG_NL - 1), s = 0;
                for (size_t k = 0; k < n_levels; k++) {
                    double p = weibull_p(lv[k].x_log10, t, beta, guess, lapse);
                    if (p < 1e-12) p = 1e-12;
                    if (p > 1 - 1e-12) p = 1 - 1e-12;
                    s += lv[k].k * log(p) + (lv[k].n - lv[k].k) * log1p(-p);
                }
                lk[l] = s;
                if (s > lmx) lmx = s;
            }
            double sum = 0;
            for (int l = 0; l < MG_NL; l++) sum += exp(lk[l] - lmx);
            /* prior flat in the width (proportional to 1/beta): density e^-u on the u grid */
            ll[i][j] = lmx + log(sum) - u;
            if (ll[i][j] > mx) mx = ll[i][j];
        }
    }
    for (int i = 0; i < n_t; i++) mt[i] = 0;
    for (int j = 0; j < MG_NU; j++) mu[j] = 0;
    for (int i = 0; i < n_t; i++)
        for (int j = 0; j < MG_NU; j++) {
            double w = exp(ll[i][j] - mx);
            mt[i] += w;
            mu[j] += w;
        }
    free(ll);
    return 0;
}

/* The p-quantile of a marginal given at n points g0 .. g1 (each point's mass spread evenly over
 * its cell). */
static double marginal_quantile(const double *m, int n, double g0, double g1, double p)
{
    double tot = 0, c = 0, h = (g1 - g0) / (n - 1);
    for (int i = 0; i < n; i++) tot += m[i];
    for (int i = 0; i < n; i++) {
        double prev = c;
        c += m[i] / tot;
        if (c >= p) return g0 + h * i - h / 2 + h * (p - prev) / (c - prev);
    }
    return g1;
}

int csf_weibull_marginal_ci(const csf_psy_level *lv, size_t n_levels, const csf_weibull_fit *fit, double max_lapse,
                            double conf, double *t_lo, double *t_hi, double *beta_lo, double *beta_hi)
{
    *t_lo = *t_hi = *beta_lo = *beta_hi = NAN;
    double xmin, xmax;
    if (!lv || n_levels < 2 || !fit || !data_range(lv, n_levels, &xmin, &xmax) || !(conf > 0 && conf < 1) ||
        !(max_lapse >= 0 && max_lapse < 0.5) || !(fit->guess >= 0 && fit->guess < 1))
        return -1;
    double t0 = xmin - 1, t1 = xmax + 1, mt1[MG_NT1], mt[MG_NT], mu[MG_NU];
    if (marginals(lv, n_levels, fit->guess, max_lapse, t0, t1, MG_NT1, mt1, mu) != 0) return -1;
    double top = 0;
    for (int i = 0; i < MG_NT1; i++) top = fmax(top, mt1[i]);
    int a = 0, b = MG_NT1 - 1;
    while (a < b && mt1[a] < 1e-9 * top) a++;
    while (b > a && mt1[b] < 1e-9 * top) b--;
    double h = (t1 - t0) / (MG_NT1 - 1), r0 = fmax(t0, t0 + h * (a - 1)), r1 = fmin(t1, t0 + h * (b + 1));
    if (marginals(lv, n_levels, fit->guess, max_lapse, r0, r1, MG_NT, mt, mu) != 0) return -1;
    double lo = (1 - conf) / 2, u0 = log(CSF_FIT_BETA_MIN), u1 = log(CSF_FIT_BETA_MAX);
    *t_lo = marginal_quantile(mt, MG_NT, r0, r1, lo);
    *t_hi = marginal_quantile(mt, MG_NT, r0, r1, 1 - lo);
    *beta_lo = exp(marginal_quantile(mu, MG_NU, u0, u1, lo));
    *beta_hi = exp(marginal_quantile(mu, MG_NU, u0, u1, 1 - lo));
    return 0;
}
