/* Self-check of the presenter: render frames offscreen, read them back, turn pixels into
 * luminance with the caller's idea of the display's truth (a simulated display model, or a
 * profile), and measure what was drawn: spatial frequency, orientation, position, Michelson
 * contrast averaged over frames, mean luminance, and the effective luminance resolution.
 * Used by `csfcal stimulus check`, the stimulus tests and bench_frame. */
#ifndef CSF_STIMULI_SELFCHECK_H
#define CSF_STIMULI_SELFCHECK_H

#include <stdint.h>

#include "stimuli/presenter.h"

/* Luminance in cd/m2 of one pixel with drive values r, g, b in [0,1]. */
typedef double (*csf_pixel_lum_fn)(void *ctx, double r01, double g01, double b01);

typedef struct {
    int frames;
    double freq_cpd;          /* frequency maximising the carrier projection (angle space) */
    double orientation_deg;   /* orientation maximising it */
    double ecc_deg, polar_deg;/* centroid of the contrast energy */
    double contrast;          /* Michelson, least squares on the frame-averaged luminance */
    double mean_lum_cdm2;     /* background/patch mean from the same fit */
} csf_selfcheck_result;

/* Renders `frames` frames of s (Gabor or grating, static), measures them. The presenter must be
 * headless or windowed with rendering on every frame. */
csf_status csf_selfcheck_stimulus(csf_presenter *p, const csf_stimulus *s, int frames,
                                  csf_pixel_lum_fn lum, void *lum_ctx, csf_selfcheck_result *out,
                                  csf_error *err);

typedef struct {
    int levels, frames, patch_px;
    double max_err_frac;     /* max |measured - requested| patch-mean luminance / display range */
    double rms_err_frac;
    double effective_bits;   /* -log2(max_err_frac) */
} csf_selfcheck_resolution;

/* Effective luminance resolution: `levels` random uniform fields between 20 % and 80 % of peak
 * luminance (counter RNG on seed), each shown for `frames` frames; the mean luminance of the
 * central patch_px x patch_px patch over the frames is compared with the request. */
csf_status csf_selfcheck_resolution_run(csf_presenter *p, int levels, int frames, int patch_px,
                                        uint64_t seed, csf_pixel_lum_fn lum, void *lum_ctx,
                                        csf_selfcheck_resolution *out, csf_error *err);

/* ---- drifting carriers: the phase on each rendered frame ----
 * A phase meter is a quadrature matched filter at the patch: each read-back frame's luminance
 * (through the caller's luminance truth) is fitted, least squares over the patch, by
 * L = m + a env cos(2 pi f w) + b env sin(2 pi f w) at the stimulus' own frequency, orientation
 * and envelope (w the position along the modulation direction, angle space), which gives the
 * mean m, the contrast hypot(a, b) / m and the carrier phase atan2(-b, a) at the patch centre
 * (the convention of csf_stimulus.phase_deg, in radians). Pixels within
 * CSF_PHASE_METER_FIX_EXCLUDE_DEG of the fixation point (the fixation mark's place) are not
 * fitted. from_region = 1 reads the region with
 * csf_presenter_readback_region (full resolution, without a caption) instead of the frame. */
#define CSF_PHASE_METER_FIX_EXCLUDE_DEG 0.25
typedef struct csf_phase_meter csf_phase_meter;
typedef struct {
    double phase_rad; /* (-pi, pi] */
    double contrast;  /* Michelson, the fitted carrier amplitude over the fitted mean */
    double mean_lum_cdm2;
} csf_phase_reading;

/* s: a Gabor or grating whose patch stays in place (velocity_dps 0); its phase and drift are
 * what is measured, everything else is taken as given. */
csf_status csf_phase_meter_open(csf_presenter *p, const csf_stimulus *s, int from_region,
                                csf_pixel_lum_fn lum, void *lum_ctx, csf_phase_meter **out, csf_error *err);
/* Reads the presenter's last frame and fits it. */
csf_status csf_phase_meter_read(csf_phase_meter *m, csf_phase_reading *out, csf_error *err);
/* The frequency maximising the carrier projection on the frame last read (within +-15 % of the
 * stimulus' own), given the mean luminance that read fitted. */
csf_status csf_phase_meter_freq(csf_phase_meter *m, double mean_lum_cdm2, double *freq_cpd, csf_error *err);
void csf_phase_meter_close(csf_phase_meter *m);

/* Drift speed and phase continuity from phases read at presentation times. The phases are
 * unwrapped against the times: each step is the step the asked drift predicts,
 * 2 pi tf (t_k - t_k-1), plus the measured deviation from it wrapped into (-pi, pi] (so speed
 * errors up to half a cycle per frame interval are seen as they are). The measured temporal
 * frequency is the least-squares slope of the unwrapped phase over time. Continuity: every
 * step's deviation is within step_tolerance_rad, a quarter of one refresh period's step (at least
 * CSF_DRIFT_MIN_STEP_TOL_RAD). A presenter that advanced the phase by frame count would show, at
 * a held frame, a deviation of one period's step (2 pi tf / refresh) and a slow speed. */
#define CSF_DRIFT_MIN_STEP_TOL_RAD 0.02
#define CSF_DRIFT_SPEED_TOL 0.01 /* measured speed within 1 % of the asked speed */
typedef struct {
    int frames, frames_missed; /* frames read; intervals longer than 1.5 periods */
    double tf_asked_hz, tf_measured_hz, tf_rel_error;
    double frame_step_rad; /* 2 pi tf / refresh: one refresh period's phase step */
    double step_tolerance_rad;
    double max_step_error_rad;                    /* max |deviation| over all intervals */
    double max_held_step_error_rad;               /* the same over held (missed) intervals; 0 when none */
    double held_step_rad, held_step_expected_rad; /* the first held interval (NAN when none):
                                                     measured step and 2 pi tf interval */
    int continuous;
} csf_drift_fit;

csf_status csf_drift_fit_phases(const double *t_s, const double *phase_rad, int n, double tf_hz,
                                double refresh_hz, csf_drift_fit *out, csf_error *err);

typedef struct {
    csf_drift_fit fit;
    double freq_cpd;                /* measured on the first frame */
    double contrast, mean_lum_cdm2; /* per-frame fits, averaged */
    double speed_asked_dps;         /* drift_hz / freq_cpd */
    double speed_measured_dps;      /* measured tf / measured frequency */
    double speed_rel_error;
    int speed_ok; /* |speed_rel_error| <= CSF_DRIFT_SPEED_TOL */
} csf_selfcheck_drift_result;

/* Runs s (drift_hz != 0, patch in place) as one trial of `frames` refresh periods through
 * csf_presenter_run_trial, with injected or random missed frames as the presenter is set up,
 * reads every stimulus frame back (it uses and then removes the presenter's frame hook), and
 * measures its drift. The presenter must render every frame. */
csf_status csf_selfcheck_drift(csf_presenter *p, const csf_stimulus *s, int frames, csf_pixel_lum_fn lum,
                               void *lum_ctx, csf_selfcheck_drift_result *out, csf_error *err);

#endif
