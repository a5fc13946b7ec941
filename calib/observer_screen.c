/* The simulated person's eyes on the presenter (see observer_screen.h). */
#include "calib/observer_screen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/display_model.h"
#include "model/observer_view.h"
#include "stimuli/geometry.h"

/* Places are cached by (frequency, eccentricity, polar angle): a session shows a few dozen. */
#define CACHE_N 64

typedef struct {
    double freq, ecc, polar;
    int x, y, w, h; /* region in screen pixels, top row first */
    csf_view_place *pl;
    int pinned;
} place;

struct csf_obs_screen {
    csf_presenter *pres;
    const csf_geometry *g;
    csf_display_model *model;
    const csf_display_profile *profile;
    csf_view_display disp;
    char display_desc[400];
    double sigma_deg, orientation_deg;
    int step;
    place cache[CACHE_N];
    int n_cache, evict;
    /* the current look */
    int n_look, look[CSF_OBS_SCREEN_MAX_PLACES];
    int looking, per_frame, max_frames, frame_k, frames_seen;
    double latest;
    double ecc_deg, ref_velocity_dps, period_s;
    int pending; /* the last frame presented was looked at: its time on screen is open */
    double pending_t_s;
    csf_view_gain_fn gain;
    void *gain_ctx;
    uint16_t *buf;
    size_t buf_px;
    csf_status hook_st;
    csf_error hook_err;
};

static double model_lum(void *ctx, double r, double g, double b)
{
    return csf_display_model_lum((const csf_display_model *)ctx, r, g, b);
}

/* A profile as the truth: grey through the grey curve, mixed pixels additively by channel. */
static double profile_lum(void *ctx, double r, double g, double b)
{
    const csf_display_profile *p = ctx;
    if ((r == g && g == b) || !csf_profile_has_channels(p)) return csf_profile_grey_lum(p, (r + g + b) / 3);
    return csf_profile_lum_black(p) + csf_profile_channel_lum(p, 0, r) + csf_profile_channel_lum(p, 1, g) +
           csf_profile_channel_lum(p, 2, b);
}

static csf_status open_display(csf_obs_screen *s, const char *display, double gamma, csf_error *err)
{
    char spec[1100];
    const char *pd = csf_profile_display(s->profile);
    if (!display || !display[0]) {
        if (csf_display_model_spec_from_sim_photometer(pd, spec, sizeof spec) == 0) {
            snprintf(s->display_desc, sizeof s->display_desc, "%.300s (the profile's display)", spec);
        } else {
            snprintf(s->display_desc, sizeof s->display_desc, "profile (the display '%.200s' the profile "
                     "describes)", pd);
            s->model = NULL;
            return CSF_OK;
        }
    } else if (!strcmp(display, "profile")) {
        snprintf(s->display_desc, sizeof s->display_desc, "profile (%.200s)", csf_profile_id(s->profile));
        return CSF_OK;
    } else {
        if (gamma > 0) snprintf(spec, sizeof spec, "%.900s,gamma=%g", display, gamma);
        else snprintf(spec, sizeof spec, "%.1000s", display);
        snprintf(s->display_desc, sizeof s->display_desc, "%.390s", spec);
    }
    csf_status st = csf_display_model_create(spec, &s->model, err);
    if (st != CSF_OK && err) {
        char m[sizeof err->msg];
        snprintf(m, sizeof m, "%s", err->msg);
        csf_error_set(err, st, "--observer view=frame: display '%.200s': %s", spec, m);
    }
    return st;
}

static void on_frame(void *ctx, csf_presenter *pres, const csf_frame_info *fi);

