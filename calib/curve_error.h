/* How far a display profile's curve is off between the levels it was fitted through, from those
 * levels alone: each interior level left out in turn and predicted from the rest (the profile's own
 * monotone cubic, csf_profile_fit_curve), its miss less its noise scaled from the merged interval to
 * each half at the order of convergence the curve shows; knots the model keeps as corners, corners
 * hidden inside an interval, and intervals no level witnesses, each estimated on its own terms.
 * Pure functions of the levels: display calibration (calib/display_calib.c) places levels and
 * states the profile's error with them. */
#ifndef CSF_CURVE_ERROR_H
#define CSF_CURVE_ERROR_H

#include <stddef.h>

/* Leave-one-out error estimate per interval of the m levels (drives dv ascending, mean luminance
 * dl, relative sd of each mean sd_rel; is_channel: a primary, whose curve starts at zero, else
 * grey above its black), noise taken off (see "the stated error" in calib/display_calib.c): est
 * (m - 1 entries) the larger of each interval's two witnesses, for placing levels; est_min (may
 * be NULL) their geometric mean, for the statement. p_max caps the measured order of convergence
 * (2 for a "met" decision, 3 for the statement). Intervals wholly below 10 % of the peak get 0.3 of
 * their estimate in est (they matter less). Returns the largest est (0 with fewer than two levels). */
double csf_curve_interval_errors(const double *dv, const double *dl, size_t m, int is_channel,
                                 const double *sd_rel, double p_max, double *est, double *est_min);

#endif
