/* The display profile's stated error against the truth it was measured on: on a held-out
 * simulated display (an OLED with gamma 2.0 and 400 cd/m2, power limiting across channels: a
 * variant the estimator was not tuned on; docs/display-profile.md, "How wrong the profile is")
 * at two instrument noise levels, the stated max error above 10 % of peak must be within a
 * factor of 1.5 of the true one, for grey and for the channels; and what the calibration states
 * must be what the profile records. On a display whose channels rise with different gammas
 * (2.0 / 2.4 / 2.7, heldout_bt1886.csv), the channels' statement over five seeds must be within
 * 1.5x of the truth in the median: red reaches 10 % of its peak where grey is at 3 %, and a
 * statement that took grey's error above grey's own 10 % point and the ratio fit's in-sample
 * residuals said a third of the truth there. On a display with a LUT's ripple finer than the
 * sweep's levels, the grey statement is within 1.5x only with the spot checks between them. On a
 * smooth curve with a lifted black and an S-shaped toe read at 0.02 % noise, the grey statement is
 * within 1.4x in the median. On a slope step between the channels' levels, "target met" is rarely
 * said falsely. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/display_calib.h"
#include "model/display_model.h"
#include "devices/photometer.h"
#include "../check.h"

static const char *TRUTH = "oled,gamma=2.0,lmax=400";

static double true_grey_err(const csf_display_model *m, const csf_display_profile *p)
{
    double peak = csf_display_model_lum(m, 1, 1, 1), worst = 0;
    for (int i = 0; i <= 2040; i++) {
        double v = i / 2040.0, t = csf_display_model_lum(m, v, v, v);
        if (t >= 0.1 * peak) worst = fmax(worst, fabs(csf_profile_grey_lum(p, v) / t - 1));
    }
    return worst;
}

static double true_channel_err(const csf_display_model *m, const csf_display_profile *p)
{
    double black = csf_display_model_lum(m, 0, 0, 0), worst = 0;
    for (int ch = 0; ch < 3; ch++) {
        double peak = csf_display_model_lum(m, ch == 0, ch == 1, ch == 2) - black;
        for (int i = 0; i <= 2040; i++) {
            double v = i / 2040.0;
            double t = csf_display_model_lum(m, ch == 0 ? v : 0, ch == 1 ? v : 0, ch == 2 ? v : 0) - black;
            if (t >= 0.1 * peak) worst = fmax(worst, fabs(csf_profile_channel_lum(p, ch, v) / t - 1));
        }
    }
    return worst;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One calibration with the default options (checks spot checks per curve; -1 keeps the default) of
 * truth read through the simulated photometer at noise_rel: *m the truth, *p the profile (NULL when
 * the calibration fails), *o the options it ran with. The caller frees *m and *p. */
static csf_status calibrate_sim(const char *truth, double noise_rel, uint64_t seed, int checks,
                                csf_display_model **m, csf_display_profile **p, csf_display_calib_result *res,
                                csf_display_calib_opts *o, csf_error *err)
{
    char spec[400];
    snprintf(spec, sizeof spec, "sim:display=%s,noise=%g", truth, noise_rel);
    csf_photometer *ph = NULL;
    *p = NULL;
    *m = NULL;
    int made = csf_display_model_create(truth, m, err) == CSF_OK;
    CHECK(made);
    if (!made) return CSF_E_INVALID_ARG;
    int opened = csf_photometer_open(spec, seed, &ph, err) == CSF_OK;
    CHECK(opened);
    if (!opened) return CSF_E_INVALID_ARG;
    csf_display_calib_defaults(o);
    if (checks >= 0) o->checks = checks;
    csf_status st = csf_display_calibrate(ph, o, NULL, NULL, seed, p, res, err);
    csf_photometer_close(ph);
    return st;
}

/* The median over seeds 1..5 of stated/true on truth at noise_rel with checks spot checks per
 * curve; channels: the largest of r, g, b, else grey. */
