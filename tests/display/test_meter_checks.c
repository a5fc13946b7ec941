/* Sanity checks on a photometer's readings (calib/meter_check.h) and what the calibration does
 * when one fails: a message naming the instrument and the problem, the failing reading stored with
 * its values, the session paused, and --resume with a working instrument making the profile an
 * unfaulted session makes. Each fault comes from the simulated photometer (fault=KIND@N); without
 * the check, the calibration would finish on the bad readings (the first block shows which). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib/meter_check.h"
#include "cli/display_placement.h"
#include "devices/photometer_driver.h"
#include "calib_truth.h"
#include "tests/check.h"

/* Every calibration here runs on seed 21 with the default budget. */
static csf_display_profile *calibrate(const char *spec, csf_store *store, int64_t *sid,
                                      csf_display_calib_result *res, csf_status *st_out, csf_error *err)
{
    return calib_sim_run(spec, 21, 0, store, sid, res, st_out, err);
}

static void unit_checks(void)
{
    csf_meter_limits l;
    csf_meter_limits_default(&l);
    char why[400];
    csf_photometer_reading r = {.lum_cdm2 = 100, .xyz = {95, 100, 108}, .has_xyz = 1};
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 0);
    r.lum_cdm2 = -0.5;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    CHECK_STR_CONTAINS(why, "negative");
    r.lum_cdm2 = NAN;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    r.lum_cdm2 = 10001;
    r.xyz[1] = 10001;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    CHECK_STR_CONTAINS(why, "beyond any display");
    r.lum_cdm2 = 9999; /* just inside the display class */
    r.xyz[1] = 9999;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 0);
    r.lum_cdm2 = 100;
    r.xyz[1] = 101.9; /* within 2 % */
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 0);
    r.xyz[1] = 102.2;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    CHECK_STR_CONTAINS(why, "disagrees");
    r.xyz[1] = 100;
    r.xyz[2] = -5;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    r.xyz[2] = NAN;
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 1);
    r.has_xyz = 0; /* a luminance-only meter: XYZ is not looked at */
    CHECK_INT_EQ(csf_meter_absurd(&r, &l, why, sizeof why), 0);

    /* frozen: identical answers for patches 0.1 apart or more, never for repeats of one patch */
    csf_photometer_reading a = {.lum_cdm2 = 42.5}, b = a;
    double white[3] = {1, 1, 1}, grey[3] = {0.95, 0.95, 0.95}, half[3] = {0.5, 0.5, 0.5};
    CHECK_INT_EQ(csf_meter_frozen(&a, white, &b, white, &l, why, sizeof why), 0);
    CHECK_INT_EQ(csf_meter_frozen(&a, white, &b, grey, &l, why, sizeof why), 0);
    CHECK_INT_EQ(csf_meter_frozen(&a, white, &b, half, &l, why, sizeof why), 1);
    b.lum_cdm2 = 42.50001;
    CHECK_INT_EQ(csf_meter_frozen(&a, white, &b, half, &l, why, sizeof why), 0);

    CHECK_INT_EQ(csf_meter_no_contrast(180, 0.35, &l, why, sizeof why), 0);
    CHECK_INT_EQ(csf_meter_no_contrast(0.6, 0.35, &l, why, sizeof why), 1);
    CHECK_INT_EQ(csf_meter_no_contrast(0.6, NAN, &l, why, sizeof why), 0); /* "too dark" is a change */

    CHECK_INT_EQ(csf_meter_white_step(180, 185, 1, 0.0005, &l, why, sizeof why), 0);   /* 2.8 % */
    CHECK_INT_EQ(csf_meter_white_step(180, 162, 1, 0.0005, &l, why, sizeof why), 1);   /* -10 % */
    CHECK_INT_EQ(csf_meter_white_step(180, 162, 0.9, 0.0005, &l, why, sizeof why), 0); /* model said so */
    CHECK_INT_EQ(csf_meter_white_step(180, 170, 1, 0.01, &l, why, sizeof why), 0);     /* noisy meter: 6 sd */

    CHECK_INT_EQ(csf_meter_above_white(100, 180, 0.001, why, sizeof why), 0);
    CHECK_INT_EQ(csf_meter_above_white(200, 180, 0.001, why, sizeof why), 1);
}

/* The patch against the meter's field: too small refused with the figures, far too large warned,
 * and each driver declares a field (spot meters in degrees, contact meters in mm). */
