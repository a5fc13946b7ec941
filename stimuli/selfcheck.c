/* See selfcheck.h. Measurements work on the frame-averaged luminance image of a region around
 * the patch, in the same exact angle space as the renderer (geometry.h), so that a bias in the
 * drawing shows as a difference between requested and measured values. */
#include "stimuli/selfcheck.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

#define DEG (M_PI / 180.0)

typedef struct {
    int x0, y0, w, h;     /* ROI in render pixels, top-left origin */
    double *lum;          /* frame-averaged luminance, w*h */
    double *u, *v, *xmm, *ymm;
} roi_t;

static void roi_free(roi_t *r)
{
    free(r->lum);
    free(r->u);
    free(r->v);
    free(r->xmm);
    free(r->ymm);
}

static void render_px_to_mm(const csf_geometry *g, int rw, int rh, double i, double j, double *x, double *y)
{
    *x = ((i + 0.5) / rw - 0.5) * g->width_mm;
    *y = (0.5 - (j + 0.5) / rh) * g->height_mm;
}

/* Luminance of each framebuffer level sent to all three channels, and of arbitrary triplets. */
typedef struct {
    csf_pixel_lum_fn fn;
    void *ctx;
    int maxlevel;
    double *grey;
} lum_cache;

static double pix_lum(const lum_cache *c, const uint16_t *px)
{
    if (px[0] == px[1] && px[1] == px[2]) return c->grey[px[0]];
    return c->fn(c->ctx, (double)px[0] / c->maxlevel, (double)px[1] / c->maxlevel,
                 (double)px[2] / c->maxlevel);
}

static csf_status cache_init(lum_cache *c, csf_presenter *p, csf_pixel_lum_fn fn, void *ctx, csf_error *err)
{
    c->fn = fn;
    c->ctx = ctx;
    c->maxlevel = (1 << csf_presenter_bits(p)) - 1;
    /* zeroed, although the loop below fills every level: the analyzer cannot tell maxlevel >= 1 */
    c->grey = calloc((size_t)c->maxlevel + 1, sizeof(double));
    if (!c->grey) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int k = 0; k <= c->maxlevel; k++) {
        double d = (double)k / c->maxlevel;
        c->grey[k] = fn(ctx, d, d, d);
    }
    return CSF_OK;
}

/* Accumulates `frames` frames of stimulus s (NULL = blank) into the ROI's luminance average. */
static csf_status accumulate(csf_presenter *p, const csf_stimulus *s, int frames, const lum_cache *lc,
                             roi_t *r, csf_error *err)
{
    int rw, rh;
    csf_presenter_render_size(p, &rw, &rh);
    uint16_t *buf = malloc(sizeof(uint16_t) * 3 * (size_t)rw * rh);
    if (!buf) return csf_error_set(err, CSF_E_NOMEM, "out of memory for readback");
    memset(r->lum, 0, sizeof(double) * (size_t)r->w * r->h);
    csf_status st = CSF_OK;
    for (int f = 0; f < frames && !st; f++) {
        csf_frame_info fi;
        st = csf_presenter_draw(p, s, 0, &fi, err);
        if (!st) st = csf_presenter_readback_levels(p, buf, err);
        if (st) break;
        for (int j = 0; j < r->h; j++)
            for (int i = 0; i < r->w; i++)
                r->lum[(size_t)j * r->w + i] +=
                    pix_lum(lc, buf + 3 * ((size_t)(r->y0 + j) * rw + (r->x0 + i)));
    }
    for (size_t k = 0; k < (size_t)r->w * r->h; k++) r->lum[k] /= frames;
    free(buf);
    return st;
}

static double envelope(const csf_stimulus *s, double u, double v)
{
    double r2 = u * u + v * v;
    if (s->kind == CSF_STIM_GABOR) return exp(-r2 / (2 * s->sigma_deg * s->sigma_deg));
    double R = s->radius_deg > 0 ? s->radius_deg : 2.0, e = s->edge_deg > 0 ? s->edge_deg : 0.25;
    double r = sqrt(r2);
    if (r <= R) return 1;
    if (r >= R + e) return 0;
    return 0.5 + 0.5 * cos(M_PI * (r - R) / e);
}

