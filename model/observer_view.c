/* Matched-filter measurement of what is on screen at a place (see observer_view.h). */
#include "model/observer_view.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_velocity.h"

/* One looked-at frame for the motion analysis: its time, time on screen (NAN: not yet known)
 * and its own fit. */
typedef struct {
    double t_s, dur_s, l0, a, b;
} view_sample;

struct csf_view_place {
    int n_px;
    int *idx;        /* used pixels */
    float *bc, *bs;  /* E cos, E sin at each used pixel */
    int n_used;
    double minv[3][3]; /* inverse of the normal matrix of (1, E cos, E sin) */
    double acc[3];     /* sum over frames of sum_i L_i * basis_k(i) */
    int frames;
    double freq_cpd;
    view_sample *smp; /* frames added with a time */
    int n_smp, cap_smp;
};

csf_status csf_view_display_init(csf_view_display *d, csf_view_lum_fn lum, void *ctx, int maxlevel,
                                 csf_error *err)
{
    memset(d, 0, sizeof *d);
    if (!lum || maxlevel < 1 || maxlevel > 65535)
        return csf_error_set(err, CSF_E_INVALID_ARG, "view display: no luminance function or max level %d "
                             "outside 1 to 65535", maxlevel);
    d->grey_cdm2 = malloc(sizeof(double) * (size_t)(maxlevel + 1));
    if (!d->grey_cdm2) return csf_error_set(err, CSF_E_NOMEM, "view display: out of memory");
    d->lum = lum;
    d->ctx = ctx;
    d->maxlevel = maxlevel;
    for (int k = 0; k <= maxlevel; k++) {
        double v = (double)k / maxlevel;
        d->grey_cdm2[k] = lum(ctx, v, v, v);
    }
    return CSF_OK;
}

void csf_view_display_free(csf_view_display *d)
{
    if (!d) return;
    free(d->grey_cdm2);
    d->grey_cdm2 = NULL;
}

double csf_view_display_pixel(const csf_view_display *d, const uint16_t rgb[3])
{
    int m = d->maxlevel;
    int r = rgb[0] > m ? m : rgb[0], g = rgb[1] > m ? m : rgb[1], b = rgb[2] > m ? m : rgb[2];
    if (r == g && g == b) return d->grey_cdm2[r];
    return d->lum(d->ctx, (double)r / m, (double)g / m, (double)b / m);
}