static void patch_checks(void)
{
    char why[600];
    /* an LS-100 (1 deg) at 570 mm: 2 deg is the least patch, 1.5 deg is refused */
    CHECK_INT_EQ(csf_patch_for_meter(1.5, 570, 300, 1.0, 0, why, sizeof why), 2);
    CHECK_STR_CONTAINS(why, "1.5 deg patch (14.9 mm at 570 mm)");
    CHECK_STR_CONTAINS(why, "1 deg field");
    CHECK_STR_CONTAINS(why, "at least 2 deg (19.9 mm)");
    CHECK_INT_EQ(csf_patch_for_meter(2.0, 570, 300, 1.0, 0, why, sizeof why), 0);
    CHECK_INT_EQ(csf_patch_for_meter(10.0, 570, 300, 1.0, 0, why, sizeof why), 0);
    /* a PR-670 on its 1/8 deg aperture takes a quarter-degree patch */
    CHECK_INT_EQ(csf_patch_for_meter(0.25, 570, 300, 0.125, 0, why, sizeof why), 0);
    CHECK_INT_EQ(csf_patch_for_meter(0.2, 570, 300, 0.125, 0, why, sizeof why), 2);
    /* a contact meter's 20 mm face needs 30 mm: 3.0 deg at 570 mm, 1.7 deg at 1000 mm */
    CHECK_INT_EQ(csf_patch_for_meter(2.5, 570, 300, 0, 20, why, sizeof why), 2);
    CHECK_STR_CONTAINS(why, "20 mm face");
    CHECK_STR_CONTAINS(why, "(30.0 mm)");
    CHECK_INT_EQ(csf_patch_for_meter(2.5, 1000, 300, 0, 20, why, sizeof why), 0);
    /* far larger than needed: a warning, and the full field counts as the screen's height */
    CHECK_INT_EQ(csf_patch_for_meter(20, 570, 300, 1.0, 0, why, sizeof why), 1);
    CHECK_STR_CONTAINS(why, "non-uniformity");
    CHECK_INT_EQ(csf_patch_for_meter(0, 570, 300, 1.0, 0, why, sizeof why), 1);
    CHECK_INT_EQ(csf_patch_for_meter(0, 570, 200, 0, 20, why, sizeof why), 0);
    /* every driver declares its field: a spot meter's angle or a contact meter's face */
    for (const csf_photometer_driver *const *d = csf_photometer_drivers(); *d; d++)
        CHECK_MSG(((*d)->field_deg > 0) != ((*d)->field_mm > 0), "driver %s declares deg %g, mm %g",
                  (*d)->name, (*d)->field_deg, (*d)->field_mm);
    /* the simulated meter's field, through the callers' API */
    csf_photometer *ph = NULL;
    csf_error err;
    if (csf_photometer_open("sim:display=lcd", 1, &ph, &err) == CSF_OK) {
        double fdeg = 0, fmm = -1;
        csf_photometer_field(ph, &fdeg, &fmm);
        CHECK(fdeg == 1.0 && fmm == 0);
        csf_photometer_close(ph);
    }
    /* the PR-670's aperture option is parsed before the port is opened; the PR-655 has none */
    CHECK_INT_EQ(csf_photometer_open("pr670:/nonexistent/tty,aperture=1/3", 1, &ph, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "aperture=1|1/2|1/4|1/8");
    CHECK_INT_EQ(csf_photometer_open("pr655:/nonexistent/tty,aperture=1/2", 1, &ph, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_photometer_open("pr670:/nonexistent/tty,", 1, &ph, &err), CSF_E_INVALID_ARG);
    CHECK(csf_photometer_open("pr670:/nonexistent/tty,aperture=1/8,timeout_s=5", 1, &ph, &err) !=
          CSF_E_INVALID_ARG);
}

/* The placement screen's "stable": four readings within 1 % of their mean. */
static void placement_checks(void)
{
    double spread;
    const double still[] = {90, 180.2, 180.5, 180.1, 180.4};
    CHECK_INT_EQ(csf_placement_stable(still, 3, &spread), 0);
    CHECK(isnan(spread));
    CHECK_INT_EQ(csf_placement_stable(still, 4, &spread), 0); /* 90: the meter was still moving */
    CHECK_INT_EQ(csf_placement_stable(still, 5, &spread), 1);
    CHECK_NEAR(spread, 0.4 / 180.3, 1e-9);
    const double sliding[] = {180, 181, 182.5, 183};
    CHECK_INT_EQ(csf_placement_stable(sliding, 4, &spread), 0);
    const double dark[] = {0, 0, 0, 0};
    CHECK_INT_EQ(csf_placement_stable(dark, 4, &spread), 0);
}

int main(void)
{
    unit_checks();
    patch_checks();
    placement_checks();
    csf_error err;
    csf_error_clear(&err);
    csf_display_calib_result ref_res;
    csf_display_profile *ref = calibrate("sim:display=lcd", NULL, NULL, &ref_res, NULL, &err);
    CHECK(ref != NULL);
    if (!ref) return CHECK_RESULT();
    int nw = ref_res.n_warmup, first_ref = nw + 6; /* reading numbers: warm-up, six darks, white */
    char dir[] = "/tmp/csfcal-test-meter-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char db[600];
    snprintf(db, sizeof db, "%s/store.sqlite", dir);
    csf_store *store = NULL;
    CHECK_INT_EQ(csf_store_open(db, &store, &err), CSF_OK);

    /* resume: 0 = the resumed session makes the unfaulted one's profile bit for bit; 1 = readings
     * taken since the last good white were set aside and measured again (about `extra` more), the
     * profile meets the target; -1 = not resumed */
    struct { const char *kind; int at; csf_status code; const char *msg; int resume, extra; } faults[] = {
        {"stuck", 0, CSF_E_DEVICE, "stale answer", 0, 0},          /* at the first dark: answers white */
        {"stuck", 1, CSF_E_DEVICE, "stale answer", 0, 0},          /* at the first white ref: answers dark */
        {"offscreen", 0, CSF_E_DEVICE, "hardly changes", 1, 6},    /* darks are room light: seen at white */
        {"offscreen", -1, CSF_E_DEVICE, "hardly changes", -1, 0},  /* from the first reading on */
        {"dim", 1, CSF_E_DEVICE, "white changed", 1, 0},           /* the display dims by 10 %: the darks
                                                                      since the last white are set aside */
        {"dim", 2, CSF_E_DEVICE, "white changed", 1, 0},           /* ... inside the grey sweep */
        {"offscreen", 2, CSF_E_DEVICE, "hardly changes", 1, 0},     /* the sensor slips off in the sweep */
        {"glare", 30, CSF_E_DEVICE, "above white", 0, 0},          /* a grey sweep level reads a lamp */
        {"negative", 30, CSF_E_PROTOCOL, "negative", 0, 0},
        {"nan", 31, CSF_E_PROTOCOL, "not a number", 0, 0},
        {"huge", 40, CSF_E_PROTOCOL, "beyond any display", 0, 0},
        {"badxyz", 25, CSF_E_PROTOCOL, "disagrees", 0, 0},
    };
    for (size_t k = 0; store && k < sizeof faults / sizeof faults[0]; k++) {
        /* at: 0 = the first dark reading, 1 = the first white reference, 2 = 12 readings into the grey
         * sweep, -1 = reading 0, else N */
        int at = faults[k].at == 0 ? nw : faults[k].at == 1 ? first_ref : faults[k].at == 2 ? first_ref + 18
               : faults[k].at == -1 ? 0 : faults[k].at;
        char spec[128];
        snprintf(spec, sizeof spec, "sim:display=lcd,fault=%s@%d", faults[k].kind, at);
        int64_t sid = 0;
        csf_display_calib_result res;
        csf_status st = CSF_OK;
        csf_error_clear(&err);
        csf_display_profile *p = calibrate(spec, store, &sid, &res, &st, &err);
        CHECK_MSG(st == faults[k].code, "%s: status %d (%s)", spec, (int)st, err.msg);
        CHECK_STR_CONTAINS(err.msg, faults[k].msg);
        CHECK_STR_CONTAINS(err.msg, "photometer sim:display=lcd"); /* names the instrument */
        CHECK(p == NULL);
        csf_profile_free(p);
        csf_reading *rd = NULL;
        size_t n = 0;
        CHECK_INT_EQ(csf_store_get_readings(store, sid, &rd, &n, &err), CSF_OK);
        /* every reading up to the failing one is stored; the failing one with its values */
        if (faults[k].at == -1) { /* the warm-up settles on room light; the first dark fails */
            CHECK_MSG(n >= 7 && strcmp(rd[n - 1].channel, "dark") == 0, "%s: %zu readings", spec, n);
        } else if (faults[k].at == 0 && faults[k].resume == 1) { /* caught at the first white */
            CHECK_MSG(n == (size_t)first_ref + 1, "%s: %zu readings stored, expected %d", spec, n, first_ref + 1);
        } else if (faults[k].at == 2) { /* caught at the white reference after the grey sweep */
            CHECK_MSG(n > (size_t)at + 1 && strcmp(rd[n - 1].channel, "grey") == 0 && rd[n - 1].drive01 == 1,
                      "%s: %zu readings, last %s at %g", spec, n, n ? rd[n - 1].channel : "-", n ? rd[n - 1].drive01 : 0);
        } else {
            CHECK_MSG(n == (size_t)at + 1, "%s: %zu readings stored, expected %d", spec, n, at + 1);
        }
        if (n) {
            CHECK_MSG(rd[n - 1].status == CSF_READING_ERROR, "%s: last status %s", spec,
                      rd[n - 1].status_text);
            if (strcmp(faults[k].kind, "nan") != 0)
                CHECK_MSG(isfinite(rd[n - 1].lum_cdm2), "%s: the failing reading's value is not kept", spec);
        }
        free(rd);
        csf_session_info si;
        memset(&si, 0, sizeof si);
        CHECK_INT_EQ(csf_store_get_session(store, sid, &si, &err), CSF_OK);
        CHECK(si.state == CSF_SESSION_PAUSED);
        csf_session_info_free(&si);
        if (faults[k].resume < 0) continue; /* its warm-up readings are room light: resumed, it would still be */
        int64_t sid2 = sid;
        p = calibrate("sim:display=lcd", store, &sid2, &res, &st, &err);
        CHECK_MSG(st == CSF_OK && p, "resume after %s: %s", spec, err.msg);
        if (p && faults[k].resume == 0) {
            CHECK_MSG(profile_same_model(p, ref), "resumed after %s: not the unfaulted session's profile", spec);
            CHECK_INT_EQ(res.n_readings, ref_res.n_readings);
        }
        if (p && faults[k].resume == 1) {
            double e[4];
            profile_errors(p, "lcd", e);
            CHECK_MSG(e[3] <= 0.0025, "resumed after %s: grey error %g", spec, e[3]);
            for (int c = 0; c < 3; c++) CHECK_MSG(e[c] <= 0.005, "resumed after %s: channel %d error %g", spec, c, e[c]);
            CHECK_MSG(fabs(csf_profile_lum_black(p) / 0.35 - 1) < 0.02, "resumed after %s: black %g", spec,
                      csf_profile_lum_black(p));
            /* what was set aside is measured again (adaptive levels may differ by a reading or two) */
            if (faults[k].extra)
                CHECK_MSG(res.n_readings >= ref_res.n_readings + faults[k].extra - 2, "resumed after %s: %d readings, "
                          "unfaulted %d", spec, res.n_readings, ref_res.n_readings);
            CHECK_MSG(res.n_sweep <= 48, "resumed after %s: %d sweep readings", spec, res.n_sweep);
        }
        csf_profile_free(p);
    }

    /* the display class: a 100 cd/m2 limit refuses the 180 cd/m2 LCD's white */
    {
        csf_photometer *ph = NULL;
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd", 21, &ph, &err), CSF_OK);
        csf_display_calib_opts o;
        csf_display_calib_defaults(&o);
        o.max_lum_cdm2 = 100;
        csf_display_profile *p = NULL;
        csf_display_calib_result res;
        CHECK_INT_EQ(csf_display_calibrate(ph, &o, NULL, NULL, 21, &p, &res, &err), CSF_E_PROTOCOL);
        CHECK_STR_CONTAINS(err.msg, "limit 100 cd/m2");
        csf_profile_free(p);
        csf_photometer_close(ph);
    }
    /* the instrument's own faults are named too, with what to do */
    {
        csf_display_calib_result res;
        csf_status st = CSF_OK;
        csf_display_profile *p = calibrate("sim:display=lcd,fault=dark@0", NULL, NULL, &res, &st, &err);
        CHECK_INT_EQ(st, CSF_E_TOO_DARK);
        CHECK_STR_CONTAINS(err.msg, "photometer sim:display=lcd,fault=dark@0, reading 0 (warm-up white");
        CHECK_STR_CONTAINS(err.msg, "cap on");
        csf_profile_free(p);
        p = calibrate("sim:display=lcd,fault=timeout@20", NULL, NULL, &res, &st, &err);
        CHECK_INT_EQ(st, CSF_E_TIMEOUT);
        CHECK_STR_CONTAINS(err.msg, "fell silent");
        csf_profile_free(p);
        p = calibrate("sim:display=lcd,fault=saturate@20", NULL, NULL, &res, &st, &err);
        CHECK_INT_EQ(st, CSF_E_SATURATED);
        CHECK_STR_CONTAINS(err.msg, "range");
        csf_profile_free(p);
    }
    /* verify refuses an absurd answer instead of reporting it as the display's deviation */
    {
        csf_photometer *ph = NULL;
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd,fault=negative@12", 21, &ph, &err), CSF_OK);
        csf_display_verify_opts vo;
        csf_display_verify_defaults(&vo);
        csf_display_verify_result vr;
        if (ph) {
            CHECK_INT_EQ(csf_display_verify_run(ph, ref, &vo, &vr, &err), CSF_E_PROTOCOL);
            CHECK_STR_CONTAINS(err.msg, "negative");
            CHECK_STR_CONTAINS(err.msg, "photometer sim:display=lcd");
        }
        csf_photometer_close(ph);
    }
    csf_profile_free(ref);
    csf_store_close(store);
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK_INT_EQ(system(cmd), 0);
    return CHECK_RESULT();
}
