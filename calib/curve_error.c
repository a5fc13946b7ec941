/* The profile's own error between its levels, estimated from the levels alone (see
 * calib/curve_error.h). */
#include "calib/curve_error.h"

#include "results/display_profile.h"

#include <math.h>
#include <stdlib.h>

/* A knot the model keeps as a corner: is the kink really at it? Extend the secants on both sides;
 * where they cross inside a neighbouring interval, the break lies there, and the gap between the
 * crossing and the straight model (its noise taken off) is that interval's error, into est. */
static void corner_estimates(const double *dv, const double *dl, size_t m, size_t k, const double *sd_rel,
                             double *est, char *seen)
{
    double peak_c = dl[m - 1];
    for (int side = 0; side < 2; side++) {
        /* side 0: lines (k-1,k) and (k+1,k+2) meet in [k,k+1]; side 1: (k-2,k-1) and (k,k+1) in [k-1,k] */
        size_t a0 = side ? k - 2 : k - 1, a1 = side ? k - 1 : k, b0 = side ? k : k + 1,
               b1 = side ? k + 1 : k + 2;
        if ((side && k < 2) || b1 >= m) continue;
        /* lines over at least 0.03 of drive where knots allow: a secant over two close
         * knots is mostly instrument noise */
        while (a0 > 0 && dv[a1] - dv[a0] < 0.03) a0--;
        while (b1 + 1 < m && dv[b1] - dv[b0] < 0.03) b1++;
        double s1 = (dl[a1] - dl[a0]) / (dv[a1] - dv[a0]), s2 = (dl[b1] - dl[b0]) / (dv[b1] - dv[b0]);
        if (!(fabs(s1 - s2) > 0)) continue;
        double xs = (dl[b0] - dl[a1] + s1 * dv[a1] - s2 * dv[b0]) / (s1 - s2);
        if (!(xs > dv[a1] && xs < dv[b0])) continue;
        double ys = dl[a1] + s1 * (xs - dv[a1]);
        double lin = dl[a1] + (dl[b0] - dl[a1]) * (xs - dv[a1]) / (dv[b0] - dv[a1]);
        double e = fabs(ys - lin) / fmax(ys, 0.1 * peak_c);
        /* ys - lin = (r + f) L[a1] - r L[a0] - f L[b0] with r, f the crossing's distance over the
         * two spans: its noise taken off as for a left-out knot */
        double r = (xs - dv[a1]) / (dv[a1] - dv[a0]), f = (xs - dv[a1]) / (dv[b0] - dv[a1]);
        double var = (pow((r + f) * sd_rel[a1] * dl[a1], 2) + pow(r * sd_rel[a0] * dl[a0], 2) +
                      pow(f * sd_rel[b0] * dl[b0], 2)) /
                     pow(fmax(ys, 0.1 * peak_c), 2);
        e = e * e > 4 * var ? sqrt(e * e - var) : 0;
        if (e > est[a1]) est[a1] = e; /* interval [a1, b0] */
        seen[a1] = 1;
    }
}

/* An interval no knot could witness (beside a corner at the curve's end, say) is not known to be
 * right: its estimate is how far the model bends away from the straight line across it at the
 * middle, the curvature the model assumes there unchecked. A sweep with readings left splits it
 * (its new knot is then witnessed); a statement made without that reading says it. */
static double unwitnessed_estimate(const double *dv, const double *dl, size_t m, int is_channel, size_t i)
{
    double mid = 0.5 * (dv[i] + dv[i + 1]), pred;
    csf_error e;
    if (csf_profile_fit_curve(dv, dl, m, is_channel, &mid, &pred, 1, &e)) return 0;
    double lin = 0.5 * (dl[i] + dl[i + 1]);
    return fabs(pred - lin) / fmax(pred, 0.1 * dl[m - 1]);
}

/* The local exponent of the curve between knots p < q, d ln y / d ln v with y the luminance above
 * base (black for grey, none for a channel), and its noise from the knots' relative sds; NAN where a
 * knot is at drive 0 or not above base. */
static double local_exponent(const double *dv, const double *dl, double base, const double *sd_rel, size_t p,
                             size_t q, double *sd)
{
    double yp = dl[p] - base, yq = dl[q] - base, w = log(dv[q] / dv[p]);
    if (!(dv[p] > 0) || !(yp > 0) || !(yq > 0) || !(w > 0)) return NAN;
    double sp = sd_rel[p] * dl[p] / yp, sq = sd_rel[q] * dl[q] / yq;
    *sd = sqrt(sp * sp + sq * sq) / w;
    return log(yq / yp) / w;
}