csf_status csf_obs_screen_open(csf_presenter *pres, const csf_display_profile *profile,
                               const char *display, double display_gamma, double sigma_deg,
                               double orientation_deg, int frame_step, csf_obs_screen **out,
                               csf_error *err)
{
    *out = NULL;
    if (!pres || !profile || frame_step < 1 || frame_step > 30 || !(sigma_deg > 0))
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer screen: bad arguments (frame_step %d: 1 to 30)",
                             frame_step);
    csf_obs_screen *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    s->pres = pres;
    s->g = csf_presenter_geometry(pres);
    s->profile = profile;
    s->sigma_deg = sigma_deg;
    s->orientation_deg = orientation_deg;
    s->step = frame_step;
    double hz = csf_presenter_refresh_hz(pres);
    s->period_s = hz > 0 ? 1.0 / hz : 1.0 / 60;
    csf_status st = open_display(s, display, display_gamma, err);
    if (st == CSF_OK) {
        int maxlevel = (1 << csf_presenter_bits(pres)) - 1;
        st = s->model ? csf_view_display_init(&s->disp, model_lum, s->model, maxlevel, err)
                      : csf_view_display_init(&s->disp, profile_lum, (void *)profile, maxlevel, err);
    }
    if (st != CSF_OK) {
        csf_obs_screen_close(s);
        return st;
    }
    csf_presenter_set_frame_hook(pres, on_frame, s);
    *out = s;
    return CSF_OK;
}

void csf_obs_screen_close(csf_obs_screen *s)
{
    if (!s) return;
    if (s->pres) csf_presenter_set_frame_hook(s->pres, NULL, NULL);
    for (int i = 0; i < s->n_cache; i++) csf_view_place_free(s->cache[i].pl);
    csf_view_display_free(&s->disp);
    csf_display_model_free(s->model);
    free(s->buf);
    free(s);
}

const char *csf_obs_screen_display(const csf_obs_screen *s) { return s->display_desc; }

/* Builds a place: the disc's bounding box in pixels, each pixel's angle-space coordinates. */
static csf_status make_place(csf_obs_screen *s, double freq, double ecc, double polar, place *out,
                             csf_error *err)
{
    const csf_geometry *g = s->g;
    double r_deg = CSF_OBS_SCREEN_RADIUS_SIGMAS * s->sigma_deg;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, cx, cy;
    if (!csf_geometry_deg_to_px(g, ecc, polar, &cx, &cy) || cx < 0 || cy < 0 || cx > g->width_px ||
        cy > g->height_px)
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer screen: a place at %g deg, polar %g deg is "
                             "off-screen", ecc, polar);
    for (int i = 0; i < 48; i++) {
        double e2, p2, px, py;
        csf_geometry_move(g, ecc, polar, 7.5 * i, r_deg, &e2, &p2);
        if (!csf_geometry_deg_to_px(g, e2, p2, &px, &py)) continue;
        x0 = fmin(x0, px), x1 = fmax(x1, px), y0 = fmin(y0, py), y1 = fmax(y1, py);
    }
    int ix0 = (int)fmax(0, floor(x0) - 2), iy0 = (int)fmax(0, floor(y0) - 2);
    int ix1 = (int)fmin(g->width_px, ceil(x1) + 2), iy1 = (int)fmin(g->height_px, ceil(y1) + 2);
    int w = ix1 - ix0, h = iy1 - iy0;
    if (w < 4 || h < 4 || w > CSF_REGION_MAX_PX || h > CSF_REGION_MAX_PX)
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer screen: the region around %g deg, polar %g "
                             "deg is %dx%d px (4 to %d a side)", ecc, polar, w, h, CSF_REGION_MAX_PX);
    size_t n = (size_t)w * h;
    float *u = malloc(n * sizeof *u), *v = malloc(n * sizeof *v);
    unsigned char *use = malloc(n);
    if (!u || !v || !use) {
        free(u), free(v), free(use);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    /* The shader's own mapping (stimuli/presenter.c): pixel -> screen mm -> direction from the
     * eye -> azimuthal-equidistant (u, v) around the place's centre direction c with tangent
     * basis h, v; the same as csf_geometry_local_uv, written out because it runs per pixel. */
    double c[3], hb[3], vb[3], fc[3], fh[3], fv[3];
    csf_geometry_centre_basis(g, ecc, polar, c, hb, vb);
    csf_geometry_centre_basis(g, 0.0, 0.0, fc, fh, fv);
    const double cos_mask = cos(CSF_OBS_SCREEN_FIX_MASK_DEG * M_PI / 180), r2 = r_deg * r_deg;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t k = (size_t)j * w + i;
            double fx = ix0 + i + 0.5, fy = g->height_px - (iy0 + j + 0.5);
            double d[3] = {(fx / g->width_px - 0.5) * g->width_mm - g->eye_x_mm,
                           (fy / g->height_px - 0.5) * g->height_mm - g->eye_y_mm, -g->distance_mm};
            double dn = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int q = 0; q < 3; q++) d[q] /= dn;
            double dc = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
            double cr[3] = {d[1] * c[2] - d[2] * c[1], d[2] * c[0] - d[0] * c[2], d[0] * c[1] - d[1] * c[0]};
            double a = atan2(sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]), dc);
            double xh = d[0] * hb[0] + d[1] * hb[1] + d[2] * hb[2], yv = d[0] * vb[0] + d[1] * vb[1] + d[2] * vb[2];
            double sl = hypot(xh, yv), sc = (sl > 1e-12 ? a / sl : 1.0) * 180 / M_PI;
            double uu = sc * xh, vv = sc * yv;
            u[k] = (float)uu;
            v[k] = (float)vv;
            use[k] = uu * uu + vv * vv <= r2 && d[0] * fc[0] + d[1] * fc[1] + d[2] * fc[2] < cos_mask;
        }
    csf_view_place *pl = NULL;
    csf_status st = csf_view_place_create(u, v, use, (int)n, freq, s->orientation_deg, s->sigma_deg, &pl, err);
    free(u), free(v), free(use);
    if (st != CSF_OK) return st;
    *out = (place){freq, ecc, polar, ix0, iy0, w, h, pl, 0};
    return CSF_OK;
}

