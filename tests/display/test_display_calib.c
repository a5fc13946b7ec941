/* Calibration procedure against the simulated truth: accuracy target and reading budget per
 * display kind, reproducibility, each instrument fault ending cleanly with every reading kept,
 * and --resume finishing the profile from the store. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib_truth.h"
#include "tests/check.h"

typedef struct {
    int calls, abort_at;
    double last[3];
} patch_log;

static int log_patch(void *user, const double rgb01[3], uint64_t reading_index)
{
    patch_log *l = user;
    CHECK_INT_EQ((long long)reading_index, (long long)l->calls); /* one index per live reading, in order */
    memcpy(l->last, rgb01, sizeof l->last);
    return ++l->calls == l->abort_at;
}

static int budget_override = 0;

static csf_display_profile *calibrate(const char *spec, uint64_t seed, csf_store *store, int64_t *sid,
                                      csf_display_calib_result *res, csf_status *st_out, csf_error *err)
{
    return calib_sim_run(spec, seed, budget_override, store, sid, res, st_out, err);
}

int main(void)
{
    csf_error err;
    csf_error_clear(&err);
    /* accuracy per display kind: the target (<= 0.25 % above 10 % of peak, <= 48 sweep
     * readings), on the simulator's default instrument */
    const char *kinds[][2] = {{"sim:display=crt", "crt"}, {"sim:display=lcd", "lcd"},
                              {"sim:display=file=" CSF_TEST_DATA "/kink.csv", "file=" CSF_TEST_DATA "/kink.csv"},
                              {"sim:display=oled", "oled"}};
    for (int k = 0; k < 4; k++) {
        csf_display_calib_result res;
        csf_display_profile *p = calibrate(kinds[k][0], 7, NULL, NULL, &res, NULL, &err);
        CHECK_MSG(p != NULL, "%s: %s", kinds[k][0], err.msg);
        if (!p) continue;
        double e[4];
        profile_errors(p, kinds[k][1], e);
        fprintf(stderr, "%s: sweep %d, all %d, grey %.4f %% r %.4f %% g %.4f %% b %.4f %%, add %.2f %%\n",
                kinds[k][1], res.n_sweep, res.n_readings, 100 * e[3], 100 * e[0], 100 * e[1], 100 * e[2],
                100 * res.additivity_error);
        CHECK_MSG(e[3] <= 0.0025, "%s grey error %g", kinds[k][0], e[3]);
        for (int c = 0; c < 3; c++) CHECK_MSG(e[c] <= 0.005, "%s channel %d error %g", kinds[k][0], c, e[c]);
        CHECK(res.n_sweep <= 48);
        CHECK(res.warmup_stable);
        CHECK_INT_EQ(res.monotonic_violations, 0);
        /* the LCD's channel interaction is found; the CSV display is additive */
        if (k == 1) CHECK_MSG(res.additivity_error > 0.015, "lcd additivity %g", res.additivity_error);
        if (k == 2) CHECK_MSG(fabs(res.additivity_error) < 0.003, "csv additivity %g", res.additivity_error);
        csf_profile_free(p);
    }

    /* error sources apart: with the instrument's noise off, what is left is the model and the
     * level placement (and drift correction); asked for a target of 0.05 % (a run stops once its
     * stated error meets the target), it must reach far below the default target, channels
     * included (they are fitted through the grey curve) */
    {
        calib_target_override = 0.0005;
        const char *nf[][2] = {{"sim:display=crt,noise=0,abs_noise=0", "crt"},
                               {"sim:display=lcd,noise=0,abs_noise=0", "lcd"},
                               {"sim:display=file=" CSF_TEST_DATA "/kink.csv,noise=0,abs_noise=0",
                                "file=" CSF_TEST_DATA "/kink.csv"}};
        for (int k = 0; k < 3; k++) {
            csf_display_calib_result res;
            csf_display_profile *p = calibrate(nf[k][0], 3, NULL, NULL, &res, NULL, &err);
            CHECK_MSG(p != NULL, "%s: %s", nf[k][0], err.msg);
            if (!p) continue;
            double e[4];
            profile_errors(p, nf[k][1], e);
            CHECK_MSG(e[3] <= 0.0006, "noise-free %s grey error %g", nf[k][1], e[3]);
            for (int c = 0; c < 3; c++) CHECK_MSG(e[c] <= 0.0015, "noise-free %s channel %d error %g", nf[k][1], c, e[c]);
            CHECK_INT_EQ(res.n_profile, res.n_readings - res.n_warmup - res.n_check);
            CHECK_INT_EQ(res.n_check, 4 * 4); /* four spot checks on each of grey, r, g, b */
            /* the saved profile carries the grey-derived channel curves exactly */
            char *text = NULL;
            csf_display_profile *q = NULL;
            CHECK_INT_EQ(csf_profile_to_text(p, &text, &err), CSF_OK);
            if (text) CHECK_INT_EQ(csf_profile_parse(text, strlen(text), &q, &err), CSF_OK);
            if (q)
                for (int c = 0; c < 3; c++)
                    for (int i = 0; i <= 100; i++)
                        CHECK_NEAR(csf_profile_channel_lum(q, c, i / 100.0), csf_profile_channel_lum(p, c, i / 100.0), 0);
            free(text);
            csf_profile_free(q);
            csf_profile_free(p);
        }
        calib_target_override = 0;
    }

    /* channels through grey: used on the default displays, and at seed 7 every channel meets
     * the grey target too */
    {
        csf_display_calib_result res;
        csf_display_profile *p = calibrate("sim:display=crt", 7, NULL, NULL, &res, NULL, &err);
        if (p) {
            double e[4];
            profile_errors(p, "crt", e);
            for (int c = 0; c < 3; c++) {
                CHECK_INT_EQ(res.channel_via_grey[c], 1);
                CHECK_MSG(e[c] <= 0.0025, "crt channel %d error %g", c, e[c]);
            }
            /* bad knots are refused */
            double v[3] = {0, 0.5, 1}, L[3] = {0, 2, 1};
            CHECK(csf_profile_set_channel_knots(p, 0, v, L, 3, &err) != CSF_OK);
            CHECK(csf_profile_set_channel_knots(p, 3, v, L, 3, &err) != CSF_OK);
            L[1] = 0.5;
            CHECK_INT_EQ(csf_profile_set_channel_knots(p, 0, v, L, 3, &err), CSF_OK);
            CHECK_NEAR(csf_profile_channel_lum(p, 0, 0.5), 0.5, 1e-12);
        }
        csf_profile_free(p);
    }

    /* reproducible: same seed, same model */
    {
        csf_display_calib_result r1, r2;
        csf_display_profile *a = calibrate("sim:display=lcd", 11, NULL, NULL, &r1, NULL, &err);
        csf_display_profile *b = calibrate("sim:display=lcd", 11, NULL, NULL, &r2, NULL, &err);
        if (a && b) {
            CHECK_INT_EQ(r1.n_readings, r2.n_readings);
            for (int i = 0; i <= 50; i++) CHECK_NEAR(csf_profile_grey_lum(a, i / 50.0), csf_profile_grey_lum(b, i / 50.0), 0);
        }
        csf_profile_free(a);
        csf_profile_free(b);
    }

    /* the show_patch hook (where the presenter draws for a real instrument) sees every live
     * reading's patch, and its failure aborts cleanly */
    {
        csf_photometer *ph = NULL;
        CHECK_INT_EQ(csf_photometer_open("sim:display=crt", 2, &ph, &err), CSF_OK);
        csf_display_calib_opts o;
        csf_display_calib_defaults(&o);
        patch_log lg = {0, 0, {0, 0, 0}};
        o.show_patch = log_patch;
        o.show_patch_user = &lg;
        csf_display_profile *p = NULL;
        csf_display_calib_result res;
        CHECK_INT_EQ(csf_display_calibrate(ph, &o, NULL, NULL, 2, &p, &res, &err), CSF_OK);
        CHECK_INT_EQ(lg.calls, res.n_readings);
        CHECK_NEAR(lg.last[0] + lg.last[1] + lg.last[2], 3, 0); /* ends on a white reference */
        csf_profile_free(p);
        lg.calls = 0;
        lg.abort_at = 10;
        CHECK_INT_EQ(csf_display_calibrate(ph, &o, NULL, NULL, 2, &p, &res, &err), CSF_E_ABORTED);
        CHECK_STR_CONTAINS(err.msg, "could not be drawn");
        CHECK(p == NULL);
        csf_photometer_close(ph);
    }

    /* "too dark" during the dark readings: the sensor off the screen must not
     * become black = 0 cd/m2, uninterrupted or resumed. The LCD's true black is 0.35 cd/m2. */
    {
        csf_display_calib_result base;
        csf_display_profile *p0 = calibrate("sim:display=lcd", 5, NULL, NULL, &base, NULL, &err);
        CHECK(p0 != NULL);
        int nw = base.n_warmup; /* the dark series is readings nw .. nw+5 */
        double black0 = p0 ? csf_profile_lum_black(p0) : 0;
        CHECK_MSG(fabs(black0 / 0.35 - 1) < 0.02, "lcd black %g", black0);
        /* a series that mixes "too dark" and real readings is measured again */
        char spec[160];
        snprintf(spec, sizeof spec, "sim:display=lcd,fault=dark@%d+3", nw + 2);
        csf_display_calib_result res;
        csf_display_profile *p = calibrate(spec, 5, NULL, NULL, &res, NULL, &err);
        CHECK_MSG(p != NULL, "%s: %s", spec, err.msg);
        if (p) {
            CHECK_MSG(fabs(csf_profile_lum_black(p) / 0.35 - 1) < 0.02, "mixed dark series: black %g", csf_profile_lum_black(p));
            /* the dark series once more; the sweep's noise draws follow the reading numbers, so
             * only the readings outside the sweep are compared */
            CHECK_INT_EQ(res.n_readings - res.n_sweep, base.n_readings - base.n_sweep + 6);
        }
        csf_profile_free(p);
        /* a series of only "too dark" on a display whose black is measurable: the confirming dark
         * reading after the white references contradicts it, and it is measured again */
        snprintf(spec, sizeof spec, "sim:display=lcd,fault=dark@%d+6", nw);
        p = calibrate(spec, 5, NULL, NULL, &res, NULL, &err);
        CHECK_MSG(p != NULL, "%s: %s", spec, err.msg);
        if (p) {
            CHECK_MSG(fabs(csf_profile_lum_black(p) / 0.35 - 1) < 0.02, "too-dark series: black %g", csf_profile_lum_black(p));
            /* the series and its confirming reading once more (outside the sweep, as above) */
            CHECK_INT_EQ(res.n_readings - res.n_sweep, base.n_readings - base.n_sweep + 7);
        }
        csf_profile_free(p);
        /* an OLED's black really is below the floor: "too dark" confirmed, black 0 */
        p = calibrate("sim:display=oled", 5, NULL, NULL, &res, NULL, &err);
        CHECK(p != NULL);
        if (p) CHECK_NEAR(csf_profile_lum_black(p), 0, 0);
        csf_profile_free(p);
        /* resumed: the sensor fell off at the dark series and stayed off (the session stops at the
         * white after it); resumed with it back on, the stored "too dark" series is not kept */
        char sdir[] = "/tmp/csfcal-test-dark-XXXXXX";
        CHECK(mkdtemp(sdir) != NULL);
        char sdb[600];
        snprintf(sdb, sizeof sdb, "%s/store.sqlite", sdir);
        csf_store *ds = NULL;
        CHECK_INT_EQ(csf_store_open(sdb, &ds, &err), CSF_OK);
        for (int k = 0; ds && k < 2; k++) {
            /* k = 0: the case, the whole series too dark; k = 1: a mixed series, then a
             * second one too dark */
            snprintf(spec, sizeof spec, "sim:display=lcd,fault=dark@%d", nw + (k ? 3 : 0));
            int64_t sid = 0;
            csf_status st = CSF_OK;
            p = calibrate(spec, 5, ds, &sid, &res, &st, &err);
            CHECK_MSG(st == CSF_E_TOO_DARK, "%s: status %d (%s)", spec, (int)st, err.msg);
            csf_profile_free(p);
            p = calibrate("sim:display=lcd", 5, ds, &sid, &res, &st, &err);
            CHECK_MSG(st == CSF_OK && p, "resume after %s: %s", spec, err.msg);
            if (p) CHECK_MSG(fabs(csf_profile_lum_black(p) / 0.35 - 1) < 0.02, "resumed after %s: black %g", spec,
                             csf_profile_lum_black(p));
            csf_profile_free(p);
        }
        /* a black level at the instrument's floor answers both ways in every series: refused after
         * three, with the reason, and resumable */
        {
            int64_t sid = 0;
            csf_status st = CSF_OK;
            p = calibrate("sim:display=lcd,black=0.01,abs_noise=0.002", 5, ds, &sid, &res, &st, &err);
            CHECK_MSG(st == CSF_E_INSUFFICIENT, "black at the floor: status %d (%s)", (int)st, err.msg);
            CHECK_STR_CONTAINS(err.msg, "mix 'too dark' answers");
            CHECK(p == NULL);
            csf_session_info si;
            memset(&si, 0, sizeof si);
            if (ds && csf_store_get_session(ds, sid, &si, &err) == CSF_OK) {
                CHECK(si.state == CSF_SESSION_PAUSED);
                csf_session_info_free(&si);
            }
        }
        csf_store_close(ds);
        char cmd[700];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", sdir);
        CHECK_INT_EQ(system(cmd), 0);
        csf_profile_free(p0);
    }

    /* verify: warm-up as in calibrate (a cold display is not reported from its first readings),
     * channels too */
    {
        csf_display_calib_result res;
        csf_display_profile *p = calibrate("sim:display=lcd", 8, NULL, NULL, &res, NULL, &err);
        csf_photometer *ph = NULL;
        csf_display_verify_opts vo;
        csf_display_verify_defaults(&vo);
        vo.channels = 1;
        csf_display_verify_result vr;
        /* the default simulated monitor starts 1 % dim and settles in about a minute: after the
         * warm-up check it matches its fresh profile to its noise, r, g, b included */
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd", 31, &ph, &err), CSF_OK);
        if (p && ph) {
            CHECK_INT_EQ(csf_display_verify_run(ph, p, &vo, &vr, &err), CSF_OK);
            CHECK(vr.warm);
            CHECK(vr.n_warmup >= 6);
            CHECK_MSG(fabs(vr.white_dev_rel) < 0.003, "warm white deviation %g", vr.white_dev_rel);
            for (int c = 0; c < CSF_CH_COUNT; c++) {
                CHECK_MSG(vr.dev_rel[c] < 0.01, "curve %d deviation %g", c, vr.dev_rel[c]);
                CHECK_MSG(vr.n_checked[c] >= 3, "curve %d: %d levels", c, vr.n_checked[c]);
            }
        }
        csf_photometer_close(ph);
        /* a monitor that is still warming up after the check's 40 readings: not warm */
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd,warmup_s=120,drift=0.3", 31, &ph, &err), CSF_OK);
        if (p && ph) {
            CHECK_INT_EQ(csf_display_verify_run(ph, p, &vo, &vr, &err), CSF_OK);
            CHECK(!vr.warm);
            CHECK_INT_EQ(vr.n_warmup, 40);
        }
        csf_photometer_close(ph);
        /* a brighter monitor of the same kind: every curve deviates */
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd,lmax=200", 31, &ph, &err), CSF_OK);
        if (p && ph) {
            CHECK_INT_EQ(csf_display_verify_run(ph, p, &vo, &vr, &err), CSF_OK);
            for (int c = 0; c < CSF_CH_COUNT; c++) CHECK_MSG(vr.dev_rel[c] > 0.05, "curve %d deviation %g", c, vr.dev_rel[c]);
        }
        csf_photometer_close(ph);
        ph = NULL;
        /* channels on a grey-only profile: refused */
        csf_photometer *ph2 = NULL;
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd", 31, &ph2, &err), CSF_OK);
        csf_photometer_open("sim:display=lcd", 31, &ph, &err);
        csf_display_calib_opts o;
        csf_display_calib_defaults(&o);
        o.channels = 0;
        csf_display_profile *grey = NULL;
        if (ph2 && csf_display_calibrate(ph2, &o, NULL, NULL, 8, &grey, &res, &err) == CSF_OK && ph) {
            CHECK_INT_EQ(csf_display_verify_run(ph, grey, &vo, &vr, &err), CSF_E_INVALID_ARG);
            CHECK_STR_CONTAINS(err.msg, "no r, g, b curves");
        }
        csf_profile_free(grey);
        csf_photometer_close(ph);
        csf_photometer_close(ph2);
        csf_profile_free(p);
    }

    /* 8-bit levels only: every measured drive is k/255, and the target still holds on the lcd */
    {
        csf_photometer *ph = NULL;
        CHECK_INT_EQ(csf_photometer_open("sim:display=lcd", 4, &ph, &err), CSF_OK);
        csf_display_calib_opts o;
        csf_display_calib_defaults(&o);
        o.drive_levels = 255;
        csf_display_profile *p = NULL;
        csf_display_calib_result res;
        if (ph && csf_display_calibrate(ph, &o, NULL, NULL, 4, &p, &res, &err) == CSF_OK) {
            const csf_profile_reading *r;
            size_t n = csf_profile_readings(p, &r), off = 0;
            for (size_t i = 0; i < n; i++)
                if (fabs(r[i].drive01 * 255 - floor(r[i].drive01 * 255 + 0.5)) > 1e-9) off++;
            CHECK_INT_EQ(off, 0);
            double e[4];
            profile_errors(p, "lcd", e);
            CHECK_MSG(e[3] <= 0.0025, "8-bit lcd grey error %g", e[3]);
            csf_profile_free(p);
        } else {
            CHECK_MSG(0, "8-bit calibration: %s", err.msg);
        }
        csf_photometer_close(ph);
    }

    /* a noisy instrument (0.2 % per reading) gets repeats; with a budget to match, the grey curve
     * is within 0.35 % in the median of five seeds (one run's max error scatters: 0.05-0.46 % over
     * 20 seeds, bench_display) */
    {
        budget_override = 160;
        double grey[5];
        int n = 0;
        for (uint64_t seed = 5; seed < 10; seed++) {
            csf_display_calib_result res;
            csf_display_profile *p =
                calibrate("sim:display=crt,noise=0.002", seed, NULL, NULL, &res, NULL, &err);
            CHECK_MSG(p != NULL, "noisy crt seed %d: %s", (int)seed, err.msg);
            if (!p) continue;
            double e[4];
            profile_errors(p, "crt", e);
            grey[n++] = e[3];
            CHECK(res.n_sweep <= 160);
            /* 0.2 % per reading: levels are read up to 4 times and averaged, so the curve is
             * better than two single readings' noise; the noise estimate sees the instrument */
            CHECK_MSG(res.noise_rel > 0.0008, "noise estimate %g", res.noise_rel);
            size_t nr = csf_profile_readings(p, NULL);
            CHECK_MSG((size_t)res.n_sweep > csf_profile_knots(p, CSF_CH_GREY, NULL, NULL) +
                      csf_profile_knots(p, 0, NULL, NULL) + csf_profile_knots(p, 1, NULL, NULL) +
                      csf_profile_knots(p, 2, NULL, NULL) - 7, "no repeats (%d sweep readings, %zu kept)", res.n_sweep, nr);
            csf_profile_free(p);
        }
        for (int i = 1; i < n; i++)
            for (int j = i; j > 0 && grey[j - 1] > grey[j]; j--) {
                double t = grey[j];
                grey[j] = grey[j - 1];
                grey[j - 1] = t;
            }
        if (n == 5) CHECK_MSG(grey[2] <= 0.0035, "noisy crt grey error, median of 5 seeds %g", grey[2]);
        budget_override = 0;
    }

    /* faults: each ends with its status and a message, readings kept in the store, the session
     * paused; --resume with a working instrument finishes it and meets the target */
    struct {
        const char *fault;
        csf_status code;
        const char *msg;
    } faults[] = {
        {"unplug@5", CSF_E_GONE, "disconnected"}, /* during the warm-up check */
        {"unplug@30", CSF_E_GONE, "disconnected"},
        {"timeout@25", CSF_E_TIMEOUT, "did not answer"},
        {"garbage@40", CSF_E_PROTOCOL, "unreadable"},
        {"dark@35", CSF_E_TOO_DARK, "too dark"},
        {"saturate@28", CSF_E_SATURATED, "saturated"},
        {"timeout@45", CSF_E_TIMEOUT, "did not answer"}, /* inside the channel sweeps */
    };
    /* the profile an unfaulted session makes: a faulted session, resumed, must make the same one
     * (the failed attempt is retried under its own reading number and clock) */
    csf_display_calib_result ref_res;
    csf_display_profile *ref = calibrate("sim:display=lcd", 21, NULL, NULL, &ref_res, NULL, &err);
    CHECK(ref != NULL);
    char dir[] = "/tmp/csfcal-test-calib-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char db[600];
    snprintf(db, sizeof db, "%s/store.sqlite", dir);
    csf_store *store = NULL;
    CHECK_INT_EQ(csf_store_open(db, &store, &err), CSF_OK);
    for (size_t k = 0; store && k < sizeof faults / sizeof faults[0]; k++) {
        char spec[128];
        snprintf(spec, sizeof spec, "sim:display=lcd,fault=%s", faults[k].fault);
        int64_t sid = 0;
        csf_display_calib_result res;
        csf_status st = CSF_OK;
        csf_error_clear(&err);
        csf_display_profile *p = calibrate(spec, 21, store, &sid, &res, &st, &err);
        CHECK_MSG(st == faults[k].code, "%s: status %d (%s)", spec, (int)st, err.msg);
        CHECK_STR_CONTAINS(err.msg, faults[k].msg);
        CHECK(p == NULL);
        CHECK(sid > 0);
        int at = atoi(strchr(faults[k].fault, '@') + 1);
        csf_reading *rd = NULL;
        size_t n = 0;
        CHECK_INT_EQ(csf_store_get_readings(store, sid, &rd, &n, &err), CSF_OK);
        /* every attempt up to and including the failed one is stored */
        CHECK_INT_EQ(n, (size_t)at + 1);
        if (n) CHECK(rd[n - 1].status != CSF_READING_OK);
        free(rd);
        csf_session_info si;
        memset(&si, 0, sizeof si);
        CHECK_INT_EQ(csf_store_get_session(store, sid, &si, &err), CSF_OK);
        CHECK(si.state == CSF_SESSION_PAUSED);
        csf_session_info_free(&si);
        /* resume with the instrument reconnected */
        int64_t sid2 = sid;
        p = calibrate("sim:display=lcd", 21, store, &sid2, &res, &st, &err);
        CHECK_MSG(st == CSF_OK && p, "resume after %s: %s", faults[k].fault, err.msg);
        CHECK(sid2 == sid);
        if (p) {
            double e[4];
            profile_errors(p, "lcd", e);
            CHECK_MSG(e[3] <= 0.0025, "resumed grey error %g", e[3]);
            CHECK(res.n_sweep <= 48);
            CHECK_MSG(ref && profile_same_model(p, ref), "resumed after %s: not the unfaulted session's profile",
                      faults[k].fault);
            CHECK_INT_EQ(res.n_readings, ref_res.n_readings);
            csf_profile_free(p);
        }
        CHECK_INT_EQ(csf_store_get_session(store, sid, &si, &err), CSF_OK);
        CHECK(si.state == CSF_SESSION_FINISHED);
        csf_session_info_free(&si);
        /* a finished session is not resumed again */
        p = calibrate("sim:display=lcd", 21, store, &sid2, &res, &st, &err);
        CHECK_INT_EQ(st, CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(err.msg, "already finished");
        csf_profile_free(p);
    }
    /* replay is deterministic: the same paused session resumed from two copies of the store
     * gives the same profile, bit for bit */
    if (store) {
        int64_t sid = 0;
        csf_display_calib_result res;
        csf_status st = CSF_OK;
        csf_display_profile *p = calibrate("sim:display=oled,fault=garbage@33", 9, store, &sid, &res, &st, &err);
        CHECK_INT_EQ(st, CSF_E_PROTOCOL);
        csf_profile_free(p);
        csf_store_close(store);
        store = NULL;
        char db2[700], cmd[4096];
        snprintf(db2, sizeof db2, "%s/copy.sqlite", dir);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s' && for x in -wal -shm; do [ -e '%s'$x ] && cp '%s'$x '%s'$x; done; true",
                 db, db2, db, db, db2);
        CHECK_INT_EQ(system(cmd), 0);
        csf_store *s1 = NULL, *s2 = NULL;
        CHECK_INT_EQ(csf_store_open(db, &s1, &err), CSF_OK);
        CHECK_INT_EQ(csf_store_open(db2, &s2, &err), CSF_OK);
        int64_t a = sid, b = sid;
        csf_display_profile *pa = s1 ? calibrate("sim:display=oled", 9, s1, &a, &res, &st, &err) : NULL;
        csf_display_profile *pb = s2 ? calibrate("sim:display=oled", 9, s2, &b, &res, &st, &err) : NULL;
        CHECK(pa && pb);
        if (pa && pb) {
            CHECK_INT_EQ(csf_profile_knots(pa, CSF_CH_GREY, NULL, NULL), csf_profile_knots(pb, CSF_CH_GREY, NULL, NULL));
            for (int i = 0; i <= 100; i++) {
                CHECK_NEAR(csf_profile_grey_lum(pa, i / 100.0), csf_profile_grey_lum(pb, i / 100.0), 0);
                CHECK_NEAR(csf_profile_channel_lum(pa, 2, i / 100.0), csf_profile_channel_lum(pb, 2, i / 100.0), 0);
            }
        }
        csf_profile_free(pa);
        csf_profile_free(pb);
        csf_store_close(s1);
        csf_store_close(s2);
        snprintf(cmd, sizeof cmd, "rm -f '%s' '%s-wal' '%s-shm'", db2, db2, db2);
        CHECK_INT_EQ(system(cmd), 0);
    }
    csf_profile_free(ref);
    csf_store_close(store);
    unlink(db);
    char wal[620];
    snprintf(wal, sizeof wal, "%s-wal", db);
    unlink(wal);
    snprintf(wal, sizeof wal, "%s-shm", db);
    unlink(wal);
    rmdir(dir);
    return CHECK_RESULT();
}
