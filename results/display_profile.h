/* Display profile: what luminance each drive value produces on one monitor, measured with a
 * photometer (contract [C]). File format: docs/display-profile.md ("csfcal-display-profile 1",
 * key = value lines then CSV sections).
 *
 * The model per curve (grey R=G=B, and r, g, b when measured) is a monotone cubic Hermite
 * interpolant (Fritsch–Carlson slopes) through (drive01, lum_cdm2) knots; its inverse is solved
 * exactly on the same piecewise cubic, so csf_profile_grey_lum(csf_profile_grey_drive(L)) == L
 * to rounding inside [black, max]. Luminances are absolute cd/m2, including the black level. */
#ifndef CSF_DISPLAY_PROFILE_H
#define CSF_DISPLAY_PROFILE_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

typedef struct csf_display_profile csf_display_profile;

enum { CSF_CH_R = 0, CSF_CH_G = 1, CSF_CH_B = 2, CSF_CH_GREY = 3, CSF_CH_COUNT = 4 };

/* Loads a profile file; refuses malformed files with the line and the problem. */
csf_status csf_profile_load(const char *path, csf_display_profile **out, csf_error *err);
/* Parses a profile held in memory (what csf_profile_load does after reading the file). */
csf_status csf_profile_parse(const char *text, size_t len, csf_display_profile **out, csf_error *err);
csf_status csf_profile_save(const csf_display_profile *p, const char *path, csf_error *err);
/* Serialises to a malloc'd NUL-terminated string (caller frees). */
csf_status csf_profile_to_text(const csf_display_profile *p, char **out, csf_error *err);

/* The documented default display, used when no profile is given: sRGB-like gain-offset-gamma,
 * gamma 2.2, black 0.2 cd/m2, white 100 cd/m2, Rec.709 luminance weights per channel. Its id is
 * "default-gamma2.2-100cdm2". Returns NULL only when out of memory. */
csf_display_profile *csf_profile_default(void);
void csf_profile_free(csf_display_profile *p);

/* Stable id for table metadata: "<display>-<date>-<hash of the model>", at most 48 characters.
 * <display> is the display name when it has at most 24 characters and no '/' (path), else its
 * first word and a hash of the whole name (no file paths of a photometer spec in an id). */
const char *csf_profile_id(const csf_display_profile *p);
/* Name of the display the profile was measured on (its "display" line; "default" for the
 * documented default display). */
const char *csf_profile_display(const csf_display_profile *p);
double csf_profile_lum_black(const csf_display_profile *p); /* cd/m2, grey at drive 0 */
double csf_profile_lum_max(const csf_display_profile *p);   /* cd/m2, grey at drive 1 */
/* Forward model, R=G=B=drive01 (clamped to [0,1]). */
double csf_profile_grey_lum(const csf_display_profile *p, double drive01);
/* Exact inverse of the forward model; luminance outside [black, max] is clamped to [0,1]. */
double csf_profile_grey_drive(const csf_display_profile *p, double lum_cdm2);
/* "% of white" has one meaning everywhere in csfcal (display info, every export): luminance over
 * white, black included, Y = L / white, so drive 0 gives black / white and cd/m2 = Y * white (the
 * exports keep the black so that a reader gets absolute luminance back; docs/display-profile.md).
 * csf_profile_rel_lum gives Y of the grey curve at drive01 (NAN for a profile without light);
 * csf_profile_lum_from_rel turns a Y back into cd/m2: Y * white. */
double csf_profile_rel_lum(const csf_display_profile *p, double drive01);
double csf_profile_lum_from_rel(const csf_display_profile *p, double rel);
/* 1 when per-channel curves were measured (or modelled, for the default profile). */
int csf_profile_has_channels(const csf_display_profile *p);
/* Channel curves: luminance of channel ch alone at drive01, *excluding* the black level, so that
 * black + r + g + b predicts an additive mix. Inverse takes the same black-excluded luminance.
 * Without channels: NAN. */
double csf_profile_channel_lum(const csf_display_profile *p, int ch, double drive01);
double csf_profile_channel_drive(const csf_display_profile *p, int ch, double lum_cdm2);
/* Days since the profile was measured (from its created_utc), against the current time. */
double csf_profile_age_days(const csf_display_profile *p);
/* For code that uses a profile: 1 and a sentence in msg when the profile is older than
 * max_age_days (csf_config.profile_max_age_days; <= 0 disables), else 0 and msg = "". */
