/* Shared fixtures for the csflut tests: a realistic 8x6 table made from the analytic CSF with
 * measurement noise (counter RNG, so reproducible), and a reference interpolator written the
 * straightforward way (libm log, explicit cell search) to check the library against. */
#ifndef CSF_TESTS_LUT_FIXTURE_H
#define CSF_TESTS_LUT_FIXTURE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_model.h"
#include "results/csflut/csflut.h"
#include "core/rng.h"

static const double fx_freq[8] = {0.5, 1, 2, 4, 8, 16, 24, 32};
static const double fx_ecc[6] = {0, 5, 10, 20, 30, 40};

typedef struct {
    double thr[48], se[48];
    csflut_build b;
} fx_table;

/* Model thresholds with log-normal noise of sd noise_log10; thresholds above `inf_above` are
 * written as +inf (never visible). */
static inline void fx_make(fx_table *t, uint64_t seed, double noise_log10, double inf_above)
{
    csf_model_params p = csf_model_default();
    for (int e = 0; e < 6; e++)
        for (int f = 0; f < 8; f++) {
            int k = e * 8 + f;
            double th = csf_model_threshold(&p, fx_freq[f], fx_ecc[e]);
            th *= pow(10.0, noise_log10 * csf_rng_normal(seed, 7, (uint64_t)k));
            t->thr[k] = th > inf_above ? INFINITY : th;
            t->se[k] = k % 7 == 3 ? NAN : 0.03 + 0.002 * fx_ecc[e];
        }
    memset(&t->b, 0, sizeof t->b);
    t->b.n_freq = 8;
    t->b.n_ecc = 6;
    t->b.freq_cpd = fx_freq;
    t->b.ecc_deg = fx_ecc;
    t->b.threshold = t->thr;
    t->b.stderr_log10 = t->se;
    t->b.observer = "sim:seed=1";
    t->b.display_profile_id = "lcd-test-0001";
    t->b.method = "fade";
    t->b.date_utc = "2026-11-22T06:00:00Z";
    t->b.tool_version = "csfcal test";
    t->b.viewing_distance_mm = 600;
    t->b.mean_lum_cdm2 = 80;
    t->b.trials = 240;
}

static inline csflut_table *fx_open(const csflut_build *b)
{
    unsigned char *buf;
    size_t len;
    if (csflut_write_memory(b, &buf, &len) != CSFLUT_OK) return NULL;
    csflut_table *t = NULL;
    csflut_open_memory(buf, len, &t);
    free(buf);
    return t;
}

/* Reference: the library's documented interpolation written the plain way. Natural log of the
 * thresholds blended bilinearly in (ln f, ecc), clamped; an invisible node enters as the cap
 * (log2 cap: the smallest power of two >= log2(max(1, highest finite threshold)) + 1); +inf only
 * when every corner with a non-zero weight is invisible. */
static inline double ref_cap_ln(const double *v, int n)
{
    double m = 1;
    for (int k = 0; k < n; k++)
        if (isfinite(v[k]) && v[k] > m) m = v[k];
    double want = log(m) / log(2) + 1, cap = 1;
    while (cap < want) cap *= 2;
    return cap * log(2);
}

static inline double ref_threshold(const double *fr, int nf, const double *ec, int ne, const double *v,
                            double f, double e)
{
    if (f < fr[0]) f = fr[0];
    if (f > fr[nf - 1]) f = fr[nf - 1];
    if (e < ec[0]) e = ec[0];
    if (e > ec[ne - 1]) e = ec[ne - 1];
    int i = 0, j = 0;
    if (nf > 1) {
        for (i = 0; i < nf - 2; i++)
            if (f < fr[i + 1]) break;
    }
    if (ne > 1) {
        for (j = 0; j < ne - 2; j++)
            if (e < ec[j + 1]) break;
    }
    int i1 = nf > 1 ? i + 1 : i, j1 = ne > 1 ? j + 1 : j;
    double wf = nf > 1 ? (log(f) - log(fr[i])) / (log(fr[i1]) - log(fr[i])) : 0;
    double we = ne > 1 ? (e - ec[j]) / (ec[j1] - ec[j]) : 0;
    double cap = ref_cap_ln(v, nf * ne);
    const double w[4] = {(1 - wf) * (1 - we), wf * (1 - we), (1 - wf) * we, wf * we};
    const double c[4] = {v[j * nf + i], v[j * nf + i1], v[j1 * nf + i], v[j1 * nf + i1]};
    double sum = 0;
    int visible = 0;
    for (int k = 0; k < 4; k++) {
        if (w[k] > 0 && isfinite(c[k])) visible = 1;
        sum += w[k] * (isfinite(c[k]) ? log(c[k]) : cap);
    }
    return visible ? exp(sum) : INFINITY;
}

/* Relative difference that treats equal infinities as equal. */
static inline double rel_diff(double a, double b)
{
    if (a == b) return 0;
    if (isinf(a) || isinf(b) || a != a || b != b) return INFINITY;
    return fabs(a - b) / fmax(fabs(a), fabs(b));
}

#endif
