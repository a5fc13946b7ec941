/* The simulated person sees motion (model/observer_view.h, calib/observer_screen.h): the
 * spatio-temporal matched filter finds a drift at its temporal frequency and weighs it by the
 * person's sensitivity there relative to the velocity asked about, so a grating drawn frozen, at
 * the wrong speed or juddering is seen differently from one drawn right, while a static grating
 * asked about as static is seen as the fit of the mean light, as before. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/observer_screen.h"
#include "model/csf_velocity.h"
#include "model/observer_sim.h"
#include "model/observer_view.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"
#include "tests/check.h"

/* ---- the model alone, on synthetic frames ---- */

#define SIDE 48
#define MAXLEVEL 65535

static double linear_lum(void *ctx, double r, double g, double b)
{
    (void)ctx;
    return 100.0 * (r + g + b) / 3;
}

typedef struct {
    csf_view_display d;
    csf_view_place *pl;
    float u[SIDE * SIDE], v[SIDE * SIDE];
    uint16_t rgb[SIDE * SIDE * 3];
    double freq_cpd;
} synth;

static int synth_open(synth *s, double freq_cpd)
{
    csf_error e;
    s->freq_cpd = freq_cpd;
    for (int j = 0; j < SIDE; j++)
        for (int i = 0; i < SIDE; i++) {
            s->u[j * SIDE + i] = (float)(-2.0 + 4.0 * (i + 0.5) / SIDE);
            s->v[j * SIDE + i] = (float)(-2.0 + 4.0 * (j + 0.5) / SIDE);
        }
    if (csf_view_display_init(&s->d, linear_lum, NULL, MAXLEVEL, &e) != CSF_OK) return 0;
    return csf_view_place_create(s->u, s->v, NULL, SIDE * SIDE, freq_cpd, 0.0, 0.7, &s->pl, &e) == CSF_OK;
}

static void synth_close(synth *s)
{
    csf_view_place_free(s->pl);
    csf_view_display_free(&s->d);
}

/* One frame of a Gabor of contrast c at carrier phase phase_rad (mean 50 cd/m2), with
 * pixel noise of sd noise_cdm2 (a fixed generator, so runs repeat). */
static void synth_frame(synth *s, double c, double phase_rad, double noise_cdm2, unsigned *rng)
{
    for (int k = 0; k < SIDE * SIDE; k++) {
        double u = s->u[k], v = s->v[k];
        double env = exp(-(u * u + v * v) / (2 * 0.7 * 0.7));
        double n = 0;
        for (int q = 0; q < 12; q++) {
            *rng = *rng * 1103515245u + 12345u;
            n += (*rng >> 8) / 16777216.0;
        }
        double L = 50 * (1 + c * env * cos(2 * M_PI * s->freq_cpd * u - phase_rad)) + noise_cdm2 * (n - 6);
        long lv = lround(L / 100 * MAXLEVEL);
        uint16_t lev = (uint16_t)(lv < 0 ? 0 : lv > MAXLEVEL ? MAXLEVEL : lv);
        s->rgb[3 * k] = s->rgb[3 * k + 1] = s->rgb[3 * k + 2] = lev;
    }
}

/* n frames 1/60 s apart of a grating drifting at tf_hz (frame k held hold[k] periods, NULL: 1). */
static void synth_run(synth *s, double c, double tf_hz, int n, const int *hold, double noise, unsigned seed)
{
    csf_error e;
    csf_view_place_reset(s->pl);
    double t = 0;
    unsigned rng = seed;
    for (int k = 0; k < n; k++) {
        synth_frame(s, c, 2 * M_PI * tf_hz * t, noise, &rng);
        CHECK(csf_view_place_add_frame_at(s->pl, &s->d, s->rgb, t, &e) == CSF_OK);
        double dur = (hold ? hold[k] : 1) / 60.0;
        csf_view_place_set_duration(s->pl, dur);
        t += dur;
    }
}

