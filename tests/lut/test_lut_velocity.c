/* csflut with a velocity axis (freq x ecc x velocity, as the observer calibration writes): the
 * warp log(|v| + 0.5) against a straightforward reference, finite at v = 0; never-visible nodes
 * along velocity (no fail-open next to them); the conservative view slice by slice; the inverse
 * lookup at a velocity; the 2-D, 3-D, 4-D and batch paths agreeing bit for bit. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_velocity.h"
#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

enum { NV = 5, NODES = 8 * 6 * NV };
static const double vel[NV] = {0, 1, 4, 8, 16};

typedef struct {
    double thr[NODES], se[NODES];
    csflut_build b;
} v_table;

/* Model thresholds times the Kelly-Daly velocity gain (model/csf_velocity.h), with log-normal
 * noise; above inf_above written as never visible. */
static void v_make(v_table *t, uint64_t seed, double noise_log10, double inf_above)
{
    csf_model_params p = csf_model_default();
    csf_velocity_params vp = csf_velocity_default();
    for (int v = 0; v < NV; v++)
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++) {
                int k = (v * 6 + e) * 8 + f;
                double th = csf_model_threshold(&p, fx_freq[f], fx_ecc[e]) /
                            pow(10.0, csf_velocity_log10_gain(&vp, fx_freq[f], vel[v]));
                th *= pow(10.0, noise_log10 * csf_rng_normal(seed, 11, (uint64_t)k));
                t->thr[k] = th > inf_above ? INFINITY : th;
                t->se[k] = 0.04;
            }
    memset(&t->b, 0, sizeof t->b);
    t->b = (csflut_build){.n_freq = 8,
                          .n_ecc = 6,
                          .n_vel = NV,
                          .freq_cpd = fx_freq,
                          .ecc_deg = fx_ecc,
                          .vel_dps = vel,
                          .threshold = t->thr,
                          .stderr_log10 = t->se};
}

/* The documented interpolation the plain way: natural-log thresholds blended trilinearly in
 * (ln f, ecc, ln(|v| + 0.5)), clamped; an invisible node as the cap; +inf only when every corner
 * with a non-zero weight is invisible. */
static int cell_of(const double *x, int n, double q, double *w)
{
    if (q <= x[0]) {
        *w = 0;
        return 0;
    }
    if (q >= x[n - 1]) {
        *w = 1;
        return n - 2;
    }
    int i = 0;
    while (i < n - 2 && q >= x[i + 1]) i++;
    *w = (q - x[i]) / (x[i + 1] - x[i]);
    return i;
}

static double ref3(const double *v, double f, double e, double vq)
{
    double lf[8], lv[NV], wf, we, wv;
    for (int i = 0; i < 8; i++) lf[i] = log(fx_freq[i]);
    for (int i = 0; i < NV; i++) lv[i] = log(vel[i] + CSF_VELOCITY_WARP_V0_DPS);
    int i = cell_of(lf, 8, log(f), &wf), j = cell_of(fx_ecc, 6, e, &we);
    int k = cell_of(lv, NV, log(fabs(vq) + CSF_VELOCITY_WARP_V0_DPS), &wv);
    double cap = ref_cap_ln(v, NODES), sum = 0;
    int visible = 0;
    for (int c = 0; c < 8; c++) {
        int di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
        double w = (di ? wf : 1 - wf) * (dj ? we : 1 - we) * (dk ? wv : 1 - wv);
        double x = v[((k + dk) * 6 + j + dj) * 8 + i + di];
        if (w > 0 && isfinite(x)) visible = 1;
        sum += w * (isfinite(x) ? log(x) : cap);
    }
    return visible ? exp(sum) : INFINITY;
}

static double rnd_vel(csf_rng *r)
{
    return -20 + 60 * csf_rng_next_uniform(r);
} /* -20..40 */

