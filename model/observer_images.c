/* Simulated observer for image pairs (see observer_images.h). */
#include "model/observer_images.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

enum { ST_IMG_LAPSE = 0x1a6e, ST_IMG_SEEN, ST_IMG_GUESS, ST_IMG_RT };

#define DOG_PEAK_CPP 0.153     /* sqrt(ln 4 / 3 / (2 pi^2)): peak of G(s) - G(2s), cycles/px * s */
#define DOG_PEAK_GAIN 0.4725   /* exp(-ln4/3) - exp(-4 ln4/3) */

/* The CSF thresholds are for Gabors of sigma 1 deg, the session's stimuli
 * (docs/observer-calibration.md; calib/observer_calib.c). */
#define REF_SIGMA_DEG 1.0

/* mean over a period of |sin x|^p = Gamma((p + 1) / 2) / (sqrt(pi) Gamma(p / 2 + 1)) */
static double mean_abs_sin_pow(double p)
{
    return exp(lgamma((p + 1) / 2) - lgamma(p / 2 + 1)) / sqrt(M_PI);
}

/* Separable Gaussian blur with replicated edges; tmp and out are w*h. */
static int blur(const float *in, float *tmp, float *out, int w, int h, double sigma_px)
{
    int rad = (int)ceil(3 * sigma_px);
    double *k = calloc((size_t)rad * 2 + 1, sizeof *k); /* zeroed: the analyzer cannot tell rad >= 0 */
    if (!k) return -1; /* out not written: the caller must not read it */
    double sum = 0;
    for (int i = -rad; i <= rad; i++) sum += k[i + rad] = exp(-0.5 * i * i / (sigma_px * sigma_px));
    for (int i = 0; i <= 2 * rad; i++) k[i] /= sum;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc = 0;
            for (int i = -rad; i <= rad; i++) {
                int xx = x + i < 0 ? 0 : x + i >= w ? w - 1 : x + i;
                /* xx is clamped to [0, w - 1] and in is w * h: the analyzer loses that */
                acc += k[i + rad] * in[(size_t)y * w + xx]; // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult)
            }
            tmp[(size_t)y * w + x] = (float)acc;
        }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc = 0;
            for (int i = -rad; i <= rad; i++) {
                int yy = y + i < 0 ? 0 : y + i >= h ? h - 1 : y + i;
                /* yy is clamped to [0, h - 1] and tmp is w * h: the analyzer loses that */
                acc += k[i + rad] * tmp[(size_t)yy * w + x]; // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult)
            }
            out[(size_t)y * w + x] = (float)acc;
        }
    free(k);
    return 0;
}

int csf_image_pair_evaluate(const csf_observer_sim *o, const float *lum_a, const float *lum_b, int w,
                            int h, double size_deg, double ecc_deg, double polar_deg,
                            csf_image_pair_eval *out)
{
    return csf_image_pair_evaluate_v(o, lum_a, lum_b, w, h, size_deg, ecc_deg, polar_deg, 0.0, out);
}

