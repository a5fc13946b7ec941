/* csfcal stimulus show --png, checked from the files alone: each PNG is decoded with libpng,
 * turned into luminance through the simulated display it was drawn for, and fitted here (not
 * through stimuli/selfcheck.c) with a Gabor of unknown mean, amplitude, phase and frequency in
 * exact visual angle: the single frame's contrast and frequency are the asked ones, the caption
 * changes only its own corner, and the N frames of --frames N advance in phase at the asked
 * speed. Usage: test_show_png CSFCAL */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

typedef struct {
    unsigned w, h;
    unsigned char *rgb;
} image;

static int load_png(const char *path, image *im)
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
        return -1;
    }
    return 0;
}

typedef struct {
    double mean, contrast, phase_rad;
} gabor_fit;

/* Least squares L = m + a env cos(2 pi f u) + b env sin(2 pi f u) over the patch (u along the
 * modulation direction, orientation 0), pixels near fixation left out. */
static gabor_fit fit_at(const image *im, const csf_geometry *g, const csf_display_model *dm, double f)
{
    double A[3][3] = {{0}}, y[3] = {0};
    for (unsigned j = 0; j < im->h; j++)
        for (unsigned i = 0; i < im->w; i++) {
            double x = ((i + 0.5) / im->w - 0.5) * g->width_mm, yy = (0.5 - (j + 0.5) / im->h) * g->height_mm;
            double u, v, ecc, pol;
            csf_geometry_local_uv(g, ECC_DEG, 0, x, yy, &u, &v);
            csf_geometry_mm_to_deg(g, x, yy, &ecc, &pol);
            double env = exp(-(u * u + v * v) / 2.0);
            if (env < 1e-3 || ecc < 0.3) continue;
            const unsigned char *px = im->rgb + 3 * ((size_t)j * im->w + i);
            double L = csf_display_model_lum(dm, px[0] / 255.0, px[1] / 255.0, px[2] / 255.0);
            double b[3] = {1, env * cos(2 * M_PI * f * u), env * sin(2 * M_PI * f * u)};
            for (int r = 0; r < 3; r++) {
                y[r] += b[r] * L;
                for (int c = 0; c < 3; c++) A[r][c] += b[r] * b[c];
            }
        }
    for (int c = 0; c < 3; c++) /* Gauss-Jordan; A is symmetric positive definite */
        for (int r = 0; r < 3; r++) {
            if (r == c) continue;
            double q = A[r][c] / A[c][c];
            for (int k = 0; k < 3; k++) A[r][k] -= q * A[c][k];
            y[r] -= q * y[c];
        }
    double m = y[0] / A[0][0], a = y[1] / A[1][1], b = y[2] / A[2][2];
    return (gabor_fit){m, hypot(a, b) / m, atan2(-b, a)};
}

/* The frequency with the largest fitted amplitude, on a 0.5 % grid around the asked one. */
static double best_freq(const image *im, const csf_geometry *g, const csf_display_model *dm)
{
    double best = 0, best_c = -1;
    for (double f = 0.8 * FREQ_CPD; f <= 1.2 * FREQ_CPD; f += 0.005 * FREQ_CPD) {
        gabor_fit r = fit_at(im, g, dm, f);
        if (r.contrast > best_c) {
            best_c = r.contrast;
            best = f;
        }
    }
    return best;
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
    image clean = {0}, cap = {0};
    CHECK_INT_EQ(load_png(p1, &clean), 0);
    CHECK_INT_EQ(load_png(p2, &cap), 0);
    if (!clean.rgb || !cap.rgb) return;
    CHECK_INT_EQ((long)clean.w, 640L);
    CHECK_INT_EQ((long)clean.h, 360L);
    double f = best_freq(&clean, g, dm);
    gabor_fit r = fit_at(&clean, g, dm, FREQ_CPD);
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
        image im = {0};
        CHECK_MSG(load_png(path, &im) == 0, "%s", path);
        if (!im.rgb) return;
        if (k == 0) f = best_freq(&im, g, dm);
        t[k] = k / REFRESH_HZ;
        ph[k] = fit_at(&im, g, dm, FREQ_CPD).phase_rad;
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
