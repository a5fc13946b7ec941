/* The observer procedure's trials as the person sees them: fade ramps, two-interval and
 * four-place forced-choice trials on the presenter, and the stored record of each. Internal to
 * the observer procedure. */
#ifndef CSF_OBSERVER_TRIALS_H
#define CSF_OBSERVER_TRIALS_H

#include <stdint.h>

#include "calib/afc_layout.h"
#include "calib/observer_person.h"
#include "calib/procedure.h"
#include "results/store/store.h"

#define GABOR_SIGMA_DEG 1.0   /* the CSF parameters are for Gabors of sigma ~1 deg (model/csf_model.h) */
#define FIXATION_S 0.3        /* fixation before each trial */
#define RESPONSE_WINDOW_S 1.0 /* presses still accepted after the ramp ends */
#define ANTICIPATION_S 0.15   /* presses sooner than this after onset are anticipations */
#define AFC_INTERVAL_S 0.5
#define AFC_ISI_S 0.5
#define PRACTICE_CONTRAST 0.3
#define PRACTICE_FREQ 2.0
#define PRACTICE_S 2.0
/* Place cues (placeholders) before a forced-choice trial: rings around the places where the
 * grating can appear (the four places, or the one place of both intervals), so that the person
 * knows where to attend; spatial uncertainty would raise a human's threshold above the detection
 * threshold the table must hold. The rings are on for the first CUE_S of the fixation period and
 * are removed CUE_GAP_S before the grating appears, so that they cannot mask it and their offset
 * is over by its onset (cue onset to grating onset = FIXATION_S, a usual pre-cue lead); the
 * fixation period keeps its length, so the trials' frame counts and timing are unchanged. Their
 * radius is the patch radius (3 sigma, CSF_AFC_PATCH_RADIUS_SIGMAS), outside the visible Gabor;
 * the four places are at least two patch radii apart, so their rings do not overlap. Not used by
 * the fade method, whose grating appears at an unknown place on purpose. */
#define CUE_S 0.2
#define CUE_GAP_S (FIXATION_S - CUE_S)
#define CUE_RADIUS_DEG (CSF_AFC_PATCH_RADIUS_SIGMAS * GABOR_SIGMA_DEG)

/* Seconds of the person's time one main trial of task takes (four: four places at once), as a
 * session plans it: fixation, the stimulus, a typical answer. */
double obs_trial_expected_s(csf_task task, int four);

typedef struct {
    csf_presenter *pres;
    person *who;
    double mean_lum;
    double period_s;
    int drift_sign; /* this trial's drift direction (+1 / -1) for cells that drift */
} runner;

typedef struct {
    int response;
    double rt_s, contrast_at_response, click_x, click_y;
    int valid;
    char flags[64];
    csf_trial_record rec;
    int have_rec;
    double shown_mean, shown_max;
    int frames_planned, frames_shown, frames_missed;
    double velocity_dps; /* the carrier's drift as shown, signed by its direction (0: static) */
} trial_result;

void obs_make_stimulus(csf_stimulus *s, double freq, double ecc, double polar, double contrast,
                       double mean_lum);
/* 1 when a Gabor of freq at ecc fits on screen, below the Nyquist limit there, at some whole-degree
 * polar angle (the first one into *polar if not NULL); else 0, with the presenter's reason for
 * polar angle 0 in *why (if not NULL). */
int obs_cell_fits(csf_presenter *pres, double freq, double ecc, double mean_lum, double *polar,
                  csf_error *why);
/* A polar angle on the cell's eccentricity ring where the whole patch fits on screen: the plan's
 * own if it fits, else the nearest of 24 rotations that does (deterministic, so resume agrees). */
int obs_fit_polar(csf_presenter *pres, double freq, double ecc, double polar, double mean_lum, double *out);
/* One fade trial: fixation, ramp (or blank frames for a catch trial), response window, click. */
csf_status obs_run_fade(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        double polar, int is_practice, trial_result *tr, csf_error *err);
/* One 2AFC trial: place cue, two intervals, the grating in one of them; the person picks one. */
csf_status obs_run_2afc(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        double polar, trial_result *tr, csf_error *err);
/* One four-place trial (spatial 4AFC): fixation with the four places cued, then one interval as
 * long as a 2AFC interval with the grating at place plan->signal_interval of the layout (the
 * plan's polar_deg is not used), then the answer: a click (the nearest place) or a place key. */
csf_status obs_run_4afc(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        const csf_afc_layout *lay, trial_result *tr, csf_error *err);
/* How many alternatives a planned trial has: 2 or 4 for forced choice, 0 for fade. */
int obs_plan_alternatives(const csf_trial_plan *plan);
void obs_fill_trial(csf_trial *t, int64_t sid, int seq, const char *method, const csf_cell *c, double polar,
                    double mean_lum, const csf_trial_plan *plan, int practice, const trial_result *tr);
/* The outcome update() saw, rebuilt from a stored trial (the resume path and the live path use
 * this same function, so they cannot disagree). */
csf_trial_outcome obs_outcome_of(const csf_trial *t, csf_task task);

#endif