static double kd_gain(double f, double v)
{
    csf_velocity_params p = csf_velocity_default();
    return csf_velocity_log10_gain(&p, f, v);
}

static void test_model_static_unchanged(void)
{
    synth s;
    CHECK(synth_open(&s, 2));
    /* noisy static gratings asked about as static: the fit of the mean light, to rounding */
    const double cons[] = {0.004, 0.02, 0.3};
    for (int i = 0; i < 3; i++) {
        synth_run(&s, cons[i], 0, 30, NULL, 0.2, 17u + (unsigned)i);
        csf_view_motion_info info;
        double mean_fit = csf_view_place_contrast(s.pl, NULL);
        double seen = csf_view_place_motion_contrast(s.pl, 0, 0, -INFINITY, 1 / 60.0, NULL, NULL, &info);
        CHECK_MSG(fabs(seen - mean_fit) <= 1e-9 * mean_fit, "c %g: seen %.12g, mean fit %.12g", cons[i], seen,
                  mean_fit);
        CHECK(info.tf_hz == 0 && info.n_frames == 30);
        CHECK(fabs(log10(seen / cons[i])) < 0.01);
    }
    synth_close(&s);
}

static void test_model_drift(void)
{
    synth s;
    CHECK(synth_open(&s, 2));
    double c = 0.05, f = 2;
    /* drawn right: a drift of 3 deg/s (6 Hz) asked about at 3 deg/s is its contrast (less the
     * display's sample-and-hold, sinc(6/60) = 0.984) */
    synth_run(&s, c, f * 3, 30, NULL, 0, 1);
    csf_view_motion_info info;
    double right = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, NULL, NULL, &info);
    CHECK_MSG(fabs(log10(right / c)) < 0.02, "drawn right: %.4g seen for %.4g", right, c);
    CHECK_NEAR(fabs(info.velocity_dps), 3, 0.1);
    double mean_fit = csf_view_place_contrast(s.pl, NULL);
    CHECK_MSG(mean_fit < 0.1 * c, "a drift averages away in the mean light: %.3g", mean_fit);
    /* the other direction is the same speed */
    synth_run(&s, c, -f * 3, 30, NULL, 0, 1);
    double back = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, NULL, NULL, &info);
    CHECK_NEAR(log10(back), log10(right), 0.005);
    CHECK(info.tf_hz < 0);
    /* frozen, asked about at 3 deg/s: the static grating weighed by S(f, 0) / S(f, 3) */
    synth_run(&s, c, 0, 30, NULL, 0, 1);
    double frozen = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, NULL, NULL, &info);
    CHECK_NEAR(log10(frozen / c), -kd_gain(f, 3), 0.01);
    CHECK(info.tf_hz == 0);
    /* too fast (8 deg/s, 16 Hz): weighed by S(f, 8) / S(f, 3) */
    synth_run(&s, c, f * 8, 30, NULL, 0, 1);
    double fast = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, NULL, NULL, &info);
    double sh = log10(sin(M_PI * 16 / 60.0) / (M_PI * 16 / 60.0)); /* the hold's loss at 16 Hz */
    CHECK_NEAR(log10(fast / c), kd_gain(f, 8) - kd_gain(f, 3) + sh, 0.03);
    printf("2 cpd asked at 3 deg/s: right %.4g frozen %.4g 8 deg/s %.4g (drawn %.3g)\n", right, frozen, fast,
           c);
    CHECK(kd_gain(f, 8) < kd_gain(f, 3) - 0.3 && fast < 0.6 * right); /* faster is harder to see at 2 cpd */
    /* a juddering drift: every other frame held three periods (the same phase law, from the
     * frames' times): its energy leaves the drift's temporal frequency */
    int hold[30];
    for (int k = 0; k < 30; k++) hold[k] = k % 2 ? 3 : 1;
    synth_run(&s, c, f * 3, 30, hold, 0, 1);
    double judder = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, NULL, NULL, &info);
    printf("judder: %.4g at %.3g deg/s\n", judder, info.velocity_dps);
    CHECK_MSG(judder < right * pow(10.0, -0.03), "judder %.4g, drawn right %.4g", judder, right);
    synth_close(&s);
}

