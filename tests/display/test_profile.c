/* Display profile: model through readings, exact inverse, monotonicity under noise, file round
 * trip, refusal of malformed files, the documented default. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "results/display_profile.h"
#include "core/rng.h"
#include "tests/check.h"

static double truth(double v) { return 0.3 + 150.0 * pow(v, 2.4) * (1 + 0.05 * sin(3 * v)); }

int main(void)
{
    /* readings of a known curve at 17 levels, grey only, with one repeat */
    csf_profile_reading r[40];
    size_t n = 0;
    for (int i = 0; i <= 16; i++) {
        double v = i / 16.0;
        r[n++] = (csf_profile_reading){CSF_CH_GREY, v, truth(v), {0, 0, 0}, 0};
    }
    r[n++] = (csf_profile_reading){CSF_CH_GREY, 0.5, truth(0.5) * 1.002, {0, 0, 0}, 0};
    csf_profile_meta meta = {"test display", "unit test", "2026-11-20T10:00:00Z", "t", NAN};
    csf_display_profile *p = NULL;
    csf_error err;
    csf_error_clear(&err);
    CHECK_INT_EQ(csf_profile_build(r, n, &meta, &p, &err), CSF_OK);
    if (!p) return CHECK_RESULT();
    CHECK_NEAR(csf_profile_lum_black(p), truth(0), 1e-12);
    CHECK_NEAR(csf_profile_lum_max(p), truth(1), 1e-9);
    CHECK(!csf_profile_has_channels(p));
    CHECK(isnan(csf_profile_channel_lum(p, 0, 0.5)));
    /* passes through the knots (repeat averaged) */
    CHECK_NEAR(csf_profile_grey_lum(p, 0.25), truth(0.25), 1e-9);
    CHECK_NEAR(csf_profile_grey_lum(p, 0.5), truth(0.5) * 1.001, 1e-9);
    /* accurate between knots: a smooth curve with 17 knots */
    double worst = 0;
    for (int i = 0; i <= 1000; i++) {
        double v = i / 1000.0;
        if (truth(v) < 0.1 * truth(1)) continue;
        double e = fabs(csf_profile_grey_lum(p, v) / truth(v) - 1);
        if (e > worst) worst = e;
    }
    CHECK_MSG(worst < 0.0025, "interpolation error %g", worst);
    /* exact inverse, monotone forward */
    double prev = -1, max_rt = 0;
    for (int i = 0; i <= 2000; i++) {
        double v = i / 2000.0;
        double L = csf_profile_grey_lum(p, v);
        CHECK(L >= prev);
        prev = L;
        double back = csf_profile_grey_drive(p, L);
        double rt = fabs(csf_profile_grey_lum(p, back) - L) / L;
        if (rt > max_rt) max_rt = rt;
    }
    CHECK_MSG(max_rt < 1e-12, "inverse round trip %g", max_rt);
    CHECK_NEAR(csf_profile_grey_drive(p, 0.0), 0, 0);
    CHECK_NEAR(csf_profile_grey_drive(p, 1e6), 1, 0);
    CHECK_NEAR(csf_profile_grey_drive(p, truth(0.625)), 0.625, 1e-12);
    /* age from created_utc; flagged past the limit */
    CHECK(csf_profile_age_days(p) > 0);
    char amsg[400];
    CHECK_INT_EQ(csf_profile_age_warning(p, 36500, amsg, sizeof amsg), 0);
    CHECK(amsg[0] == 0);
    CHECK_INT_EQ(csf_profile_age_warning(p, 0.5, amsg, sizeof amsg), 1);
    CHECK_STR_CONTAINS(amsg, "days old (limit profile_max_age_days = 0.5)");
    CHECK_INT_EQ(csf_profile_age_warning(p, 0, amsg, sizeof amsg), 0);
    CHECK_STR_CONTAINS(csf_profile_id(p), "test-display-20261120-");
    /* "% of white" is luminance over white, black included: one function for info and the exports */
    CHECK_NEAR(csf_profile_rel_lum(p, 0), truth(0) / truth(1), 1e-12);
    CHECK_NEAR(csf_profile_rel_lum(p, 1), 1, 1e-12);
    CHECK_NEAR(csf_profile_lum_from_rel(p, 0.5), 0.5 * truth(1), 1e-9);
    for (int i = 1; i < 10; i++) {
        double rel = i / 10.0;
        double v = csf_profile_grey_drive(p, csf_profile_lum_from_rel(p, rel));
        CHECK_NEAR(csf_profile_rel_lum(p, v), rel, 1e-9);
    }
    /* ids stay short: a photometer spec with a file path gives its first word and a hash of the
     * whole name, never the path; different paths, different ids; a short name is kept */
    {
        const char *names[3] = {"sim:display=file=/home/someone/private/lab/curves/monitor-7.csv,noise=0.001",
                                "sim:display=file=/home/someone/private/lab/curves/monitor-8.csv,noise=0.001",
                                "lab-lcd-3"};
        char ids[3][200];
        for (int k = 0; k < 3; k++) {
            csf_profile_meta m2 = {names[k], "unit test", "2026-11-20T10:00:00Z", "t", NAN};
            csf_display_profile *q = NULL;
            CHECK_INT_EQ(csf_profile_build(r, n, &m2, &q, &err), CSF_OK);
            snprintf(ids[k], sizeof ids[k], "%s", q ? csf_profile_id(q) : "");
            CHECK_MSG(strlen(ids[k]) <= 48, "id '%s' longer than 48", ids[k]);
            CHECK_MSG(!strchr(ids[k], '/') && !strstr(ids[k], "home") && !strstr(ids[k], "csv"),
                      "id '%s' carries the path", ids[k]);
            csf_profile_free(q);
        }
        CHECK_MSG(strncmp(ids[0], "sim-", 4) == 0 && strstr(ids[0], "-20261120-"), "id '%s'", ids[0]);
        CHECK(strcmp(ids[0], ids[1]) != 0);
        CHECK_MSG(strncmp(ids[2], "lab-lcd-3-20261120-", 19) == 0, "id '%s'", ids[2]);
    }

    /* save / load round trip: identical model */
    char path[] = "/tmp/csfcal-test-profile-XXXXXX";
    int fd = mkstemp(path);
    close(fd);
    CHECK_INT_EQ(csf_profile_save(p, path, &err), CSF_OK);
    csf_display_profile *q = NULL;
    CHECK_INT_EQ(csf_profile_load(path, &q, &err), CSF_OK);
    if (q) {
        for (int i = 0; i <= 100; i++) {
            double v = i / 100.0;
            CHECK_NEAR(csf_profile_grey_lum(q, v), csf_profile_grey_lum(p, v), 0);
        }
        CHECK(strcmp(csf_profile_id(q), csf_profile_id(p)) == 0);
        CHECK_INT_EQ(csf_profile_readings(q, NULL), n);
        csf_profile_free(q);
    }
    unlink(path);
    csf_profile_free(p);

    /* noisy readings crossing each other: the model stays monotone (pool-adjacent-violators) */
    csf_profile_reading nr[64];
    n = 0;
    for (int i = 0; i <= 40; i++) {
        double v = i / 40.0;
        double L = truth(v) * (1 + 0.02 * csf_rng_normal(5, 1, (uint64_t)i));
        if (i == 0) L = truth(0);
        if (i == 40) L = truth(1);
        nr[n++] = (csf_profile_reading){CSF_CH_GREY, v, L, {0, 0, 0}, 0};
    }
    CHECK_INT_EQ(csf_profile_build(nr, n, &meta, &p, &err), CSF_OK);
    if (p) {
        prev = -1;
        int bad = 0;
        for (int i = 0; i <= 4000; i++) {
            double L = csf_profile_grey_lum(p, i / 4000.0);
            if (L < prev) bad++;
            prev = L;
        }
        CHECK_INT_EQ(bad, 0);
        csf_profile_free(p);
    }

    /* channels + primaries */
    n = 0;
    const double w[3] = {0.25, 0.65, 0.10};
    const double prim[3][3] = {{0.412, 0.2126, 0.019}, {0.357, 0.7152, 0.119}, {0.180, 0.0722, 0.950}};
    csf_profile_reading cr[100];
    for (int i = 0; i <= 8; i++) {
        double v = i / 8.0;
        cr[n++] = (csf_profile_reading){CSF_CH_GREY, v, 0.3 + 100 * pow(v, 2.2), {0.95 * (0.3 + 100 * pow(v, 2.2)), 0.3 + 100 * pow(v, 2.2), 1.08 * (0.3 + 100 * pow(v, 2.2))}, 1};
        for (int c = 0; i > 0 && c < 3; c++) {
            double L = 0.3 + 100 * w[c] * pow(v, 2.2);
            double s = 100 * pow(v, 2.2) / prim[c][1] * w[c];
            cr[n++] = (csf_profile_reading){c, v, L, {0.3 * 0.95 + prim[c][0] * s, L, 0.3 * 1.08 + prim[c][2] * s}, 1};
        }
    }
    CHECK_INT_EQ(csf_profile_build(cr, n, &meta, &p, &err), CSF_OK);
    if (p) {
        CHECK(csf_profile_has_channels(p));
        CHECK_NEAR(csf_profile_channel_lum(p, 1, 1.0), 65, 1e-9);
        CHECK_NEAR(csf_profile_channel_lum(p, 2, 0.0), 0, 1e-12);
        CHECK_NEAR(csf_profile_channel_lum(p, 0, 0.5), 25 * pow(0.5, 2.2), 25 * 0.0025 * pow(0.5, 2.2));
        CHECK_NEAR(csf_profile_channel_drive(p, 0, 25 * pow(0.5, 2.2)), 0.5, 1e-3);
        double xyz[4][3];
        CHECK(csf_profile_primaries_xyz(p, xyz));
        CHECK_NEAR(xyz[0][1], 25, 1e-9);
        CHECK_NEAR(xyz[2][2] / xyz[2][1], 0.950 / 0.0722, 1e-6);
        /* round trip with channels and primaries */
        char *text = NULL;
        CHECK_INT_EQ(csf_profile_to_text(p, &text, &err), CSF_OK);
        csf_display_profile *q2 = NULL;
        CHECK_INT_EQ(csf_profile_parse(text, strlen(text), &q2, &err), CSF_OK);
        if (q2) {
            CHECK(csf_profile_has_channels(q2));
            CHECK_NEAR(csf_profile_channel_lum(q2, 1, 0.37), csf_profile_channel_lum(p, 1, 0.37), 0);
            double xyz2[4][3];
            CHECK(csf_profile_primaries_xyz(q2, xyz2));
            CHECK_NEAR(xyz2[1][0], xyz[1][0], 0);
            csf_profile_free(q2);
        }
        free(text);
        csf_profile_free(p);
    }

    /* too little data */
    csf_profile_reading one = {CSF_CH_GREY, 0.5, 10, {0, 0, 0}, 0};
    CHECK_INT_EQ(csf_profile_build(&one, 1, &meta, &p, &err), CSF_E_INSUFFICIENT);
    CHECK_STR_CONTAINS(err.msg, "drive 0 and 1");
    csf_profile_reading flat[2] = {{CSF_CH_GREY, 0, 10, {0}, 0}, {CSF_CH_GREY, 1, 10, {0}, 0}};
    CHECK_INT_EQ(csf_profile_build(flat, 2, &meta, &p, &err), CSF_E_INSUFFICIENT);
    CHECK_STR_CONTAINS(err.msg, "does not rise");

    /* malformed files */
    struct { const char *text, *want; int code; } bad[] = {
        {"", "empty file", CSF_E_FORMAT},
        {"hello\n", "not a csfcal display profile", CSF_E_FORMAT},
        {"csfcal-display-profile 2\n", "version 2", CSF_E_UNSUPPORTED},
        {"csfcal-display-profile 1\nid = x\n", "no [curve grey]", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,1\n0.5,0.5\n1,2\n", "knots must rise", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 9\n", "transform_gamma", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,1\n0.5,2\n", "drive 0 and 1", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve purple]\n", "unknown curve", CSF_E_FORMAT},
        /* outside bytes in a message are made printable: a control sequence is shown, not obeyed */
        {"csfcal-display-profile 1\n[curve \x1b[2J]\n", "unknown curve '\\x1b[2J'", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[\x07" "bell]\n", "unknown section [\\x07bell]", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,1\n1,2\n[curve r]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,0\n1,1\n", "all of r, g, b", CSF_E_FORMAT},
        {"csfcal-display-profile 1\ncreated_utc = yesterday\n", "created_utc", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[curve grey]\ntransform_gamma = 2\ndrive01,lum_cdm2\n0,1\n1,nan\n", "expected drive01", CSF_E_FORMAT},
        {"csfcal-display-profile 1\n[readings]\nchannel,drive01,lum_cdm2,X,Y,Z\ngrey,0.5,1,2,,\n", "X,Y,Z all or none", CSF_E_FORMAT},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        csf_display_profile *b = NULL;
        csf_error_clear(&err);
        csf_status st = csf_profile_parse(bad[i].text, strlen(bad[i].text), &b, &err);
        CHECK_MSG((int)st == bad[i].code, "case %zu: status %d, message %s", i, (int)st, err.msg);
        CHECK_STR_CONTAINS(err.msg, bad[i].want);
        CHECK(b == NULL);
    }
    /* a minimal valid file, with an unknown key (forward compatible) */
    const char *ok = "csfcal-display-profile 1\nfuture_key = 3\n[curve grey]\ntransform_gamma = 2.2\n"
                     "drive01,lum_cdm2\n0,0.5\n0.5,20\n1,100\n";
    CHECK_INT_EQ(csf_profile_parse(ok, strlen(ok), &p, &err), CSF_OK);
    if (p) {
        CHECK_NEAR(csf_profile_grey_lum(p, 0.5), 20, 1e-9);
        CHECK(csf_profile_id(p)[0] != 0);
        csf_profile_free(p);
    }
    CHECK_INT_EQ(csf_profile_load("/nonexistent/dir/p.profile", &p, &err), CSF_E_IO);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/dir/p.profile");

    /* the documented default display */
    p = csf_profile_default();
    CHECK(p != NULL);
    if (p) {
        CHECK(strcmp(csf_profile_id(p), "default-gamma2.2-100cdm2") == 0);
        CHECK_NEAR(csf_profile_lum_black(p), 0.2, 1e-12);
        CHECK_NEAR(csf_profile_lum_max(p), 100, 1e-9);
        CHECK_NEAR(csf_profile_grey_lum(p, 0.5), 0.2 + 99.8 * pow(0.5, 2.2), 1e-9);
        CHECK_NEAR(csf_profile_grey_drive(p, 0.2 + 99.8 * pow(0.3, 2.2)), 0.3, 1e-12);
        CHECK(csf_profile_has_channels(p));
        CHECK_NEAR(csf_profile_channel_lum(p, 1, 1), 99.8 * 0.7152, 1e-9);
        csf_profile_free(p);
    }
    /* a kink between two levels: the model adds the vertex where the lines from both sides
     * cross, so the kink is not rounded over the interval; a smooth curve gets no extra knot */
    {
        /* gamma 2.3 with the slope 35 % steeper above drive 0.6275 (continuous there) */
#define KINK_L(v) ((v) <= 0.6275 ? 0.2 + 100 * pow((v), 2.3) \
                                 : 0.2 + 100 * (pow(0.6275, 2.3) + 1.35 * (pow((v), 2.3) - pow(0.6275, 2.3))))
        double lv[] = {0, 0.125, 0.25, 0.375, 0.5, 0.55, 0.6, 0.625, 0.6325, 0.66, 0.7, 0.75, 0.875, 1};
        size_t nl = sizeof lv / sizeof lv[0];
        double lum[16], ev[3] = {0.6275, 0.63, 0.626}, el[3];
        for (size_t i = 0; i < nl; i++) lum[i] = KINK_L(lv[i]);
        CHECK_INT_EQ(csf_profile_fit_curve(lv, lum, nl, 0, ev, el, 3, &err), CSF_OK);
        for (int i = 0; i < 3; i++)
            CHECK_MSG(fabs(el[i] / KINK_L(ev[i]) - 1) < 0.0005, "kink model at %g off by %g", ev[i],
                      el[i] / KINK_L(ev[i]) - 1);
        double cd[4];
        size_t nc = csf_profile_fit_corners(lv, lum, nl, 0, cd, 4, &err);
        CHECK_INT_EQ(nc, 1);
        if (nc) CHECK_NEAR(cd[0], 0.6275, 0.0005);
        /* smooth: same levels on a plain power law, no corner and no added knot */
        for (size_t i = 0; i < nl; i++) lum[i] = 0.2 + 100 * pow(lv[i], 2.3);
        CHECK_INT_EQ(csf_profile_fit_corners(lv, lum, nl, 0, cd, 4, &err), 0);
        CHECK_INT_EQ(csf_profile_fit_curve(lv, lum, nl, 0, ev, el, 3, &err), CSF_OK);
        for (int i = 0; i < 3; i++) CHECK_NEAR(el[i] / (0.2 + 100 * pow(ev[i], 2.3)), 1, 0.0005);
#undef KINK_L
    }
    /* points that do not rise are refused, and the knots allocated before that are freed (the
     * sanitizer's leak check at exit fails the test otherwise) */
    {
        double lv[] = {0, 0.5, 1}, lum[] = {50, 20, 10}, ev[1] = {0.5}, el[1], cd[2];
        CHECK_INT_EQ(csf_profile_fit_curve(lv, lum, 3, 0, ev, el, 1, &err), CSF_E_INSUFFICIENT);
        CHECK_INT_EQ(csf_profile_fit_corners(lv, lum, 3, 0, cd, 2, &err), 0);
    }
    return CHECK_RESULT();
}