static void test_warp_matches_reference(void)
{
    for (uint64_t seed = 1; seed <= 4; seed++) {
        v_table vt;
        v_make(&vt, seed, 0.1, seed % 2 ? 1.0 : 1e30);
        csflut_table *t = fx_open(&vt.b);
        CHECK(t != NULL);
        if (!t) return;
        CHECK(csflut_velocity_warp_v0(t) == CSF_VELOCITY_WARP_V0_DPS);
        csflut_set_conservative(t, 0);
        int exact = 1;
        for (int v = 0; v < NV; v++)
            for (int e = 0; e < 6; e++)
                for (int f = 0; f < 8; f++)
                    if (rel_diff(csflut_threshold3(t, fx_freq[f], fx_ecc[e], vel[v]),
                                 vt.thr[(v * 6 + e) * 8 + f]) > 5e-14)
                        exact = 0; /* through log2 and exp2: ulps of log2 x, up to 80 here */
        CHECK_MSG(exact, "seed %llu: a node does not return its value", (unsigned long long)seed);
        csf_rng r;
        csf_rng_init(&r, seed, 3);
        double worst = 0;
        int at_zero = 0;
        for (int q = 0; q < 20000; q++) {
            double f = 0.3 * pow(2, 7.0 * csf_rng_next_uniform(&r));
            double e = -2 + 47 * csf_rng_next_uniform(&r), v = q % 10 ? rnd_vel(&r) : 0.0;
            double got = csflut_threshold3(t, f, e, v), want = ref3(vt.thr, f, e, v);
            double d = rel_diff(got, want);
            if (d > worst) worst = d;
            if (v == 0 && isfinite(got)) at_zero++;
        }
        CHECK_MSG(worst < 1e-10, "seed %llu: worst relative difference %g", (unsigned long long)seed, worst);
        CHECK(at_zero > 0); /* v = 0 is an ordinary, finite query */
        /* half-way in the warp between 1 and 4 deg/s: the geometric mean of the two slices */
        double vm = sqrt(1.5 * 4.5) - 0.5, a = vt.thr[(1 * 6 + 0) * 8 + 3], b = vt.thr[(2 * 6 + 0) * 8 + 3];
        if (isfinite(a) && isfinite(b)) CHECK(rel_diff(csflut_threshold3(t, 4, 0, vm), sqrt(a * b)) < 1e-13);
        /* drift direction does not matter */
        CHECK(csflut_threshold3(t, 3, 2, -2.5) == csflut_threshold3(t, 3, 2, 2.5));
        CHECK(isnan(csflut_threshold3(t, 3, 2, NAN)));
        CHECK(isnan(csflut_threshold3(t, NAN, 2, 1)));
        CHECK(!csflut_perceptible3(t, 3, 2, NAN, 1));
        csflut_close(t);
    }
}

/* Every query path agrees bit for bit: 2-D at the lowest velocity, 3-D, 4-D, the batches. */
static void test_paths_agree(void)
{
    v_table vt;
    v_make(&vt, 9, 0.12, 1.0);
    csflut_table *t = fx_open(&vt.b);
    CHECK(t != NULL);
    if (!t) return;
    enum { N = 5000 };
    static double f[N], e[N], v[N], out3[N], out4[N];
    csf_rng r;
    csf_rng_init(&r, 9, 4);
    for (int i = 0; i < N; i++) {
        f[i] = 0.3 * pow(2, 7.0 * csf_rng_next_uniform(&r));
        e[i] = -2 + 47 * csf_rng_next_uniform(&r);
        v[i] = i % 7 ? rnd_vel(&r) : (i % 2 ? 0.0 : NAN);
    }
    for (int view = 0; view < 2; view++) {
        csflut_set_conservative(t, view);
        csflut_threshold3_batch(t, f, e, v, out3, N);
        csflut_threshold4_batch(t, f, e, v, NULL, out4, N);
        int same = 1, same2d = 1;
        for (int i = 0; i < N; i++) {
            double s3 = csflut_threshold3(t, f[i], e[i], v[i]);
            double s4 = csflut_threshold4(t, f[i], e[i], v[i], 123);
            if (memcmp(&s3, &out3[i], 8) || memcmp(&s3, &s4, 8) || memcmp(&s3, &out4[i], 8)) same = 0;
            double s2 = csflut_threshold(t, f[i], e[i]), s0 = csflut_threshold3(t, f[i], e[i], 0);
            if (memcmp(&s2, &s0, 8)) same2d = 0;
        }
        CHECK_MSG(same, "view %d: scalar, batch and 4-D queries differ", view);
        CHECK_MSG(same2d, "view %d: the 2-D query is not the 3-D one at v = 0", view);
    }
    csflut_close(t);
    /* velocity nodes too close for the bucketed search: the batch takes the general path */
    const double vclose[4] = {0, 1e-6, 2e-6, 100};
    vt.b.vel_dps = vclose;
    vt.b.n_vel = 4;
    t = fx_open(&vt.b);
    CHECK(t != NULL);
    if (!t) return;
    csflut_threshold3_batch(t, f, e, v, out3, N);
    int same = 1;
    for (int i = 0; i < N; i++) {
        double s3 = csflut_threshold3(t, f[i], e[i], v[i]);
        if (memcmp(&s3, &out3[i], 8)) same = 0;
    }
    CHECK(same);
    csflut_close(t);
}

