/* A Gabor fitted to a picture of the screen (a PNG written by `stimulus show --png`, or a
 * screenshot of its window converted to PNG), independently of stimuli/selfcheck.c: each pixel is
 * turned into luminance through a simulated display, placed in exact visual angle through the
 * station geometry, and the patch is fitted by least squares with a Gabor of unknown mean,
 * amplitude and phase; the frequency is the one with the largest fitted amplitude. Used by
 * test_show_png and show_shot_fit. */
#ifndef CSF_TESTS_GABOR_FIT_H
#define CSF_TESTS_GABOR_FIT_H

#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include "model/display_model.h"
#include "stimuli/geometry.h"

typedef struct {
    unsigned w, h;
    unsigned char *rgb;
} gfit_image;

/* 8-bit RGB pixels of a PNG file; 0, or -1 when it cannot be read. */
static inline int gfit_load_png(const char *path, gfit_image *im)
{
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&pi, path)) return -1;
    pi.format = PNG_FORMAT_RGB;
    im->w = pi.width;
    im->h = pi.height;
    im->rgb = malloc(PNG_IMAGE_SIZE(pi));
    if (!im->rgb || !png_image_finish_read(&pi, NULL, im->rgb, 0, NULL)) {
        png_image_free(&pi);
        free(im->rgb);
        im->rgb = NULL;
        return -1;
    }
    return 0;
}

/* Where the Gabor is and how it is modulated: orientation 0 (vertical bars), sigma in degrees. */
typedef struct {
    double ecc_deg, polar_deg, sigma_deg;
} gfit_patch;

typedef struct {
    double mean, contrast, phase_rad;
} gfit_result;

/* Solves the symmetric positive definite 3x3 system A x = y in place (Gauss-Jordan). */
static inline void gfit_solve3(double A[3][3], double y[3])
{
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) {
            if (r == c) continue;
            double q = A[r][c] / A[c][c];
            for (int k = 0; k < 3; k++) A[r][k] -= q * A[c][k];
            y[r] -= q * y[c];
        }
    for (int r = 0; r < 3; r++) y[r] /= A[r][r];
}

/* The patch's pixels in visual angle: u along the modulation direction, the envelope, and the
 * luminance through the display (pixels near fixation, the fixation mark, left out). The image
 * covers the whole configured screen (g), whatever its pixel size. */
typedef struct {
    size_t n;
    double *u, *env, *lum;
} gfit_pixels;

static inline int gfit_prepare(const gfit_image *im, const csf_geometry *g, const csf_display_model *dm,
                               const gfit_patch *pt, gfit_pixels *px)
{
    size_t cap = (size_t)im->w * im->h;
    px->n = 0;
    px->u = malloc(cap * sizeof *px->u);
    px->env = malloc(cap * sizeof *px->env);
    px->lum = malloc(cap * sizeof *px->lum);
    if (!px->u || !px->env || !px->lum) return -1;
    for (unsigned j = 0; j < im->h; j++)
        for (unsigned i = 0; i < im->w; i++) {
            double x = ((i + 0.5) / im->w - 0.5) * g->width_mm, yy = (0.5 - (j + 0.5) / im->h) * g->height_mm;
            double u, v, ecc, pol;
            csf_geometry_local_uv(g, pt->ecc_deg, pt->polar_deg, x, yy, &u, &v);
            csf_geometry_mm_to_deg(g, x, yy, &ecc, &pol);
            double env = exp(-(u * u + v * v) / (2.0 * pt->sigma_deg * pt->sigma_deg));
            if (env < 1e-3 || ecc < 0.3) continue;
            const unsigned char *c = im->rgb + 3 * ((size_t)j * im->w + i);
            px->u[px->n] = u;
            px->env[px->n] = env;
            px->lum[px->n++] = csf_display_model_lum(dm, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        }
    return 0;
}

static inline void gfit_pixels_free(gfit_pixels *px)
{
    free(px->u);
    free(px->env);
    free(px->lum);
}

/* Least squares L = m + a env cos(2 pi f u) + b env sin(2 pi f u) over the patch's pixels. */
static inline gfit_result gfit_at(const gfit_pixels *px, double f)
{
    double A[3][3] = {{0}}, y[3] = {0};
    for (size_t k = 0; k < px->n; k++) {
        double b[3] = {1, px->env[k] * cos(2 * M_PI * f * px->u[k]),
                       px->env[k] * sin(2 * M_PI * f * px->u[k])};
        for (int r = 0; r < 3; r++) {
            y[r] += b[r] * px->lum[k];
            for (int c = 0; c < 3; c++) A[r][c] += b[r] * b[c];
        }
    }
    gfit_solve3(A, y);
    return (gfit_result){y[0], hypot(y[1], y[2]) / y[0], atan2(-y[2], y[1])};
}

/* The frequency with the largest fitted amplitude: the best of a grid of step_rel around f0
 * (+-20 %), refined by the vertex of the parabola through it and its two neighbours. */
static inline double gfit_best_freq(const gfit_pixels *px, double f0, double step_rel)
{
    double best = f0, best_c = -1, step = step_rel * f0;
    for (double f = 0.8 * f0; f <= 1.2 * f0; f += step) {
        gfit_result r = gfit_at(px, f);
        if (r.contrast > best_c) {
            best_c = r.contrast;
            best = f;
        }
    }
    double lo = gfit_at(px, best - step).contrast, hi = gfit_at(px, best + step).contrast;
    double curv = lo - 2 * best_c + hi;
    return curv < 0 ? best + 0.5 * step * (lo - hi) / curv : best;
}

#endif
