#include "imgdiff.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Gain of G(s) - G(2s) at its peak frequency 0.1976/s cycles per pixel: a Gaussian of sigma s
 * passes exp(-2 pi^2 s^2 f^2); the difference peaks where exp(3 a f^2) = 4 (a = 2 pi^2 s^2), at
 * 4^(-1/3) - 4^(-4/3). */
#define DOG_PEAK_GAIN 0.47247
#define DOG_PEAK_FREQ_CPP_TIMES_SIGMA 0.19765

static void blur_1d(const float *in, float *out, int w, int h, int stride_x, int stride_y,
                    const float *k, int radius)
{
    /* along x when stride_x = 1 (w samples per line, h lines); along y with the strides swapped */
    for (int line = 0; line < h; line++)
        for (int i = 0; i < w; i++) {
            float acc = 0;
            for (int j = -radius; j <= radius; j++) {
                int p = i + j < 0 ? 0 : (i + j >= w ? w - 1 : i + j); /* edge clamped */
                acc += k[j + radius] * in[(size_t)line * stride_y + (size_t)p * stride_x];
            }
            out[(size_t)line * stride_y + (size_t)i * stride_x] = acc;
        }
}

static int gaussian(const float *in, float *out, float *tmp, int w, int h, double sigma)
{
    int radius = (int)ceil(3 * sigma);
    float *k = calloc((size_t)radius * 2 + 1, sizeof *k); /* zeroed: the analyzer cannot tell radius >= 0 */
    if (!k) return -1;
    double sum = 0;
    for (int j = -radius; j <= radius; j++) sum += k[j + radius] = (float)exp(-0.5 * j * j / (sigma * sigma));
    for (int j = 0; j <= 2 * radius; j++) k[j] = (float)(k[j] / sum);
    blur_1d(in, tmp, w, h, 1, w, k, radius);
    blur_1d(tmp, out, h, w, w, 1, k, radius);
    free(k);
    return 0;
}

static void to_lum(const uint8_t *rgb, float *lum, int n, const lod_shade *s)
{
    float table[256];
    for (int v = 0; v < 256; v++) table[v] = (float)lod_shade_lum(s, pow(v / 255.0, 2.2));
    for (int i = 0; i < n; i++) lum[i] = table[rgb[3 * i]];
}

static void plain_measures(const float *la, const float *lb, const uint8_t *a, const uint8_t *b,
                           int n, lod_diff *out)
{
    double mean = 0, sq = 0, mx = 0;
    for (int i = 0; i < n; i++) {
        double d = la[i] - lb[i];
        mean += la[i];
        sq += d * d;
        mx = fabs(d) > mx ? fabs(d) : mx;
        out->changed_pixels += a[3 * i] != b[3 * i];
    }
    mean /= n;
    out->rms_contrast = sqrt(sq / n) / mean;
    out->max_contrast = mx / mean;
}

/* threshold at (f, ecc) for pixel i: static, or the lower of the thresholds at the ends of the
 * pixel's velocity range */
static double pixel_threshold(const csflut_table *t, double f_cpd, double ecc_deg, const float *vel_lo,
                              const float *vel_hi, size_t i)
{
    if (!vel_lo) return csflut_threshold(t, f_cpd, ecc_deg);
    double lum = csflut_default_luminance(t);
    double a = csflut_threshold4(t, f_cpd, ecc_deg, vel_lo[i], lum);
    return vel_hi[i] == vel_lo[i] ? a : fmin(a, csflut_threshold4(t, f_cpd, ecc_deg, vel_hi[i], lum));
}

static int image_diff(const uint8_t *a, const uint8_t *b, int width, int height, const lod_shade *s,
                      double ppd, const double gaze_px[2], const csflut_table *t, const float *vel_lo,
                      const float *vel_hi, lod_diff *out)
{
    size_t n = (size_t)width * height;
    float *buf = malloc(n * 8 * sizeof *buf);
    if (!buf) return -1;
    float *la = buf, *lb = buf + n, *ga0 = buf + 2 * n, *gb0 = buf + 3 * n, *ga1 = buf + 4 * n,
          *gb1 = buf + 5 * n, *tmp = buf + 6 * n, *ecc = buf + 7 * n;
    memset(out, 0, sizeof *out);
    to_lum(a, la, (int)n, s);
    to_lum(b, lb, (int)n, s);
    plain_measures(la, lb, a, b, (int)n, out);
    double dist_px = ppd * 180 / 3.14159265358979323846;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            double dx = x + 0.5 - gaze_px[0], dy = y + 0.5 - gaze_px[1];
            ecc[(size_t)y * width + x] = (float)(atan(sqrt(dx * dx + dy * dy) / dist_px) * 180 / 3.14159265358979323846);
        }
    double pooled4 = 0;
    int rc = 0;
    if (gaussian(la, ga0, tmp, width, height, 0.5) || gaussian(lb, gb0, tmp, width, height, 0.5)) rc = -1;
    for (double sigma = 0.5; rc == 0 && 2 * sigma <= 0.25 * (width < height ? width : height); sigma *= 2) {
        if (gaussian(la, ga1, tmp, width, height, 2 * sigma) || gaussian(lb, gb1, tmp, width, height, 2 * sigma)) {
            rc = -1;
            break;
        }
        double f_cpd = DOG_PEAK_FREQ_CPP_TIMES_SIGMA / sigma * ppd;
        for (size_t i = 0; i < n; i++) {
            double ca = (ga0[i] - ga1[i]) / ga1[i], cb = (gb0[i] - gb1[i]) / gb1[i];
            double d = fabs(ca - cb) / DOG_PEAK_GAIN;
            if (d == 0) continue;
            double v = d / pixel_threshold(t, f_cpd, ecc[i], vel_lo, vel_hi, i); /* +inf threshold: 0 */
            pooled4 += v * v * v * v;
            if (v > out->peak_visibility) {
                out->peak_visibility = v;
                out->peak_freq_cpd = f_cpd;
                out->peak_ecc_deg = ecc[i];
            }
        }
        memcpy(ga0, ga1, n * sizeof *ga0);
        memcpy(gb0, gb1, n * sizeof *gb0);
    }
    out->pooled_visibility = pow(pooled4, 0.25);
    free(buf);
    return rc;
}

int lod_image_diff(const uint8_t *a, const uint8_t *b, int width, int height, const lod_shade *s, double ppd,
                   const double gaze_px[2], const csflut_table *t, lod_diff *out)
{
    return image_diff(a, b, width, height, s, ppd, gaze_px, t, NULL, NULL, out);
}

int lod_image_diff_moving(const uint8_t *a, const uint8_t *b, int width, int height, const lod_shade *s,
                          double ppd, const double gaze_px[2], const csflut_table *t, const float *vel_lo,
                          const float *vel_hi, lod_diff *out)
{
    return image_diff(a, b, width, height, s, ppd, gaze_px, t, vel_lo, vel_hi, out);
}
