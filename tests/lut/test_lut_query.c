/* csflut queries: interpolation against a straightforward reference, out-of-grid clamping,
 * infinities, the conservative view's properties on noisy tables, the inverse lookup, the radian
 * and wavelength forms, and the batch API. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

#define DEG_PER_RAD 57.295779513082320876798

static double rnd_freq(csf_rng *r) { return 0.3 * pow(2, 7.0 * csf_rng_next_uniform(r)); } /* 0.3..38 */
static double rnd_ecc(csf_rng *r) { return -2 + 47 * csf_rng_next_uniform(r); }             /* -2..45 */

static void test_raw_matches_reference(void)
{
    for (uint64_t seed = 1; seed <= 5; seed++) {
        fx_table fx;
        fx_make(&fx, seed, 0.1, seed % 2 ? 1.0 : 1e30);
        csflut_table *t = fx_open(&fx.b);
        CHECK(t != NULL);
        if (!t) return;
        csflut_set_conservative(t, 0);
        CHECK_INT_EQ(csflut_get_conservative(t), 0);
        /* exact at every node */
        int exact = 1;
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++)
                if (!(csflut_threshold(t, fx_freq[f], fx_ecc[e]) == fx.thr[e * 8 + f])) exact = 0;
        CHECK(exact);
        /* random points, including outside the grid */
        csf_rng r;
        csf_rng_init(&r, seed, 1);
        double worst = 0;
        for (int i = 0; i < 20000; i++) {
            double f = rnd_freq(&r), e = rnd_ecc(&r);
            double got = csflut_threshold(t, f, e);
            double want = ref_threshold(fx_freq, 8, fx_ecc, 6, fx.thr, f, e);
            double d = rel_diff(got, want);
            if (d > worst) worst = d;
        }
        CHECK_MSG(worst < 1e-10, "worst relative difference %g", worst);
        csflut_close(t);
    }
}

static void test_interpolation_and_clamping(void)
{
    fx_table fx;
    fx_make(&fx, 21, 0.0, 1e30);
    csflut_table *t = fx_open(&fx.b);
    csflut_set_conservative(t, 0);
    /* log-frequency interpolation: the geometric mean of two nodes is the arithmetic mean of
     * their thresholds */
    double mid = csflut_threshold(t, sqrt(2 * 4), 5);
    CHECK(rel_diff(mid, 0.5 * (fx.thr[8 + 2] + fx.thr[8 + 3])) < 1e-13);
    /* linear eccentricity */
    CHECK(rel_diff(csflut_threshold(t, 8, 25), 0.5 * (fx.thr[3 * 8 + 4] + fx.thr[4 * 8 + 4])) < 1e-13);
    /* clamping to the edges */
    CHECK(csflut_threshold(t, 0.01, 0) == fx.thr[0]);
    CHECK(csflut_threshold(t, 0.0, 0) == fx.thr[0]);
    CHECK(csflut_threshold(t, -3.0, 0) == fx.thr[0]);
    CHECK(csflut_threshold(t, 1000, 0) == fx.thr[7]);
    CHECK(csflut_threshold(t, INFINITY, 0) == fx.thr[7]);
    CHECK(csflut_threshold(t, 4, -5) == fx.thr[3]);
    CHECK(csflut_threshold(t, 4, 90) == fx.thr[5 * 8 + 3]);
    CHECK(csflut_threshold(t, 1e-300, 1e300) == fx.thr[5 * 8]);
    CHECK(isnan(csflut_threshold(t, NAN, 3)));
    CHECK(isnan(csflut_threshold(t, 3, NAN)));
    CHECK(!csflut_perceptible(t, NAN, 1, 0));
    CHECK(isnan(csflut_threshold(NULL, 3, 3)));
    csflut_close(t);
}

static void test_infinity(void)
{
    fx_table fx;
    fx_make(&fx, 22, 0.0, 1e30);
    fx.thr[5 * 8 + 7] = INFINITY; /* 32 cpd at 40 deg */
    fx.thr[5 * 8 + 6] = INFINITY; /* 24 cpd at 40 deg */
    csflut_table *t = fx_open(&fx.b);
    csflut_set_conservative(t, 0);
    CHECK(isinf(csflut_threshold(t, 32, 40)));
    CHECK(isinf(csflut_threshold(t, 28, 40)));
    CHECK(isinf(csflut_threshold(t, 20, 40)));       /* between finite 16 and infinite 24 */
    CHECK(isinf(csflut_threshold(t, 32, 35)));       /* between finite 30 deg and infinite 40 */
    CHECK(csflut_threshold(t, 16, 40) == fx.thr[5 * 8 + 5]); /* exactly on the finite node */
    CHECK(csflut_threshold(t, 32, 30) == fx.thr[4 * 8 + 7]);
    CHECK(!csflut_perceptible(t, 30, 1.0, 40));
    CHECK(csflut_perceptible(t, 30, 1.0, 30) == (1.0 >= fx.thr[4 * 8 + 7]) ||
          csflut_perceptible(t, 30, 1.0, 30) == (1.0 >= csflut_threshold(t, 30, 30)));
    /* the inverse stops at the last finite node */
    double c = fx.thr[5 * 8 + 5] * 1.5;
    CHECK(csflut_max_frequency(t, c, 40) == 16);
    /* no NaN anywhere */
    csf_rng r;
    csf_rng_init(&r, 22, 2);
    int nan_seen = 0;
    for (int i = 0; i < 5000; i++)
        if (isnan(csflut_threshold(t, rnd_freq(&r), rnd_ecc(&r)))) nan_seen = 1;
    CHECK(!nan_seen);
    csflut_close(t);
}