/* The person's own gain: a person insensitive to motion (vsteep=0) sees a frozen grating and a
 * drifting one alike. */
static double person_gain(void *ctx, double f, double e, double v)
{
    return csf_observer_sim_velocity_log10_gain((const csf_observer_sim *)ctx, f, e, v);
}

static void test_model_person(void)
{
    csf_observer_sim *flat = NULL;
    csf_error e;
    CHECK(csf_observer_sim_create("sim:vsteep=0", 1, &flat, &e) == CSF_OK);
    if (!flat) return;
    synth s;
    CHECK(synth_open(&s, 2));
    synth_run(&s, 0.05, 0, 30, NULL, 0, 1);
    double frozen = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, person_gain, flat, NULL);
    synth_run(&s, 0.05, 6, 30, NULL, 0, 1);
    double right = csf_view_place_motion_contrast(s.pl, 0, 3, -INFINITY, 1 / 60.0, person_gain, flat, NULL);
    CHECK_NEAR(log10(frozen), log10(0.05), 0.005);
    CHECK_NEAR(log10(right), log10(0.05 * sin(M_PI * 0.1) / (M_PI * 0.1)), 0.01);
    /* only the frames of the window count */
    csf_view_motion_info info;
    double last = csf_view_place_motion_contrast(s.pl, 0, 3, 0.41, 1 / 60.0, person_gain, flat, &info);
    CHECK(info.n_frames == 5 && last > 0); /* frames 25 .. 29 at k / 60 s */
    synth_close(&s);
    csf_observer_sim_free(flat);
}

/* ---- on the presenter: what a session's person sees ---- */

static csf_presenter *open_pres(const csf_display_profile *prof)
{
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    if (csf_geometry_init(&cfg.geometry, 531, 299, 640, 360, 570, 0, 0, &e) != CSF_OK) return NULL;
    cfg.render_width_px = 64;
    cfg.render_height_px = 36;
    cfg.profile = prof;
    cfg.seed = 5;
    csf_presenter *p = NULL;
    if (csf_presenter_open(&cfg, &p, &e) != CSF_OK) {
        fprintf(stderr, "presenter: %s\n", e.msg);
        return NULL;
    }
    return p;
}

typedef struct {
    int n, frames;
} stop_after;

static int stop_cb(void *ctx, const csf_frame_info *fi)
{
    (void)fi;
    stop_after *s = ctx;
    return ++s->frames >= s->n;
}

#define N_FRAMES 30

/* N_FRAMES stimulus frames of a Gabor drifting at drift_hz (frame k of the trial late by late[k]
 * periods), looked at as a grating of freq asked about at ref_v; the contrast seen. */
static double look_trial(csf_presenter *p, csf_obs_screen *eyes, long base, double freq, double drift_hz,
                         double ref_v, const int *late, csf_view_motion_info *info)
{
    csf_error e;
    csf_presenter_set_frame_index(p, base);
    for (int k = 0; late && k < N_FRAMES; k++)
        if (late[k]) CHECK(csf_presenter_inject_missed(p, base + k, late[k], &e) == CSF_OK);
    csf_stimulus s = {.kind = CSF_STIM_GABOR,
                      .freq_cpd = freq,
                      .sigma_deg = 1.0,
                      .ecc_deg = 5,
                      .polar_deg = 0,
                      .contrast = 0.05,
                      .mean_lum_cdm2 = 50,
                      .drift_hz = drift_hz};
    csf_envelope env = {CSF_ENV_FIXED, 3.0, 0, 0};
    const double polar = 0;
    CHECK(csf_obs_screen_look_v(eyes, freq, 5, ref_v, &polar, 1, N_FRAMES, &e) == CSF_OK);
    stop_after st = {N_FRAMES, 0};
    csf_trial_record rec;
    CHECK(csf_presenter_run_trial(p, &s, &env, 1, stop_cb, &st, &rec, &e) == CSF_OK);
    if (late) CHECK(rec.frames_missed > 0);
    csf_trial_record_free(&rec);
    double c = 0;
    CHECK(csf_obs_screen_stop_info(eyes, &c, info, &e) == CSF_OK);
    return c;
}

