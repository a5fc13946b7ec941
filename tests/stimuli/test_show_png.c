/* csfcal stimulus show --png, checked from the files alone: each PNG is decoded with libpng,
 * turned into luminance through the simulated display it was drawn for, and fitted here (not
 * through stimuli/selfcheck.c) with a Gabor of unknown mean, amplitude, phase and frequency in
 * exact visual angle: the single frame's contrast and frequency are the asked ones, the caption
 * changes only its own corner, and the N frames of --frames N advance in phase at the asked
 * speed. Usage: test_show_png CSFCAL */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gabor_fit.h"
#include "stim_test.h"
#include "tests/check.h"

#define FREQ_CPD 1.5
#define ECC_DEG 3.0
#define CONTRAST 0.3
#define VELOCITY_DPS 2.0
#define N_FRAMES 12
#define REFRESH_HZ 60.0
#define COMMON                                                                                               \
    "--headless --screen-px 640x360 --screen-mm 531x299 --distance-mm 570 "                                  \
    "--photometer sim:display=lcd --freq 1.5 --ecc 3 --contrast 0.3 --sigma 1 --seed 4"

static const gfit_patch PATCH = {ECC_DEG, 0, 1.0};

/* The patch's pixels of one picture (exits when they cannot be held). */
static gfit_pixels pixels_of(const gfit_image *im, const csf_geometry *g, const csf_display_model *dm)
{
    gfit_pixels px;
    if (gfit_prepare(im, g, dm, &PATCH, &px)) {
        fprintf(stderr, "out of memory for the fit\n");
        exit(1);
    }
    return px;
}

static int run(const char *csfcal, const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "EGL_PLATFORM=surfaceless '%s' stimulus show %s " COMMON " >/dev/null", csfcal,
             args);
    return system(cmd);
}

static void test_one_frame(const char *csfcal, const char *dir, const csf_geometry *g,
                           const csf_display_model *dm)
{
    char a1[1024], a2[1024], p1[512], p2[512];
    snprintf(p1, sizeof p1, "%s/clean.png", dir);
    snprintf(p2, sizeof p2, "%s/caption.png", dir);
    snprintf(a1, sizeof a1, "--clean --png '%s'", p1);
    snprintf(a2, sizeof a2, "--png '%s'", p2);
    CHECK_INT_EQ(run(csfcal, a1), 0);
    CHECK_INT_EQ(run(csfcal, a2), 0);
    gfit_image clean = {0}, cap = {0};
    CHECK_INT_EQ(gfit_load_png(p1, &clean), 0);
    CHECK_INT_EQ(gfit_load_png(p2, &cap), 0);
    if (!clean.rgb || !cap.rgb) return;
    CHECK_INT_EQ((long)clean.w, 640L);
    CHECK_INT_EQ((long)clean.h, 360L);
    gfit_pixels px = pixels_of(&clean, g, dm);
    double f = gfit_best_freq(&px, FREQ_CPD, 0.005);
    gfit_result r = gfit_at(&px, FREQ_CPD);
    gfit_pixels_free(&px);
    CHECK_MSG(fabs(f / FREQ_CPD - 1) < 0.02, "frequency %g cpd", f);
    CHECK_MSG(fabs(r.contrast / CONTRAST - 1) < 0.03, "contrast %g", r.contrast);
    /* the caption writes only into the top rows */
    size_t top = (size_t)clean.w * 3 * (clean.h / 10), diff_top = 0, diff_rest = 0;
    for (size_t i = 0; i < (size_t)clean.w * clean.h * 3; i++)
        if (clean.rgb[i] != cap.rgb[i]) *(i < top ? &diff_top : &diff_rest) += 1;
    CHECK_MSG(diff_top > 100, "caption changed %zu values", diff_top);
    CHECK_INT_EQ((long)diff_rest, 0L);
    free(clean.rgb);
    free(cap.rgb);
}

static void test_frames(const char *csfcal, const char *dir, const csf_geometry *g,
                        const csf_display_model *dm)
{
    char args[1024], path[512];
    snprintf(args, sizeof args, "--clean --velocity %g --frames %d --png '%s/'", VELOCITY_DPS, N_FRAMES, dir);
    CHECK_INT_EQ(run(csfcal, args), 0);
    double t[N_FRAMES], ph[N_FRAMES], f = FREQ_CPD;
    for (int k = 0; k < N_FRAMES; k++) {
        snprintf(path, sizeof path, "%s/frame_%04d.png", dir, k);
        gfit_image im = {0};
        CHECK_MSG(gfit_load_png(path, &im) == 0, "%s", path);
        if (!im.rgb) return;
        gfit_pixels px = pixels_of(&im, g, dm);
        if (k == 0) f = gfit_best_freq(&px, FREQ_CPD, 0.005);
        t[k] = k / REFRESH_HZ;
        ph[k] = gfit_at(&px, FREQ_CPD).phase_rad;
        gfit_pixels_free(&px);
        if (k > 0) ph[k] = ph[k - 1] + remainder(ph[k] - ph[k - 1], 2 * M_PI); /* steps < pi */
        free(im.rgb);
    }
    snprintf(path, sizeof path, "%s/frame_%04d.png", dir, N_FRAMES);
    CHECK_MSG(access(path, F_OK) != 0, "%s written beyond --frames", path);
    double st = 0, sp = 0, stt = 0, stp = 0;
    for (int k = 0; k < N_FRAMES; k++) {
        st += t[k];
        sp += ph[k];
        stt += t[k] * t[k];
        stp += t[k] * ph[k];
    }
    double slope = (N_FRAMES * stp - st * sp) / (N_FRAMES * stt - st * st);
    double speed = slope / (2 * M_PI * f);
    CHECK_MSG(fabs(speed / VELOCITY_DPS - 1) < 0.01, "phase advances at %g deg/s, asked %g", speed,
              VELOCITY_DPS);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_show_png CSFCAL\n");
        return 2;
    }
    char dir[] = "/tmp/csf_show_png_XXXXXX";
    if (!mkdtemp(dir)) return 2;
    csf_geometry g;
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 640, 360, 570, 0, 0, &e), CSF_OK);
    csf_display_model *dm = stim_test_model("lcd");
    test_one_frame(argv[1], dir, &g, dm);
    test_frames(argv[1], dir, &g, dm);
    csf_display_model_free(dm);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return CHECK_RESULT();
}