static void test_conservative_view(void)
{
    int n_violations = 0;
    for (uint64_t seed = 30; seed < 36; seed++) {
        fx_table fx;
        fx_make(&fx, seed, 0.15, 1.0); /* noisy: raw table is non-monotone */
        csflut_table *t = fx_open(&fx.b);
        CHECK(csflut_get_conservative(t) == 1); /* default on */
        const double *cons = csflut_conservative_thresholds(t);
        /* node rule: never above the raw value, and the minimum over the upper-right quadrant */
        int rule = 1;
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++) {
                double m = INFINITY;
                for (int e2 = e; e2 < 6; e2++)
                    for (int f2 = f; f2 < 8; f2++) m = fmin(m, fx.thr[e2 * 8 + f2]);
                if (!(cons[e * 8 + f] == m)) rule = 0;
                if (!(cons[e * 8 + f] <= fx.thr[e * 8 + f])) rule = 0;
            }
        CHECK(rule);
        /* the raw noisy table violates monotonicity somewhere, otherwise this test is empty */
        csflut_set_conservative(t, 0);
        int raw_violation = 0;
        for (int e = 0; e < 6; e++) {
            int peak = 0;
            for (int f = 1; f < 8; f++)
                if (fx.thr[e * 8 + f] < fx.thr[e * 8 + peak]) peak = f;
            for (int f = peak; f < 7; f++)
                if (fx.thr[e * 8 + f + 1] < fx.thr[e * 8 + f]) raw_violation++;
        }
        for (int e = 0; e < 5; e++)
            for (int f = 0; f < 8; f++)
                if (fx.thr[(e + 1) * 8 + f] < fx.thr[e * 8 + f]) raw_violation++;
        fprintf(stderr, "seed %d: %d raw monotonicity violations\n", (int)seed, raw_violation);
        n_violations += raw_violation;
        csflut_set_conservative(t, 1);
        /* dense sampling: non-decreasing in frequency everywhere and in eccentricity everywhere */
        int mono_f = 1, mono_e = 1, below_peak = 1;
        for (int ie = 0; ie <= 90; ie++) {
            double e = ie * 0.5;
            double prev = 0;
            double peak = csflut_peak_frequency(t, e), tpeak = csflut_threshold(t, peak, e);
            for (int i = 0; i <= 400; i++) {
                double f = 0.2 * pow(2, i * 8.0 / 400);
                double th = csflut_threshold(t, f, e);
                if (th < prev * (1 - 1e-14)) mono_f = 0;
                prev = th;
                if (f < peak && rel_diff(th, tpeak) > 1e-14) below_peak = 0;
                double th_e2 = csflut_threshold(t, f, e + 0.37);
                if (th_e2 < th * (1 - 1e-14)) mono_e = 0;
            }
        }
        CHECK(mono_f);
        CHECK(mono_e);
        CHECK(below_peak);
        /* the conservative view never says "invisible" where the raw view says "visible" */
        csf_rng r;
        csf_rng_init(&r, seed, 3);
        int safe = 1;
        for (int i = 0; i < 5000; i++) {
            double f = rnd_freq(&r), e = rnd_ecc(&r);
            csflut_set_conservative(t, 0);
            double raw = csflut_threshold(t, f, e);
            csflut_set_conservative(t, 1);
            if (csflut_threshold(t, f, e) > raw) safe = 0;
        }
        CHECK(safe);
        /* shift by k standard errors: nodes with known stderr drop by 10^(-k se) before the
         * envelope; unknown stderr is not shifted */
        CHECK_INT_EQ(csflut_set_stderr_shift(t, 2.0), CSFLUT_OK);
        CHECK(csflut_get_stderr_shift(t) == 2.0);
        cons = csflut_conservative_thresholds(t);
        int shift_ok = 1;
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++) {
                double m = INFINITY;
                for (int e2 = e; e2 < 6; e2++)
                    for (int f2 = f; f2 < 8; f2++) {
                        int k = e2 * 8 + f2;
                        double v = fx.thr[k];
                        if (isfinite(fx.se[k]) && isfinite(v)) v *= pow(10, -2.0 * fx.se[k]);
                        m = fmin(m, v);
                    }
                if (rel_diff(cons[e * 8 + f], m) > 1e-15) shift_ok = 0;
            }
        CHECK(shift_ok);
        CHECK_INT_EQ(csflut_set_stderr_shift(t, -1), CSFLUT_E_ARG);
        CHECK_INT_EQ(csflut_set_stderr_shift(t, NAN), CSFLUT_E_ARG);
        csflut_close(t);
    }
    CHECK(n_violations >= 3); /* the noisy tables really needed the conservative rule */
}

