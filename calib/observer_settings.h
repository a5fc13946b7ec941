/* The settings an observer session is stored with (sessions.settings, JSON) and read back from
 * on --resume. Once on disk they are outside input: the reader takes them through jansson with
 * every value in range and refuses anything else (tests/fuzz/fuzz_observer_settings.c). */
#ifndef CSF_OBSERVER_SETTINGS_H
#define CSF_OBSERVER_SETTINGS_H

#include <stddef.h>

#include "calib/observer_calib.h"

typedef struct {
    char method[16];
    char observer[256];
    int trials, practice;
    double freqs[CSF_OBS_MAX_AXIS], eccs[CSF_OBS_MAX_AXIS];
    int n_freqs, n_eccs;
    double vels[CSF_OBS_MAX_AXIS]; /* drift velocities, deg/s (n_vels 0: static gratings only) */
    int n_vels;
    int drift_direction; /* 0 random per trial, +1 forward, -1 backward */
    double precision;    /* > 0: the session stops at this predicted RMS error (log10); trials is the cap */
    int break_every;
    int afc;             /* 2 or 4: forced-choice layout asked for (sessions stored without it: 2) */
    double fade_anchors; /* share of a fade session's trials that are forced-choice anchors, 0-0.5;
                            0 = none (sessions stored without it had none); stored for fade
                            sessions only, 0 for the others */
    char profile_id[256]; /* display profile the session began with ("" in sessions stored
                             before it was kept here: the session row's display then says) */
} csf_obs_settings;

/* JSON object of s (jansson: strings escaped) into buf; sigma_deg: the Gabor's sigma, recorded
 * for readers. Returns 0, or -1 (buf empty) when it does not fit in len bytes. */
int csf_obs_settings_to_json(const csf_obs_settings *s, double sigma_deg, char *buf, size_t len);
/* Fills s from stored JSON; keys older sessions did not store get their documented fallbacks.
 * Returns 0, or -1 when the text is not such an object or a value is missing or out of range. */
int csf_obs_settings_from_json(const char *json, csf_obs_settings *s);

#endif
