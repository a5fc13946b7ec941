/* Simulated observer: a person as a model, standing in for the human in tests, benchmarks and
 * `--observer sim[:key=value,...]` sessions.
 *
 * Truth. Threshold contrast per (freq_cpd, ecc_deg) from the log-parabola x stelaCSF surface of
 * model/csf_model.h (keys smax, fmax, beta [bandwidth, octaves], delta, ecc_a, ecc_b,
 * field=nasal) or from a CSV table (table=FILE.csv, columns freq_cpd,ecc_deg,threshold; see
 * csf_obs_table_parse). A threshold >= 1 means never visible. A grating drifting at velocity v
 * has threshold(f, e, v) = threshold(f, e) / 10^csf_velocity_log10_gain(f, v) (Kelly 1979, Daly
 * 1998; keys vc1, vc2, vsteep, vmin), or a 3-D table's own value (a velocity_dps column).
 *
 * Psychometric function: Weibull in log10 contrast (model/psychometric.h) with slope `slope`
 * (default 3.5) and lapse `lapse` (default 0.02). 2AFC guess rate `guess` (default 0.5).
 *
 * Fade-in trials (Luebke & Hallen 2001, sec. 6.1). Per trial the simulated person
 *   - attends with probability 1 - lapse (a lapse: the stimulus is never detected);
 *   - while attending, detects at a frame with the hazard of csf_psy_fade_hazard on the running
 *     maximum of the log contrast the presenter REPORTS as shown (csf_frame_info.contrast_shown),
 *     so P(detected by the frame) = F(highest contrast shown so far): a missed frame repeats the
 *     previous contrast and adds nothing; a dropped contrast adds nothing;
 *   - presses a reaction time after detection: ex-Gaussian (rt_mu 0.30 s, rt_sigma 0.04 s,
 *     rt_tau 0.10 s; rt_mean=M rescales mu so the mean is M);
 *   - presses spontaneously (false alarm) with probability `fa` per trial at a uniform time over
 *     the presentation, and anticipates (presses 0.02-0.12 s after onset) with probability
 *     `anticip`; both happen whether or not anything is shown, catch trials expose them;
 *   - then clicks where the grating was: true position plus Gaussian error, sd click_sd +
 *     click_sd_ecc * ecc (deg; defaults 0.4 and 0.08); after a false alarm it clicks at a random
 *     place within click_range (default 20 deg) of fixation.
 * 2AFC trials: P(correct) = Weibull(guess, lapse) at log10 of the mean contrast shown in the
 * signal interval (minus the other interval's, if any), response time log-normal around 0.6 s.
 * m-alternative trials (csf_observer_sim_afc, e.g. four places shown at once): P(correct) =
 * 1/m + (1 - 1/m - lapse)(1 - exp(-10^(slope (x - t)))), x = log10 of the contrast shown at the
 * signal place (minus the highest elsewhere), a wrong answer uniformly one of the other places,
 * response time log-normal around 0.7 s.
 *
 * Decision models and session effects (docs/observer-calibration.md, all off by default, so the
 * default observer is the one described above): decision=sdt (signal detection, devices/
 * observer_sdt.h: m-AFC by the largest of m noisy internal responses, yes/no fade by looks
 * against a criterion), slope/lapse/k drawn from the seed, fatigue (threshold rising with the
 * trial index), criterion drift (a seeded random walk over trials, yes/no only), runs of
 * attention lapses, and Pieron reaction times in the fade task.
 *
 * Every random draw comes from core/rng.h keyed by (seed, stream, trial index * 4096 + frame),
 * so a trial replays identically after a kill and resume. The model reads only what a person
 * would see (what is on screen, when); never the procedure's plan, catch flag or estimates. */
#ifndef CSF_OBSERVER_SIM_H
#define CSF_OBSERVER_SIM_H

#include <stddef.h>
#include <stdint.h>

#include "model/csf_model.h"
#include "model/csf_velocity.h"
#include "core/csf_status.h"

/* ---- threshold tables (table=FILE.csv) ----------------------------------------------------- */

/* A full grid of thresholds: n_freq x n_ecc (2-D) or n_freq x n_ecc x n_vel (3-D), rows in any
 * order in the file. */
typedef struct {
    int n_freq, n_ecc;
    int n_vel;                   /* 0: a 2-D table (no velocity_dps column) */
    double *freq_cpd, *ecc_deg;  /* ascending */
    double *velocity_dps;        /* ascending, n_vel entries (one entry, 0, for a 2-D table) */
    double *log10_threshold;     /* [(vel * n_ecc + ecc) * n_freq + freq]; thresholds >= 1 stored as 1 */
} csf_obs_table;

/* Parses CSV text: '#' comments, blank lines, an optional header line naming the columns (any
 * order; each once): freq_cpd, ecc_deg, threshold and optionally velocity_dps. Without a header
 * the columns are freq_cpd,ecc_deg,threshold; a table with velocity_dps needs the header. Each
 * data row one number per column; freq in (0, 1000] cpd, ecc in [0, 180] deg, velocity in
 * [0, 1000] deg/s (the drift's direction does not matter, so no negative speeds), threshold > 0
 * (or "inf"); at most 64 distinct values per axis; every (freq, ecc[, velocity]) combination
 * exactly once. Errors name the line and the broken limit. */
