/* A realistic sample store for the report and export tests: an observer session whose thresholds
 * come from the log-parabola x stelaCSF model with measurement noise (and whose person time is
 * its instructions, frames and answers), and a display session with noisy gamma-curve readings
 * and the display profile built from them. */
#ifndef CSF_STORE_SAMPLE_H
#define CSF_STORE_SAMPLE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_model.h"
#include "results/display_profile.h"
#include "core/rng.h"
#include "results/store/store.h"
#include "store_test_util.h"

static const double sample_freqs[] = {0.5, 1, 2, 4, 8, 16, 24};
static const double sample_eccs[] = {0, 5, 10, 20};
#define SAMPLE_NF 7
#define SAMPLE_NE 4
#define SAMPLE_TRIALS 240
#define SAMPLE_FRAMES 30
#define SAMPLE_INSTRUCTIONS_S 30.0

/* Frames per trial at 60 Hz with jitter; trial seq % 40 == 7 misses one frame (a 2-frame gap). */
static inline void sample_intervals(uint64_t seed, int seq, double *iv)
{
    for (int k = 0; k < SAMPLE_FRAMES; k++)
        iv[k] = 1.0 / 60.0 + 0.0003 * csf_rng_normal(seed, 30, (uint64_t)(seq * 100 + k));
    if (seq % 40 == 7) iv[12] = 2.0 / 60.0 + 0.0002;
}

static inline double sample_display_lum(uint64_t seed, int ch, double v, int idx)
{
    static const double weight[4] = {0.2126, 0.7152, 0.0722, 1.0};
    double black = 0.25, white = 110.0;
    /* Gamma 2.2 with an S-shaped low end, 0.4 % multiplicative noise. */
    double shape = pow(v, 2.2) * (1.0 - 0.04 * sin(M_PI * v));
    double noise = 1.0 + 0.004 * csf_rng_normal(seed, 40, (uint64_t)idx);
    return (black + white * weight[ch] * shape) * noise;
}