/* Whether a corner could hide inside interval i, one the knots cannot show because none falls on it
 * (a channel that clips, a LUT's joint between two segments). A display curve is close to a power
 * law piece by piece, so in ln y against ln v its pieces are nearly straight: a corner inside i shows
 * as a jump of the local exponent from the line left of i to the line right of it, larger than the
 * smooth bending the lines further out show. The corner is then where the two lines cross (they
 * pass through the interval's ends); *xs, *ys get it (drive, luminance as dl holds it) and *share the
 * part of the jump that neither the smooth bending nor the knots' noise (two sd, then taken off in
 * quadrature, as for a left-out knot) explains. Returns 0 when no corner can be inside. */
static int hidden_corner(const double *dv, const double *dl, size_t m, int is_channel, const double *sd_rel,
                         size_t i, double *xs, double *ys, double *share)
{
    if (i < 1 || i + 2 >= m) return 0;
    double base = is_channel || !(dv[0] == 0) ? 0 : dl[0];
    /* the lines beside i over at least 0.03 of drive where knots allow (as corner_estimates) */
    size_t a0 = i - 1, b1 = i + 2;
    while (a0 > 1 && dv[i] - dv[a0] < 0.03) a0--;
    while (b1 + 1 < m && dv[b1] - dv[i + 1] < 0.03) b1++;
    double sl, sr;
    double gl = local_exponent(dv, dl, base, sd_rel, a0, i, &sl),
           gr = local_exponent(dv, dl, base, sd_rel, i + 1, b1, &sr);
    if (isnan(gl) || isnan(gr)) return 0;
    /* the smooth bending: the change of exponent per unit of ln v just outside, on each side that
     * has room, carried across from the left line's middle to the right line's */
    double ul = 0.5 * log(dv[a0] * dv[i]), ur = 0.5 * log(dv[i + 1] * dv[b1]), bend = 0, dummy;
    int sides = 0;
    if (a0 >= 2) {
        size_t z = a0 - 1;
        while (z > 1 && dv[a0] - dv[z] < 0.03) z--;
        double g = local_exponent(dv, dl, base, sd_rel, z, a0, &dummy);
        if (!isnan(g)) bend = fmax(bend, fabs(gl - g) / (ul - 0.5 * log(dv[z] * dv[a0]))), sides++;
    }
    if (b1 + 1 < m) {
        size_t z = b1 + 1;
        while (z + 1 < m && dv[z] - dv[b1] < 0.03) z++;
        double g = local_exponent(dv, dl, base, sd_rel, b1, z, &dummy);
        if (!isnan(g)) bend = fmax(bend, fabs(g - gr) / (0.5 * log(dv[b1] * dv[z]) - ur)), sides++;
    }
    /* both sides: near an end one side proves nothing (a smooth curve may bend more and more
     * towards it: an LCD's toe, an OLED limiting its power near white), as for bracketed_corners */
    if (sides < 2) return 0;
    double jump = fabs(gr - gl), excess = jump - bend * (ur - ul), var = sl * sl + sr * sr;
    if (!(excess * excess > 4 * var) || !(excess > 0)) return 0;
    double li = log(dv[i]), lj = log(dv[i + 1]), yi = log(dl[i] - base), yj = log(dl[i + 1] - base);
    double u = (yj - yi + gl * li - gr * lj) / (gl - gr);
    if (!(u > li && u < lj)) return 0;
    *xs = exp(u);
    *ys = exp(yi + gl * (u - li)) + base;
    *share = sqrt(excess * excess - var) / jump;
    return 1;
}

/* A corner inside an interval leaves the knots at its ends, and so leave-one-out, nearly blind: an
 * interval of the range the target covers where one could hide (hidden_corner) gets what the model
 * misses of the corner the lines beside it make, into est and est_min (may be NULL) where larger. */
static void hidden_corner_errors(const double *dv, const double *dl, size_t m, int is_channel,
                                 const double *sd_rel, double *est, double *est_min)
{
    double peak = dl[m - 1];
    for (size_t i = 1; i + 2 < m; i++) {
        double xs, ys, share, pred;
        csf_error e;
        if (!(dl[i + 1] >= 0.1 * peak) ||
            !hidden_corner(dv, dl, m, is_channel, sd_rel, i, &xs, &ys, &share) ||
            csf_profile_fit_curve(dv, dl, m, is_channel, &xs, &pred, 1, &e))
            continue;
        double h = share * fabs(ys - pred) / fmax(ys, 0.1 * peak);
        if (h > est[i]) est[i] = h;
        if (est_min && h > est_min[i]) est_min[i] = h;
    }
}

