/* Photometric calibration of a monitor: warm-up check, dark, adaptive grey and per-channel sweeps
 * with drift tracking, monotonicity and additivity checks. Every reading goes to the store the
 * moment it is taken; a session stopped by an instrument fault resumes from its stored readings.
 *
 * Determinism: each decision (next level, stop, repeat) depends only on the readings taken so
 * far, so a resumed session replays its stored readings through the same code and reaches the
 * same state an uninterrupted run had, then continues live. */
#ifndef CSF_DISPLAY_CALIB_H
#define CSF_DISPLAY_CALIB_H

#include <stdint.h>

#include "devices/photometer.h"
#include "core/csf_status.h"
#include "results/display_profile.h"
#include "results/store/store.h"

#define CSF_DISPLAY_MAX_CHECKS 64

typedef struct {
    double target_rel;     /* accuracy target: max relative luminance error above 10 % of peak (0.0025) */
    int budget;            /* most sweep readings, grey plus channels (48) */
    int checks;            /* spot checks per curve between the sweep's levels, never fitted (4; 0
                              to CSF_DISPLAY_MAX_CHECKS): what the levels cannot show, finer
                              structure or a corner inside an interval, enters the statement */
    int channels;          /* 1: also measure r, g, b curves (default) */
    double warmup_wait_s;  /* time between warm-up readings (5 s) */
    int warmup_max;        /* most warm-up readings (40) */
    int progress;          /* 1: progress bar on stderr */
    const char *display_name; /* for the profile id; NULL = photometer spec */
    /* Draws the patch on the screen before each reading (csf_presenter_draw_patch); NULL:
     * nothing is drawn, which only a simulated instrument can work with. The photometer is told
     * the patch (csf_photometer_show_patch) just before the hook runs, so the hook may replace
     * that built-in uniform source with the rendered frame (csf_photometer_set_source: what
     * `csfcal display calibrate --render` does for the simulator). reading_index is the
     * instrument's reading number (what the simulator's noise is drawn with; a failed attempt
     * that stopped the session is retried under the same number after --resume): a hook that
     * makes its frames a function of it (the dither's frame number) shows a resumed session
     * exactly what the uninterrupted one showed. Returns 0, or non-zero to abort. */
    int (*show_patch)(void *user, const double rgb01[3], uint64_t reading_index);
    void *show_patch_user;
    int drive_levels;      /* highest framebuffer code: levels are multiples of 1/drive_levels
                              (255 for 8 bit, 1023 for 10 bit); 0 = continuous (default: csfcal
                              dithers patches, so fractional drive values are shown) */
    double max_lum_cdm2;   /* a reading above it is refused as absurd (0 = 10000 cd/m2, the top of
                              SMPTE ST 2084; see calib/meter_check.h) */
} csf_display_calib_opts;

void csf_display_calib_defaults(csf_display_calib_opts *o);

typedef struct {
    int n_readings;        /* every reading taken or replayed (warm-up, dark, references, sweeps) */
    int n_sweep;           /* grey and channel sweep readings (the figure the target is stated for) */
    int n_check;           /* spot checks (not part of the profile) */
    int n_warmup;
    /* 1: the display was judged warm (calib/warmup_model.h); 0: gave up after warmup_max */
    int warmup_stable;
    /* the settling model's predicted white change over an hour's session after the warm-up (0: no
     * drift seen) */
    double warmup_remaining_rel;
    /* the model's expected further wait when the warm-up gave up (0 when warm; INFINITY: the
     * model puts white at or below zero) */
    double warmup_wait_s;
    double noise_rel;      /* instrument noise estimated from white references */
    double drift_rel;      /* white change from first to last reference */
    double est_error_rel[CSF_CH_COUNT];   /* stated max relative error above 10 % of each curve's
                                           peak: the knots' noise (median of the worst knot error,
                                           from the measured repeatability) and the model's error
                                           (leave-one-out at the gaps' scale), in quadrature; inf
                                           when the levels are too few to say
                                           (docs/display-profile.md) */
    double met_error_rel[CSF_CH_COUNT];   /* the same with the worst knot's noise at its 90th
                                           percentile: what the stopping rule and target_met use
                                           (met: every curve's at or below the target) */
    double check_error_rel[CSF_CH_COUNT]; /* the systematic error the spot checks show, scaled to a
                                             maximum over the range; NAN without checks. The stated
                                             error takes it where it exceeds the model's part */
    double additivity_error; /* (black + sum of channel increments) / white - 1; NAN if not measured */
    int monotonic_violations; /* neighbour pairs that fall by more than 3 sd of noise */
    char monotonic_msg[256];
    int channel_via_grey[3]; /* 1: channel c modelled through the grey curve (ratio fit within
                                noise); 0: its own curve through its readings */
    int n_profile;           /* readings the profile is built from: sweeps + dark + white references
                              (n_readings less warm-up, spot checks and readings set aside) */
    int target_met;          /* 1: every curve's stated error is at or below target_rel; 0: the budget
                              ended first, or the spot checks raised a statement the sweep had met
                              (said on stderr by the CLI, in --json, in the profile) */
    int checks_raised;       /* 1: the target is missed only because of what the spot checks show
                              (structure finer than the levels: more sweep readings do not help) */
} csf_display_calib_result;

/* Runs (or resumes, when session_id > 0 and the store holds its readings) a calibration.
 * store may be NULL (nothing is recorded; no resume). When store is given and *session_id is 0,
 * a new session is begun and its id returned in *session_id. On an instrument fault the readings
 * taken so far are kept, the session is marked "paused" and the fault's error is returned. */
csf_status csf_display_calibrate(csf_photometer *ph, const csf_display_calib_opts *opts,
                                 csf_store *store, int64_t *session_id, uint64_t seed,
                                 csf_display_profile **out, csf_display_calib_result *res,
                                 csf_error *err);

/* The step test of the warm-up judgement (calib/warmup_model.h, which calibrate and verify use):
 * the mean of the last three white readings differs from the three before by less than
 * max(target_rel / 4, 2.5 sd of the last three x sqrt(2/3)). Returns 1 when w[0..n-1] passes;
 * *change_rel (may be NULL) gets that relative change (NAN under 6 readings). */
int csf_display_warm_settled(const double *white_cdm2, int n, double target_rel, double *change_rel);

#endif