static double median_ratio(const char *truth, double noise_rel, int checks, int channels)
{
    double ratio[5];
    int n = 0;
    for (uint64_t seed = 1; seed <= 5; seed++) {
        csf_display_model *m;
        csf_display_profile *p;
        csf_display_calib_result res;
        csf_display_calib_opts o;
        csf_error err;
        if (calibrate_sim(truth, noise_rel, seed, checks, &m, &p, &res, &o, &err) == CSF_OK) {
            double sc = 0;
            for (int c = 0; c < 3; c++) sc = fmax(sc, res.est_error_rel[c]);
            ratio[n++] =
                channels ? sc / true_channel_err(m, p) : res.est_error_rel[CSF_CH_GREY] / true_grey_err(m, p);
            CHECK(res.n_check == (checks ? 4 * checks : 0));
        }
        csf_profile_free(p);
        csf_display_model_free(m);
    }
    CHECK(n == 5);
    if (n == 0) return NAN;
    qsort(ratio, (size_t)n, sizeof *ratio, cmp_double);
    printf("%s, noise %g %%, %d checks: %s stated/true, median of %d seeds %.2f (%.2f-%.2f)\n", truth,
           100 * noise_rel, checks, channels ? "channels" : "grey", n, ratio[n / 2], ratio[0], ratio[n - 1]);
    return ratio[n / 2];
}

/* The channels' stated/true over seeds 1..5 on a display whose channels differ in gamma. */
static void channels_differ(double noise_rel)
{
    double med = median_ratio("file=" CSF_TEST_DATA "/heldout_bt1886.csv", noise_rel, 4, 1);
    CHECK_MSG(med >= 1 / 1.5 && med <= 1.5, "channels stated/true median %.3f at noise %g", med, noise_rel);
}

/* A driver LUT's ripple between the sweep's levels: the levels cannot show it, so without spot
 * checks the statement is a fraction of the truth; with them it is within 1.5x. */
static void finer_than_levels(double noise_rel)
{
    const char *truth = "file=" CSF_TEST_DATA "/heldout_lutwiggle.csv";
    double with = median_ratio(truth, noise_rel, 4, 0), without = median_ratio(truth, noise_rel, 0, 0);
    CHECK_MSG(with >= 1 / 1.5 && with <= 1.5, "ripple: grey stated/true median %.3f with checks", with);
    CHECK_MSG(without < 1 / 1.5,
              "ripple: grey stated/true median %.3f without checks (the levels should miss it)", without);
}

/* A smooth curve read with a quiet meter: the statement is the model's error, estimated from how far
 * the curve misses a left-out level. The step from that miss to the levels' own spacing divides it
 * by 2^p, p the order the curve shows there (about 3 on a smooth stretch); a fixed p = 2 states 1.5
 * times the truth and more here. */
static void smooth_quiet(void)
{
    double med = median_ratio("file=" CSF_TEST_DATA "/heldout7_toe.csv", 0.0002, 4, 0);
    CHECK_MSG(med >= 1 / 1.5 && med <= 1.4, "toe curve: grey stated/true median %.3f at noise 0.02 %%", med);
}

/* A slope step that each channel takes at its own drive (0.64 / 0.66 / 0.69, heldout8_midkink.csv)
 * lies between the channels' levels: grey shows it diluted, and a channel modelled through grey
 * copies grey's version. Over ten seeds at 0.05 % noise the calibration may say "target met" on
 * at most three runs whose true error (grey or channels) is above the target (about one in ten
 * runs on the benchmark's 30 seeds); with the spot checks at the golden-ratio drives alone it did
 * on about half the runs, every run that claimed it. */
