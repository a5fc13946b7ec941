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

/* ROI of stimulus s in a frame of fw x fh pixels covering the screen: the bounding box of the
 * patch extent (+20 %), with every pixel's screen position (mm) and local angle coordinates. */
static csf_status roi_open(const csf_geometry *g, const csf_stimulus *s, int fw, int fh, roi_t *r,
                           csf_error *err)
{
    double extent = s->kind == CSF_STIM_GABOR
                        ? 3.0 * s->sigma_deg
                        : (s->radius_deg > 0 ? s->radius_deg : 2.0) + (s->edge_deg > 0 ? s->edge_deg : 0.25);
    double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
    for (int i = 0; i < 48; i++) {
        double e2, p2, x, y;
        csf_geometry_move(g, s->ecc_deg, s->polar_deg, 7.5 * i, 1.2 * extent, &e2, &p2);
        if (!csf_geometry_deg_to_mm(g, e2, p2, &x, &y)) continue;
        xmin = fmin(xmin, x), xmax = fmax(xmax, x), ymin = fmin(ymin, y), ymax = fmax(ymax, y);
    }
    memset(r, 0, sizeof *r);
    r->x0 = (int)floor((xmin / g->width_mm + 0.5) * fw);
    int x1 = (int)ceil((xmax / g->width_mm + 0.5) * fw);
    r->y0 = (int)floor((0.5 - ymax / g->height_mm) * fh);
    int y1 = (int)ceil((0.5 - ymin / g->height_mm) * fh);
    if (r->x0 < 0) r->x0 = 0;
    if (r->y0 < 0) r->y0 = 0;
    if (x1 > fw) x1 = fw;
    if (y1 > fh) y1 = fh;
    r->w = x1 - r->x0;
    r->h = y1 - r->y0;
    if (r->w < 4 || r->h < 4)
        return csf_error_set(err, CSF_E_INSUFFICIENT, "the patch covers fewer than 4x4 rendered pixels");
    size_t n = (size_t)r->w * r->h;
    r->lum = malloc(sizeof(double) * n);
    r->u = malloc(sizeof(double) * n);
    r->v = malloc(sizeof(double) * n);
    r->xmm = malloc(sizeof(double) * n);
    r->ymm = malloc(sizeof(double) * n);
    if (!r->lum || !r->u || !r->v || !r->xmm || !r->ymm) {
        roi_free(r);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    for (int j = 0; j < r->h; j++)
        for (int i = 0; i < r->w; i++) {
            size_t k = (size_t)j * r->w + i;
            render_px_to_mm(g, fw, fh, r->x0 + i, r->y0 + j, &r->xmm[k], &r->ymm[k]);
            csf_geometry_local_uv(g, s->ecc_deg, s->polar_deg, r->xmm[k], r->ymm[k], &r->u[k], &r->v[k]);
        }
    return CSF_OK;
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

/* Solves A x = y (3x3) by Gaussian elimination with partial pivoting; A and y are overwritten.
 * Returns -1 when A is singular. */
static int solve3(double A[3][3], double y[3], double sol[3])
{
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
    for (int i = 2; i >= 0; i--) {
        double t = y[i];
        for (int j = i + 1; j < 3; j++) t -= A[i][j] * sol[j];
        sol[i] = t / A[i][i];
    }
    return 0;
}

/* Solves the 3x3 normal equations of L = m + a*e*cos + b*e*sin. */
static int fit_linear(const roi_t *r, const csf_stimulus *s, double f, double o, double ph0, double *m,
                      double *a, double *b)
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
    double sol[3];
    if (solve3(A, y, sol)) return -1;
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
    roi_t r;
    st = roi_open(g, s, rw, rh, &r, err);
    if (st) return st;
    size_t n = (size_t)r.w * r.h;
    lum_cache lc = {0};
    st = cache_init(&lc, p, lum, lum_ctx, err);
    if (!st) st = accumulate(p, s, frames, &lc, &r, err);
    if (st) {
        free(lc.grey);
        roi_free(&r);
        return st;
    }
    double m, a, b;
    if (fit_linear(&r, s, s->freq_cpd, s->orientation_deg, 0, &m, &a, &b)) {
        free(lc.grey);
        roi_free(&r);
        return csf_error_set(err, CSF_E_INSUFFICIENT, "the patch's pixels do not determine a carrier");
    }
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

/* ---------------- carrier phase per frame and drift speed ---------------- */

struct csf_phase_meter {
    csf_presenter *p;
    csf_stimulus s;
    int from_region;
    roi_t r;
    lum_cache lc;
    double *ec, *es;     /* envelope x cos and x sin of the carrier at phase 0, per ROI pixel */
    unsigned char *keep; /* 0 for pixels under the fixation mark, left out of the fit */
    double A[3][3];      /* normal matrix of the fit (the same for every frame) */
    uint16_t *buf;       /* read-back pixels: the whole frame, or the ROI (from_region) */
    size_t buf_px;
};

void csf_phase_meter_close(csf_phase_meter *m)
{
    if (!m) return;
    roi_free(&m->r);
    free(m->lc.grey);
    free(m->ec);
    free(m->es);
    free(m->keep);
    free(m->buf);
    free(m);
}

/* The carrier at phase 0 under the envelope, and the fit's normal matrix. Pixels within
 * CSF_PHASE_METER_FIX_EXCLUDE_DEG of the fixation direction are left out: a session's fixation
 * mark (dark, at the screen's foot of the normal) is not part of the grating, and over a foveal
 * patch's peak it would read as a loss of contrast. */
static void meter_basis(csf_phase_meter *m)
{
    const csf_stimulus *s = &m->s;
    const csf_geometry *g = csf_presenter_geometry(m->p);
    double co = cos(s->orientation_deg * DEG), so = sin(s->orientation_deg * DEG);
    memset(m->A, 0, sizeof m->A);
    for (size_t k = 0; k < (size_t)m->r.w * m->r.h; k++) {
        double ecc, polar;
        csf_geometry_mm_to_deg(g, m->r.xmm[k], m->r.ymm[k], &ecc, &polar);
        m->keep[k] = !(ecc < CSF_PHASE_METER_FIX_EXCLUDE_DEG);
        if (!m->keep[k]) continue;
        double e = envelope(s, m->r.u[k], m->r.v[k]);
        double ph = 2 * M_PI * s->freq_cpd * (m->r.u[k] * co + m->r.v[k] * so);
        m->ec[k] = e * cos(ph);
        m->es[k] = e * sin(ph);
        double x[3] = {1.0, m->ec[k], m->es[k]};
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) m->A[i][j] += x[i] * x[j];
    }
}

csf_status csf_phase_meter_open(csf_presenter *p, const csf_stimulus *s, int from_region,
                                csf_pixel_lum_fn lum, void *lum_ctx, csf_phase_meter **out, csf_error *err)
{
    if (!p || !s || !lum || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "phase meter: NULL argument");
    *out = NULL;
    if (s->kind != CSF_STIM_GABOR && s->kind != CSF_STIM_GRATING)
        return csf_error_set(err, CSF_E_INVALID_ARG, "the phase meter measures Gabors and gratings only");
    if (s->velocity_dps != 0)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "the phase meter needs a patch that stays in place (velocity_dps 0); "
                             "a drifting carrier is drift_hz");
    csf_status st = csf_presenter_validate(p, s, err);
    if (st) return st;
    csf_phase_meter *m = calloc(1, sizeof *m);
    if (!m) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    m->p = p;
    m->s = *s;
    m->from_region = from_region;
    const csf_geometry *g = csf_presenter_geometry(p);
    int fw = g->width_px, fh = g->height_px;
    if (!from_region) csf_presenter_render_size(p, &fw, &fh);
    st = roi_open(g, s, fw, fh, &m->r, err);
    if (!st) st = cache_init(&m->lc, p, lum, lum_ctx, err);
    if (st) {
        csf_phase_meter_close(m);
        return st;
    }
    size_t n = (size_t)m->r.w * m->r.h;
    m->buf_px = from_region ? n : (size_t)fw * fh;
    m->ec = malloc(sizeof(double) * n);
    m->es = malloc(sizeof(double) * n);
    m->keep = malloc(n);
    m->buf = malloc(sizeof(uint16_t) * 3 * m->buf_px);
    if (!m->ec || !m->es || !m->keep || !m->buf) {
        csf_phase_meter_close(m);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    meter_basis(m);
    *out = m;
    return CSF_OK;
}

/* The last frame's luminance over the ROI into m->r.lum. */
static csf_status meter_pixels(csf_phase_meter *m, csf_error *err)
{
    roi_t *r = &m->r;
    csf_status st = m->from_region
                        ? csf_presenter_readback_region(m->p, r->x0, r->y0, r->w, r->h, m->buf, err)
                        : csf_presenter_readback_levels(m->p, m->buf, err);
    if (st) return st;
    int fw = 0;
    csf_presenter_render_size(m->p, &fw, NULL);
    for (int j = 0; j < r->h; j++)
        for (int i = 0; i < r->w; i++) {
            size_t at = m->from_region ? (size_t)j * r->w + i : (size_t)(r->y0 + j) * fw + (r->x0 + i);
            r->lum[(size_t)j * r->w + i] = pix_lum(&m->lc, m->buf + 3 * at);
        }
    return CSF_OK;
}

csf_status csf_phase_meter_read(csf_phase_meter *m, csf_phase_reading *out, csf_error *err)
{
    if (!m || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "phase meter: NULL argument");
    csf_status st = meter_pixels(m, err);
    if (st) return st;
    double y[3] = {0, 0, 0}, A[3][3], sol[3];
    for (size_t k = 0; k < (size_t)m->r.w * m->r.h; k++) {
        if (!m->keep[k]) continue;
        double L = m->r.lum[k];
        y[0] += L;
        y[1] += L * m->ec[k];
        y[2] += L * m->es[k];
    }
    memcpy(A, m->A, sizeof A);
    if (solve3(A, y, sol) || !(sol[0] > 0))
        return csf_error_set(err, CSF_E_INSUFFICIENT,
                             "phase meter: the patch's pixels do not determine a carrier");
    /* L = m (1 + c env cos(2 pi f w + phi)) = m + (m c cos phi) env cos - (m c sin phi) env sin */
    out->mean_lum_cdm2 = sol[0];
    out->contrast = hypot(sol[1], sol[2]) / sol[0];
    out->phase_rad = atan2(-sol[2], sol[1]);
    return CSF_OK;
}

csf_status csf_phase_meter_freq(csf_phase_meter *m, double mean_lum_cdm2, double *freq_cpd, csf_error *err)
{
    if (!m || !freq_cpd) return csf_error_set(err, CSF_E_INVALID_ARG, "phase meter: NULL argument");
    const csf_stimulus *s = &m->s;
    *freq_cpd = maximise(&m->r, s, mean_lum_cdm2, s->freq_cpd, s->orientation_deg, 0, 0.85 * s->freq_cpd,
                         1.15 * s->freq_cpd);
    return CSF_OK;
}

/* The angle in (-pi, pi]. */
static double wrap_pi(double a)
{
    a = fmod(a + M_PI, 2 * M_PI);
    if (a <= 0) a += 2 * M_PI;
    return a - M_PI;
}

/* Least-squares slope of y over t. */
static double ls_slope(const double *t, const double *y, int n)
{
    double st = 0, sy = 0, stt = 0, sty = 0;
    for (int i = 0; i < n; i++) {
        st += t[i];
        sy += y[i];
        stt += t[i] * t[i];
        sty += t[i] * y[i];
    }
    double d = n * stt - st * st;
    return d > 0 ? (n * sty - st * sy) / d : NAN;
}

csf_status csf_drift_fit_phases(const double *t_s, const double *phase_rad, int n, double tf_hz,
                                double refresh_hz, csf_drift_fit *out, csf_error *err)
{
    if (!t_s || !phase_rad || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "drift fit: NULL argument");
    if (n < 3) return csf_error_set(err, CSF_E_INSUFFICIENT, "drift fit: %d frames, at least 3 needed", n);
    if (!(tf_hz != 0 && isfinite(tf_hz) && refresh_hz > 0 && fabs(tf_hz) < 0.5 * refresh_hz))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "drift fit: temporal frequency %g Hz must be non-zero and below half the "
                             "refresh rate (%g Hz)",
                             tf_hz, 0.5 * refresh_hz);
    double *unw = malloc(sizeof(double) * (size_t)n);
    if (!unw) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    memset(out, 0, sizeof *out);
    double period = 1.0 / refresh_hz;
    out->frames = n;
    out->tf_asked_hz = tf_hz;
    out->frame_step_rad = 2 * M_PI * tf_hz * period;
    out->step_tolerance_rad = fmax(0.25 * fabs(out->frame_step_rad), CSF_DRIFT_MIN_STEP_TOL_RAD);
    out->held_step_rad = out->held_step_expected_rad = NAN;
    unw[0] = phase_rad[0];
    for (int k = 1; k < n; k++) {
        double dt = t_s[k] - t_s[k - 1];
        /* unwrapped against the presentation times: the step the asked drift predicts plus the
         * measured deviation from it, which is unambiguous while it stays under half a cycle */
        double pred = 2 * M_PI * tf_hz * dt, dev = wrap_pi(phase_rad[k] - phase_rad[k - 1] - pred);
        unw[k] = unw[k - 1] + pred + dev;
        out->max_step_error_rad = fmax(out->max_step_error_rad, fabs(dev));
        if (dt > 1.5 * period) {
            out->frames_missed++;
            out->max_held_step_error_rad = fmax(out->max_held_step_error_rad, fabs(dev));
            if (isnan(out->held_step_rad)) {
                out->held_step_rad = pred + dev;
                out->held_step_expected_rad = pred;
            }
        }
    }
    out->tf_measured_hz = ls_slope(t_s, unw, n) / (2 * M_PI);
    out->tf_rel_error = out->tf_measured_hz / tf_hz - 1;
    out->continuous = out->max_step_error_rad <= out->step_tolerance_rad;
    free(unw);
    return CSF_OK;
}

