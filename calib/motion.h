/* Drifting gratings in a calibration grid: which cells a display can show, the message that names
 * the limit, and the drift of each trial.
 *
 * A carrier of f cpd drifting at v deg/s inside a stationary envelope flickers at v*f Hz at every
 * point. Sampled at the refresh rate R, a temporal frequency at or above R/2 aliases: the frames
 * show a slower drift, or one in the other direction (Watson, Ahumada & Farrell 1986), so such a
 * cell is not measured at all. */
#ifndef CSF_MOTION_H
#define CSF_MOTION_H

#include <stddef.h>
#include <stdint.h>

#include "calib/procedure.h"

/* 1 when the display cannot show cell c at refresh_hz (v * f >= refresh_hz / 2). */
int csf_motion_aliases(const csf_cell *c, double refresh_hz);

/* Marks every cell that aliases (out[k] = 1) and returns how many. */
int csf_motion_mark_not_shown(const csf_cell *cells, int n_cells, double refresh_hz, unsigned char *out);

/* The highest velocity a grating of freq_cpd can drift at on this display without aliasing
 * (exclusive: anything below it can be shown). */
double csf_motion_max_velocity_dps(double freq_cpd, double refresh_hz);

/* For a refusal: "at 120 Hz, 8 cpd allows below 7.5 deg/s, 16 cpd below 3.75 deg/s" over the
 * frequencies that have a cell that aliases. */
void csf_motion_limits_text(const double *freqs_cpd, int n_freqs, const double *vels_dps, int n_vels,
                            double refresh_hz, char *buf, size_t len);

/* The drift direction of a trial: fixed (+1 / -1) or, for fixed_direction 0, drawn from
 * (seed, trial_key) so that a resumed session shows the same drift it stored. */
int csf_motion_direction(uint64_t seed, uint64_t trial_key, int fixed_direction);

/* The carrier's drift temporal frequency (Hz, signed by direction) for a cell's velocity. */
double csf_motion_drift_hz(const csf_cell *c, int direction);

#endif
