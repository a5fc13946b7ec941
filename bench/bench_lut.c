/* bench_lut: threshold lookups per second on one core over a realistic 8 x 6 table (the default
 * model observer, never-visible cells as +inf), scalar and batch, against the analytic CSF the
 * table was made from (log-parabola x stelaCSF eccentricity, model/csf_model.h), in the same
 * run; exactness checked against a straightforward reference interpolator (libm log and exp,
 * linear cell search); and how often a truly visible query (analytic threshold <= 1) is answered
 * too high or "never visible", by the library and by the linear blend it had before 2.0.0. Then
 * the same for an 8 x 6 x 5 table with a velocity axis (0-16 deg/s, the model times the
 * Kelly-Daly velocity gain of model/csf_velocity.h), scalar and batch, whose batch rate is
 * compared with the 2-D batch rate (target: at least half).
 *   usage: bench_lut [N_QUERIES]   (default 2,000,000) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/csf_model.h"
#include "model/csf_velocity.h"
#include "results/csflut/csflut.h"
#include "core/rng.h"

static const double freq[8] = {0.5, 1, 2, 4, 8, 16, 24, 32};
static const double ecc[6] = {0, 5, 10, 20, 30, 40};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts); /* CPU time: the machine is shared */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void cell(double f, double e, int *i, int *j, double *wf, double *we)
{
    f = fmin(fmax(f, freq[0]), freq[7]);
    e = fmin(fmax(e, ecc[0]), ecc[5]);
    *i = 0;
    *j = 0;
    while (*i < 6 && f >= freq[*i + 1]) (*i)++;
    while (*j < 4 && e >= ecc[*j + 1]) (*j)++;
    *wf = (log(f) - log(freq[*i])) / (log(freq[*i + 1]) - log(freq[*i]));
    *we = (e - ecc[*j]) / (ecc[*j + 1] - ecc[*j]);
}

/* Before csflut 2.0.0: linear blend of thresholds, one +inf corner makes the cell +inf. */
static double old_lerp(double a, double b, double w)
{
    if (w <= 0) return a;
    if (w >= 1) return b;
    if (isinf(a) || isinf(b)) return INFINITY;
    return a + (b - a) * w;
}

static double old_threshold(const double *v, double f, double e)
{
    int i, j;
    double wf, we;
    cell(f, e, &i, &j, &wf, &we);
    return old_lerp(old_lerp(v[j * 8 + i], v[j * 8 + i + 1], wf),
                    old_lerp(v[(j + 1) * 8 + i], v[(j + 1) * 8 + i + 1], wf), we);
}

/* The documented interpolation, the plain way: natural-log thresholds blended, an invisible node
 * as the cap (2^cap_log2 with cap_log2 the smallest power of two >= log2(max(1, highest finite))
 * + 1), +inf only when every weighted corner is invisible. */