/* |projection| of (L - m) * env onto the complex carrier of frequency f, orientation o. */
static double projection(const roi_t *r, const csf_stimulus *s, double m, double f, double o)
{
    double co = cos(o * DEG), so = sin(o * DEG), re = 0, im = 0;
    size_t n = (size_t)r->w * r->h;
    for (size_t k = 0; k < n; k++) {
        double e = envelope(s, r->u[k], r->v[k]);
        if (e < 1e-4) continue;
        double ph = 2 * M_PI * f * (r->u[k] * co + r->v[k] * so);
        double a = (r->lum[k] - m) * e;
        re += a * cos(ph);
        im += a * sin(ph);
    }
    return hypot(re, im);
}

/* Golden-section maximisation of g(x) on [a, b] after a coarse scan (the peak is unimodal near
 * the request). which = 0 varies frequency, 1 orientation. */
static double maximise(const roi_t *r, const csf_stimulus *s, double m, double f, double o, int which,
                       double a, double b)
{
    const int coarse = 17;
    double best = a, bestv = -1;
    for (int i = 0; i < coarse; i++) {
        double x = a + (b - a) * i / (coarse - 1);
        double val = which ? projection(r, s, m, f, x) : projection(r, s, m, x, o);
        if (val > bestv) {
            bestv = val;
            best = x;
        }
    }
    double step = (b - a) / (coarse - 1), lo = best - step, hi = best + step;
    const double gr = 0.6180339887498949;
    double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo);
    double f1 = which ? projection(r, s, m, f, x1) : projection(r, s, m, x1, o);
    double f2 = which ? projection(r, s, m, f, x2) : projection(r, s, m, x2, o);
    for (int it = 0; it < 40 && hi - lo > 1e-7 * fabs(b); it++) {
        if (f1 < f2) {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + gr * (hi - lo);
            f2 = which ? projection(r, s, m, f, x2) : projection(r, s, m, x2, o);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - gr * (hi - lo);
            f1 = which ? projection(r, s, m, f, x1) : projection(r, s, m, x1, o);
        }
    }
    return 0.5 * (lo + hi);
}

/* Solves the 3x3 normal equations of L = m + a*e*cos + b*e*sin. */
static int fit_linear(const roi_t *r, const csf_stimulus *s, double f, double o, double ph0,
                      double *m, double *a, double *b)
{
    double A[3][3] = {{0}}, y[3] = {0};
    double co = cos(o * DEG), so = sin(o * DEG);
    size_t n = (size_t)r->w * r->h;
    for (size_t k = 0; k < n; k++) {
        double e = envelope(s, r->u[k], r->v[k]);
        double ph = 2 * M_PI * f * (r->u[k] * co + r->v[k] * so) + ph0;
        double x[3] = {1.0, e * cos(ph), e * sin(ph)};
        for (int i = 0; i < 3; i++) {
            y[i] += x[i] * r->lum[k];
            for (int j = 0; j < 3; j++) A[i][j] += x[i] * x[j];
        }
    }
    /* Gaussian elimination with partial pivoting */
    for (int c = 0; c < 3; c++) {
        int piv = c;
        for (int i = c + 1; i < 3; i++)
            if (fabs(A[i][c]) > fabs(A[piv][c])) piv = i;
        if (fabs(A[piv][c]) < 1e-300) return -1;
        for (int j = 0; j < 3; j++) {
            double t = A[c][j];
            A[c][j] = A[piv][j];
            A[piv][j] = t;
        }
        double t = y[c];
        y[c] = y[piv];
        y[piv] = t;
        for (int i = c + 1; i < 3; i++) {
            double q = A[i][c] / A[c][c];
            for (int j = c; j < 3; j++) A[i][j] -= q * A[c][j];
            y[i] -= q * y[c];
        }
    }
    double sol[3];
    for (int i = 2; i >= 0; i--) {
        double t = y[i];
        for (int j = i + 1; j < 3; j++) t -= A[i][j] * sol[j];
        sol[i] = t / A[i][i];
    }
    *m = sol[0];
    *a = sol[1];
    *b = sol[2];
    return 0;
}

