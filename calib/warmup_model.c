/* The warm-up judgement (calib/warmup_model.h). */
#include "calib/warmup_model.h"

#include <math.h>
#include <string.h>

#include "calib/display_calib.h"

/* Least squares of A and B for one tau; the residual sum of squares, or INFINITY when the two
 * columns are too nearly collinear to separate (tau far below or above the readings' span). */
static double fit_at(const double *t_s, const double *y, int n, double tau, double *A, double *B)
{
    double s0 = 0, s1 = 0, s11 = 0, sy = 0, s1y = 0, syy = 0;
    for (int i = 0; i < n; i++) {
        double e = exp(-t_s[i] / tau);
        s0 += 1;
        s1 += e;
        s11 += e * e;
        sy += y[i];
        s1y += e * y[i];
        syy += y[i] * y[i];
    }
    double det = s0 * s11 - s1 * s1;
    if (!(det > 1e-12 * s0 * s11)) return INFINITY;
    double a = (s11 * sy - s1 * s1y) / det, b = (s0 * s1y - s1 * sy) / det;
    *A = a;
    *B = b;
    return syy - 2 * a * sy - 2 * b * s1y + a * a * s0 + 2 * a * b * s1 + b * b * s11;
}

int csf_exp_settle_fit(const double *t_s, const double *y, int n, double *A, double *B, double *tau_s,
                       double *sse)
{
    double best = INFINITY, btau = 0, a, b;
    for (int k = 0; k <= 64; k++) {
        double tau = 1.0 * pow(1.15, k);
        double e2 = fit_at(t_s, y, n, tau, &a, &b);
        if (e2 < best) {
            best = e2;
            btau = tau;
        }
    }
    if (!isfinite(best)) return -1;
    /* the grid's 15 % steps put a 60 s constant at 57.6 or 66.2 s, which moves the predicted wait
     * by a quarter; a golden-section search in log tau between the neighbours finds the minimum */
    const double g = 0.5 * (sqrt(5.0) - 1);
    double lo = log(btau / 1.15), hi = log(btau * 1.15);
    for (int it = 0; it < 40; it++) {
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        if (fit_at(t_s, y, n, exp(x1), &a, &b) < fit_at(t_s, y, n, exp(x2), &a, &b)) hi = x2;
        else lo = x1;
    }
    double e2 = fit_at(t_s, y, n, exp(0.5 * (lo + hi)), &a, &b);
    if (e2 <= best) btau = exp(0.5 * (lo + hi));
    *sse = fmax(fit_at(t_s, y, n, btau, A, B), 0);
    *tau_s = btau;
    return 0;
}

/* Is the exponential's improvement over a constant more than noise? The two extra parameters
 * (B, tau) give F = ((sse0 - sse1) / 2) / (sse1 / (n - 3)); with 2 numerator degrees of freedom
 * its tail has the closed form P(F > f) = (1 + 2f/m)^(-m/2), m = n - 3, which is
 * (sse1 / sse0)^(m/2). */
static int drift_significant(double sse0, double sse1, int n)
{
    if (n < 6 || !(sse0 > 0)) return 0;
    if (!(sse1 > 0)) return 1; /* an exact fit of a changing white */
    double p = pow(sse1 / sse0, 0.5 * (n - 3));
    return p < 0.01;
}

/* Fills the model's predictions at the last reading t_last (time since the first reading). */
static void predict(csf_warm_judgement *j, double t_last, double target_rel, double session_s)
{
    double now = j->A_cdm2 + j->B_cdm2 * exp(-t_last / j->tau_s);
    if (!(now > 0) || !(j->A_cdm2 > 0)) {
        /* a model that puts white at or below zero describes no display: do not call it warm */
        j->remaining_rel = INFINITY;
        j->settled_gap_rel = INFINITY;
        j->wait_s = INFINITY;
        return;
    }
    double left = fabs(j->B_cdm2) * exp(-t_last / j->tau_s); /* |w(t_last) - A| */
    double frac = 1 - exp(-session_s / j->tau_s);            /* the part of it the session sees */
    j->settled_gap_rel = left / now;
    j->remaining_rel = left * frac / now;
    /* the remaining drift falls as e^(-t/tau): it reaches the target after tau ln(remaining/target) */
    j->wait_s = j->remaining_rel > target_rel ? j->tau_s * log(j->remaining_rel / target_rel) : 0;
}

int csf_display_warm_judge(const double *t_s, const double *w_cdm2, int n, double target_rel,
                           double session_s, csf_warm_judgement *j)
{
    memset(j, 0, sizeof *j);
    j->A_cdm2 = j->B_cdm2 = j->tau_s = NAN;
    j->step_settled = csf_display_warm_settled(w_cdm2, n, target_rel, &j->change_rel);
    if (n < 6) {
        j->wait_s = NAN;
        return 0;
    }
    double t[256], mean = 0, sse0 = 0;
    int m = n < 256 ? n : 256;
    const double *y = w_cdm2 + (n - m);
    for (int i = 0; i < m; i++) {
        t[i] = t_s[n - m + i] - t_s[n - m]; /* an instrument's clock can be far from zero */
        mean += y[i];
    }
    mean /= m;
    for (int i = 0; i < m; i++) sse0 += (y[i] - mean) * (y[i] - mean);
    double A, B, tau, sse1;
    if (csf_exp_settle_fit(t, y, m, &A, &B, &tau, &sse1) == 0 && drift_significant(sse0, sse1, m)) {
        j->model_significant = 1;
        j->A_cdm2 = A;
        j->B_cdm2 = B;
        j->tau_s = tau;
        predict(j, t[m - 1], target_rel, session_s);
    }
    j->warm = j->step_settled && !(j->remaining_rel >= target_rel);
    return j->warm;
}

double csf_sample_sd(const double *x, int n)
{
    double m = 0, s = 0;
    for (int i = 0; i < n; i++) m += x[i];
    m /= n;
    for (int i = 0; i < n; i++) s += (x[i] - m) * (x[i] - m);
    return n > 1 ? sqrt(s / (n - 1)) : 0;
}
