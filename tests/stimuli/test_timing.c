/* Frame timing on the virtual clock: timestamps, injected missed frames and their flags, trial
 * records (contrast per refresh period, deviation flags), temporal envelopes, response stops,
 * the bookkeeping-only fast path, drift and motion. */
#include <math.h>
#include <string.h>

#include "stim_test.h"
#include "tests/check.h"

static csf_presenter *open_small(int dither, int render_every, uint64_t seed)
{
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&cfg.geometry, 531, 299, 1920, 1080, 570, 0, 0, &e), CSF_OK);
    cfg.render_width_px = 240; /* reduced raster, full geometry */
    cfg.render_height_px = 135;
    cfg.dither = dither;
    cfg.render_every = render_every;
    cfg.seed = seed;
    return stim_test_open(&cfg);
}

static csf_stimulus gabor(double c)
{
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = 2;
    s.sigma_deg = 1;
    s.contrast = c;
    return s;
}

typedef struct {
    int stop_at;
    int calls;
    double last_c;
} stop_ctx;

static int stop_after(void *ctx, const csf_frame_info *f)
{
    stop_ctx *s = ctx;
    s->calls++;
    s->last_c = f->contrast_shown;
    return s->calls >= s->stop_at;
}

int main(void)
{
    csf_error e;
    csf_presenter *p = open_small(CSF_DITHER_NOISE, 1, 1);
    /* virtual clock: 1/60 s per frame, missed frames injected */
    CHECK_INT_EQ(csf_presenter_inject_missed(p, 5, 2, &e), CSF_OK);
    csf_stimulus s = gabor(0.05);
    for (int i = 0; i < 8; i++) {
        csf_frame_info fi;
        CHECK_INT_EQ(csf_presenter_draw(p, i % 2 ? &s : NULL, 1, &fi, &e), CSF_OK);
        CHECK_INT_EQ(fi.frame_index, i);
        double want_t = (i + (i >= 5 ? 2 : 0)) / 60.0;
        CHECK_NEAR(fi.t_s, want_t, 1e-12);
        CHECK_INT_EQ(fi.missed, i == 5);
        CHECK_NEAR(fi.interval_s, i == 0 ? 0 : (i == 5 ? 3 : 1) / 60.0, 1e-12);
        CHECK_NEAR(fi.contrast_shown, i % 2 ? 0.05 : 0.0, 0);
        CHECK(fi.rendered);
    }
    CHECK_INT_EQ(csf_presenter_inject_missed(p, 9, 0, &e), CSF_E_INVALID_ARG);

    /* fixed 0.5 s trial: 30 periods, all at the stimulus contrast */
    csf_envelope env = {CSF_ENV_FIXED, 0.5, 0, 0};
    csf_trial_record r;
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &env, 1, NULL, NULL, &r, &e), CSF_OK);
    CHECK_INT_EQ(r.frames_planned, 30);
    CHECK_INT_EQ(r.frames_shown, 30);
    CHECK_INT_EQ(r.frames_drawn, 31);
    CHECK_INT_EQ(r.frames_missed, 0);
    CHECK_INT_EQ(r.deviated, 0);
    CHECK_MSG(strcmp(r.flags, "") == 0, "flags \"%s\"", r.flags);
    CHECK_NEAR(r.contrast_shown_mean, 0.05, 1e-12);
    CHECK_NEAR(r.t_end_s - r.t_onset_s, 0.5, 1e-9);
    csf_trial_record_free(&r);

    /* the same with a frame missed in the middle: flagged, but contrast stays as planned */
    long f0 = 8 + 31;
    CHECK_INT_EQ(csf_presenter_inject_missed(p, f0 + 10, 1, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &env, 1, NULL, NULL, &r, &e), CSF_OK);
    CHECK_INT_EQ(r.frames_missed, 1);
    CHECK_INT_EQ(r.frames_shown, 30);
    CHECK_INT_EQ(r.frames_drawn, 30);
    CHECK_INT_EQ(r.deviated, 1);
    CHECK_MSG(strcmp(r.flags, "missed_frames") == 0, "flags \"%s\"", r.flags);
    csf_trial_record_free(&r);

    /* fade-in 0.001 -> 0.1 over 2 s, linear in log contrast; a missed frame holds a lower
     * contrast for an extra period: missed_frames and contrast_dev */
    s.contrast = 0.1;
    csf_envelope fade = {CSF_ENV_FADE_LOG, 2.0, 0, 0.001};
    CHECK_NEAR(csf_envelope_contrast(&fade, 0.1, 0), 0.001, 1e-15);
    CHECK_NEAR(csf_envelope_contrast(&fade, 0.1, 1.0), 0.01, 1e-12);
    CHECK_NEAR(log10(csf_envelope_contrast(&fade, 0.1, 0.5)), -2.5, 1e-12);
    CHECK_NEAR(csf_envelope_contrast(&fade, 0.1, 2.0), 0.0, 0);
    long f1 = f0 + 30;
    CHECK_INT_EQ(csf_presenter_inject_missed(p, f1 + 60, 2, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &fade, 1, NULL, NULL, &r, &e), CSF_OK);
    CHECK_INT_EQ(r.frames_planned, 120);
    CHECK_INT_EQ(r.frames_shown, 120);
    CHECK_INT_EQ(r.frames_missed, 1);
    CHECK_MSG(strcmp(r.flags, "missed_frames,contrast_dev") == 0, "flags \"%s\"", r.flags);
    /* held frame: periods 59, 60, 61 show the contrast planned for period 59 */
    CHECK_NEAR(r.contrast_per_period[60], r.contrast_per_period[59], 0);
    CHECK_NEAR(r.contrast_per_period[62], csf_envelope_contrast(&fade, 0.1, 62 / 60.0), 1e-12);
    CHECK(r.max_abs_deviation > 0);
    csf_trial_record_free(&r);

    /* a clean fade ends at the request, and stop() cuts it short (a response) */
    stop_ctx sc = {45, 0, 0};
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &fade, 1, stop_after, &sc, &r, &e), CSF_OK);
    CHECK_INT_EQ(r.stopped_by_callback, 1);
    CHECK_INT_EQ(r.frames_shown, 45);
    CHECK_INT_EQ(r.deviated, 0);
    CHECK_NEAR(sc.last_c, csf_envelope_contrast(&fade, 0.1, 44 / 60.0), 1e-12);
    CHECK_NEAR(r.contrast_shown_last, sc.last_c, 0);
    csf_trial_record_free(&r);

    /* raised cosine envelope */
    csf_envelope rc = {CSF_ENV_RAISED_COSINE, 1.0, 0.2, 0};
    CHECK_NEAR(csf_envelope_contrast(&rc, 0.1, 0.1), 0.05, 1e-12);
    CHECK_NEAR(csf_envelope_contrast(&rc, 0.1, 0.5), 0.1, 1e-12);
    CHECK_NEAR(csf_envelope_contrast(&rc, 0.1, 0.9), 0.05, 1e-12);
    CHECK_NEAR(csf_envelope_contrast(&rc, 0.1, 1.1), 0.0, 0);

    /* bad trials are refused before anything is shown */
    csf_envelope bad = {CSF_ENV_FADE_LOG, 1.0, 0, 0.5};
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &bad, 1, NULL, NULL, &r, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "fade start contrast");
    csf_presenter_close(p);

    /* miss rate: reproducible per seed, about the requested fraction */
    int counts[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        p = open_small(CSF_DITHER_NOISE, -1, 99);
        csf_presenter_set_miss_rate(p, 0.1);
        s = gabor(0.05);
        for (int i = 0; i < 600; i++) {
            csf_frame_info fi;
            CHECK_INT_EQ(csf_presenter_draw(p, &s, 1, &fi, &e), CSF_OK);
            counts[k] += fi.missed;
            CHECK_INT_EQ(fi.rendered, 0);
        }
        /* nothing rasterised: readback says why */
        uint16_t px[3];
        CHECK_INT_EQ(csf_presenter_readback_levels(p, px, &e), CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(e.msg, "render_every");
        csf_presenter_close(p);
    }
    CHECK_INT_EQ(counts[0], counts[1]);
    CHECK(counts[0] > 30 && counts[0] < 95);

    /* drift: half a cycle later the carrier is inverted; motion: the patch is where a static
     * patch at the moved eccentricity is (no dither, so frames compare pixel for pixel) */
    p = open_small(CSF_DITHER_NONE, 1, 1);
    int w, h;
    csf_presenter_render_size(p, &w, &h);
    size_t n = (size_t)w * h * 3;
    uint16_t *a = malloc(n * 2), *b = malloc(n * 2);
    csf_frame_info fi;
    s = gabor(0.5);
    s.drift_hz = 2;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
    csf_presenter_readback_levels(p, a, &e);
    s.time_s = 0.25;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
    csf_presenter_readback_levels(p, b, &e);
    int bg = a[0];
    size_t centre = 0; /* the pixel farthest from the background in the first frame */
    for (size_t i = 0; i < n; i += 3)
        if (abs(a[i] - bg) > abs(a[centre] - bg)) centre = i;
    CHECK((a[centre] - bg) * (b[centre] - bg) < 0); /* bright peak became dark */
    CHECK(abs(a[centre] - bg) > 20);
    s = gabor(0.5);
    s.ecc_deg = 2;
    s.velocity_dps = 4;
    s.motion_dir_deg = 0;
    s.time_s = 1.0;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
    csf_presenter_readback_levels(p, a, &e);
    s.ecc_deg = 6;
    s.velocity_dps = 0;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
    csf_presenter_readback_levels(p, b, &e);
    size_t diff = 0;
    for (size_t i = 0; i < n; i++) diff += a[i] != b[i];
    CHECK_MSG(diff < n / 1000, "%zu of %zu values differ", diff, n);
    /* a moving trial whose path would leave the screen is refused up front */
    s.ecc_deg = 2;
    s.velocity_dps = 60;
    CHECK_INT_EQ(csf_presenter_run_trial(p, &s, &env, 0, NULL, NULL, &r, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "the screen reaches 25 deg");
    free(a);
    free(b);
    csf_presenter_close(p);
    return CHECK_RESULT();
}