/* Inverse of a symmetric 3x3 matrix by cofactors; 0 when it is (numerically) singular. */
static int invert3(const double a[3][3], double out[3][3])
{
    double c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    double c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    double c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    double det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    double scale = fabs(a[0][0] * a[1][1] * a[2][2]);
    if (!(fabs(det) > 1e-12 * scale) || !isfinite(det)) return 0;
    out[0][0] = c00 / det;
    out[1][0] = c01 / det;
    out[2][0] = c02 / det;
    out[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
    out[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
    out[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
    out[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
    out[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
    out[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
    return 1;
}

csf_status csf_view_place_create(const float *u_deg, const float *v_deg, const unsigned char *use,
                                 int n_px, double freq_cpd, double orientation_deg, double sigma_deg,
                                 csf_view_place **out, csf_error *err)
{
    *out = NULL;
    if (!u_deg || !v_deg || n_px <= 0 || n_px > (1 << 24))
        return csf_error_set(err, CSF_E_INVALID_ARG, "view place: %d pixels (1 to %d)", n_px, 1 << 24);
    if (!(freq_cpd > 0 && freq_cpd <= 1000) || !(sigma_deg >= 0.02 && sigma_deg <= 30) ||
        !isfinite(orientation_deg))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "view place: frequency %g cpd (0 to 1000) / sigma %g deg (0.02 to 30) / "
                             "orientation %g deg out of range", freq_cpd, sigma_deg, orientation_deg);
    csf_view_place *pl = calloc(1, sizeof *pl);
    if (pl) {
        pl->idx = malloc(sizeof(int) * (size_t)n_px);
        pl->bc = malloc(sizeof(float) * (size_t)n_px);
        pl->bs = malloc(sizeof(float) * (size_t)n_px);
    }
    if (!pl || !pl->idx || !pl->bc || !pl->bs) {
        csf_view_place_free(pl);
        return csf_error_set(err, CSF_E_NOMEM, "view place: out of memory");
    }
    pl->n_px = n_px;
    pl->freq_cpd = freq_cpd;
    double co = cos(orientation_deg * M_PI / 180), si = sin(orientation_deg * M_PI / 180);
    double m[3][3] = {{0}};
    for (int i = 0; i < n_px; i++) {
        double u = u_deg[i], v = v_deg[i];
        if (!isfinite(u) || !isfinite(v)) {
            csf_view_place_free(pl);
            return csf_error_set(err, CSF_E_INVALID_ARG, "view place: pixel %d has no finite angle", i);
        }
        if (use && !use[i]) continue;
        double e = exp(-(u * u + v * v) / (2 * sigma_deg * sigma_deg));
        double ph = 2 * M_PI * freq_cpd * (u * co + v * si);
        double b[3] = {1.0, e * cos(ph), e * sin(ph)};
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) m[r][c] += b[r] * b[c];
        pl->idx[pl->n_used] = i;
        pl->bc[pl->n_used] = (float)b[1];
        pl->bs[pl->n_used] = (float)b[2];
        pl->n_used++;
    }
    if (pl->n_used < 16 || !invert3(m, pl->minv)) {
        int n = pl->n_used;
        csf_view_place_free(pl);
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "view place: %d usable pixels cannot separate a %g cpd Gabor from the "
                             "mean (at least 16 and a non-singular fit needed)", n, freq_cpd);
    }
    *out = pl;
    return CSF_OK;
}

void csf_view_place_free(csf_view_place *pl)
{
    if (!pl) return;
    free(pl->idx);
    free(pl->bc);
    free(pl->bs);
    free(pl->smp);
    free(pl);
}

void csf_view_place_reset(csf_view_place *pl)
{
    pl->acc[0] = pl->acc[1] = pl->acc[2] = 0;
    pl->frames = 0;
    pl->n_smp = 0;
}

/* The projections of one frame's light on (1, E cos, E sin), added to the running sums. */
static void project_frame(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb, double y[3])
{
    double s0 = 0, s1 = 0, s2 = 0;
    for (int j = 0; j < pl->n_used; j++) {
        double L = csf_view_display_pixel(d, rgb + 3 * (size_t)pl->idx[j]);
        s0 += L;
        s1 += L * pl->bc[j];
        s2 += L * pl->bs[j];
    }
    y[0] = s0, y[1] = s1, y[2] = s2;
    pl->acc[0] += s0;
    pl->acc[1] += s1;
    pl->acc[2] += s2;
    pl->frames++;
}

void csf_view_place_add_frame(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb)
{
    double y[3];
    project_frame(pl, d, rgb, y);
}

csf_status csf_view_place_add_frame_at(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb,
                                       double t_s, csf_error *err)
{
    if (pl->n_smp == pl->cap_smp) {
        int cap = pl->cap_smp ? 2 * pl->cap_smp : 64;
        view_sample *n = realloc(pl->smp, sizeof *n * (size_t)cap);
        if (!n) return csf_error_set(err, CSF_E_NOMEM, "view place: out of memory keeping %d frames", cap);
        pl->smp = n;
        pl->cap_smp = cap;
    }
    double y[3], c[3];
    project_frame(pl, d, rgb, y);
    for (int r = 0; r < 3; r++) c[r] = pl->minv[r][0] * y[0] + pl->minv[r][1] * y[1] + pl->minv[r][2] * y[2];
    pl->smp[pl->n_smp++] = (view_sample){t_s, NAN, c[0], c[1], c[2]};
    return CSF_OK;
}

void csf_view_place_set_duration(csf_view_place *pl, double duration_s)
{
    if (pl->n_smp > 0 && duration_s > 0) pl->smp[pl->n_smp - 1].dur_s = duration_s;
}

int csf_view_place_frames(const csf_view_place *pl) { return pl->frames; }

double csf_view_place_contrast(const csf_view_place *pl, double *mean_cdm2)
{
    if (mean_cdm2) *mean_cdm2 = 0;
    if (pl->frames == 0) return 0.0;
    double y[3], c[3];
    for (int k = 0; k < 3; k++) y[k] = pl->acc[k] / pl->frames;
    for (int r = 0; r < 3; r++) c[r] = pl->minv[r][0] * y[0] + pl->minv[r][1] * y[1] + pl->minv[r][2] * y[2];
    if (mean_cdm2) *mean_cdm2 = c[0];
    if (!(c[0] > 0)) return 0.0; /* a black field: no contrast to speak of */
    return hypot(c[1], c[2]) / c[0];
}

/* ---- motion energy (observer_view.h) ---- */

/* The frames of a window with their weights: the sustained component and the mean light. */
typedef struct {
    const view_sample *s;
    int n;
    double default_dur, total_dur, l0, span_s;
    double complex z0;
} view_window;

static double sample_dur(const view_window *w, int k)
{
    double d = w->s[k].dur_s;
    return d > 0 ? d : w->default_dur;
}

static double sinc_pi(double x)
{
    return fabs(x) < 1e-12 ? 1.0 : sin(M_PI * x) / (M_PI * x);
}

/* R(tf): the moving part of the window at temporal frequency tf_hz, each frame held on screen
 * for its duration (zero-order hold), relative to the window's mean light sum. */
static double complex moving_component(const view_window *w, double tf_hz)
{
    double complex r = 0;
    for (int k = 0; k < w->n; k++) {
        double d = sample_dur(w, k), t = w->s[k].t_s + 0.5 * d;
        double complex z = w->s[k].a + I * w->s[k].b - w->z0;
        r += z * d * sinc_pi(tf_hz * d) * cexp(-I * 2 * M_PI * tf_hz * t);
    }
    return r / w->total_dur;
}

/* 10^(gain(f, v) - gain(f, v_ref)), limited to 10^+-12 so that no weight overflows. */
static double weight(csf_view_gain_fn gain, void *ctx, double freq_cpd, double ecc_deg, double v,
                     double gain_ref)
{
    double g = gain(ctx, freq_cpd, ecc_deg, v) - gain_ref;
    if (isnan(g)) return 0.0;
    return pow(10.0, fmax(-12.0, fmin(12.0, g)));
}

static double default_gain(void *ctx, double freq_cpd, double ecc_deg, double velocity_dps)
{
    (void)ctx, (void)ecc_deg;
    csf_velocity_params p = csf_velocity_default();
    return csf_velocity_log10_gain(&p, freq_cpd, velocity_dps);
}

/* The window's frames (time >= since_s), their total time, mean light and sustained part. */
static void open_window(const csf_view_place *pl, double since_s, double default_dur, view_window *w)
{
    int first = pl->n_smp;
    while (first > 0 && !(pl->smp[first - 1].t_s < since_s)) first--;
    *w = (view_window){.s = pl->smp + first, .n = pl->n_smp - first, .default_dur = default_dur};
    double sl = 0;
    double complex sz = 0;
    for (int k = 0; k < w->n; k++) {
        double d = sample_dur(w, k);
        w->total_dur += d;
        sl += d * w->s[k].l0;
        sz += d * (w->s[k].a + I * w->s[k].b);
    }
    if (w->n == 0 || !(w->total_dur > 0)) return;
    w->l0 = sl / w->total_dur;
    w->z0 = sz / w->total_dur;
    w->span_s = w->s[w->n - 1].t_s + sample_dur(w, w->n - 1) - w->s[0].t_s;
}

double csf_view_place_motion_contrast(const csf_view_place *pl, double ecc_deg, double ref_velocity_dps,
                                      double since_s, double default_duration_s, csf_view_gain_fn gain,
                                      void *gain_ctx, csf_view_motion_info *info)
{
    view_window w;
    open_window(pl, since_s, default_duration_s, &w);
    if (info) *info = (csf_view_motion_info){0, 0, 0, w.n};
    if (w.n == 0 || !(w.l0 > 0)) return 0.0; /* nothing looked at, or a black field */
    if (!gain) gain = default_gain;
    double f = pl->freq_cpd;
    double gain_ref = gain(gain_ctx, f, ecc_deg, ref_velocity_dps);
    if (isnan(gain_ref)) gain_ref = 0;
    double best = cabs(w.z0) * weight(gain, gain_ctx, f, ecc_deg, 0.0, gain_ref), best_tf = 0;
    if (info) info->static_contrast = cabs(w.z0) / w.l0;
    if (w.n >= 2 && w.span_s > 0) {
        double step = 1.0 / (4 * w.span_s), nyquist = 0.5 * w.n / w.span_s;
        int n_bank = (int)fmin(CSF_VIEW_BANK_MAX, floor(nyquist / step));
        for (int j = 1; j <= n_bank; j++)
            for (int sign = -1; sign <= 1; sign += 2) {
                double tf = sign * j * step;
                double e = cabs(moving_component(&w, tf)) *
                           weight(gain, gain_ctx, f, ecc_deg, fabs(tf) / f, gain_ref);
                if (e > best) best = e, best_tf = tf;
            }
    }
    if (info) info->tf_hz = best_tf, info->velocity_dps = best_tf / f;
    return best / w.l0;
}
