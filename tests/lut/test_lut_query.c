/* csflut queries: geometric interpolation against a straightforward reference, out-of-grid
 * clamping, never-visible nodes (a finite cap inside a cell, +inf only where every corner is
 * invisible), the issue-10 figures on the bundled example table, the conservative view's properties on noisy tables, the inverse lookup, the radian
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
        /* the stored value at every node (through log2 and exp2: a few ulp) */
        int exact = 1;
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++)
                if (rel_diff(csflut_threshold(t, fx_freq[f], fx_ecc[e]), fx.thr[e * 8 + f]) > 2e-15)
                    exact = 0;
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
    /* geometric blend: at the geometric mean of two frequencies the threshold is the geometric
     * mean of theirs, and so half-way between two eccentricities */
    double mid = csflut_threshold(t, sqrt(2 * 4), 5);
    CHECK(rel_diff(mid, sqrt(fx.thr[8 + 2] * fx.thr[8 + 3])) < 1e-13);
    CHECK(rel_diff(csflut_threshold(t, 8, 25), sqrt(fx.thr[3 * 8 + 4] * fx.thr[4 * 8 + 4])) < 1e-13);
    /* never above the linear blend */
    CHECK(mid <= 0.5 * (fx.thr[8 + 2] + fx.thr[8 + 3]));
    /* clamping to the edges */
    CHECK(rel_diff(csflut_threshold(t, 0.01, 0), fx.thr[0]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 0.0, 0), fx.thr[0]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, -3.0, 0), fx.thr[0]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 1000, 0), fx.thr[7]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, INFINITY, 0), fx.thr[7]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 4, -5), fx.thr[3]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 4, 90), fx.thr[5 * 8 + 3]) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 1e-300, 1e300), fx.thr[5 * 8]) < 2e-15);
    CHECK(isnan(csflut_threshold(t, NAN, 3)));
    CHECK(isnan(csflut_threshold(t, 3, NAN)));
    CHECK(!csflut_perceptible(t, NAN, 0, 1));
    CHECK(isnan(csflut_threshold(NULL, 3, 3)));
    csflut_close(t);
}

static void test_infinity(void)
{
    fx_table fx;
    fx_make(&fx, 22, 0.0, 1.0); /* above contrast 1: never visible (16-32 cpd beyond 0 deg) */
    fx.thr[7] = INFINITY;       /* 32 cpd at 0 deg */
    fx.thr[6] = INFINITY;       /* 24 cpd at 0 deg */
    csflut_table *t = fx_open(&fx.b);
    csflut_set_conservative(t, 0);
    /* +inf only where every corner with a weight is invisible */
    CHECK(isinf(csflut_threshold(t, 32, 0)));
    CHECK(isinf(csflut_threshold(t, 28, 0)));
    CHECK(isinf(csflut_threshold(t, 28, 3)));
    CHECK(isinf(csflut_threshold(t, 50, 45)));
    CHECK(!csflut_perceptible(t, 30, 0, 1.0));
    /* next to a visible node the threshold is close to that node's (finite cap), not +inf */
    double t16 = fx.thr[5], t8_5 = fx.thr[8 + 4];
    double near16 = csflut_threshold(t, 16 * 1.01, 0), near8 = csflut_threshold(t, 8, 5.05);
    CHECK_MSG(isfinite(near16) && near16 >= t16 && near16 < t16 * 1.2, "16.16 cpd: %g vs %g",
              near16, t16);
    CHECK_MSG(isfinite(near8) && near8 < t8_5 * 1.2, "8 cpd at 5.05 deg: %g vs %g", near8, t8_5);
    CHECK(isfinite(csflut_threshold(t, 9, 1))); /* the query: a cell with 3 of 4 visible */
    /* the cap is twice contrast 1 here, so a blend towards it rises monotonically below 2 */
    double prev = t16;
    int rising = 1;
    for (int k = 1; k < 100; k++) {
        double f = 16 * pow(1.5, k / 100.0), th = csflut_threshold(t, f, 0);
        if (!(th >= prev && th < 2.0)) rising = 0;
        prev = th;
    }
    CHECK(rising);
    CHECK(rel_diff(csflut_threshold(t, 16, 0), t16) < 2e-15); /* on the finite node */
    /* the inverse is exact against the new interpolation, also inside a cell with a cap */
    double c = t16 * 1.5;
    double mf = csflut_max_frequency(t, 0, c);
    CHECK_MSG(mf > 16 && mf < 24 && rel_diff(csflut_threshold(t, mf, 0), c) < 1e-11,
              "max_frequency %g, threshold there %g, want %g", mf, csflut_threshold(t, mf, 0), c);
    /* a contrast above the cap is visible up to, not at, the invisible node */
    CHECK(csflut_max_frequency(t, 0, 100.0) == 24);
    CHECK(csflut_max_frequency(t, 0, INFINITY) == 24);
    /* no NaN anywhere */
    csf_rng r;
    csf_rng_init(&r, 22, 2);
    int nan_seen = 0;
    for (int i = 0; i < 5000; i++)
        if (isnan(csflut_threshold(t, rnd_freq(&r), rnd_ecc(&r)))) nan_seen = 1;
    CHECK(!nan_seen);
    csflut_close(t);
}

