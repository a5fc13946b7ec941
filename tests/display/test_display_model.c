/* Simulated display truth: each kind behaves like its physics, specs and CSV files are checked. */
#include <stdlib.h>
#include <string.h>

#include "model/display_model.h"
#include "tests/check.h"

static csf_display_model *make(const char *spec)
{
    csf_display_model *m = NULL;
    csf_error err;
    csf_error_clear(&err);
    csf_status st = csf_display_model_create(spec, &m, &err);
    CHECK_MSG(st == CSF_OK, "%s: %s", spec, err.msg);
    return m;
}

static void check_monotone(const csf_display_model *m, const char *name)
{
    double prev[4] = {-1, -1, -1, -1};
    int bad = 0;
    for (int i = 0; i <= 1000; i++) {
        double v = i / 1000.0;
        double l[4] = {csf_display_model_lum(m, v, 0, 0), csf_display_model_lum(m, 0, v, 0),
                       csf_display_model_lum(m, 0, 0, v), csf_display_model_lum(m, v, v, v)};
        for (int c = 0; c < 4; c++) {
            if (l[c] < prev[c]) bad++;
            prev[c] = l[c];
        }
    }
    CHECK_MSG(bad == 0, "%s: %d decreasing steps", name, bad);
}

int main(void)
{
    csf_display_model *crt = make("crt"), *lcd = make("lcd"), *oled = make("oled");
    if (!crt || !lcd || !oled) return CHECK_RESULT();
    check_monotone(crt, "crt");
    check_monotone(lcd, "lcd");
    check_monotone(oled, "oled");
    /* black and white as documented */
    CHECK_NEAR(csf_display_model_lum(crt, 0, 0, 0), 0.05, 1e-12);
    CHECK_NEAR(csf_display_model_lum(crt, 1, 1, 1), 95.05, 1e-9);
    CHECK_NEAR(csf_display_model_lum(lcd, 0, 0, 0), 0.35, 1e-12);
    CHECK_NEAR(csf_display_model_lum(lcd, 1, 1, 1), 180.35, 1e-9);
    CHECK(csf_display_model_lum(oled, 0, 0, 0) < 0.001);
    /* CRT: cut-off below ~2 % drive; additive channels */
    CHECK_NEAR(csf_display_model_lum(crt, 0.01, 0.01, 0.01), 0.05, 1e-12);
    double sum = csf_display_model_lum(crt, 0.6, 0, 0) + csf_display_model_lum(crt, 0, 0.6, 0) +
                 csf_display_model_lum(crt, 0, 0, 0.6) - 2 * 0.05;
    CHECK_NEAR(sum, csf_display_model_lum(crt, 0.6, 0.6, 0.6), 1e-9);
    /* CRT grey is not a single power law: channel gammas differ */
    double g_mid = log((csf_display_model_lum(crt, 0.5, 0.5, 0.5) - 0.05) / 95.0) / log(0.5 * 1.02 - 0.02);
    CHECK(g_mid > 2.3 && g_mid < 2.45);
    /* LCD: channels alone add up to a few % more than white (interaction) */
    double chsum = csf_display_model_lum(lcd, 1, 0, 0) + csf_display_model_lum(lcd, 0, 1, 0) +
                   csf_display_model_lum(lcd, 0, 0, 1) - 2 * 0.35;
    double add_err = chsum / csf_display_model_lum(lcd, 1, 1, 1) - 1;
    CHECK_MSG(add_err > 0.01 && add_err < 0.05, "lcd additivity error %g", add_err);
    /* LCD: S-shaped toe: well below a pure power law near black, close to it at mid-range */
    double l05 = csf_display_model_lum(lcd, 0.05, 0.05, 0.05) - 0.35;
    CHECK(l05 < 0.5 * 180 * pow(0.05, 2.25));
    /* OLED: power limiting makes white fall short of the channel sum */
    double osum = csf_display_model_lum(oled, 1, 0, 0) + csf_display_model_lum(oled, 0, 1, 0) +
                  csf_display_model_lum(oled, 0, 0, 1);
    CHECK(osum > csf_display_model_lum(oled, 1, 1, 1) * 1.02);
    /* XYZ: Y equals luminance; white near D65 chromaticity */
    double xyz[3];
    csf_display_model_xyz(lcd, 1, 1, 1, xyz);
    CHECK_NEAR(xyz[1], csf_display_model_lum(lcd, 1, 1, 1), 1e-9);
    CHECK_NEAR(xyz[0] / (xyz[0] + xyz[1] + xyz[2]), 0.3127, 0.01);
    /* options */
    csf_display_model *c2 = make("crt,lmax=200,black=1,gamma=2.0");
    if (c2) {
        CHECK_NEAR(csf_display_model_lum(c2, 1, 1, 1), 201, 1e-9);
        CHECK(csf_display_model_lum(c2, 0.5, 0.5, 0.5) > csf_display_model_lum(crt, 0.5, 0.5, 0.5) / 95 * 200);
        csf_display_model_free(c2);
    }
    CHECK(strcmp(csf_display_model_kind(lcd), "lcd") == 0);
    /* bad specs: clear messages naming the problem */
    const char *bad[] = {"plasma", "crt,gamma=9", "lcd,lmax=-1", "crt,foo=1", "crt,gamma", "oled,interaction=0.1",
                         "file=/nonexistent/x.csv", ""};
    const char *want[] = {"unknown display kind", "out of range", "out of range", "unknown display option",
                          "not key=value", "unknown display option", "cannot open", NULL};
    for (int i = 0; i < 7; i++) {
        csf_display_model *m = NULL;
        csf_error err;
        csf_error_clear(&err);
        CHECK(csf_display_model_create(bad[i], &m, &err) != CSF_OK);
        CHECK(m == NULL);
        CHECK_STR_CONTAINS(err.msg, want[i]);
    }
    /* CSV: the shipped kinked display */
    csf_display_model *k = make("file=" CSF_TEST_DATA "/kink.csv");
    if (k) {
        check_monotone(k, "kink.csv");
        CHECK_NEAR(csf_display_model_lum(k, 1, 1, 1), 140 + 0.2, 1e-4);
        /* linear interpolation between levels 100 and 101 */
        double a = csf_display_model_lum(k, 100 / 255.0, 0, 0), b = csf_display_model_lum(k, 101 / 255.0, 0, 0);
        CHECK_NEAR(csf_display_model_lum(k, 100.25 / 255.0, 0, 0), a + 0.25 * (b - a), 1e-9);
        /* additive */
        CHECK_NEAR(csf_display_model_lum(k, 0.3, 0.3, 0.3) - 0.2,
                   (csf_display_model_lum(k, 0.3, 0, 0) - 0.2) + (csf_display_model_lum(k, 0, 0.3, 0) - 0.2) +
                       (csf_display_model_lum(k, 0, 0, 0.3) - 0.2), 1e-9);
        csf_display_model_free(k);
    }
    /* CSV errors */
    struct { const char *text, *want; } csv[] = {
        {"level,r_cdm2,g_cdm2,b_cdm2\n0,0,0,0\n", "level 1 missing"},
        {"0,0,0,0\n0,1,1,1\n", "given twice"},
        {"0,0,0\n", "4 comma-separated"},
        {"300,0,0,0\n", "integer 0..255"},
        {"0,x,0,0\n", "field 2 is not a number"},
        {"0,0,0,0,9\n", "trailing text"},
        {"0,-1,0,0\n", "out of range"},
        {"hello\n", "expected level"},
    };
    for (size_t i = 0; i < sizeof csv / sizeof csv[0]; i++) {
        csf_display_model *m = NULL;
        csf_error err;
        csf_error_clear(&err);
        CHECK(csf_display_model_from_csv(csv[i].text, strlen(csv[i].text), "t.csv", &m, &err) != CSF_OK);
        CHECK_STR_CONTAINS(err.msg, csv[i].want);
        CHECK(m == NULL);
    }
    /* decreasing curve refused */
    {
        char *t = malloc(256 * 40);
        size_t n = 0;
        for (int l = 0; l < 256; l++) n += (size_t)sprintf(t + n, "%d,%g,%g,%g\n", l, l == 100 ? 0.0 : l * 0.1, l * 0.2, l * 0.01);
        csf_display_model *m = NULL;
        csf_error err;
        CHECK(csf_display_model_from_csv(t, n, "dec.csv", &m, &err) == CSF_E_FORMAT);
        CHECK_STR_CONTAINS(err.msg, "decreases at level 100");
        free(t);
    }
    csf_display_model_free(crt);
    csf_display_model_free(lcd);
    csf_display_model_free(oled);
    return CHECK_RESULT();
}
