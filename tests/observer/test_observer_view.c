/* The simulated person's eyes: the presenter's full-resolution region readback
 * is the frame's own pixels there, and the matched filter of model/observer_view.h measures the
 * contrast that is on screen at a place -- the Gabor's when it is drawn there through a right
 * profile, a changed one through a wrong profile, about nothing for a flat frame, a grating drawn
 * elsewhere or at another frequency -- never the plan (it is never given the plan). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/observer_screen.h"
#include "model/display_model.h"
#include "model/observer_view.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"
#include "tests/check.h"

static double model_grey(void *ctx, double d)
{
    return csf_display_model_lum((const csf_display_model *)ctx, d, d, d);
}

/* A 640 x 360 px screen of the default size in mm (about 12 px/deg at the centre, Nyquist about
 * 6 cpd), so that the whole frame can be rendered too. */
static csf_presenter *open_pres(int w, int h, const csf_display_profile *prof, csf_display_model *grey)
{
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    if (csf_geometry_init(&cfg.geometry, 531, 299, 640, 360, 570, 0, 0, &e) != CSF_OK) return NULL;
    cfg.render_width_px = w;
    cfg.render_height_px = h;
    cfg.profile = prof;
    if (grey) {
        cfg.grey_lum_fn = model_grey;
        cfg.grey_lum_ctx = grey;
        cfg.grey_lum_name = "test-model";
    }
    cfg.seed = 11;
    csf_presenter *p = NULL;
    if (csf_presenter_open(&cfg, &p, &e) != CSF_OK) {
        fprintf(stderr, "presenter: %s\n", e.msg);
        return NULL;
    }
    return p;
}

static csf_stimulus gabor(double freq, double ecc, double polar, double contrast)
{
    csf_stimulus s = {0};
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = freq;
    s.sigma_deg = 1.0;
    s.ecc_deg = ecc;
    s.polar_deg = polar;
    s.contrast = contrast;
    s.mean_lum_cdm2 = 50;
    return s;
}

/* The region is the same pixels as the full-resolution frame at that place, frame after frame
 * (dither included), while the session's own frame is small. (One presenter at a time: each
 * makes its GL context current when it opens.) */
#define RX 300
#define RY 60
#define RW 120
#define RH 90
static void draw_three(csf_presenter *p, int full, uint16_t *out[3])
{
    csf_error e;
    double marks_ecc[1] = {5}, marks_polar[1] = {30};
    for (int f = 0; f < 3; f++) {
        csf_stimulus s = gabor(2, 5, 30, 0.02);
        if (f == 2) CHECK(csf_presenter_set_marks(p, 1, marks_ecc, marks_polar, 3, &e) == CSF_OK);
        csf_frame_info fi;
        CHECK(csf_presenter_draw(p, f == 2 ? NULL : &s, 1, &fi, &e) == CSF_OK);
        if (full) {
            uint16_t *all = malloc(sizeof(uint16_t) * 640 * 360 * 3);
            CHECK(csf_presenter_readback_levels(p, all, &e) == CSF_OK);
            for (int j = 0; j < RH; j++)
                memcpy(out[f] + (size_t)j * RW * 3, all + (size_t)(RY + j) * 640 * 3 + (size_t)RX * 3,
                       sizeof(uint16_t) * RW * 3);
            free(all);
        } else {
            CHECK(csf_presenter_readback_region(p, RX, RY, RW, RH, out[f], &e) == CSF_OK);
        }
    }
}