int csf_profile_age_warning(const csf_display_profile *p, double max_age_days, char *msg, size_t len);

/* --- building a profile from readings (the calibration procedure) --- */

typedef struct {
    int channel;       /* CSF_CH_R/G/B/GREY; the dark reading is GREY at drive 0 */
    double drive01;
    double lum_cdm2;
    double xyz[3];
    int has_xyz;
} csf_profile_reading;

typedef struct {
    const char *display_name;   /* e.g. "sim:display=lcd" or a monitor name; id prefix */
    const char *instrument;     /* photometer identification string */
    const char *created_utc;    /* "YYYY-MM-DDTHH:MM:SSZ"; NULL = now */
    const char *tool_version;   /* NULL = CSF_VERSION */
    double additivity_error;    /* relative (R+G+B+black vs white - 1); NAN if not measured */
} csf_profile_meta;

/* Builds a profile from raw readings: averages repeats at the same drive, enforces monotonicity
 * (pool-adjacent-violators when noise makes neighbours cross; reported as CSF_E_INSUFFICIENT if a
 * curve is decreasing by more than noise), fits the Hermite model. Needs >= 2 grey levels
 * including 0 and 1. Keeps the readings in the profile. */
csf_status csf_profile_build(const csf_profile_reading *readings, size_t n,
                             const csf_profile_meta *meta, csf_display_profile **out,
                             csf_error *err);

/* Fits one curve exactly as a profile does (averages repeats, pool-adjacent-violators, fitted
 * power transform, monotone Hermite) through (drive01, lum_cdm2) and evaluates it at eval_drive01.
 * The points must include drive 0 and 1. is_channel: luminances exclude black (base 0). Used by
 * the calibration to place levels (leave-one-out error) and by the benchmark. */
csf_status csf_profile_fit_curve(const double *drive01, const double *lum_cdm2, size_t n,
                                 int is_channel, const double *eval_drive01, double *eval_lum_cdm2,
                                 size_t n_eval, csf_error *err);

/* The knots where that fitted curve has a corner (a slope break kept as a kink, not rounded):
 * writes up to max of their drives, returns how many. */
size_t csf_profile_fit_corners(const double *drive01, const double *lum_cdm2, size_t n, int is_channel,
                               double *corner_drive01, size_t max, csf_error *err);

/* Replaces the model of channel ch (CSF_CH_R/G/B) of a profile that has channels with the monotone
 * curve through the given knots (drive strictly rising from 0 to 1, luminance black-excluded and
 * never falling), fitted as any curve (power transform, Hermite, corners). The readings are kept;
 * the id is recomputed. The calibration uses it to store a channel curve derived from the grey
 * curve and the channel's readings (see docs/display-profile.md, "Channels through grey"). */
csf_status csf_profile_set_channel_knots(csf_display_profile *p, int ch, const double *drive01,
                                         const double *lum_cdm2, size_t n, csf_error *err);

/* Knots of one curve (model), for plots/exports. Returns the count; arrays owned by p. */
size_t csf_profile_knots(const csf_display_profile *p, int ch, const double **drive01,
                         const double **lum_cdm2);
/* Raw readings kept in the profile. */
size_t csf_profile_readings(const csf_display_profile *p, const csf_profile_reading **out);
/* Primaries (and white) XYZ at full drive, black subtracted; returns 0 when unknown. */
int csf_profile_primaries_xyz(const csf_display_profile *p, double rgbw_xyz[4][3]);
double csf_profile_additivity_error(const csf_display_profile *p); /* NAN if unknown */
/* What the calibration stated about the profile (docs/display-profile.md, "How wrong the profile
 * is"): the target (max relative error above 10 % of peak), each curve's stated error (NAN when
 * not measured, inf when it could not be estimated) and whether all met the target. Returns 1
 * (met), 0 (the budget ended first), or -1 when the profile states nothing (an older file, the
 * default display). */
int csf_profile_statement(const csf_display_profile *p, double *target_rel,
                          double stated_error_rel[CSF_CH_COUNT]);
void csf_profile_set_statement(csf_display_profile *p, double target_rel,
                               const double stated_error_rel[CSF_CH_COUNT], int target_met);
const char *csf_profile_instrument(const csf_display_profile *p);
const char *csf_profile_created_utc(const csf_display_profile *p);

#endif
