/* Per-user CSF calibration session (`csfcal observer calibrate`): instructions, practice trials
 * (which also measure the person's simple reaction time for the fade method), interleaved trials
 * of the chosen procedure drawn through the presenter, breaks and progress, every trial durably
 * stored before the next is shown, resume by replaying stored trials, and at the end the
 * threshold table (.csflut), thresholds in the store, the report plot and a one-line summary.
 *
 * Simulated observers run on the presenter's virtual clock (headless), so a session takes only
 * the time to compute and store it; human observers run windowed with a keyboard/mouse responder.
 * Escape (human) or SIGINT/SIGTERM pauses: the session is marked "paused" and can be resumed. */
#ifndef CSF_OBSERVER_CALIB_H
#define CSF_OBSERVER_CALIB_H

#include <stdint.h>

#include "core/station.h"
#include "core/csf_status.h"

#define CSF_OBS_MAX_AXIS 16

typedef struct {
    const csf_config *cfg;      /* geometry, refresh, store path, profile path, observer spec */
    const char *observer_spec;  /* "sim[:...]" or "human[:NAME]"; NULL = cfg->observer, else "sim" */
    const char *method;         /* "bayes" (default), "fade", "2afc" */
    const char *out_path;       /* .csflut to write (required) */
    const char *plot_path;      /* report plot (.png/.pdf/.svg), NULL = none */
    const char *store_path;     /* resolved store path */
    double freqs_cpd[CSF_OBS_MAX_AXIS];
    int n_freqs;                /* 0 = default: 6 log-spaced 0.5-16 cpd capped by Nyquist */
    double eccs_deg[CSF_OBS_MAX_AXIS];
    int n_eccs;                 /* 0 = default: 0, 5, 10, 20 deg capped by the screen */
    double vels_dps[CSF_OBS_MAX_AXIS];
    int n_vels;                 /* 0 = static gratings only (a 2-D table); else the carrier drifts
                                   at each velocity (deg/s, 0 = static) and the table is 3-D */
    int drift_direction;        /* 0 = each trial's drift direction drawn at random (default);
                                   +1 / -1 = always along / against the carrier's modulation axis */
    int trials;                 /* budget of main trials (0 = default: 120; with velocities 5 per
                                   cell the display can show); with precision_log10 the cap
                                   (0 = default: 40 per cell shown) */
    double precision_log10;     /* > 0: stop once the table's predicted RMS error over its visible
                                   cells (from the method's own per-cell errors) is at or below this
                                   (log10 units); 0 = a fixed budget */
    int practice;               /* practice trials (default 3; -1 = default) */
    int break_every;            /* trials between breaks (default 40) */
    uint64_t seed;
    int headless;
    int64_t resume_id;          /* 0 = new session */
    int render_every;           /* presenter render_every for simulated sessions (0 = default: 1,
                                   -1 with --observer sim:view=frame) */
    int render_w, render_h;     /* headless render size for simulated sessions (default 64 x 36) */
    int quiet;                  /* no progress on stderr */
    int afc;                    /* forced-choice layout for 2AFC-task methods (bayes, 2afc): 4 =
                                   four places shown at once where they fit, 2 = two intervals
                                   everywhere; 0 = not given (4). Stored with the session; fade
                                   sessions store 2, their anchors' layout. */
    double fade_anchor_share;   /* --fade-anchors: share of a fade session's trials that are
                                   forced-choice anchors; 0 = default (0.25), negative = none.
                                   Stored with the session. */
    int demo;                   /* --demo: practice trials with feedback to show a participant the
                                   task; nothing is stored or written (out_path not needed) */
    int allow_profile_change;   /* --resume with a display profile other than the session's: refused
                                   unless set; then the change is recorded in the session (a
                                   "profile_change" artifact) and the table names every profile */
    /* Tests only (no command-line option): faults injected into a simulated session's presenter
     * (stimuli/presenter.h fault_polar_offset_deg / fault_blank): gratings drawn at the wrong
     * place, or not drawn at all, while the plan and the reported contrast stay the same. */
    double fault_polar_offset_deg;
    int fault_blank;
    /* Tests only: with --observer sim:view=frame, called after each forced-choice trial with the
     * contrasts the person saw and those the presenter reported, per place or interval (n = 2 or
     * 4; reported = 0 where nothing was planned), to compare what reaches the person with the plan. */
    void (*seen_hook)(void *ctx, int n, const double *seen, const double *reported);
    void *seen_hook_ctx;
} csf_obs_options;