static void test_region_is_the_frame(void)
{
    uint16_t *a[3], *b[3];
    for (int f = 0; f < 3; f++) {
        a[f] = calloc((size_t)RW * RH * 3, sizeof(uint16_t));
        b[f] = calloc((size_t)RW * RH * 3, sizeof(uint16_t));
    }
    csf_presenter *full = open_pres(0, 0, NULL, NULL); /* renders all 640 x 360 */
    CHECK(full != NULL);
    if (full) draw_three(full, 1, a);
    csf_presenter_close(full);
    csf_presenter *small = open_pres(64, 36, NULL, NULL); /* renders 64 x 36 */
    CHECK(small != NULL);
    if (!small) return;
    draw_three(small, 0, b);
    for (int f = 0; f < 3; f++) {
        long diff = 0, varied = 0;
        for (size_t i = 0; i < (size_t)RW * RH * 3; i++) {
            diff += a[f][i] != b[f][i];
            varied += b[f][i] != b[f][0];
        }
        CHECK_MSG(diff == 0, "frame %d: %ld region levels differ from the full frame", f, diff);
        CHECK_MSG(varied > 100, "frame %d: the region is flat (%ld varied levels)", f, varied);
        free(a[f]);
        free(b[f]);
    }
    /* refused: outside the screen, after a text screen */
    csf_error e;
    uint16_t one[3 * 4];
    CHECK(csf_presenter_readback_region(small, 639, 0, 2, 2, one, &e) == CSF_E_INVALID_ARG);
    CHECK(csf_presenter_readback_region(small, 0, -1, 2, 2, one, &e) == CSF_E_INVALID_ARG);
    CHECK(csf_presenter_text_screen(small, "x", &e) == CSF_OK);
    CHECK(csf_presenter_readback_region(small, 0, 0, 2, 2, one, &e) == CSF_E_INVALID_ARG);
    csf_presenter_close(small);
}

/* Draws `frames` frames of s (NULL: blank) while the eyes look at n places; returns contrasts. */
static void seen(csf_presenter *p, csf_obs_screen *eyes, const csf_stimulus *s, double freq, double ecc,
                 const double *polar, int n, int frames, double *out)
{
    csf_error e;
    CHECK(csf_obs_screen_look(eyes, freq, ecc, polar, n, frames, &e) == CSF_OK);
    for (int f = 0; f < frames; f++) {
        csf_frame_info fi;
        CHECK(csf_presenter_draw(p, s, 1, &fi, &e) == CSF_OK);
    }
    CHECK(csf_obs_screen_stop(eyes, out, &e) == CSF_OK);
}

/* With the display the profile describes, the contrast seen is the contrast drawn. */
static void test_measures_what_is_drawn(void)
{
    csf_display_profile *prof = csf_profile_default();
    csf_presenter *p = open_pres(64, 36, prof, NULL);
    CHECK(p != NULL);
    if (!p) return;
    csf_obs_screen *eyes = NULL;
    csf_error e;
    CHECK(csf_obs_screen_open(p, prof, "", 0, 1.0, 0.0, 3, &eyes, &e) == CSF_OK);
    if (!eyes) return;
    CHECK(csf_obs_screen_frames(eyes) == 0);
    const double polar4[4] = {0, 90, 180, 270};
    const double freqs[] = {0.5, 1, 2, 4};
    const double cons[] = {0.003, 0.01, 0.1};
    double worst = 0, noise = 0;
    for (size_t fi = 0; fi < sizeof freqs / sizeof freqs[0]; fi++)
        for (size_t ci = 0; ci < sizeof cons / sizeof cons[0]; ci++) {
            csf_stimulus s = gabor(freqs[fi], 8, polar4[(fi + ci) % 4], cons[ci]);
            double c[4];
            seen(p, eyes, &s, freqs[fi], 8, polar4, 4, 30, c);
            CHECK(csf_obs_screen_frames(eyes) == 10); /* frames 0, 3, ... 27 */
            int sig = (int)((fi + ci) % 4);
            double err = fabs(log10(c[sig] / cons[ci]));
            if (err > worst) worst = err;
            for (int k = 0; k < 4; k++)
                if (k != sig && c[k] > noise) noise = c[k];
        }
    printf("drawn vs seen: worst |log10 ratio| %.4f, largest contrast seen at empty places %.2e\n", worst,
           noise);
    CHECK_MSG(worst < 0.02, "contrast seen differs from the contrast drawn by %.4f log10", worst);
    CHECK_MSG(noise < 3e-4, "empty places show contrast %.2e", noise);
    /* a flat frame: nothing anywhere */
    double c[4];
    seen(p, eyes, NULL, 2, 8, polar4, 4, 30, c);
    for (int k = 0; k < 4; k++) CHECK_MSG(c[k] < 3e-4, "flat frame: place %d shows %.2e", k, c[k]);
    /* a grating halfway between two places, or at twice the frequency looked for: little */
    csf_stimulus off = gabor(2, 8, 45, 0.1), other = gabor(4, 8, 0, 0.1);
    seen(p, eyes, &off, 2, 8, polar4, 4, 30, c);
    for (int k = 0; k < 4; k++) CHECK_MSG(c[k] < 0.1 * 0.05, "misplaced grating: place %d shows %.3g", k, c[k]);
    seen(p, eyes, &other, 2, 8, polar4, 4, 30, c);
    CHECK_MSG(c[0] < 0.1 * 0.05, "grating at twice the frequency shows %.3g", c[0]);
    /* fade mode: frame by frame */
    csf_stimulus s = gabor(1, 0, 0, 0.02);
    CHECK(csf_obs_screen_look(eyes, 1, 0, polar4, 1, 0, &e) == CSF_OK);
    csf_frame_info f;
    CHECK(csf_presenter_draw(p, NULL, 1, &f, &e) == CSF_OK);
    CHECK(csf_obs_screen_latest(eyes) < 3e-4);
    /* the person judges the last CSF_OBS_SCREEN_WINDOW_S: once it holds only the grating, what is
     * seen is what is drawn (the onset itself is a temporal change, weighed as such) */
    int n_on = (int)ceil(CSF_OBS_SCREEN_WINDOW_S * csf_presenter_refresh_hz(p)) + 3;
    for (int k = 0; k < n_on; k++) CHECK(csf_presenter_draw(p, &s, 1, &f, &e) == CSF_OK);
    CHECK_MSG(fabs(log10(csf_obs_screen_latest(eyes) / 0.02)) < 0.02, "fade frame: %.4g seen",
              csf_obs_screen_latest(eyes));
    CHECK(csf_obs_screen_stop(eyes, NULL, &e) == CSF_OK);
    /* refused */
    CHECK(csf_obs_screen_look(eyes, 1, 0, polar4, 5, 30, &e) == CSF_E_INVALID_ARG);
    CHECK(csf_obs_screen_look(eyes, 1, 60, polar4, 1, 30, &e) == CSF_E_INVALID_ARG);
    csf_obs_screen_close(eyes);
    csf_presenter_close(p);
    csf_profile_free(prof);
}