static csf_status find_place(csf_obs_screen *s, double freq, double ecc, double polar, int *index,
                             csf_error *err)
{
    for (int i = 0; i < s->n_cache; i++)
        if (s->cache[i].freq == freq && s->cache[i].ecc == ecc && s->cache[i].polar == polar) {
            *index = i;
            return CSF_OK;
        }
    place p;
    csf_status st = make_place(s, freq, ecc, polar, &p, err);
    if (st != CSF_OK) return st;
    int slot = s->n_cache;
    if (slot == CACHE_N) {
        do slot = s->evict = (s->evict + 1) % CACHE_N;
        while (s->cache[slot].pinned);
        csf_view_place_free(s->cache[slot].pl);
    } else {
        s->n_cache++;
    }
    s->cache[slot] = p;
    size_t need = (size_t)p.w * p.h;
    if (need > s->buf_px) {
        uint16_t *b = realloc(s->buf, need * 3 * sizeof *b);
        if (!b) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
        s->buf = b;
        s->buf_px = need;
    }
    *index = slot;
    return CSF_OK;
}

static double person_gain(void *ctx, double freq_cpd, double ecc_deg, double velocity_dps)
{
    return csf_observer_sim_velocity_log10_gain((const csf_observer_sim *)ctx, freq_cpd, ecc_deg,
                                                velocity_dps);
}

void csf_obs_screen_set_gain(csf_obs_screen *s, csf_view_gain_fn gain, void *ctx)
{
    s->gain = gain;
    s->gain_ctx = ctx;
}

void csf_obs_screen_set_person(csf_obs_screen *s, const csf_observer_sim *o)
{
    if (o) csf_obs_screen_set_gain(s, person_gain, (void *)o);
    else csf_obs_screen_set_gain(s, NULL, NULL);
}

csf_status csf_obs_screen_look(csf_obs_screen *s, double freq_cpd, double ecc_deg,
                               const double *polar_deg, int n, int max_frames, csf_error *err)
{
    return csf_obs_screen_look_v(s, freq_cpd, ecc_deg, 0.0, polar_deg, n, max_frames, err);
}