/* Never visible along velocity: a query next to a visible node stays close to it; +inf only
 * where every weighted corner is invisible. */
static void test_no_fail_open_along_velocity(void)
{
    v_table vt;
    v_make(&vt, 13, 0.0, 1e30);
    /* at 8 and 16 deg/s every node at 16 and 32 cpd is never visible */
    for (int v = 3; v < NV; v++)
        for (int e = 0; e < 6; e++)
            for (int f = 5; f < 8; f++) vt.thr[(v * 6 + e) * 8 + f] = INFINITY;
    csflut_table *t = fx_open(&vt.b);
    CHECK(t != NULL);
    if (!t) return;
    csflut_set_conservative(t, 0);
    double near = csflut_threshold3(t, 16, 0, 4.000001), node = vt.thr[(2 * 6 + 0) * 8 + 5];
    CHECK_MSG(isfinite(near) && rel_diff(near, node) < 1e-3, "next to a visible node: %g vs %g", near, node);
    /* between 4 and 8 deg/s the threshold rises towards the invisible slice but stays finite */
    double prev = 0;
    int finite_rising = 1;
    for (int k = 0; k <= 100; k++) {
        double vq = 4 + 4 * k / 100.0, th = csflut_threshold3(t, 16, 0, vq);
        if (k < 100 && (!isfinite(th) || th < prev)) finite_rising = 0;
        if (k == 100 && !isinf(th)) finite_rising = 0;
        prev = th;
    }
    CHECK(finite_rising);
    CHECK(isinf(csflut_threshold3(t, 20, 3, 12)));    /* every corner invisible */
    CHECK(isinf(csflut_threshold3(t, 32, 40, 100)));  /* clamped beyond them */
    CHECK(isfinite(csflut_threshold3(t, 12, 3, 12))); /* 8 cpd corners are visible */
    csflut_close(t);
}