static double ref_threshold(const double *v, double f, double e)
{
    int i, j;
    double wf, we;
    cell(f, e, &i, &j, &wf, &we);
    double m = 1, cap = 1;
    for (int k = 0; k < 48; k++)
        if (isfinite(v[k]) && v[k] > m) m = v[k];
    while (cap < log2(m) + 1) cap *= 2;
    cap *= log(2);
    const double w[4] = {(1 - wf) * (1 - we), wf * (1 - we), (1 - wf) * we, wf * we};
    const double c[4] = {v[j * 8 + i], v[j * 8 + i + 1], v[(j + 1) * 8 + i], v[(j + 1) * 8 + i + 1]};
    double sum = 0;
    int visible = 0;
    for (int k = 0; k < 4; k++) {
        if (w[k] > 0 && isfinite(c[k])) visible = 1;
        sum += w[k] * (isfinite(c[k]) ? log(c[k]) : cap);
    }
    return visible ? exp(sum) : INFINITY;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Of the truly visible queries: how many answered +inf, how many higher than the truth, and the
 * median / 90th percentile / maximum excess in log10 among those answered too high. */
static void fail_open_report(const char *name, const double *got, const double *truth, size_t n)
{
    size_t visible = 0, n_inf = 0, n_high = 0, n_high01 = 0;
    double *ex = malloc(n * sizeof *ex);
    if (!ex) return;
    for (size_t i = 0; i < n; i++) {
        if (!(truth[i] <= 1)) continue;
        visible++;
        if (isinf(got[i])) n_inf++;
        else if (got[i] > truth[i]) {
            ex[n_high++] = log10(got[i] / truth[i]);
            if (ex[n_high - 1] > 0.1) n_high01++;
        }
    }
    qsort(ex, n_high, sizeof *ex, cmp_double);
    printf("%-30s %8.2f %% %8.2f %% %8.2f %% %+8.3f %+8.3f %+8.3f\n", name,
           100.0 * (double)n_inf / (double)visible, 100.0 * (double)n_high / (double)visible,
           100.0 * (double)n_high01 / (double)visible, n_high ? ex[n_high / 2] : 0.0,
           n_high ? ex[n_high * 9 / 10] : 0.0, n_high ? ex[n_high - 1] : 0.0);
    free(ex);
}

/* ---- the 3-D table: frequency x eccentricity x velocity ---------------------------------- */
static const double vel[5] = {0, 1, 4, 8, 16};

/* The documented 3-D interpolation the plain way (raw view): natural-log thresholds blended
 * trilinearly in (ln f, ecc, ln(|v| + 0.5)), invisible nodes as the cap. */
static double ref_threshold3(const double *v, double cap_ln, double f, double e, double vq)
{
    int i, j, k = 0;
    double wf, we, wv;
    cell(f, e, &i, &j, &wf, &we);
    double c = log(fmin(fabs(vq), vel[4]) + CSF_VELOCITY_WARP_V0_DPS);
    while (k < 3 && c >= log(vel[k + 1] + CSF_VELOCITY_WARP_V0_DPS)) k++;
    wv = (c - log(vel[k] + CSF_VELOCITY_WARP_V0_DPS)) /
         (log(vel[k + 1] + CSF_VELOCITY_WARP_V0_DPS) - log(vel[k] + CSF_VELOCITY_WARP_V0_DPS));
    double sum = 0;
    int visible = 0;
    for (int q = 0; q < 8; q++) {
        int di = q & 1, dj = (q >> 1) & 1, dk = q >> 2;
        double w = (di ? wf : 1 - wf) * (dj ? we : 1 - we) * (dk ? wv : 1 - wv);
        double x = v[((k + dk) * 6 + j + dj) * 8 + i + di];
        if (w > 0 && isfinite(x)) visible = 1;
        sum += w * (isfinite(x) ? log(x) : cap_ln);
    }
    return visible ? exp(sum) : INFINITY;
}

typedef struct {
    const csflut_table *t;
    const csf_model_params *p;
    const double *f, *e, *v;
    double *out;
    size_t n;
} job;

static void run_scalar(job *j)
{
    for (size_t i = 0; i < j->n; i++) j->out[i] = csflut_threshold(j->t, j->f[i], j->e[i]);
}
static void run_batch(job *j) { csflut_threshold_batch(j->t, j->f, j->e, j->out, j->n); }
static void run_scalar3(job *j)
{
    for (size_t i = 0; i < j->n; i++) j->out[i] = csflut_threshold3(j->t, j->f[i], j->e[i], j->v[i]);
}
static void run_batch3(job *j)
{
    csflut_threshold3_batch(j->t, j->f, j->e, j->v, j->out, j->n);
}
static void run_model(job *j)
{
    for (size_t i = 0; i < j->n; i++) j->out[i] = csf_model_threshold(j->p, j->f[i], j->e[i]);
}

/* Best of 5 timed passes (the machine is shared; the best pass is the least disturbed). */
static double rate(void (*fn)(job *), job *j)
{
    double best = 1e30;
    fn(j); /* warm caches */
    for (int rep = 0; rep < 5; rep++) {
        double t0 = now_s();
        fn(j);
        double dt = now_s() - t0;
        if (dt < best) best = dt;
    }
    return (double)j->n / best;
}

/* The 3-D table's lookups, its exactness against ref_threshold3, and its batch rate against the
 * 2-D batch rate r_batch2. Returns 1 when exact. */
static int bench3(const csf_model_params *p, const double *f, const double *e, double *out, size_t n,
                  double r_batch2)
{
    csf_velocity_params vp = csf_velocity_default();
    double thr[8 * 6 * 5], m = 1;
    for (int k = 0; k < 5; k++)
        for (int q = 0; q < 6; q++)
            for (int i = 0; i < 8; i++) {
                double th = csf_model_threshold(p, freq[i], ecc[q]) /
                            pow(10.0, csf_velocity_log10_gain(&vp, freq[i], vel[k]));
                thr[(k * 6 + q) * 8 + i] = th > 1 ? INFINITY : th;
                if (th <= 1 && th > m) m = th;
            }
    csflut_build b = {.n_freq = 8,
                      .n_ecc = 6,
                      .n_vel = 5,
                      .freq_cpd = freq,
                      .ecc_deg = ecc,
                      .vel_dps = vel,
                      .threshold = thr};
    unsigned char *buf;
    size_t len;
    csflut_table *t = NULL;
    if (csflut_write_memory(&b, &buf, &len) != CSFLUT_OK || csflut_open_memory(buf, len, &t) != CSFLUT_OK)
        return 0;
    free(buf);
    double *v = malloc(n * sizeof *v);
    if (!v) return 0;
    csf_rng r;
    csf_rng_init(&r, 2026, 2);
    for (size_t i = 0; i < n; i++) v[i] = 16.0 * csf_rng_next_uniform(&r); /* 0 .. 16 deg/s */
    job j = {t, p, f, e, v, out, n};
    csflut_set_conservative(t, 0);
    run_batch3(&j);
    double cap = 1;
    while (cap < log2(m) + 1) cap *= 2;
    double worst = 0;
    size_t n_bad = 0;
    for (size_t i = 0; i < n; i++) {
        double want = ref_threshold3(thr, cap * log(2), f[i], e[i], v[i]), got = out[i];
        if (isinf(want) || isinf(got)) {
            n_bad += got != want;
            continue;
        }
        double d = fabs(got - want) / fabs(want);
        if (d > worst) worst = d;
    }
    csflut_set_conservative(t, 1);
    double r_scalar = rate(run_scalar3, &j), r_batch = rate(run_batch3, &j);
    printf("\n%zu random 3-D queries over an 8 x 6 x 5 table (velocity 0-16 deg/s uniform, warp\n"
           "log(v + 0.5); the 2-D mix above), one thread, best of 5 passes\n\n",
           n);
    printf("%-36s %12s %10s %14s\n", "method", "Mlookups/s", "ns/lookup", "vs 2-D batch");
    printf("%-36s %12.1f %10.2f %13.1f%%\n", "csflut_threshold3 (scalar, cons.)", r_scalar / 1e6,
           1e9 / r_scalar, 100 * r_scalar / r_batch2);
    printf("%-36s %12.1f %10.2f %13.1f%%\n", "csflut_threshold3_batch", r_batch / 1e6, 1e9 / r_batch,
           100 * r_batch / r_batch2);
    printf("exactness vs reference (raw view): max relative difference %.3g, %zu disagreeing on "
           "infinity\n",
           worst, n_bad);
    printf("target: 3-D batch >= 50 %% of the 2-D batch rate %s\n",
           r_batch >= 0.5 * r_batch2 ? "MET" : "NOT MET");
    csflut_close(t);
    free(v);
    return worst <= 1e-6 && n_bad == 0;
}

int main(int argc, char **argv)
{
    size_t n = 2000000;
    if (argc > 1) {
        char *end;
        long v = strtol(argv[1], &end, 10);
        if (*end || v < 1000 || v > 100000000) {
            fprintf(stderr, "bench_lut: N_QUERIES must be 1000 to 100000000\n");
            return 2;
        }
        n = (size_t)v;
    }
    csf_model_params p = csf_model_default();
    double thr[48];
    for (int e = 0; e < 6; e++)
        for (int f = 0; f < 8; f++) {
            double t = csf_model_threshold(&p, freq[f], ecc[e]);
            thr[e * 8 + f] = t > 1 ? INFINITY : t;
        }
    csflut_build b = {.n_freq = 8, .n_ecc = 6, .freq_cpd = freq, .ecc_deg = ecc, .threshold = thr};
    unsigned char *buf;
    size_t len;
    csflut_table *t = NULL;
    if (csflut_write_memory(&b, &buf, &len) != CSFLUT_OK || csflut_open_memory(buf, len, &t) != CSFLUT_OK) {
        fprintf(stderr, "bench_lut: cannot build the table\n");
        return 1;
    }
    free(buf);
    double *f = malloc(n * sizeof *f), *e = malloc(n * sizeof *e), *out = malloc(n * sizeof *out);
    if (!f || !e || !out) return 1;
    csf_rng r;
    csf_rng_init(&r, 2026, 1);
    for (size_t i = 0; i < n; i++) {
        f[i] = 0.5 * pow(64.0, csf_rng_next_uniform(&r)); /* log-uniform 0.5 .. 32 cpd */
        e[i] = 40.0 * csf_rng_next_uniform(&r);
    }
    job j = {t, &p, f, e, NULL, out, n};

    /* exactness first (raw view: the reference knows no conservative rule) */
    csflut_set_conservative(t, 0);
    run_batch(&j);
    double worst = 0;
    size_t n_inf = 0, n_bad = 0;
    for (size_t i = 0; i < n; i++) {
        double want = ref_threshold(thr, f[i], e[i]), got = out[i];
        if (isinf(want) || isinf(got)) {
            n_inf++;
            if (got != want) n_bad++;
            continue;
        }
        double d = fabs(got - want) / fabs(want);
        if (d > worst) worst = d;
    }
    double r_scalar_raw = rate(run_scalar, &j);
    csflut_set_conservative(t, 1);
    double r_scalar = rate(run_scalar, &j), r_batch = rate(run_batch, &j), r_model = rate(run_model, &j);

    printf("bench_lut: %zu random 2-D queries over an 8 x 6 table (0.5-32 cpd log-uniform, 0-40 deg),\n"
           "one thread, best of 5 passes\n\n", n);
    printf("%-36s %12s %10s %14s\n", "method", "Mlookups/s", "ns/lookup", "vs analytic");
    printf("%-36s %12.1f %10.2f %13.1fx\n", "csflut_threshold (scalar, conservative)", r_scalar / 1e6,
           1e9 / r_scalar, r_scalar / r_model);
    printf("%-36s %12.1f %10.2f %13.1fx\n", "csflut_threshold (scalar, raw)", r_scalar_raw / 1e6,
           1e9 / r_scalar_raw, r_scalar_raw / r_model);
    printf("%-36s %12.1f %10.2f %13.1fx\n", "csflut_threshold_batch", r_batch / 1e6, 1e9 / r_batch,
           r_batch / r_model);
    printf("%-36s %12.1f %10.2f %13.1fx\n", "analytic CSF (csf_model_threshold)", r_model / 1e6,
           1e9 / r_model, 1.0);
    printf("\nexactness vs reference (raw view): max relative difference %.3g over %zu finite results;\n"
           "%zu never-visible results, %zu disagreeing on infinity\n", worst, n - n_inf, n_inf, n_bad);

    /* fail-open: truly visible queries answered too high or never visible */
    double *truth = malloc(n * sizeof *truth), *old = malloc(n * sizeof *old);
    if (!truth || !old) return 1;
    run_model(&j);
    memcpy(truth, out, n * sizeof *out);
    for (size_t i = 0; i < n; i++) old[i] = old_threshold(thr, f[i], e[i]);
    printf("\nagainst the analytic CSF, share of the truly visible queries (analytic threshold <= 1)\n"
           "answered never visible or too high, and the excess (log10) of those answered too high:\n");
    printf("%-30s %10s %10s %10s %8s %8s %8s\n", "interpolation", "invisible", "too high",
           "> +0.1 lg", "median", "p90", "max");
    fail_open_report("linear, inf poisons (< 2.0)", old, truth, n);
    csflut_set_conservative(t, 0);
    run_batch(&j);
    fail_open_report("geometric + cap, raw", out, truth, n);
    csflut_set_conservative(t, 1);
    run_batch(&j);
    fail_open_report("geometric + cap, conservative", out, truth, n);
    free(truth);
    free(old);

    int ok3 = bench3(&p, f, e, out, n, r_batch);
    printf("\ntargets: batch >= 100 M/s %s, scalar >= 30 M/s %s, exact to 1e-6 %s\n",
           r_batch >= 100e6 ? "MET" : "NOT MET", r_scalar >= 30e6 ? "MET" : "NOT MET",
           worst <= 1e-6 && n_bad == 0 ? "MET" : "NOT MET");
    csflut_close(t);
    free(f);
    free(e);
    free(out);
    return worst <= 1e-6 && n_bad == 0 && ok3 ? 0 : 1;
}