static void joint_between_channel_levels(void)
{
    const char *truth = "file=" CSF_TEST_DATA "/heldout8_midkink.csv";
    int claimed = 0, false_met = 0;
    for (uint64_t seed = 1; seed <= 10; seed++) {
        csf_display_model *m;
        csf_display_profile *p;
        csf_display_calib_result res;
        csf_display_calib_opts o;
        csf_error err;
        csf_status st = calibrate_sim(truth, 0.0005, seed, -1, &m, &p, &res, &o, &err);
        CHECK_MSG(st == CSF_OK, "slope step, seed %d: %s", (int)seed, err.msg);
        if (st == CSF_OK && res.target_met) {
            claimed++;
            false_met += fmax(true_grey_err(m, p), true_channel_err(m, p)) > o.target_rel;
        }
        csf_profile_free(p);
        csf_display_model_free(m);
    }
    printf("slope step between the channels' levels: %d of 10 runs said met, %d of them above the target\n",
           claimed, false_met);
    CHECK_MSG(false_met <= 3, "slope step: %d of %d 'met' claims false", false_met, claimed);
}

static void run(double noise_rel, uint64_t seed)
{
    csf_display_model *m;
    csf_display_profile *p;
    csf_display_calib_result res;
    csf_display_calib_opts o;
    csf_error err;
    csf_status st = calibrate_sim(TRUTH, noise_rel, seed, -1, &m, &p, &res, &o, &err);
    CHECK_MSG(st == CSF_OK, "%s", err.msg);
    if (st == CSF_OK) {
        double tg = true_grey_err(m, p), tc = true_channel_err(m, p);
        double sg = res.est_error_rel[CSF_CH_GREY], sc = 0;
        for (int c = 0; c < 3; c++) sc = fmax(sc, res.est_error_rel[c]);
        printf("noise %g %%: grey stated %.3f %% true %.3f %% (%.2f); channels stated %.3f %% true %.3f %% "
               "(%.2f)\n",
               100 * noise_rel, 100 * sg, 100 * tg, sg / tg, 100 * sc, 100 * tc, sc / tc);
        CHECK_MSG(sg / tg >= 1 / 1.5 && sg / tg <= 1.5, "grey stated/true %.3f at noise %g", sg / tg,
                  noise_rel);
        CHECK_MSG(sc / tc >= 1 / 1.5 && sc / tc <= 1.5, "channels stated/true %.3f at noise %g", sc / tc,
                  noise_rel);
        double target, stated[CSF_CH_COUNT];
        int met = csf_profile_statement(p, &target, stated);
        CHECK(met == res.target_met);
        CHECK(target == o.target_rel);
        for (int c = 0; c < CSF_CH_COUNT; c++) CHECK(stated[c] == res.est_error_rel[c]);
        /* met is judged on the 90th percentile of the knots' noise, never below the median stated */
        double mg = res.met_error_rel[CSF_CH_GREY], mc = 0;
        for (int c = 0; c < 3; c++) mc = fmax(mc, res.met_error_rel[c]);
        CHECK(mg >= sg && mc >= sc);
        CHECK(res.target_met == (mg <= o.target_rel && mc <= o.target_rel));
        /* the file keeps the statement */
        char *text = NULL;
        csf_display_profile *q = NULL;
        CHECK(csf_profile_to_text(p, &text, &err) == CSF_OK);
        CHECK(text && csf_profile_parse(text, strlen(text), &q, &err) == CSF_OK);
        if (q) {
            double t2, s2[CSF_CH_COUNT];
            CHECK(csf_profile_statement(q, &t2, s2) == met);
            CHECK(s2[CSF_CH_GREY] == stated[CSF_CH_GREY]);
            csf_profile_free(q);
        }
        free(text);
    }
    csf_profile_free(p);
    csf_display_model_free(m);
}

int main(void)
{
    run(0.002, 2); /* twice an ordinary meter's repeatability */
    run(0.005, 2); /* a noisy one: the budget ends before the target */
    channels_differ(0.0005);
    channels_differ(0.001);
    finer_than_levels(0.0005);
    smooth_quiet();
    joint_between_channel_levels();
    return CHECK_RESULT();
}