csf_status csf_selfcheck_stimulus(csf_presenter *p, const csf_stimulus *s, int frames,
                                  csf_pixel_lum_fn lum, void *lum_ctx, csf_selfcheck_result *out,
                                  csf_error *err)
{
    if (!p || !s || !lum || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "self-check: NULL argument");
    if (s->kind != CSF_STIM_GABOR && s->kind != CSF_STIM_GRATING)
        return csf_error_set(err, CSF_E_INVALID_ARG, "self-check measures Gabors and gratings only");
    if (frames < 1 || frames > 100000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "frames %d is outside 1 to 100000", frames);
    if (s->velocity_dps != 0 || s->drift_hz != 0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "self-check needs a static stimulus (no drift or motion)");
    csf_status st = csf_presenter_validate(p, s, err);
    if (st) return st;
    const csf_geometry *g = csf_presenter_geometry(p);
    int rw, rh;
    csf_presenter_render_size(p, &rw, &rh);
    /* ROI: bounding box of the patch extent (+20 %) in render pixels */
    double extent = s->kind == CSF_STIM_GABOR ? 3.0 * s->sigma_deg
                  : (s->radius_deg > 0 ? s->radius_deg : 2.0) + (s->edge_deg > 0 ? s->edge_deg : 0.25);
    double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
    for (int i = 0; i < 48; i++) {
        double e2, p2, x, y;
        csf_geometry_move(g, s->ecc_deg, s->polar_deg, 7.5 * i, 1.2 * extent, &e2, &p2);
        if (!csf_geometry_deg_to_mm(g, e2, p2, &x, &y)) continue;
        xmin = fmin(xmin, x), xmax = fmax(xmax, x), ymin = fmin(ymin, y), ymax = fmax(ymax, y);
    }
    roi_t r;
    memset(&r, 0, sizeof r);
    r.x0 = (int)floor((xmin / g->width_mm + 0.5) * rw);
    int x1 = (int)ceil((xmax / g->width_mm + 0.5) * rw);
    r.y0 = (int)floor((0.5 - ymax / g->height_mm) * rh);
    int y1 = (int)ceil((0.5 - ymin / g->height_mm) * rh);
    if (r.x0 < 0) r.x0 = 0;
    if (r.y0 < 0) r.y0 = 0;
    if (x1 > rw) x1 = rw;
    if (y1 > rh) y1 = rh;
    r.w = x1 - r.x0;
    r.h = y1 - r.y0;
    if (r.w < 4 || r.h < 4)
        return csf_error_set(err, CSF_E_INSUFFICIENT, "the patch covers fewer than 4x4 rendered pixels");
    size_t n = (size_t)r.w * r.h;
    r.lum = malloc(sizeof(double) * n);
    r.u = malloc(sizeof(double) * n);
    r.v = malloc(sizeof(double) * n);
    r.xmm = malloc(sizeof(double) * n);
    r.ymm = malloc(sizeof(double) * n);
    lum_cache lc = {0};
    if (!r.lum || !r.u || !r.v || !r.xmm || !r.ymm) {
        roi_free(&r);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    for (int j = 0; j < r.h; j++)
        for (int i = 0; i < r.w; i++) {
            size_t k = (size_t)j * r.w + i;
            render_px_to_mm(g, rw, rh, r.x0 + i, r.y0 + j, &r.xmm[k], &r.ymm[k]);
            csf_geometry_local_uv(g, s->ecc_deg, s->polar_deg, r.xmm[k], r.ymm[k], &r.u[k], &r.v[k]);
        }
    st = cache_init(&lc, p, lum, lum_ctx, err);
    if (!st) st = accumulate(p, s, frames, &lc, &r, err);
    if (st) {
        free(lc.grey);
        roi_free(&r);
        return st;
    }
    double m, a, b;
    fit_linear(&r, s, s->freq_cpd, s->orientation_deg, 0, &m, &a, &b);
    double f = maximise(&r, s, m, s->freq_cpd, s->orientation_deg, 0, 0.85 * s->freq_cpd, 1.15 * s->freq_cpd);
    double o = maximise(&r, s, m, f, s->orientation_deg, 1, s->orientation_deg - 10, s->orientation_deg + 10);
    f = maximise(&r, s, m, s->freq_cpd, o, 0, 0.85 * s->freq_cpd, 1.15 * s->freq_cpd);
    /* contrast at the requested frequency/orientation (the quantity the procedure relies on) */
    fit_linear(&r, s, s->freq_cpd, s->orientation_deg, 0, &m, &a, &b);
    out->frames = frames;
    out->freq_cpd = f;
    out->orientation_deg = o;
    out->contrast = hypot(a, b) / m;
    out->mean_lum_cdm2 = m;
    /* position: centroid of the squared deviation from the mean */
    double sw = 0, sx = 0, sy = 0;
    for (size_t k = 0; k < n; k++) {
        double d = r.lum[k] - m, w = d * d;
        sw += w;
        sx += w * r.xmm[k];
        sy += w * r.ymm[k];
    }
    if (sw > 0) csf_geometry_mm_to_deg(g, sx / sw, sy / sw, &out->ecc_deg, &out->polar_deg);
    else out->ecc_deg = out->polar_deg = NAN;
    free(lc.grey);
    roi_free(&r);
    return CSF_OK;
}

csf_status csf_selfcheck_resolution_run(csf_presenter *p, int levels, int frames, int patch_px,
                                        uint64_t seed, csf_pixel_lum_fn lum, void *lum_ctx,
                                        csf_selfcheck_resolution *out, csf_error *err)
{
    if (!p || !lum || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "resolution: NULL argument");
    int rw, rh;
    csf_presenter_render_size(p, &rw, &rh);
    if (levels < 1 || levels > 10000 || frames < 1 || frames > 10000 || patch_px < 1 ||
        patch_px > rw || patch_px > rh)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "resolution check: levels 1..10000, frames 1..10000, patch 1..%d px",
                             rw < rh ? rw : rh);
    double black, max;
    csf_presenter_lum_range(p, &black, &max);
    lum_cache lc = {0};
    csf_status st = cache_init(&lc, p, lum, lum_ctx, err);
    if (st) return st;
    roi_t r;
    memset(&r, 0, sizeof r);
    r.w = r.h = patch_px;
    r.x0 = (rw - patch_px) / 2;
    r.y0 = (rh - patch_px) / 2;
    r.lum = malloc(sizeof(double) * (size_t)patch_px * patch_px);
    if (!r.lum) {
        free(lc.grey);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    double maxe = 0, sse = 0;
    /* the display's true range (through the caller's luminance function) */
    double range = lc.grey[lc.maxlevel] - lc.grey[0];
    for (int i = 0; i < levels && !st; i++) {
        double want = (0.2 + 0.6 * csf_rng_uniform(seed, 0x6c6576ULL, (uint64_t)i)) * max;
        if (want < black) want = black;
        csf_stimulus s;
        memset(&s, 0, sizeof s);
        s.kind = CSF_STIM_DISC; /* zero contrast: the whole field sits at mean_lum */
        s.mean_lum_cdm2 = want;
        s.radius_deg = 0.5;
        st = accumulate(p, &s, frames, &lc, &r, err);
        if (st) break;
        double sum = 0;
        for (size_t k = 0; k < (size_t)patch_px * patch_px; k++) sum += r.lum[k];
        double e = fabs(sum / ((double)patch_px * patch_px) - want) / range;
        if (e > maxe) maxe = e;
        sse += e * e;
    }
    free(lc.grey);
    roi_free(&r);
    if (st) return st;
    out->levels = levels;
    out->frames = frames;
    out->patch_px = patch_px;
    out->max_err_frac = maxe;
    out->rms_err_frac = sqrt(sse / levels);
    out->effective_bits = maxe > 0 ? -log2(maxe) : 53.0;
    return CSF_OK;
}