int csf_image_pair_evaluate_v(const csf_observer_sim *o, const float *lum_a, const float *lum_b, int w, int h,
                              double size_deg, double ecc_deg, double polar_deg, double velocity_dps,
                              csf_image_pair_eval *out)
{
    memset(out, 0, sizeof *out);
    if (!o || !lum_a || !lum_b || w < 1 || h < 1 || !(size_deg > 0) || !isfinite(velocity_dps)) return -1;
    size_t n = (size_t)w * h;
    double mean = 0;
    for (size_t i = 0; i < n; i++) mean += 0.5 * ((double)lum_a[i] + lum_b[i]);
    mean /= n;
    /* n >= 1: w and h are checked >= 1 above */
    float *d = malloc(n * sizeof *d), *g1 = malloc(n * sizeof *g1), *g2 = malloc(n * sizeof *g2), // NOLINT(clang-analyzer-optin.portability.UnixAPI)
          *tmp = malloc(n * sizeof *tmp), *avg = malloc(n * sizeof *avg), *local = malloc(n * sizeof *local);
    if (!d || !g1 || !g2 || !tmp || !avg || !local) {
        free(d), free(g1), free(g2), free(tmp), free(avg), free(local);
        return -1;
    }
    int any = 0;
    for (size_t i = 0; i < n; i++) {
        d[i] = (float)(lum_b[i] - lum_a[i]);
        avg[i] = 0.5f * (lum_a[i] + lum_b[i]);
        any |= d[i] != 0;
    }
    /* Adaptation does not follow a dark region all the way down: the eye stays adapted to at
     * least a tenth of the scene's mean (also keeps black backgrounds from dividing by zero). */
    const double floor_lum = 0.1 * mean;
    double px_deg = size_deg / w;
    double cx = ecc_deg * cos(polar_deg * M_PI / 180), cy = ecc_deg * sin(polar_deg * M_PI / 180);
    double slope = csf_observer_sim_params_get(o)->slope;
    double pooled = 0;
    int minside = w < h ? w : h;
    for (int k = 0; any && k < CSF_IMG_MAX_BANDS; k++) {
        double s = pow(2.0, k - 1); /* 0.5 px: the finest band peaks at 0.31 cycle/px */
        if (2 * s > minside / 2.0) break; /* coarser than the image */
        if (blur(d, tmp, g1, w, h, s) || blur(d, tmp, g2, w, h, 2 * s) ||
            blur(avg, tmp, local, w, h, 2 * s)) { /* Peli's local mean: what lies below the band */
            free(d), free(g1), free(g2), free(tmp), free(avg), free(local);
            return -1;
        }
        double f_cpd = DOG_PEAK_CPP / s / px_deg;
        double cmax = 0, rmax = 0, sum_px = 0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                double lum_local = local[i] > floor_lum ? local[i] : floor_lum;
                double c = lum_local > 0 ? fabs(g1[i] - g2[i]) / DOG_PEAK_GAIN / lum_local : 0;
                if (c <= 0) continue;
                double ex = cx + (x + 0.5 - 0.5 * w) * px_deg, ey = cy - (y + 0.5 - 0.5 * h) * px_deg;
                double t = csf_observer_sim_threshold_v(o, f_cpd, hypot(ex, ey), velocity_dps);
                double r = isfinite(t) && t > 0 ? c / t : 0;
                if (c > cmax) cmax = c;
                if (r > rmax) rmax = r;
                sum_px += pow(r, slope);
            }
        /* Probability summation over space (Robson & Graham 1981): the thresholds are those of a
         * Gabor of sigma REF_SIGMA_DEG, whose band contrast at threshold pools to
         * (2 pi sigma^2 / slope) * mean|sin|^slope deg^2; a difference confined to a few pixels
         * pools over far less area than that, so it needs more contrast than the grating. */
        double ref_area_deg2 = 2 * M_PI * REF_SIGMA_DEG * REF_SIGMA_DEG / slope * mean_abs_sin_pow(slope);
        double r_band = pow(sum_px * px_deg * px_deg / ref_area_deg2, 1 / slope);
        int b = out->n_bands++;
        out->freq_cpd[b] = f_cpd;
        out->contrast[b] = cmax;
        out->ratio[b] = r_band;
        out->peak_ratio[b] = rmax;
        pooled += pow(r_band, slope);
    }
    out->r = pow(pooled, 1 / slope);
    free(d), free(g1), free(g2), free(tmp), free(avg), free(local);
    return 0;
}

double csf_image_pair_p_seen(const csf_observer_sim *o, double r)
{
    if (!(r > 0)) return 0;
    return 1 - exp(-pow(r, csf_observer_sim_params_get(o)->slope));
}

static double rt_draw(uint64_t seed, uint64_t i)
{
    return 0.6 * exp(0.25 * csf_rng_normal(seed, ST_IMG_RT, i));
}

int csf_observer_sim_same_different(const csf_observer_sim *o, uint64_t seed, uint64_t trial_index,
                                    double r, double *rt_s)
{
    const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
    *rt_s = rt_draw(seed, trial_index);
    if (csf_rng_uniform(seed, ST_IMG_LAPSE, trial_index) < p->lapse)
        return csf_rng_uniform(seed, ST_IMG_GUESS, trial_index) < 0.5;
    if (csf_rng_uniform(seed, ST_IMG_SEEN, trial_index) < csf_image_pair_p_seen(o, r)) return 1;
    return csf_rng_uniform(seed, ST_IMG_GUESS, trial_index) < p->fa;
}

int csf_observer_sim_image_afc(const csf_observer_sim *o, uint64_t seed, uint64_t trial_index,
                               double r, int target, double *rt_s)
{
    const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
    *rt_s = rt_draw(seed, trial_index);
    int guess = csf_rng_uniform(seed, ST_IMG_GUESS, trial_index) < 0.5;
    if (csf_rng_uniform(seed, ST_IMG_LAPSE, trial_index) < p->lapse) return guess;
    if (csf_rng_uniform(seed, ST_IMG_SEEN, trial_index) < csf_image_pair_p_seen(o, r)) return target;
    return guess;
}