csf_status csf_obs_table_parse(const char *text, size_t len, csf_obs_table **out, csf_error *err);
csf_status csf_obs_table_load(const char *path, csf_obs_table **out, csf_error *err);
void csf_obs_table_free(csf_obs_table *t);
/* Bilinear in (log10 f, ecc) on log10 threshold, held constant outside the grid; along velocity
 * (3-D tables) linear in csf_velocity_warp(|v|), held constant outside the velocity axis. A 2-D
 * table ignores velocity_dps here (the simulated person applies the parametric velocity gain to
 * it: csf_observer_sim_threshold_v). Returns INFINITY when the interpolated threshold is >= 1
 * (never visible); NAN for a NaN argument, freq_cpd <= 0 or ecc_deg < 0. The sign of
 * velocity_dps (the drift's direction) does not matter. */
double csf_obs_table_threshold_v(const csf_obs_table *t, double freq_cpd, double ecc_deg,
                                 double velocity_dps);
/* The same at velocity 0. */
double csf_obs_table_threshold(const csf_obs_table *t, double freq_cpd, double ecc_deg);

/* ---- the simulated person ------------------------------------------------------------------- */

/* Decision models (key decision=weibull|sdt). */
typedef enum { CSF_SIM_WEIBULL = 0, CSF_SIM_SDT = 1 } csf_sim_decision;

typedef struct {
    csf_model_params model;
    double slope, lapse, guess_2afc, fa, anticip;
    double rt_mu_s, rt_sigma_s, rt_tau_s;
    double click_sd_deg, click_sd_ecc, click_range_deg;
    /* Decision model; sdt: transducer exponent k, yes/no criterion (d' units) and look time. */
    csf_sim_decision decision;
    double k_transducer, criterion_dprime, look_s;
    /* Over a session (all 0 = off, the default): threshold rise per 100 trials (log10), sd per
     * trial of the yes/no criterion's random walk (log10 contrast), probability per trial that
     * a run of attention lapses starts, and the longest run (trials). */
    double fatigue_log10_per_100, drift_log10, lapse_run_rate, lapse_run_max;
    /* Pieron reaction time in the fade task: extra pieron_k_s * (c / t)^-pieron_beta s. */
    double pieron_k_s, pieron_beta;
    /* 1 where the value was drawn from the seed (slope=draw, lapse=draw, k=draw, vsteep=draw). */
    int slope_drawn, lapse_drawn, k_drawn;
    /* Sensitivity to motion (model/csf_velocity.h): keys vc1 (c1, 0.2-2), vc2 (c2, 0.5-5),
     * vsteep (steepness, 0-3; draw: uniform over 0.5-1.5 from the seed) and vmin (fixational
     * drift floor, 0.05-0.5 deg/s); default Kelly (1979) as scaled by Daly (1998). */
    csf_velocity_params velocity;
    int vsteep_drawn;
    /* What the answers are based on (docs/observer-calibration.md, "The person looks at the
     * screen"): view=plan (0, the default) takes the contrast the presenter reports; view=frame
     * (1) makes a session read the rendered frame back at the places the person could look at,
     * turn it into light through the simulated display `display` and measure the Gabor's
     * contrast there (model/observer_view.h); the decision models then get those contrasts.
     * display: "crt", "lcd", "oled", "profile" (the profile in use is the truth), "file=PATH.csv"
     * (model/display_model.h), or "" = the display the session's profile was measured on.
     * display_gamma: replaces a crt/lcd/oled model's gamma (0 = its own). frame_step: the person
     * samples every frame_step-th frame of an interval (1 = every frame). Only sessions (calib/)
     * honour view=frame: the trial functions below always take the contrasts they are given. */
    int view_frame;
    char display[256];
    double display_gamma;
    double frame_step;
} csf_observer_sim_params;

/* Trial indices from this value up are practice trials (the session's keys): for fatigue,
 * criterion drift and lapse runs they count as the session's first trial. */
#define CSF_SIM_PRACTICE_INDEX 1000000u

typedef struct csf_observer_sim csf_observer_sim;

/* spec: "sim" or "sim:key=value,..." (keys above plus table=FILE.csv). Unknown keys and values
 * out of range are refused naming the key and its range. */
csf_status csf_observer_sim_create(const char *spec, uint64_t seed, csf_observer_sim **out,
                                   csf_error *err);
void csf_observer_sim_free(csf_observer_sim *o);
const csf_observer_sim_params *csf_observer_sim_params_get(const csf_observer_sim *o);
/* Short description for metadata, e.g. "sim(smax=250,fmax=3,...)" or "sim(table=x.csv)". */
const char *csf_observer_sim_describe(const csf_observer_sim *o);

/* The TRUE threshold (Michelson; INFINITY = never visible). For tests and benchmarks only: a
 * session never calls it. */
