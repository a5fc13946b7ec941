/* Verification of a display profile against the display now: the warm-up judgement of
 * calibration first (a display still warming up would look drifted), then white and a few levels
 * of grey, and of r, g, b, read again and compared with the profile, and the largest deviation
 * judged against the error the profile states about itself. */
#ifndef CSF_DISPLAY_VERIFY_H
#define CSF_DISPLAY_VERIFY_H

#include <stdint.h>

#include "core/csf_status.h"
#include "devices/photometer.h"
#include "results/display_profile.h"

typedef struct {
    int n_levels;         /* levels per curve between black and full drive (5; 1 to 64) */
    int channels;         /* 1: also the r, g, b curves (the profile must have them) */
    double target_rel;    /* warm-up criterion as in calibrate (0.0025) */
    double warmup_wait_s; /* as in calibrate (5 s) */
    int warmup_max;       /* as in calibrate (40); the verdict is "not warm" when white has not
                              settled by then */
    int (*show_patch)(void *user, const double rgb01[3], uint64_t reading_index); /* as above */
    void *show_patch_user;
} csf_display_verify_opts;

void csf_display_verify_defaults(csf_display_verify_opts *o);

typedef struct {
    /* 1: judged warm during the warm-up check (the judgement of calibrate, against the profile's
     * stated target when it has one) */
    int warm;
    double warmup_remaining_rel;   /* the model's predicted white change over an hour's session */
    double warmup_settled_gap_rel; /* how far white still is from where the model settles */
    double warmup_wait_s;          /* the model's expected further wait (0 when warm) */
    int n_warmup;                  /* warm-up readings taken */
    double warmup_s;               /* instrument time the warm-up check took */
    double warmup_change_rel;      /* last relative change between 3-reading means of white */
    double white_dev_rel;          /* white (grey at full drive) against the profile */
    double max_dev_rel;            /* largest deviation above 10 % of the curve's peak, all curves */
    double dev_rel[CSF_CH_COUNT];  /* the same per curve (r, g, b, grey); NAN when not checked */
    int n_checked[CSF_CH_COUNT];   /* levels compared per curve */
    int n_readings;                /* every reading, warm-up included */
    /* Agreement with what the profile states about itself (csf_profile_statement): */
    int profile_target_met;    /* 1 met, 0 the calibration's budget ended first, -1 not stated */
    double profile_stated_rel; /* the largest stated error of the curves checked (NAN: not stated) */
    double reading_noise_rel;  /* relative sd of one reading, from the settled warm-up whites */
    double allowed_dev_rel;    /* what a profile as good as stated can show here: stated + 3 sd of
                                  one verification reading (NAN: not stated) */
    int within_stated;         /* 1: max_dev_rel <= allowed_dev_rel; 0: the profile is worse than it
                                  says (or the display changed); -1: not stated */
} csf_display_verify_result;

/* Checks warm-up as calibrate does, then re-measures white and n_levels levels of grey (and of
 * r, g, b with o->channels) and compares them with the profile: channel c at drive v against
 * black + csf_profile_channel_lum(c, v). Refuses (CSF_E_INVALID_ARG) channels on a profile without
 * them. Deviations count above 10 % of each curve's peak (the range the accuracy target covers). */
csf_status csf_display_verify_run(csf_photometer *ph, const csf_display_profile *p,
                                  const csf_display_verify_opts *o, csf_display_verify_result *res,
                                  csf_error *err);

/* Grey only with the default options (warm-up check included). Returns the largest relative
 * deviation above 10 % of peak in *max_dev_rel and the white drift. */
csf_status csf_display_verify(csf_photometer *ph, const csf_display_profile *p, int n_levels,
                              double *max_dev_rel, double *white_dev_rel, csf_error *err);

#endif