typedef struct {
    int64_t session_id;
    char method[16];
    int n_trials, n_valid, n_catch, n_false_alarms, n_invalid_click, n_anticipations, n_lapses,
        n_missed_frame_trials, n_practice;
    double fa_rate;             /* presses on catch trials / catch trials (NaN without catch trials) */
    double latency_s;           /* reaction time measured on practice trials (NaN if none) */
    int n_cells, n_visible, n_invisible;
    int afc;                    /* the session's --afc (2 or 4) */
    int n_cells_four_place;     /* cells measured with four places (the rest: two intervals) */
    int n_four_place;           /* main trials shown with four places */
    double median_se_log10;
    int n_fade_anchors;         /* fade: forced-choice anchor trials run */
    double fade_offset_log10, fade_offset_sd_log10; /* fade: the person's yes/no - forced-choice
                                   threshold offset the anchors measured (NaN: no anchors planned) */
    int finished_early;         /* the procedure ran out of unstable cells before the budget */
    int reached_precision;      /* stopped because the predicted error reached --precision */
    double precision_log10;     /* the --precision asked for (0: a fixed budget) */
    double predicted_rms_log10; /* the table's predicted RMS error over its visible cells shown:
                                   the root mean square of the method's stated errors (NaN: none) */
    int table_written;
    int n_stored;               /* trials in the store for this session, practice included */
    int resumable;              /* failed after the session began: it was left paused (every
                                   stored trial kept) and --resume finishes it */
    int n_vels;                 /* velocities measured (0: static gratings, a 2-D table) */
    int n_not_shown;            /* cells whose drift would alias on this display: predicted (bayes),
                                   never presented */
    double expected_person_s;   /* the person's time this run was expected to take, said before the
                                   first trial (practice, trials, answers) */
    double expected_person_lo_s, expected_person_hi_s; /* with --precision, the range 8 in 10 people's
                                   time falls in (the method's time_spread); NaN when unknown */
    double person_s; /* the person's time this run took: the session's clock from the
                                   first trial to the last (the simulated clock in simulation,
                                   simulated answer times included) */
    double wall_s;
    char summary[600];          /* the one-line summary */
} csf_obs_result;

void csf_obs_options_defaults(csf_obs_options *o);

/* Runs (or resumes) a session: opens its resources (calib/observer_resources.c: the store, the
 * display profile, the presenter, the simulated person or a human's responder) and lends them to
 * the session's steps (calib/observer_session.h), which open nothing themselves. Every option, the output paths, the grid on this screen (reach and
 * local Nyquist limit) and, on resume, the stored settings and the display profile are checked
 * before the first trial; a refused new session writes nothing (CSF_E_INVALID_ARG).
 * CSF_E_INSUFFICIENT: the data cannot support a table (the message
 * says why: unreliable observer, cells without data ...) and nothing was written.
 * CSF_E_ABORTED: paused by Escape or a signal; the message names the --resume ID. */
csf_status csf_observer_calibrate(const csf_obs_options *opt, csf_obs_result *res, csf_error *err);

/* Writes res as one JSON object (no trailing newline) into buf. */
void csf_obs_result_json(const csf_obs_result *res, const char *out_path, const char *plot_path,
                         char *buf, unsigned long len);

#endif
