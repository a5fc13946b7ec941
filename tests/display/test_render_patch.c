/* Display calibration measures what is RENDERED: (a) a measurement patch at a fractional drive
 * (csf_presenter_draw_patch), read back from an 8-bit framebuffer and turned into light by the
 * simulated display, averages to the light of that fractional drive (the dither mixes levels k and
 * k+1 in the right proportion, per channel); (b) `csfcal display calibrate --render` on the
 * simulated lcd gives a profile as accurate against the simulated truth as the path that tells the
 * simulator the drive values, on one seed; (c) both store the same readings (count, channel and
 * status per sequence number; drive levels within 1e-3, since adaptive placement follows the
 * readings). Needs EGL surfaceless (Mesa llvmpipe). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "calib_truth.h"
#include "model/display_model.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "stimuli/presenter.h"
#include "tests/check.h"

/* Mean luminance over the patch pixels of `frames` frames; also the mean level fraction. */
static double patch_lum(csf_presenter *p, const csf_display_model *m, const csf_patch *pt, int frames,
                        double *bg_lum)
{
    int w, h, x0, y0, pw, ph;
    csf_error err;
    csf_presenter_render_size(p, &w, &h);
    CHECK_INT_EQ(csf_presenter_patch_rect(p, pt, &x0, &y0, &pw, &ph, &err), CSF_OK);
    uint16_t *lv = malloc(sizeof(uint16_t) * 3 * (size_t)w * h);
    double maxl = (1 << csf_presenter_bits(p)) - 1;
    double acc = 0, bacc = 0;
    size_t n = 0, bn = 0;
    for (int f = 0; f < frames; f++) {
        CHECK_INT_EQ(csf_presenter_draw_patch(p, pt, NULL, &err), CSF_OK);
        CHECK_INT_EQ(csf_presenter_readback_levels(p, lv, &err), CSF_OK);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const uint16_t *q = lv + 3 * ((size_t)y * w + x);
                double L = csf_display_model_lum(m, q[0] / maxl, q[1] / maxl, q[2] / maxl);
                if (x >= x0 && x < x0 + pw && y >= y0 && y < y0 + ph) {
                    acc += L;
                    n++;
                } else {
                    bacc += L;
                    bn++;
                }
            }
    }
    free(lv);
    if (bg_lum) *bg_lum = bn ? bacc / (double)bn : NAN;
    return acc / (double)n;
}

/* What an ideal dither shows: per channel, levels k and k+1 mixed by frac(v * maxlevel). With
 * channels dithered by one shared mask the mix is over the 2 corner cases when all fractions are
 * equal (grey, single channel), which is what the test uses. */
static double ideal_mix(const csf_display_model *m, double v, int ch, int maxlevel)
{
    double x = v * maxlevel, k = floor(x), f = x - k;
    if (k >= maxlevel) k = maxlevel - 1, f = 1;
    double a = k / maxlevel, b = (k + 1) / maxlevel;
    double la = ch == 3 ? csf_display_model_lum(m, a, a, a)
                        : csf_display_model_lum(m, ch == 0 ? a : 0, ch == 1 ? a : 0, ch == 2 ? a : 0);
    double lb = ch == 3 ? csf_display_model_lum(m, b, b, b)
                        : csf_display_model_lum(m, ch == 0 ? b : 0, ch == 1 ? b : 0, ch == 2 ? b : 0);
    return (1 - f) * la + f * lb;
}

