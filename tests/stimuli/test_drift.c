/* Drifting carriers measured from rendered frames: the phase meter and the drift fit on
 * synthetic phases (a frame-count drift must be caught), then frames rendered through
 * csf_presenter_run_trial with and without missed frames (speed within 1 %, phase continuous
 * across a held frame), a frame-count presenter emulated through csf_presenter_draw (caught on
 * its rendered frames), the aliasing limit, and the caption overlay (the stimulus' own pixels
 * unchanged by it). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "stim_test.h"
#include "tests/check.h"

#define REFRESH_HZ 60.0

static csf_presenter *open_small(uint64_t seed, csf_display_model *m)
{
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&cfg.geometry, 531, 299, 1920, 1080, 570, 0, 0, &e), CSF_OK);
    cfg.render_width_px = 640; /* reduced raster (12 px/deg), full geometry */
    cfg.render_height_px = 360;
    cfg.refresh_hz = REFRESH_HZ;
    cfg.seed = seed;
    cfg.grey_lum_fn = stim_test_model_grey;
    cfg.grey_lum_ctx = m;
    return stim_test_open(&cfg);
}

static csf_stimulus drifting(double freq_cpd, double velocity_dps)
{
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = freq_cpd;
    s.sigma_deg = 1;
    s.ecc_deg = 4;
    s.polar_deg = 30;
    s.orientation_deg = 20;
    s.contrast = 0.3;
    s.drift_hz = velocity_dps * freq_cpd; /* Kelly (1979): tf = v f */
    return s;
}

/* Synthetic phases: a presenter that draws at presentation time, and one that counts frames. */
static void test_fit_synthetic(void)
{
    enum { N = 90 };
    double t[N], ph_time[N], ph_count[N], tf = 6.0;
    double tk = 0;
    for (int k = 0; k < N; k++) {
        if (k == 30 || k == 61) tk += 1.0 / REFRESH_HZ; /* two held frames */
        double noise = 0.004 * (csf_rng_uniform(11, 1, (uint64_t)k) - 0.5);
        t[k] = tk;
        ph_time[k] = remainder(2 * M_PI * tf * tk + 0.3 + noise, 2 * M_PI);
        ph_count[k] = remainder(2 * M_PI * tf * k / REFRESH_HZ + 0.3 + noise, 2 * M_PI);
        tk += 1.0 / REFRESH_HZ;
    }
    csf_drift_fit f;
    csf_error e;
    CHECK_INT_EQ(csf_drift_fit_phases(t, ph_time, N, tf, REFRESH_HZ, &f, &e), CSF_OK);
    CHECK_NEAR(f.tf_measured_hz, tf, 0.001 * tf);
    CHECK_INT_EQ(f.frames_missed, 2);
    CHECK(f.continuous);
    CHECK_NEAR(f.held_step_rad, 2 * M_PI * tf * 2 / REFRESH_HZ, 0.01);
    /* frame counting: the held frames lose one period's step each and the grating runs slow */
    CHECK_INT_EQ(csf_drift_fit_phases(t, ph_count, N, tf, REFRESH_HZ, &f, &e), CSF_OK);
    CHECK(!f.continuous);
    CHECK_NEAR(f.max_held_step_error_rad, 2 * M_PI * tf / REFRESH_HZ, 0.01);
    CHECK(f.tf_rel_error < -0.015);
    /* bad input */
    CHECK_INT_EQ(csf_drift_fit_phases(t, ph_time, 2, tf, REFRESH_HZ, &f, &e), CSF_E_INSUFFICIENT);
    CHECK_INT_EQ(csf_drift_fit_phases(t, ph_time, N, 30, REFRESH_HZ, &f, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "half the refresh rate");
}

/* Sessions' path: run_trial, phase from the predicted presentation time. */
static void test_rendered(csf_display_model *m)
{
    csf_presenter *p = open_small(3, m);
    csf_error e;
    csf_selfcheck_drift_result r;
    csf_stimulus s = drifting(1.0, 4.0);
    CHECK_MSG(csf_selfcheck_drift(p, &s, 60, stim_test_model_lum, m, &r, &e) == CSF_OK, "%s", e.msg);
    CHECK_INT_EQ(r.fit.frames, 60);
    CHECK_INT_EQ(r.fit.frames_missed, 0);
    CHECK_MSG(fabs(r.speed_rel_error) < 0.01, "speed %g asked %g", r.speed_measured_dps, r.speed_asked_dps);
    CHECK(r.speed_ok && r.fit.continuous);
    CHECK_NEAR(r.contrast, 0.3, 0.015);
    /* opposite direction */
    s = drifting(1.0, -4.0);
    CHECK_MSG(csf_selfcheck_drift(p, &s, 40, stim_test_model_lum, m, &r, &e) == CSF_OK, "%s", e.msg);
    CHECK_MSG(fabs(r.speed_rel_error) < 0.01, "speed %g asked %g", r.speed_measured_dps, r.speed_asked_dps);
    /* missed frames: two injected (one held 3 periods) and a 10 % miss rate */
    long base = csf_presenter_frame_index(p);
    CHECK_INT_EQ(csf_presenter_inject_missed(p, base + 12, 1, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_inject_missed(p, base + 40, 2, &e), CSF_OK);
    csf_presenter_set_miss_rate(p, 0.1);
    s = drifting(1.5, 5.0);
    CHECK_MSG(csf_selfcheck_drift(p, &s, 90, stim_test_model_lum, m, &r, &e) == CSF_OK, "%s", e.msg);
    CHECK_MSG(r.fit.frames_missed >= 2, "%d missed", r.fit.frames_missed);
    CHECK(r.fit.frames < 90); /* time-based: a held frame takes the place of the frames it covers */
    CHECK_MSG(fabs(r.speed_rel_error) < 0.01, "speed %g asked %g", r.speed_measured_dps, r.speed_asked_dps);
    CHECK_MSG(r.fit.continuous, "max step error %g rad, tolerance %g", r.fit.max_step_error_rad,
              r.fit.step_tolerance_rad);
    CHECK_NEAR(r.fit.held_step_rad, r.fit.held_step_expected_rad, r.fit.step_tolerance_rad);
    CHECK(r.fit.held_step_expected_rad > 1.9 * r.fit.frame_step_rad);
    csf_presenter_close(p);
}

/* A presenter that advanced the carrier by frame count, emulated on the same renderer: its
 * rendered frames must fail the continuity check at the held frames. */
static void test_frame_count_caught(csf_display_model *m)
{
    csf_presenter *p = open_small(5, m);
    csf_error e;
    csf_stimulus s = drifting(1.0, 6.0);
    csf_phase_meter *pm = NULL;
    CHECK_MSG(csf_phase_meter_open(p, &s, 0, stim_test_model_lum, m, &pm, &e) == CSF_OK, "%s", e.msg);
    long base = csf_presenter_frame_index(p);
    CHECK_INT_EQ(csf_presenter_inject_missed(p, base + 20, 1, &e), CSF_OK);
    enum { N = 40 };
    double t[N], ph[N];
    for (int k = 0; k < N; k++) {
        csf_frame_info fi;
        s.time_s = k / REFRESH_HZ; /* the frame count, not the presentation time */
        CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
        csf_phase_reading rd;
        CHECK_INT_EQ(csf_phase_meter_read(pm, &rd, &e), CSF_OK);
        t[k] = fi.t_s;
        ph[k] = rd.phase_rad;
    }
    csf_drift_fit f;
    CHECK_INT_EQ(csf_drift_fit_phases(t, ph, N, s.drift_hz, REFRESH_HZ, &f, &e), CSF_OK);
    CHECK_INT_EQ(f.frames_missed, 1);
    CHECK(!f.continuous);
    CHECK_NEAR(f.max_held_step_error_rad, f.frame_step_rad, 0.25 * f.frame_step_rad);
    csf_phase_meter_close(pm);
    csf_presenter_close(p);
}

/* Aliasing: the presenter refuses drift at half the refresh rate; the meter refuses a moving patch. */
static void test_refusals(csf_display_model *m)
{
    csf_presenter *p = open_small(1, m);
    csf_error e;
    csf_stimulus s = drifting(2.0, 15.0); /* 30 Hz at 60 Hz */
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "Nyquist limit 30 Hz");
    s = drifting(2.0, 14.9);
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_OK);
    s.velocity_dps = 1;
    csf_phase_meter *pm = NULL;
    CHECK_INT_EQ(csf_phase_meter_open(p, &s, 0, stim_test_model_lum, m, &pm, &e), CSF_E_INVALID_ARG);
    CHECK(pm == NULL);
    csf_selfcheck_drift_result r;
    s = drifting(2.0, 0);
    CHECK_INT_EQ(csf_selfcheck_drift(p, &s, 30, stim_test_model_lum, m, &r, &e), CSF_E_INVALID_ARG);
    csf_presenter_close(p);
}