csf_status csf_obs_screen_look_v(csf_obs_screen *s, double freq_cpd, double ecc_deg, double ref_velocity_dps,
                                 const double *polar_deg, int n, int max_frames, csf_error *err)
{
    if (n < 1 || n > CSF_OBS_SCREEN_MAX_PLACES || !polar_deg || max_frames < 0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer screen: %d places (1 to %d)", n,
                             CSF_OBS_SCREEN_MAX_PLACES);
    if (!isfinite(ref_velocity_dps))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "observer screen: reference velocity %g deg/s is not finite", ref_velocity_dps);
    for (int i = 0; i < s->n_cache; i++) s->cache[i].pinned = 0;
    s->looking = 0;
    for (int k = 0; k < n; k++) {
        csf_status st = find_place(s, freq_cpd, ecc_deg, polar_deg[k], &s->look[k], err);
        if (st != CSF_OK) return st;
        s->cache[s->look[k]].pinned = 1;
        csf_view_place_reset(s->cache[s->look[k]].pl);
    }
    s->n_look = n;
    s->per_frame = max_frames == 0;
    s->max_frames = max_frames;
    s->frame_k = 0;
    s->frames_seen = 0;
    s->latest = 0;
    s->ecc_deg = ecc_deg;
    s->ref_velocity_dps = ref_velocity_dps;
    s->pending = 0;
    s->looking = 1;
    return CSF_OK;
}

static double seen(const csf_obs_screen *s, const place *p, double since_s, csf_view_motion_info *info)
{
    return csf_view_place_motion_contrast(p->pl, s->ecc_deg, s->ref_velocity_dps, since_s, s->period_s,
                                          s->gain, s->gain_ctx, info);
}

static void on_frame(void *ctx, csf_presenter *pres, const csf_frame_info *fi)
{
    csf_obs_screen *s = ctx;
    if (!s->looking || s->hook_st != CSF_OK) return;
    /* The frame looked at before this one stayed on screen until this one came. */
    if (s->pending)
        for (int i = 0; i < s->n_look; i++)
            csf_view_place_set_duration(s->cache[s->look[i]].pl, fi->t_s - s->pending_t_s);
    s->pending = 0;
    int k = s->frame_k++;
    if ((s->max_frames > 0 && k >= s->max_frames) || k % s->step != 0) return;
    for (int i = 0; i < s->n_look; i++) {
        place *p = &s->cache[s->look[i]];
        csf_status st = csf_presenter_readback_region(pres, p->x, p->y, p->w, p->h, s->buf, &s->hook_err);
        if (st == CSF_OK) st = csf_view_place_add_frame_at(p->pl, &s->disp, s->buf, fi->t_s, &s->hook_err);
        if (st != CSF_OK) {
            s->hook_st = st;
            return;
        }
        /* the window's frames: those presented less than CSF_OBS_SCREEN_WINDOW_S before this one */
        if (i == 0 && s->per_frame) s->latest = seen(s, p, fi->t_s - CSF_OBS_SCREEN_WINDOW_S + 1e-9, NULL);
    }
    s->pending = 1;
    s->pending_t_s = fi->t_s;
    s->frames_seen++;
}

csf_status csf_obs_screen_stop(csf_obs_screen *s, double *contrast, csf_error *err)
{
    return csf_obs_screen_stop_info(s, contrast, NULL, err);
}

csf_status csf_obs_screen_stop_info(csf_obs_screen *s, double *contrast, csf_view_motion_info *info,
                                    csf_error *err)
{
    s->looking = 0;
    if (s->hook_st != CSF_OK) {
        csf_status st = s->hook_st;
        s->hook_st = CSF_OK;
        return csf_error_set(err, st, "observer screen: %s", s->hook_err.msg);
    }
    for (int i = 0; i < s->n_look && contrast; i++)
        contrast[i] = seen(s, &s->cache[s->look[i]], -INFINITY, info ? &info[i] : NULL);
    return CSF_OK;
}

double csf_obs_screen_latest(const csf_obs_screen *s) { return s->latest; }
int csf_obs_screen_frames(const csf_obs_screen *s) { return s->frames_seen; }