/* The conservative view is the quadrant minimum within each velocity slice, and only there. */
static void test_conservative_per_slice(void)
{
    v_table vt;
    v_make(&vt, 17, 0.15, 1.0);
    csflut_table *t = fx_open(&vt.b);
    CHECK(t != NULL);
    if (!t) return;
    const double *cons = csflut_conservative_thresholds(t);
    int rule = 1, below_raw = 1;
    for (int v = 0; v < NV; v++)
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++) {
                double m = INFINITY;
                for (int e2 = e; e2 < 6; e2++)
                    for (int f2 = f; f2 < 8; f2++) m = fmin(m, vt.thr[(v * 6 + e2) * 8 + f2]);
                int k = (v * 6 + e) * 8 + f;
                if (!(cons[k] == m)) rule = 0;
                if (!(cons[k] <= vt.thr[k])) below_raw = 0;
            }
    CHECK(rule);
    CHECK(below_raw);
    /* queries never fall as frequency or eccentricity rises, at any velocity */
    csf_rng r;
    csf_rng_init(&r, 17, 5);
    int monotone = 1;
    for (int q = 0; q < 2000; q++) {
        double f = 0.3 * pow(2, 7.0 * csf_rng_next_uniform(&r)), e = 45 * csf_rng_next_uniform(&r);
        double v = rnd_vel(&r), th = csflut_threshold3(t, f, e, v);
        double floor = th * (1 - 1e-14); /* blends of equal nodes round in the last place */
        if (csflut_threshold3(t, f * 1.05, e, v) < floor || csflut_threshold3(t, f, e + 0.7, v) < floor)
            monotone = 0;
    }
    CHECK(monotone);
    /* slices are independent: lowering every node of the 16 deg/s slice changes no other */
    double before = csflut_threshold3(t, 8, 10, 4);
    for (int k = 4 * 48; k < 5 * 48; k++) vt.thr[k] = 1e-4;
    csflut_table *t2 = fx_open(&vt.b);
    CHECK(t2 != NULL);
    if (t2) {
        CHECK(csflut_threshold3(t2, 8, 10, 4) == before);
        CHECK(rel_diff(csflut_threshold3(t2, 8, 10, 16), 1e-4) < 1e-14);
        csflut_close(t2);
    }
    csflut_close(t);
}

/* max_frequency4 at a velocity inverts csflut_threshold3 and is the highest crossing. */
static void test_max_frequency_at_velocity(void)
{
    v_table vt;
    v_make(&vt, 23, 0.1, 1.0);
    csflut_table *t = fx_open(&vt.b);
    CHECK(t != NULL);
    if (!t) return;
    csf_rng r;
    csf_rng_init(&r, 23, 6);
    int inside = 0, inverts = 1, highest = 1;
    for (int view = 0; view < 2; view++) {
        csflut_set_conservative(t, view);
        for (int q = 0; q < 400; q++) {
            double e = 45 * csf_rng_next_uniform(&r), v = q % 5 ? rnd_vel(&r) : 0.0;
            double c = pow(10, -2.5 + 2.5 * csf_rng_next_uniform(&r));
            double mf = csflut_max_frequency4(t, e, v, 50, c);
            if (mf > 0.5 && mf < 32) {
                inside++;
                if (rel_diff(csflut_threshold3(t, mf, e, v), c) > 1e-11) inverts = 0;
            }
            /* nothing above it is visible (raw view too: the highest crossing) */
            double lo = mf > 0.5 ? mf : 0.5;
            if (isfinite(mf))
                for (double f = lo * 1.001; f <= 32; f *= 1.01)
                    if (csflut_threshold3(t, f, e, v) <= c * (1 - 1e-12)) highest = 0;
            if (isinf(mf) && !(csflut_threshold3(t, 32, e, v) <= c)) highest = 0;
        }
    }
    CHECK(inside > 100);
    CHECK(inverts);
    CHECK(highest);
    CHECK(csflut_max_frequency4(t, 0, 4, 50, 1e-6) == 0);
    /* above every finite threshold: visible at every frequency, or up to the first invisible
     * node from the top */
    CHECK(isinf(csflut_max_frequency4(t, 0, 4, 50, 1e6)) == (csflut_threshold3(t, 32, 0, 4) <= 1e6));
    CHECK(isnan(csflut_max_frequency4(t, 0, NAN, 50, 0.1)));
    /* at the lowest velocity it is the 2-D inverse */
    CHECK(csflut_max_frequency4(t, 7, 0, 50, 0.02) == csflut_max_frequency(t, 7, 0.02));
    csflut_close(t);
}

int main(void)
{
    test_warp_matches_reference();
    test_paths_agree();
    test_no_fail_open_along_velocity();
    test_conservative_per_slice();
    test_max_frequency_at_velocity();
    return CHECK_RESULT();
}