/* The bundled example table fails safe: thresholds next to visible nodes must come back close to
 * the analytic model the table was made from, not "never visible" or far too high (a renderer
 * would drop detail the person sees); and over a query mix almost no truly visible query may be
 * answered invisible or too high. */
static void test_example_table_fails_safe(const char *path)
{
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_file(path, &t), CSFLUT_OK);
    if (!t) return;
    csf_model_params p = csf_model_default();
    const double q[3][3] = {{9, 1, 0.014}, {8.5, 0.5, 0.010}, {5.7, 10, 0.125}};
    for (int view = 1; view >= 0; view--) {
        csflut_set_conservative(t, view);
        for (int k = 0; k < 3; k++) {
            double truth = csf_model_threshold(&p, q[k][0], q[k][1]);
            double got = csflut_threshold(t, q[k][0], q[k][1]);
            CHECK(fabs(truth - q[k][2]) < 0.001); /* the model values */
            CHECK_MSG(isfinite(got) && fabs(log10(got / truth)) < 0.1,
                      "%g cpd at %g deg (%s view): %g against a true %g", q[k][0], q[k][1],
                      view ? "conservative" : "raw", got, truth);
            CHECK(csflut_perceptible(t, q[k][0], q[k][1], truth * 1.3));
        }
    }
    /* bench_lut's query mix: 0.5-32 cpd log-uniform, 0-40 deg */
    csflut_set_conservative(t, 1);
    csf_rng r;
    csf_rng_init(&r, 2026, 1);
    int n = 200000, visible = 0, invisible = 0, high = 0;
    for (int i = 0; i < n; i++) {
        double f = 0.5 * pow(64.0, csf_rng_next_uniform(&r)), e = 40.0 * csf_rng_next_uniform(&r);
        double truth = csf_model_threshold(&p, f, e);
        if (!(truth <= 1)) continue;
        visible++;
        double got = csflut_threshold(t, f, e);
        if (isinf(got)) invisible++;
        else if (log10(got / truth) > 0.1) high++;
    }
    fprintf(stderr, "example table: %d truly visible queries, %d answered invisible, %d more than "
            "0.1 log10 too high\n", visible, invisible, high);
    CHECK(invisible == 0);
    CHECK(high < visible * 3 / 100); /* interpolating a convex log-CSF errs high between nodes */
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
            double mf = csflut_max_frequency(t, e, c);
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
            double cpr = csflut_max_frequency_cpr(t, e / DEG_PER_RAD, c);
            if (rel_diff(cpr, mf * DEG_PER_RAD) > 1e-12) exact = 0;
            if (rel_diff(csflut_min_wavelength(t, e / DEG_PER_RAD, c), 1 / cpr) > 1e-15) exact = 0;
        }
        CHECK_MSG(reached > 1000, "only %d reachable", reached);
        CHECK(exact);
        CHECK(highest);
        CHECK(edge);
        CHECK(isinf(csflut_min_wavelength(t, 0, 1e-6)));        /* nothing visible */
        CHECK(csflut_min_wavelength(t, 0, 1e6) == 0);            /* everything visible */
        CHECK(isnan(csflut_max_frequency(t, 0, NAN)));
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
    csflut_perceptible_batch(t, f, e, c, vis, N);
    int same = 1, forms = 1, vis_ok = 1;
    for (int i = 0; i < N; i++) {
        double s = csflut_threshold(t, f[i], e[i]);
        if (memcmp(&s, &out[i], 8) != 0 || memcmp(&s, &out4[i], 8) != 0) same = 0;
        if (vis[i] != csflut_perceptible(t, f[i], e[i], c[i])) vis_ok = 0;
        if (i == 7) continue;
        double fc = f[i] * DEG_PER_RAD, er = e[i] / DEG_PER_RAD;
        if (rel_diff(csflut_threshold_cpr(t, fc, er), s) > 1e-12) forms = 0;
        if (rel_diff(csflut_threshold_wavelength(t, 1 / fc, er), s) > 1e-12) forms = 0;
        if (csflut_perceptible_cpr(t, fc, er, s * 1.001) != 1) forms = 0;
        if (csflut_perceptible_wavelength(t, 1 / fc, er, s * 0.999) != 0 && isfinite(s)) forms = 0;
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

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_lut_query EXAMPLE.csflut\n");
        return 2;
    }
    test_raw_matches_reference();
    test_interpolation_and_clamping();
    test_infinity();
    test_example_table_fails_safe(argv[1]);
    test_conservative_view();
    test_max_frequency();
    test_radian_forms_and_batch();
    return CHECK_RESULT();
}