static void part_a(void)
{
    csf_error err;
    csf_display_model *m = NULL;
    CHECK_INT_EQ(csf_display_model_create("lcd", &m, &err), CSF_OK);
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    cfg.headless = 1;
    cfg.render_width_px = 128;
    cfg.render_height_px = 72;
    cfg.seed = 3;
    csf_presenter *p = NULL;
    CHECK_MSG(csf_presenter_open(&cfg, &p, &err) == CSF_OK, "%s", err.msg);
    if (!p) {
        csf_display_model_free(m);
        return;
    }
    CHECK_INT_EQ(csf_presenter_bits(p), 8);
    const double drives[] = {0.50037, 0.2503, 0.8125, 0.9991, 0.35, 0.123456};
    double worst_truth = 0, worst_mix = 0, worst_nodither = 0;
    for (size_t i = 0; i < sizeof drives / sizeof drives[0]; i++)
        for (int ch = 0; ch < 4; ch++) {
            double v = drives[i];
            csf_patch pt;
            memset(&pt, 0, sizeof pt);
            for (int c = 0; c < 3; c++) pt.drive01[c] = (ch == 3 || ch == c) ? v : 0;
            pt.size_deg = 10;
            double bg;
            double got = patch_lum(p, m, &pt, 30, &bg);
            double truth = csf_display_model_lum(m, pt.drive01[0], pt.drive01[1], pt.drive01[2]);
            double mix = ideal_mix(m, v, ch, 255);
            double e_truth = fabs(got / truth - 1), e_mix = fabs(got / mix - 1);
            /* the nearest 8-bit level, for scale: what an undithered patch would show */
            double r = round(v * 255) / 255;
            double near = ch == 3 ? csf_display_model_lum(m, r, r, r)
                                  : csf_display_model_lum(m, ch == 0 ? r : 0, ch == 1 ? r : 0, ch == 2 ? r : 0);
            double e_near = fabs(near / truth - 1);
            printf("drive %.6f %s: rendered %.5f cd/m2, truth %.5f (%.2e), ideal mix %.5f (%.2e), "
                   "nearest level %.2e\n", v, ch == 3 ? "grey" : ch == 0 ? "r" : ch == 1 ? "g" : "b", got,
                   truth, e_truth, mix, e_mix, e_near);
            /* the dither shows the straight line between levels k and k+1; the curve's bend within
             * one level is what is left against the truth, relevant where it is large (the toe) */
            double peak = csf_display_model_lum(m, ch == 3 || ch == 0, ch == 3 || ch == 1, ch == 3 || ch == 2);
            if (truth >= 0.1 * peak && e_truth > worst_truth) worst_truth = e_truth;
            if (e_mix > worst_mix) worst_mix = e_mix;
            if (e_near > worst_nodither) worst_nodither = e_near;
            /* the surround is the background drive (black here) */
            CHECK_NEAR(bg, csf_display_model_lum(m, 0, 0, 0), 1e-12);
        }
    printf("worst relative error: vs truth (above 10 %% of peak) %.2e, vs ideal dither mix %.2e (undithered "
           "nearest level: %.2e)\n",
           worst_truth, worst_mix, worst_nodither);
    CHECK_MSG(worst_mix < 3e-5, "dithered patch vs ideal level mix %.3g", worst_mix);
    CHECK_MSG(worst_truth < 1e-4, "dithered patch vs the fractional drive's light %.3g", worst_truth);
    CHECK_MSG(worst_truth < 0.25 * worst_nodither, "dither no better than rounding (%.3g vs %.3g)", worst_truth,
              worst_nodither);

    /* full field and screen fraction; refusals */
    csf_patch pt;
    memset(&pt, 0, sizeof pt);
    pt.drive01[0] = pt.drive01[1] = pt.drive01[2] = 0.5;
    int x, y, w, h;
    CHECK_INT_EQ(csf_presenter_patch_rect(p, &pt, &x, &y, &w, &h, &err), CSF_OK);
    CHECK(x == 0 && y == 0 && w == 128 && h == 72);
    pt.screen_fraction = 0.5;
    CHECK_INT_EQ(csf_presenter_patch_rect(p, &pt, &x, &y, &w, &h, &err), CSF_OK);
    CHECK_INT_EQ(h, 36);
    CHECK(x + w / 2 == 64 && y + h / 2 == 36);
    pt.size_deg = 60; /* 658 mm at 570 mm: wider than the 299 mm screen height */
    CHECK_INT_EQ(csf_presenter_draw_patch(p, &pt, NULL, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "larger than the screen");
    pt.size_deg = 0;
    pt.drive01[1] = 1.5;
    CHECK_INT_EQ(csf_presenter_draw_patch(p, &pt, NULL, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "[0, 1]");
    csf_presenter_close(p);

    /* CSF_DITHER_NONE rounds to the nearest level: one code over the whole patch */
    cfg.dither = CSF_DITHER_NONE;
    CHECK_INT_EQ(csf_presenter_open(&cfg, &p, &err), CSF_OK);
    memset(&pt, 0, sizeof pt);
    pt.drive01[0] = pt.drive01[1] = pt.drive01[2] = 0.50037; /* 127.594 -> 128 */
    double got = patch_lum(p, m, &pt, 2, NULL);
    CHECK_NEAR(got, csf_display_model_lum(m, 128 / 255.0, 128 / 255.0, 128 / 255.0), 1e-9);
    csf_presenter_close(p);
    csf_display_model_free(m);
}

static int run_cli(const char *mode, const char *db, const char *out)
{
    char *argv[] = {"display", "calibrate", "--photometer", "sim:display=lcd", "--seed", "7", "--store",
                    (char *)db, "--out", (char *)out, (char *)mode, NULL};
    return csf_cmd_display(11, argv);
}

static void part_bc(void)
{
    char dir[] = "/tmp/csf_render_patch_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char db[2][300], out[2][300];
    const char *modes[2] = {"--render", "--no-render"};
    double e[2][4];
    csf_reading *rd[2] = {NULL, NULL};
    size_t n[2] = {0, 0};
    csf_error err;
    for (int k = 0; k < 2; k++) {
        snprintf(db[k], sizeof db[k], "%s/s%d.sqlite", dir, k);
        snprintf(out[k], sizeof out[k], "%s/p%d.profile", dir, k);
        CHECK_INT_EQ(run_cli(modes[k], db[k], out[k]), 0);
        csf_display_profile *p = NULL;
        CHECK_MSG(csf_profile_load(out[k], &p, &err) == CSF_OK, "%s", err.msg);
        if (!p) return;
        profile_errors(p, "lcd", e[k]);
        csf_profile_free(p);
        printf("%-12s max error above 10 %% of peak: grey %.3f %%, r %.3f %%, g %.3f %%, b %.3f %%\n", modes[k],
               100 * e[k][3], 100 * e[k][0], 100 * e[k][1], 100 * e[k][2]);
        csf_store *s = NULL;
        CHECK_INT_EQ(csf_store_open(db[k], &s, &err), CSF_OK);
        CHECK_INT_EQ(csf_store_get_readings(s, 1, &rd[k], &n[k], &err), CSF_OK);
        csf_store_close(s);
    }
    /* (b) the target, and no worse than the unrendered path beyond noise */
    for (int ch = 0; ch < 4; ch++) {
        CHECK_MSG(e[0][ch] <= 0.0025, "rendered profile error %.4f on curve %d above the 0.25 %% target", e[0][ch], ch);
        CHECK_MSG(e[0][ch] <= e[1][ch] + 0.0005, "rendered profile error %.4f vs %.4f unrendered (curve %d)",
                  e[0][ch], e[1][ch], ch);
    }
    /* (c) same readings, same kinds; luminances agree to the dither's precision */
    CHECK_INT_EQ((long)n[0], (long)n[1]);
    double worst = 0;
    for (size_t i = 0; i < n[0] && i < n[1]; i++) {
        CHECK_INT_EQ(rd[0][i].seq, rd[1][i].seq);
        CHECK(strcmp(rd[0][i].channel, rd[1][i].channel) == 0);
        CHECK(rd[0][i].status == rd[1][i].status);
        /* adaptive levels follow the readings, which differ by the dither's residue */
        CHECK_NEAR(rd[0][i].drive01, rd[1][i].drive01, 1e-3);
        CHECK_INT_EQ(rd[0][i].has_xyz, rd[1][i].has_xyz);
        if (rd[0][i].status == CSF_READING_OK && rd[1][i].lum_cdm2 > 1) {
            double d = fabs(rd[0][i].lum_cdm2 / rd[1][i].lum_cdm2 - 1);
            if (d > worst) worst = d;
        }
    }
    printf("readings: %zu rendered, %zu unrendered; largest relative difference above 1 cd/m2: %.2e\n", n[0], n[1],
           worst);
    CHECK_MSG(worst < 1e-3, "rendered and unrendered readings differ by %.3g", worst);
    free(rd[0]);
    free(rd[1]);
    for (int k = 0; k < 2; k++) {
        unlink(db[k]);
        unlink(out[k]);
    }
    char side[320];
    snprintf(side, sizeof side, "%s/s0.sqlite-journal", dir);
    unlink(side);
    rmdir(dir);
}

int main(void)
{
    part_a();
    part_bc();
    return CHECK_RESULT();
}