double csf_observer_sim_threshold(const csf_observer_sim *o, double freq_cpd, double ecc_deg);
/* The same for a grating drifting at velocity_dps (retinal, either direction): a 3-D table's
 * own value, otherwise the static threshold divided by 10^csf_velocity_log10_gain with the
 * person's `velocity` parameters (a 2-D table too: its rows are static gratings). Velocity 0 is
 * exactly csf_observer_sim_threshold. */
double csf_observer_sim_threshold_v(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                    double velocity_dps);
/* log10 of the person's sensitivity at velocity_dps over their static sensitivity there (0 at
 * v = 0; what model/observer_view's motion energy weighs temporal components by). 0 where the
 * grating is never visible static and moving alike. */
double csf_observer_sim_velocity_log10_gain(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                            double velocity_dps);
/* The same at a trial: raised by fatigue (fatigue * n / 100 log10 at session trial n). */
double csf_observer_sim_trial_threshold(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                        uint64_t trial_index);
double csf_observer_sim_trial_threshold_v(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                          double velocity_dps, uint64_t trial_index);
/* The yes/no criterion's offset at a trial (log10 contrast; 0 without drift): a Gaussian random
 * walk with sd `drift` per trial, a pure function of (seed, n). */
double csf_observer_sim_drift_log10(const csf_observer_sim *o, uint64_t trial_index);
/* 1 when the trial falls in a run of attention lapses (the person guesses / does not look). */
int csf_observer_sim_in_lapse_run(const csf_observer_sim *o, uint64_t trial_index);

/* One fade-in trial, driven frame by frame. */
typedef struct {
    uint64_t trial;
    double freq_cpd, ecc_deg, polar_deg; /* where the grating is drawn (if anything is drawn) */
    double velocity_dps;                 /* how fast it drifts (0 = static) */
    double t_log10;          /* latent threshold there, fatigue and drift included (private) */
    double t_sens_log10;     /* the trial's sensitivity threshold (fatigue, no drift) */
    double criterion_dprime; /* sdt: this trial's yes/no criterion (drift included) */
    int last_look;           /* sdt: the last look taken (-1 none) */
    double onset_s;
    int attending;
    double t_spont_s;        /* spontaneous press time (false alarm / anticipation), INFINITY none */
    double x_max;            /* running max of log10 contrast shown */
    int frame;
    int detected;
    double t_detect_s, t_press_s;
    int press_spontaneous;   /* the press came from a false alarm / anticipation */
} csf_sim_fade_trial;

/* Starts a fade trial at time onset_s lasting (at most) duration_s. */
void csf_observer_sim_fade_begin(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                                 double ecc_deg, double polar_deg, double onset_s,
                                 double duration_s, csf_sim_fade_trial *tr);
/* The same for a grating drifting at velocity_dps (the threshold of csf_observer_sim_trial_threshold_v;
 * the draws are those of csf_observer_sim_fade_begin, which is this at velocity 0). */
void csf_observer_sim_fade_begin_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                                   double ecc_deg, double velocity_dps, double polar_deg, double onset_s,
                                   double duration_s, csf_sim_fade_trial *tr);
/* After each frame presented at t_s with the reported contrast_shown: returns 1 once the button
 * has been pressed at or before t_s, with the press time in *press_t_s. */
int csf_observer_sim_fade_frame(const csf_observer_sim *o, csf_sim_fade_trial *tr, double t_s,
                                double contrast_shown, double *press_t_s);
/* The click after a press, in visual-angle coordinates x = ecc cos(polar), y = ecc sin(polar). */
void csf_observer_sim_click(const csf_observer_sim *o, const csf_sim_fade_trial *tr,
                            double *x_deg, double *y_deg);

/* One 2AFC trial: contrast_shown[i] = mean Michelson contrast shown in interval i. Returns the
 * chosen interval (0 or 1); *rt_s the response time after the second interval. */
int csf_observer_sim_2afc(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                          double ecc_deg, const double contrast_shown[2], double *rt_s);
/* The same for a grating drifting at velocity_dps (csf_observer_sim_2afc is this at 0; same draws). */
int csf_observer_sim_2afc_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd, double ecc_deg,
                            double velocity_dps, const double contrast_shown[2], double *rt_s);

/* One m-alternative forced-choice trial (2 <= m <= CSF_SIM_AFC_MAX; four places shown at once
 * for spatial 4AFC): contrast_shown[k] = mean Michelson contrast shown at place (or interval) k,
 * k < n_alternatives. Returns the chosen place 0 .. m-1; *rt_s the response time. Guess rate 1/m
 * (the `guess` key applies to csf_observer_sim_2afc only). Draws have their own streams keyed by
 * (seed, trial_index), so csf_observer_sim_2afc's answers are unchanged by its existence. */
#define CSF_SIM_AFC_MAX 16
int csf_observer_sim_afc(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                         double ecc_deg, const double *contrast_shown, int n_alternatives,
                         double *rt_s);
/* The same for a grating drifting at velocity_dps (csf_observer_sim_afc is this at 0; same draws). */
int csf_observer_sim_afc_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd, double ecc_deg,
                           double velocity_dps, const double *contrast_shown, int n_alternatives,
                           double *rt_s);

#endif