/* The caption changes only its own pixels: the rest of a static frame is the frame without it,
 * byte for byte, and readback_region shows the stimulus without the caption. */
static void test_caption(csf_display_model *m)
{
    csf_presenter *p = open_small(9, m);
    csf_error e;
    int w, h;
    csf_presenter_render_size(p, &w, &h);
    size_t n = (size_t)w * h * 3;
    uint16_t *a = malloc(n * 2), *b = malloc(n * 2);
    csf_stimulus s = drifting(1.0, 0);
    csf_frame_info fi;
    csf_presenter_set_frame_index(p, 100);
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 1, &fi, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, a, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_set_caption(p, "freq 1 cpd  contrast 0.3", &e), CSF_OK);
    csf_presenter_set_frame_index(p, 100);
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 1, &fi, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, b, &e), CSF_OK);
    size_t diff_top = 0, diff_rest = 0, top = (size_t)w * 3 * (h / 10);
    for (size_t i = 0; i < n; i++) {
        if (a[i] == b[i]) continue;
        if (i < top) diff_top++;
        else diff_rest++;
    }
    CHECK_MSG(diff_top > 50, "caption drew %zu values", diff_top);
    CHECK_INT_EQ((long)diff_rest, 0L);
    CHECK_INT_EQ(csf_presenter_set_caption(p, "two\nlines", &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_presenter_set_caption(p, NULL, &e), CSF_OK);
    csf_presenter_set_frame_index(p, 100);
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 1, &fi, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, b, &e), CSF_OK);
    CHECK(memcmp(a, b, n * 2) == 0);
    free(a);
    free(b);
    csf_presenter_close(p);
}

int main(void)
{
    test_fit_synthetic();
    csf_display_model *m = stim_test_model("lcd");
    test_rendered(m);
    test_frame_count_caught(m);
    test_refusals(m);
    test_caption(m);
    csf_display_model_free(m);
    return CHECK_RESULT();
}