static inline int make_sample_store(const char *path, uint64_t seed, int64_t *obs_id, int64_t *disp_id)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) != CSF_OK) {
        fprintf(stderr, "sample: %s\n", err.msg);
        return -1;
    }
    int ok = 1;
    ok &= csf_store_begin_session(s, CSF_SESSION_OBSERVER, "sim-observer", "sim-lcd",
                                  "{\"method\":\"fade\",\"freqs_cpd\":[0.5,1,2,4,8,16,24],"
                                  "\"eccs_deg\":[0,5,10,20]}",
                                  seed, obs_id, &err) == CSF_OK;
    /* The person's time: a 30 s instruction screen, then each trial's frames and answer. */
    double person_s = SAMPLE_INSTRUCTIONS_S;
    for (int i = 0; ok && i < SAMPLE_TRIALS; i++) {
        csf_trial t = make_trial(*obs_id, i, seed);
        t.freq_cpd = sample_freqs[i % SAMPLE_NF];
        t.ecc_deg = sample_eccs[(i / SAMPLE_NF) % SAMPLE_NE];
        t.has_onset = 1; /* shown when the person's time so far has passed */
        t.onset_s = person_s;
        ok &= csf_store_add_trial(s, &t, &err) == CSF_OK;
        double iv[SAMPLE_FRAMES];
        sample_intervals(seed, i, iv);
        ok &= csf_store_add_frame_intervals(s, *obs_id, i, iv, SAMPLE_FRAMES, &err) == CSF_OK;
        for (int k = 0; k < SAMPLE_FRAMES; k++) person_s += iv[k];
        if (isfinite(t.rt_s)) person_s += t.rt_s;
    }
    ok &= csf_store_add_person_time(s, *obs_id, person_s, &err) == CSF_OK;
    csf_model_params mp = csf_model_default();
    csf_threshold_row rows[SAMPLE_NF * SAMPLE_NE];
    int n = 0;
    for (int e = 0; e < SAMPLE_NE; e++)
        for (int f = 0; f < SAMPLE_NF; f++) {
            csf_threshold_row *r = &rows[n];
            double th = csf_model_threshold(&mp, sample_freqs[f], sample_eccs[e]);
            double se = 0.04 + 0.06 * csf_rng_uniform(seed, 20, (uint64_t)n);
            th *= pow(10.0, se * csf_rng_normal(seed, 21, (uint64_t)n));
            r->freq_cpd = sample_freqs[f];
            r->ecc_deg = sample_eccs[e];
            r->velocity_dps = 0;
            r->lum_cdm2 = 50;
            r->threshold = th >= 1.0 ? INFINITY : th;
            r->stderr_log10 = se;
            r->n_trials = 8 + n % 5;
            n++;
        }
    ok &= csf_store_put_thresholds(s, *obs_id, rows, (size_t)n, &err) == CSF_OK;
    ok &= csf_store_add_artifact(s, *obs_id, "csflut", "sim-observer.csflut", "CSFLUT-sample", 13, &err) == CSF_OK;
    ok &= csf_store_set_session_state(s, *obs_id, CSF_SESSION_FINISHED, &err) == CSF_OK;

    ok &= csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, "sim-lcd", "{\"levels\":17}", seed, disp_id,
                                  &err) == CSF_OK;
    csf_profile_reading pr[64];
    int npr = 0, seq = 0;
    static const char *const names[4] = {"r", "g", "b", "grey"};
    for (int ch = 3; ok && ch >= 0; ch--) {
        int levels = ch == 3 ? 17 : 9;
        for (int k = ch == 3 ? 0 : 1; k < levels; k++) {
            double v = (double)k / (levels - 1);
            csf_reading r;
            memset(&r, 0, sizeof r);
            r.session_id = *disp_id;
            r.seq = seq;
            snprintf(r.channel, sizeof r.channel, "%s", k == 0 ? "dark" : names[ch]);
            r.drive01 = v;
            r.lum_cdm2 = sample_display_lum(seed, ch, v, seq);
            r.has_xyz = 1;
            r.X = 0.95 * r.lum_cdm2;
            r.Y = r.lum_cdm2;
            r.Z = 1.09 * r.lum_cdm2;
            r.t_s = 2.0 * seq;
            r.status = CSF_READING_OK;
            ok &= csf_store_add_reading(s, &r, &err) == CSF_OK;
            pr[npr].channel = ch == 3 ? CSF_CH_GREY : ch;
            pr[npr].drive01 = v;
            /* Channel curves in the profile exclude black. */
            pr[npr].lum_cdm2 = ch == 3 ? r.lum_cdm2 : r.lum_cdm2 - 0.25;
            pr[npr].has_xyz = 0;
            npr++;
            seq++;
        }
        if (ch != 3) { /* channel curves need their drive-0 point: black excluded = 0 */
            pr[npr].channel = ch;
            pr[npr].drive01 = 0;
            pr[npr].lum_cdm2 = 0;
            pr[npr].has_xyz = 0;
            npr++;
        }
    }
    csf_profile_meta meta = {"sim-lcd", "sim photometer", "2026-11-22T06:00:00Z", NULL, NAN};
    csf_display_profile *prof = NULL;
    csf_error perr;
    if (csf_profile_build(pr, (size_t)npr, &meta, &prof, &perr) == CSF_OK) {
        char *text = NULL;
        if (csf_profile_to_text(prof, &text, &perr) == CSF_OK) {
            ok &= csf_store_add_artifact(s, *disp_id, "profile", "sim-lcd.profile", text, strlen(text), &err) == CSF_OK;
            free(text);
        }
        csf_profile_free(prof);
    } else {
        fprintf(stderr, "sample: no profile artifact (%s); report falls back to interpolation\n", perr.msg);
    }
    ok &= csf_store_set_session_state(s, *disp_id, CSF_SESSION_FINISHED, &err) == CSF_OK;
    if (!ok) fprintf(stderr, "sample: %s\n", err.msg);
    csf_store_close(s);
    return ok ? 0 : -1;
}

#endif