static void test_max_frequency(void)
{
    for (int view = 0; view < 2; view++) {
        fx_table fx;
        fx_make(&fx, 40 + (uint64_t)view, 0.1, 1.0);
        csflut_table *t = fx_open(&fx.b);
        csflut_set_conservative(t, view);
        csf_rng r;
        csf_rng_init(&r, 40, (uint64_t)view);
        int reached = 0, exact = 1, highest = 1, edge = 1;
        for (int i = 0; i < 4000; i++) {
            double e = 45 * csf_rng_next_uniform(&r);
            double c = pow(10, -2.6 + 2.8 * csf_rng_next_uniform(&r)); /* 0.0025 .. 1.6 */
            double mf = csflut_max_frequency(t, c, e);
            if (isinf(mf)) {
                if (!(csflut_threshold(t, 32, e) <= c)) edge = 0;
                continue;
            }
            if (mf == 0) {
                /* not visible anywhere on the grid */
                for (int f = 0; f < 8; f++)
                    if (csflut_threshold(t, fx_freq[f], e) <= c) edge = 0;
                continue;
            }
            reached++;
            double th = csflut_threshold(t, mf, e);
            if (rel_diff(th, c) > 1e-11 && !(th < c && csflut_threshold(t, mf * 1.0000001, e) > c)) {
                exact = 0;
                fprintf(stderr, "c=%g e=%g mf=%g th=%g\n", c, e, mf, th);
            }
            /* nothing above it is visible */
            for (double f = mf * 1.001; f < 40; f *= 1.05)
                if (csflut_threshold(t, f, e) <= c) highest = 0;
            /* and the result agrees with the radian / wavelength forms */
            double cpr = csflut_max_frequency_cpr(t, c, e / DEG_PER_RAD);
            if (rel_diff(cpr, mf * DEG_PER_RAD) > 1e-12) exact = 0;
            if (rel_diff(csflut_min_wavelength(t, c, e / DEG_PER_RAD), 1 / cpr) > 1e-15) exact = 0;
        }
        CHECK_MSG(reached > 1000, "only %d reachable", reached);
        CHECK(exact);
        CHECK(highest);
        CHECK(edge);
        CHECK(isinf(csflut_min_wavelength(t, 1e-6, 0)));        /* nothing visible */
        CHECK(csflut_min_wavelength(t, 1e6, 0) == 0);            /* everything visible */
        CHECK(isnan(csflut_max_frequency(t, NAN, 0)));
        csflut_close(t);
    }
}

static void test_radian_forms_and_batch(void)
{
    fx_table fx;
    fx_make(&fx, 50, 0.1, 1.0);
    csflut_table *t = fx_open(&fx.b);
    csf_rng r;
    csf_rng_init(&r, 50, 1);
    enum { N = 4099 };
    double *f = malloc(N * sizeof *f), *e = malloc(N * sizeof *e), *c = malloc(N * sizeof *c);
    double *out = malloc(N * sizeof *out), *out4 = malloc(N * sizeof *out4);
    unsigned char *vis = malloc(N);
    for (int i = 0; i < N; i++) {
        f[i] = rnd_freq(&r);
        e[i] = rnd_ecc(&r);
        c[i] = pow(10, -2.5 + 2 * csf_rng_next_uniform(&r));
    }
    f[7] = NAN;
    csflut_threshold_batch(t, f, e, out, N);
    csflut_threshold4_batch(t, f, e, NULL, NULL, out4, N);
    csflut_perceptible_batch(t, f, c, e, vis, N);
    int same = 1, forms = 1, vis_ok = 1;
    for (int i = 0; i < N; i++) {
        double s = csflut_threshold(t, f[i], e[i]);
        if (memcmp(&s, &out[i], 8) != 0 || memcmp(&s, &out4[i], 8) != 0) same = 0;
        if (vis[i] != csflut_perceptible(t, f[i], c[i], e[i])) vis_ok = 0;
        if (i == 7) continue;
        double fc = f[i] * DEG_PER_RAD, er = e[i] / DEG_PER_RAD;
        if (rel_diff(csflut_threshold_cpr(t, fc, er), s) > 1e-12) forms = 0;
        if (rel_diff(csflut_threshold_wavelength(t, 1 / fc, er), s) > 1e-12) forms = 0;
        if (csflut_perceptible_cpr(t, fc, s * 1.001, er) != 1) forms = 0;
        if (csflut_perceptible_wavelength(t, 1 / fc, s * 0.999, er) != 0 && isfinite(s)) forms = 0;
    }
    CHECK(same);
    CHECK(vis_ok);
    CHECK(forms);
    CHECK(isnan(out[7]) && vis[7] == 0);
    free(f);
    free(e);
    free(c);
    free(out);
    free(out4);
    free(vis);
    csflut_close(t);
}

int main(void)
{
    test_raw_matches_reference();
    test_interpolation_and_clamping();
    test_infinity();
    test_conservative_view();
    test_max_frequency();
    test_radian_forms_and_batch();
    return CHECK_RESULT();
}