static void test_screen(void)
{
    csf_display_profile *prof = csf_profile_default();
    csf_presenter *p = open_pres(prof);
    csf_obs_screen *eyes = NULL;
    csf_error e;
    CHECK(p && csf_obs_screen_open(p, prof, "", 0, 1.0, 0.0, 1, &eyes, &e) == CSF_OK);
    if (!eyes) {
        csf_presenter_close(p);
        csf_profile_free(prof);
        return;
    }
    csf_view_motion_info info;
    /* 1 cpd asked about at 4 deg/s: moving helps a coarse grating (Kelly 1979) */
    double right = look_trial(p, eyes, 1000, 1, 4, 4, NULL, &info);
    CHECK_NEAR(fabs(info.velocity_dps), 4, 0.5);
    double frozen = look_trial(p, eyes, 2000, 1, 0, 4, NULL, &info);
    double slow = look_trial(p, eyes, 3000, 1, 1, 4, NULL, &info);
    printf("1 cpd at 4 deg/s: right %.4g, frozen %.4g, 1 deg/s %.4g (drawn 0.05)\n", right, frozen, slow);
    CHECK_MSG(fabs(log10(right / 0.05)) < 0.03, "drawn right: %.4g", right);
    CHECK_NEAR(log10(frozen / right), -kd_gain(1, 4), 0.04);
    CHECK_NEAR(log10(slow / right), kd_gain(1, 1) - kd_gain(1, 4), 0.04);
    CHECK(frozen < slow && slow < right);
    /* 4 cpd asked about at 2 deg/s: moving hurts a fine grating, so frozen is seen better */
    double right4 = look_trial(p, eyes, 4000, 4, 8, 2, NULL, &info);
    double frozen4 = look_trial(p, eyes, 5000, 4, 0, 2, NULL, &info);
    double fast4 = look_trial(p, eyes, 6000, 4, 16, 2, NULL, &info);
    int late[N_FRAMES] = {0};
    for (int k = 2; k < N_FRAMES; k += 2) late[k] = 2;
    double judder4 = look_trial(p, eyes, 7000, 4, 8, 2, late, &info);
    printf("4 cpd at 2 deg/s: right %.4g, frozen %.4g, 4 deg/s %.4g, judder %.4g at %.3g deg/s\n", right4,
           frozen4, fast4, judder4, info.velocity_dps);
    CHECK(frozen4 > 1.5 * right4 && fast4 < 0.5 * right4);
    CHECK_MSG(judder4 < right4 * pow(10.0, -0.03), "judder %.4g vs right %.4g", judder4, right4);
    /* static asked about as static: the contrast drawn, as before */
    double still = look_trial(p, eyes, 8000, 2, 0, 0, NULL, &info);
    CHECK_MSG(fabs(log10(still / 0.05)) < 0.02 && info.tf_hz == 0, "static: %.4g", still);
    CHECK(csf_obs_screen_look_v(eyes, 2, 5, NAN, &(double){0}, 1, 10, &e) == CSF_E_INVALID_ARG);
    csf_obs_screen_close(eyes);
    csf_presenter_close(p);
    csf_profile_free(prof);
}

int main(void)
{
    test_model_static_unchanged();
    test_model_drift();
    test_model_person();
    test_screen();
    return CHECK_RESULT();
}