/* What the frame hook of csf_selfcheck_drift collects from each stimulus frame. */
typedef struct {
    csf_phase_meter *m;
    double *t_s, *phase, contrast_sum, mean_sum;
    int n, cap;
    double freq_cpd;
    csf_status st;
    csf_error err;
} drift_log;

static void drift_hook(void *ctx, csf_presenter *p, const csf_frame_info *fi)
{
    (void)p;
    drift_log *d = ctx;
    /* the trial's closing blank frame (contrast 0) has no carrier */
    if (d->st || fi->contrast_shown <= 0 || d->n >= d->cap) return;
    csf_phase_reading r;
    d->st = csf_phase_meter_read(d->m, &r, &d->err);
    if (d->st) return;
    if (d->n == 0) d->st = csf_phase_meter_freq(d->m, r.mean_lum_cdm2, &d->freq_cpd, &d->err);
    d->t_s[d->n] = fi->t_s;
    d->phase[d->n] = r.phase_rad;
    d->contrast_sum += r.contrast;
    d->mean_sum += r.mean_lum_cdm2;
    d->n++;
}

/* One trial of s through csf_presenter_run_trial (the path every session's drifting carrier
 * takes), the carrier phase read from each frame. */
static csf_status drift_trial(csf_presenter *p, const csf_stimulus *s, int frames, drift_log *d,
                              csf_error *err)
{
    csf_envelope env = {CSF_ENV_FIXED, frames / csf_presenter_refresh_hz(p), 0, 0};
    csf_trial_record rec;
    csf_presenter_set_frame_hook(p, drift_hook, d);
    csf_status st = csf_presenter_run_trial(p, s, &env, 0, NULL, NULL, &rec, err);
    csf_presenter_set_frame_hook(p, NULL, NULL);
    if (st) return st;
    csf_trial_record_free(&rec);
    if (d->st) {
        if (err) *err = d->err;
        return d->st;
    }
    return CSF_OK;
}

