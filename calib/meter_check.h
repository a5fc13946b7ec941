/* Plausibility of a photometer's readings, for any driver: the failures a real meter shows that
 * its own protocol does not report. A driver says "too dark", "over range", "timeout" itself;
 * these checks catch what parses cleanly but cannot be the light of the patch on the screen:
 *  - an absurd value: not finite, negative, far beyond any display (the display class limit),
 *    XYZ that disagrees with the luminance or is negative;
 *  - a meter that does not see the patch: the same value twice for different patches (a frozen
 *    answer), or white hardly brighter than black (sensor off the screen, cap on, facing a wall);
 *  - a step in white that the warm-up model does not allow (the sensor moved, the display dimmed
 *    itself, room light changed).
 * Each check is a pure function of the numbers it is given; calib/display_calib.c decides when to
 * call them and names the instrument in the message. */
#ifndef CSF_METER_CHECK_H
#define CSF_METER_CHECK_H

#include <stddef.h>

#include "devices/photometer.h"

typedef struct {
    double max_lum_cdm2;     /* brightest plausible reading: 10000 cd/m2 (the top of SMPTE ST 2084,
                                above every desktop or HDR monitor a lab uses) */
    double xyz_tol_rel;      /* |XYZ's Y - luminance| allowed, relative: 0.02 */
    double min_contrast;     /* white / black at least this, else the meter does not see the
                                screen: 2 (any working display exceeds 10; a projector in a lit
                                room still exceeds 5) */
    double step_max_rel;     /* white may differ from what the warm-up model predicts by this
                                much between references: 0.03 */
    double same_min_drive;   /* patches this far apart (drive 0..1, any channel) must not read
                                bit-identical values: 0.1 */
} csf_meter_limits;

void csf_meter_limits_default(csf_meter_limits *l);

/* A reading whose numbers cannot be light. Returns 1 and writes the problem to why. */
int csf_meter_absurd(const csf_photometer_reading *r, const csf_meter_limits *l, char *why, size_t len);

/* The previous reading (patch prev_rgb) and this one (patch rgb) are bit-identical although the
 * patches differ by at least same_min_drive: the instrument repeats a stale answer. */
int csf_meter_frozen(const csf_photometer_reading *prev, const double prev_rgb[3],
                     const csf_photometer_reading *now, const double rgb[3], const csf_meter_limits *l,
                     char *why, size_t len);

/* White against black (NAN black: "too dark", which is a change). Returns 1 when white is below
 * min_contrast x black. */
int csf_meter_no_contrast(double white_cdm2, double black_cdm2, const csf_meter_limits *l, char *why,
                          size_t len);

/* A white reading against the previous one and the ratio the warm-up model predicts between
 * their times (1 without a model); noise_rel widens the allowance to 6 sd when that is larger. */
int csf_meter_white_step(double prev_cdm2, double now_cdm2, double model_ratio, double noise_rel,
                         const csf_meter_limits *l, char *why, size_t len);

/* A patch other than white reads brighter than white by more than 10 % (plus 4 sd of the
 * absolute noise): the sensor moved onto something brighter, or the instrument's range is wrong. */
int csf_meter_above_white(double lum_cdm2, double white_cdm2, double noise_abs_cdm2, char *why, size_t len);

/* Does the measuring patch suit the meter's field (csf_photometer_field)? The patch is a square of
 * side patch_deg seen from distance_mm (0: the full field, screen_min_mm across). A spot meter
 * (field_deg > 0) is taken to stand where the eye is, so its field covers field_deg of the patch
 * too; it needs CSF_SPOT_MARGIN x field_deg. A contact meter (field_mm > 0) needs field_mm +
 * CSF_CONTACT_MARGIN_MM. Returns 2 when the patch is too small (why: the patch in deg and mm, the
 * meter's need and the limit), 1 when it is more than CSF_PATCH_LARGE_FACTOR x the need (why: a
 * warning), 0 otherwise. */
#define CSF_SPOT_MARGIN 2.0
#define CSF_CONTACT_MARGIN_MM 10.0
#define CSF_PATCH_LARGE_FACTOR 8.0
int csf_patch_for_meter(double patch_deg, double distance_mm, double screen_min_mm, double field_deg,
                        double field_mm, char *why, size_t len);

#endif
