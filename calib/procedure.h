/* Adaptive psychophysical procedures behind one interface (fade-in, 2AFC, joint Bayesian).
 * A procedure sees only what an experimenter would: the stimuli it chose and the responses.
 * Determinism contract: next() depends only on the procedure's state and the trial index (random
 * choices come from core/rng.h keyed by setup->seed and the trial index), so replaying the
 * stored trials through update() rebuilds exactly the state an uninterrupted run had — that is
 * how sessions resume. */
#ifndef CSF_PROCEDURE_H
#define CSF_PROCEDURE_H

#include <stdint.h>

#include "core/csf_status.h"

/* One place of the grid: a carrier of freq_cpd at ecc_deg drifting at velocity_dps (deg/s on the
 * retina, which with the person fixating the mark is the speed on the screen; 0 = static). Its
 * temporal frequency is velocity_dps * freq_cpd. */
typedef struct {
    double freq_cpd, ecc_deg, velocity_dps;
} csf_cell;

typedef enum {
    CSF_TASK_FADE = 0,  /* yes/no detection of a grating fading in: response = pressed, rt along the ramp */
    CSF_TASK_2AFC = 1,  /* forced choice: two intervals (response 0/1) or, per cell, four locations
                           (response 0-3; csf_trial_plan.n_alternatives says which) */
} csf_task;

typedef struct {
    const csf_cell *cells;  /* the grid to measure */
    int n_cells;
    int trial_budget;       /* planned number of trials (procedures may stop earlier) */
    uint64_t seed;
    double max_contrast;    /* highest Michelson contrast the display can show at the mean luminance */
    double min_contrast;    /* lowest meaningful contrast (luminance resolution limit) */
    /* Psychometric assumptions (Weibull in log10 contrast, model/psychometric.h). */
    double slope_beta;      /* default 3.5 */
    double lapse;           /* default 0.02 */
    /* bayes only: 0 (default) = the person's slope and lapse are unknown: they are marginalised
     * (slope 1.5-6, lapse 0-0.08; docs/bayes-method.md) and slope_beta / lapse above are only
     * validated; 1 = assume slope_beta and lapse exactly. */
    int fixed_psychometric;
    double guess;           /* 0.5 for 2AFC; false-alarm rate for detection */
    /* fade-in ramp: log10 contrast rises linearly from start to end over ramp_s */
    double ramp_start_log10, ramp_end_log10, ramp_s;
    /* Added by the observer area (additive): the observer's simple reaction time, measured by the
     * session on suprathreshold practice trials (median press latency). The fade method moves the
     * press back along the ramp by this much to find the contrast at detection. 0 = unknown: the
     * fade method then assumes 0.35 s. Other methods may ignore it. */
    double reaction_latency_s;
    /* fade only: 1 = correct every press by reaction_latency_s alone (the behaviour before issue
     * 12 item 3; tests compare with it); 0 (default) = the method also measures the latency near
     * threshold with probe trials (calib/method_fade.c), since reaction times slow down there. */
    int fade_fixed_latency;
    /* fade only: the share of the budget spent on two-interval forced-choice anchor trials at the
     * end of the session, which measure the person's offset between their yes/no (fade) threshold
     * and the forced-choice one (it depends on their criterion; calib/method_fade.c). 0 = the
     * default share, negative = none (a pure yes/no session, the behaviour before the anchors),
     * at most CSF_FADE_ANCHOR_SHARE_MAX. */
    double fade_anchor_share;
#define CSF_FADE_ANCHOR_SHARE_DEFAULT 0.25
#define CSF_FADE_ANCHOR_SHARE_MAX 0.5
    /* Forced-choice layout per cell (CSF_TASK_2AFC methods): n_alternatives[c] = 2 for two
     * temporal intervals, 4 for four locations on the cell's eccentricity ring shown at once
     * (spatial 4AFC, guess rate 1/4). NULL = 2 everywhere. The session decides (a foveal cell or
     * one whose four locations do not fit apart on the screen stays two-interval); see
     * csf_afc_layout in calib/afc_layout.h. Methods that cannot use 4 treat every cell as 2. */
    const int *n_alternatives;
    /* Cells the display cannot show (a drifting carrier whose temporal frequency would alias at
     * this refresh rate): 1 = never presented. NULL = every cell can be shown. The joint method
     * writes its prediction there; the per-cell methods, which have nothing to predict from,
     * refuse such a setup. */
    const unsigned char *not_shown;
    /* The trials the session expects to run when trial_budget is only a cap (a precision stop):
     * csf_precision_planned_trials. 0 = trial_budget. A method that plans a block for the end of
     * the session (fade's anchors) plans it for this many, so the stop can come once they ran. */
    int planned_trials;
    /* The person's expected seconds for one trial at each cell (a two-interval trial takes longer
     * than four places shown at once). NULL = alike. A method that stops on precision may weigh
     * what a trial teaches by what it costs (bayes does, under a precision stop). */
    const double *trial_s;
} csf_procedure_setup;