/* How much larger an interpolant's error is at the middle of an interval than at relative position t
 * in it: a cubic's error goes as t^2 (1 - t)^2, the gain capped at 16. */
static double middle_gain(double t)
{
    return 0.0625 / fmax(t * t * (1 - t) * (1 - t), 0.0625 / 16);
}

/* The model through the knots of (dv, dl) but those lo..hi, at drive v, into *pred (tv, tl: scratch
 * of m entries). Returns 0, or non-zero when that model cannot be fitted. */
static int predict_without(const double *dv, const double *dl, size_t m, int is_channel, size_t lo, size_t hi,
                           double v, double *tv, double *tl, double *pred)
{
    size_t j = 0;
    for (size_t i = 0; i < m; i++)
        if (i < lo || i > hi) {
            tv[j] = dv[i];
            tl[j++] = dl[i];
        }
    csf_error e;
    return csf_profile_fit_curve(tv, tl, j, is_channel, &v, pred, 1, &e) != CSF_OK;
}

/* The order p at which the model's error falls with the width w of an interval (error ~ w^p) near
 * knot k, measured rather than assumed, as Richardson's extrapolation does: e2_mid (knot k left out,
 * scaled to the middle of the span it opens) against the same with knots k - 1, k and k + 1 left out
 * (a span about twice as wide). A smooth curve under this model falls about 8 times per halving
 * (p = 3), a kink inside the span 2 times (p = 1). Where the wider miss is within its noise, a
 * neighbour is a corner or knot k is too near an end, p is 2, a halving's error 1/4. */
static double convergence_order(const double *dv, const double *dl, size_t m, int is_channel,
                                const double *sd_rel, size_t k, double e2_mid, const double *corners,
                                size_t nc, double *tv, double *tl)
{
    const double p_default = 2;
    if (k < 2 || k + 2 >= m) return p_default;
    for (size_t j = 0; j < nc; j++)
        if (corners[j] == dv[k - 1] || corners[j] == dv[k + 1]) return p_default;
    double pred;
    if (predict_without(dv, dl, m, is_channel, k - 1, k + 1, dv[k], tv, tl, &pred)) return p_default;
    double peak = dl[m - 1], denom = fmax(dl[k], 0.1 * peak);
    double e4 = fabs(pred - dl[k]) / (denom > 0 ? denom : 1);
    /* the knot's noise and the prediction's from the knots two away (about 0.32 of each one's
     * variance, as for one left out), taken off as there */
    double var =
        sd_rel[k] * sd_rel[k] + 0.32 * (sd_rel[k - 2] * sd_rel[k - 2] + sd_rel[k + 2] * sd_rel[k + 2]);
    if (!(e4 * e4 > 4 * var)) return p_default;
    e4 = sqrt(e4 * e4 - var);
    double H2 = dv[k + 1] - dv[k - 1], H4 = dv[k + 2] - dv[k - 2];
    double e4_mid = e4 * middle_gain((dv[k] - dv[k - 2]) / H4);
    double p = log(e4_mid / e2_mid) / log(H4 / H2);
    if (!isfinite(p)) return p_default;
    /* a monotone cubic with slopes from secants converges at order 3 at best */
    return fmin(fmax(p, 1), 3);
}