csf_status csf_selfcheck_drift(csf_presenter *p, const csf_stimulus *s, int frames, csf_pixel_lum_fn lum,
                               void *lum_ctx, csf_selfcheck_drift_result *out, csf_error *err)
{
    if (!p || !s || !lum || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "drift check: NULL argument");
    if (frames < 3 || frames > 100000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "drift check: frames %d is outside 3 to 100000", frames);
    if (s->drift_hz == 0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "drift check: the carrier does not drift (drift_hz 0)");
    drift_log d = {.cap = frames};
    csf_status st = csf_phase_meter_open(p, s, 0, lum, lum_ctx, &d.m, err);
    if (st) return st;
    d.t_s = malloc(sizeof(double) * (size_t)frames);
    d.phase = malloc(sizeof(double) * (size_t)frames);
    if (!d.t_s || !d.phase) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    if (!st) st = drift_trial(p, s, frames, &d, err);
    memset(out, 0, sizeof *out);
    if (!st)
        st = csf_drift_fit_phases(d.t_s, d.phase, d.n, s->drift_hz, csf_presenter_refresh_hz(p), &out->fit,
                                  err);
    if (!st) {
        out->freq_cpd = d.freq_cpd;
        out->contrast = d.contrast_sum / d.n;
        out->mean_lum_cdm2 = d.mean_sum / d.n;
        out->speed_asked_dps = s->drift_hz / s->freq_cpd;
        out->speed_measured_dps = out->fit.tf_measured_hz / d.freq_cpd;
        out->speed_rel_error = out->speed_measured_dps / out->speed_asked_dps - 1;
        out->speed_ok = fabs(out->speed_rel_error) <= CSF_DRIFT_SPEED_TOL;
    }
    free(d.t_s);
    free(d.phase);
    csf_phase_meter_close(d.m);
    return st;
}