/* A profile of one display shown on another: the contrast seen is the drawn one times the ratio
 * of the two displays' logarithmic slopes at the mean's drive, d ln L_true / d ln L_profile. */
static void test_wrong_profile(void)
{
    csf_display_profile *prof = csf_profile_default();
    csf_presenter *p = open_pres(64, 36, prof, NULL);
    csf_obs_screen *eyes = NULL;
    csf_error e;
    CHECK(p && csf_obs_screen_open(p, prof, "crt", 2.8, 1.0, 0.0, 1, &eyes, &e) == CSF_OK);
    if (!eyes) return;
    csf_display_model *crt = NULL;
    CHECK(csf_display_model_create("crt,gamma=2.8", &crt, &e) == CSF_OK);
    double d0 = csf_profile_grey_drive(prof, 50), h = 1e-4;
    double slope_true = (log(model_grey(crt, d0 + h)) - log(model_grey(crt, d0 - h))) / (2 * h);
    double slope_prof = (log(csf_profile_grey_lum(prof, d0 + h)) - log(csf_profile_grey_lum(prof, d0 - h))) / (2 * h);
    double ratio = slope_true / slope_prof;
    const double polar[1] = {0};
    csf_stimulus s = gabor(1, 5, 0, 0.01);
    double c;
    seen(p, eyes, &s, 1, 5, polar, 1, 12, &c);
    printf("wrong profile: seen/drawn %.4f, predicted %.4f\n", c / 0.01, ratio);
    CHECK(fabs(log10(ratio)) > 0.05); /* the test means something */
    CHECK_MSG(fabs(log10(c / 0.01 / ratio)) < 0.01, "seen/drawn %.4f vs predicted %.4f", c / 0.01, ratio);
    csf_display_model_free(crt);
    csf_obs_screen_close(eyes);
    csf_presenter_close(p);
    csf_profile_free(prof);
}

int main(void)
{
    test_region_is_the_frame();
    test_measures_what_is_drawn();
    test_wrong_profile();
    return CHECK_RESULT();
}