/* See curve_error.h. */
double csf_curve_interval_errors(const double *dv, const double *dl, size_t m, int is_channel,
                                 const double *sd_rel, double p_max, double *est, double *est_min)
{
    if (m < 2) return 0; /* no interval */
    double peak = dl[m - 1];
    for (size_t i = 0; i + 1 < m; i++) est[i] = 0;
    /* wit[2i]: interval i's estimate from knot i (left out), wit[2i+1]: from knot i+1 */
    double *wit = malloc(2 * m * sizeof(double));
    for (size_t i = 0; wit && i < 2 * m; i++) wit[i] = NAN;
    if (!wit) est_min = NULL;
    double *tv = malloc(m * sizeof(double)), *tl = malloc(m * sizeof(double));
    char *seen = calloc(m, 1);
    double worst = 0;
    /* a knot the model already treats as a corner is not re-tested: leaving it out would always
     * look bad (the kink is lost) although the model with it is right */
    double corners[64];
    csf_error cerr;
    size_t nc = csf_profile_fit_corners(dv, dl, m, is_channel, corners, 64, &cerr);
    for (size_t k = 1; tv && tl && k + 1 < m; k++) { /* out of memory: nothing left out */
        int skip = 0;
        for (size_t j = 0; j < nc; j++)
            if (corners[j] == dv[k]) skip = 1;
        if (skip) {
            if (seen) corner_estimates(dv, dl, m, k, sd_rel, est, seen);
            continue;
        }
        double pred;
        if (predict_without(dv, dl, m, is_channel, k, k, dv[k], tv, tl, &pred)) continue;
        double denom = fmax(dl[k], 0.1 * peak);
        double ek = fabs(pred - dl[k]) / (denom > 0 ? denom : 1);
        /* The miss carries the noise of the knot's mean and of the prediction (a cubic through
         * the neighbours weighs the two nearest by about 9/16 each, so about 0.32 of each one's
         * variance): taken off in quadrature, what is left estimates the model's own error
         * (E[d^2] = bias^2 + var), unbiased, where subtracting a multiple of the sd would hide a
         * bias of the size of the noise. */
        double var =
            sd_rel[k] * sd_rel[k] + 0.32 * (sd_rel[k - 1] * sd_rel[k - 1] + sd_rel[k + 1] * sd_rel[k + 1]);
        /* a miss within two sd of its noise is no evidence of model error (the noise part of the
         * statement covers it); amplified below up to 32x, a noise residual would otherwise
         * become a large spurious model error */
        ek = ek * ek > 4 * var ? sqrt(ek * ek - var) : 0;

        /* The left-out knot saw the merged interval's error at its own position t, which is
         * small near an end even when the interval is bad: scale to the middle (middle_gain), then
         * to each part. Halving a span divides the error by 2^p, p the order the curve shows here
         * (convergence_order, at most p_max); a part of width h H gets (2 h)^3 of that, as a part
         * near an end of the span sees less of the curve's bending than its width alone says. */
        double H = dv[k + 1] - dv[k - 1], t = (dv[k] - dv[k - 1]) / H;
        double amp = middle_gain(t);
        double p =
            ek > 0 ? convergence_order(dv, dl, m, is_channel, sd_rel, k, ek * amp, corners, nc, tv, tl) : 2;
        p = fmin(p, p_max);
        double sl = ek * amp * pow(2 * t, 3) * pow(2, -p), sr = ek * amp * pow(2 * (1 - t), 3) * pow(2, -p);
        if (sl > est[k - 1]) est[k - 1] = sl;
        if (sr > est[k]) est[k] = sr;
        if (seen) seen[k - 1] = seen[k] = 1;
        if (est_min) {
            wit[2 * (k - 1) + 1] = sl;
            wit[2 * k] = sr;
        }
    }
    /* An interval has two witnesses, the knots at its ends, each left out in turn. Placing levels
     * takes the larger (est); the statement the smaller (est_min): leaving out a knot beside a
     * kink loses the kink, and its large miss says nothing about the interval on its other side,
     * which the other witness sees as it is. */
    for (size_t i = 0; est_min && i + 1 < m; i++) {
        double a = wit[2 * i], b = wit[2 * i + 1];
        est_min[i] = isnan(a) && isnan(b) ? est[i] : isnan(a) ? b : isnan(b) ? a : sqrt(a * b);
        /* a corner's own estimate (set above) stands */
        if (est[i] > fmax(isnan(a) ? 0 : a, isnan(b) ? 0 : b)) est_min[i] = est[i];
    }
    for (size_t i = 0; seen && m >= 3 && i + 1 < m; i++)
        if (!seen[i]) {
            double u = unwitnessed_estimate(dv, dl, m, is_channel, i);
            if (u > est[i]) est[i] = u;
            if (est_min && u > est_min[i]) est_min[i] = u;
        }
    hidden_corner_errors(dv, dl, m, is_channel, sd_rel, est, est_min);
    free(seen);
    free(wit);
    /* intervals entirely below 10 % of peak matter less (the accuracy target is stated above it,
     * and contrast there is set by the black level more than by the curve): lower priority */
    for (size_t i = 0; i + 1 < m; i++) {
        if (dl[i + 1] < 0.1 * peak) est[i] *= 0.3;
        if (est[i] > worst) worst = est[i];
    }
    free(tv);
    free(tl);
    return worst;
}