/* Fastest drift a cell may ask for (deg/s): beyond it the eye cannot fixate a stationary mark
 * while such motion is shown, and no display shows it without aliasing at a useful frequency. */
#define CSF_PROC_MAX_VELOCITY_DPS 200.0

typedef struct {
    int cell;               /* index into cells */
    csf_task task;
    double contrast;        /* 2AFC: the contrast shown; fade: the ramp's final (max) contrast */
    double ramp_start_log10, ramp_s; /* fade only: ramp from 10^start to contrast over ramp_s */
    int is_catch;           /* fade: no grating is shown */
    int signal_interval;    /* 2AFC: the interval (0, 1) or location (0 .. n_alternatives-1) with the grating */
    int n_alternatives;     /* 2AFC: 2 (two intervals) or 4 (four locations); the setup's choice for the cell */
    double polar_deg;       /* where on the eccentricity ring */
} csf_trial_plan;

typedef struct {
    int response;           /* fade: 1 pressed, 0 not; 2AFC: interval chosen (0/1) */
    double rt_s;            /* fade: time from ramp start to the press */
    double contrast_at_response; /* fade: contrast on screen at the press, corrected by the caller
                                    for the presenter's actual frames (NaN if no press); when the
                                    press comes after the ramp ended, the last contrast shown.
                                    2AFC (observer area's addition): mean contrast actually shown in
                                    the signal interval; NaN or 0 = as planned */
    int valid;              /* 0 when the trial is invalid (click too far, frame drops, ...) */
} csf_trial_outcome;

typedef struct {
    double threshold;       /* Michelson at the criterion; INFINITY = not visible at any contrast */
    double stderr_log10;    /* NaN when unknown */
    int n_trials;
} csf_cell_estimate;

typedef struct csf_procedure csf_procedure;

typedef struct {
    const char *name;       /* "fade", "2afc", "bayes" */
    csf_task task;
    csf_status (*create)(const csf_procedure_setup *setup, void **state, csf_error *err);
    /* Plans trial number trial_index (0-based). Returns CSF_OK, or CSF_E_ABORTED when the
     * procedure has finished early (all cells stable). */
    csf_status (*next)(void *state, int trial_index, csf_trial_plan *plan);
    void (*update)(void *state, int trial_index, const csf_trial_plan *plan, const csf_trial_outcome *outcome);
    /* Fills out[n_cells] from the current state. */
    csf_status (*estimate)(void *state, csf_cell_estimate *out, csf_error *err);
    void (*destroy)(void *state);
    /* Optional (NULL: none). The fade method's forced-choice anchors: how many were run and the
     * person's measured offset yes/no threshold - forced-choice threshold (log10, posterior mean
     * and sd). Returns 1 when there is an offset to report, 0 otherwise. */
    int (*task_offset)(void *state, int *n_anchors, double *offset_log10, double *sd_log10);
    /* The RMS error (log10) the method states at one trial a cell, if it falls as 1/sqrt(trials):
     * what a precision stop plans on. The median of simulated and held-out sessions stopped at
     * 0.10; people differ by about 1.5x in trials. */
    double reach_log10;
    /* The person's time over what a precision stop plans, its 10th and 90th percentiles over
     * simulated people (slope 1.5-6, lapse 0-0.08; bench/bench_person_time.sh at 0.10 log10):
     * people differ mostly in how steep their psychometric function is, which nothing before the
     * first trial shows. 0: not measured. */
    double time_spread_lo, time_spread_hi;
} csf_procedure_ops;

/* The trials a session of method ops should take to bring its predicted RMS error over n_shown
 * cells to precision_log10 (within cap): n_shown (ops->reach_log10 / precision)^2. */
int csf_precision_planned_trials(const csf_procedure_ops *ops, int n_shown, double precision_log10, int cap);
/* The RMS error method ops is expected to state after `trials` over n_shown cells. */
double csf_precision_expected_rms(const csf_procedure_ops *ops, int n_shown, int trials);

/* Registry (calib/procedure.c): returns NULL for an unknown name, and for "bayes" while that
 * method is not linked into this build (the session then says so and suggests fade or 2afc). */
const csf_procedure_ops *csf_procedure_find(const char *name);

extern const csf_procedure_ops csf_procedure_fade;
extern const csf_procedure_ops csf_procedure_2afc;
extern const csf_procedure_ops csf_procedure_bayes;

#endif
