/* Photometer plausibility checks (see calib/meter_check.h). */
#include "calib/meter_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void csf_meter_limits_default(csf_meter_limits *l)
{
    l->max_lum_cdm2 = 10000;
    l->xyz_tol_rel = 0.02;
    l->min_contrast = 2;
    l->step_max_rel = 0.03;
    l->same_min_drive = 0.1;
}

int csf_meter_absurd(const csf_photometer_reading *r, const csf_meter_limits *l, char *why, size_t len)
{
    double L = r->lum_cdm2;
    if (!isfinite(L)) {
        snprintf(why, len, "it answered a luminance that is not a number (%g)", L);
        return 1;
    }
    if (L < 0) {
        snprintf(why, len, "it answered a negative luminance (%.6g cd/m2)", L);
        return 1;
    }
    if (L > l->max_lum_cdm2) {
        snprintf(why, len, "it answered %.6g cd/m2, beyond any display (limit %g cd/m2)", L, l->max_lum_cdm2);
        return 1;
    }
    if (!r->has_xyz) return 0;
    const double *x = r->xyz;
    if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) {
        snprintf(why, len, "it answered XYZ that is not a number (%g %g %g)", x[0], x[1], x[2]);
        return 1;
    }
    /* noise may take a dim reading's X or Z a little below 0, never by a sizeable part of Y */
    double slack = fmax(0.02 * L, 1e-3);
    if (x[0] < -slack || x[1] < -slack || x[2] < -slack) {
        snprintf(why, len, "it answered negative tristimulus values (X %.6g, Y %.6g, Z %.6g)", x[0], x[1], x[2]);
        return 1;
    }
    if (fabs(x[1] - L) > l->xyz_tol_rel * L + 1e-3) {
        snprintf(why, len, "its XYZ (Y %.6g) disagrees with its luminance %.6g cd/m2 by more than %g %%", x[1], L,
                 100 * l->xyz_tol_rel);
        return 1;
    }
    return 0;
}

static double patch_distance(const double a[3], const double b[3])
{
    double d = 0;
    for (int k = 0; k < 3; k++) d = fmax(d, fabs(a[k] - b[k]));
    return d;
}

int csf_meter_frozen(const csf_photometer_reading *prev, const double prev_rgb[3],
                     const csf_photometer_reading *now, const double rgb[3], const csf_meter_limits *l,
                     char *why, size_t len)
{
    if (patch_distance(prev_rgb, rgb) < l->same_min_drive) return 0;
    if (!(now->lum_cdm2 > 0) || now->lum_cdm2 != prev->lum_cdm2) return 0;
    if (now->has_xyz && prev->has_xyz)
        for (int i = 0; i < 3; i++)
            if (now->xyz[i] != prev->xyz[i]) return 0;
    snprintf(why, len, "it answered exactly %.6g cd/m2 for patch (%.3g, %.3g, %.3g) and for patch "
             "(%.3g, %.3g, %.3g) before it: a stale answer, the instrument is not measuring",
             now->lum_cdm2, rgb[0], rgb[1], rgb[2], prev_rgb[0], prev_rgb[1], prev_rgb[2]);
    return 1;
}

int csf_meter_no_contrast(double white_cdm2, double black_cdm2, const csf_meter_limits *l, char *why,
                          size_t len)
{
    if (isnan(black_cdm2) || !(white_cdm2 < l->min_contrast * black_cdm2)) return 0;
    snprintf(why, len, "the reading hardly changes between black and white (%.6g and %.6g cd/m2, under "
             "%g:1): the sensor is not on the patch (cap on, off the screen, facing the room)",
             black_cdm2, white_cdm2, l->min_contrast);
    return 1;
}

int csf_meter_white_step(double prev_cdm2, double now_cdm2, double model_ratio, double noise_rel,
                         const csf_meter_limits *l, char *why, size_t len)
{
    if (!(prev_cdm2 > 0) || !(now_cdm2 > 0)) return 0;
    if (!(model_ratio > 0) || !isfinite(model_ratio)) model_ratio = 1;
    double allow = fmax(l->step_max_rel, 6 * noise_rel);
    double change = now_cdm2 / (prev_cdm2 * model_ratio) - 1;
    if (fabs(change) <= allow) return 0;
    snprintf(why, len, "white changed from %.6g to %.6g cd/m2 (%+.1f %% beyond the warm-up drift, %.1f %% "
             "allowed): the sensor moved on the screen, or the display changed its brightness (auto "
             "dimming, power saving), or the room light changed",
             prev_cdm2, now_cdm2, 100 * change, 100 * allow);
    return 1;
}

int csf_meter_above_white(double lum_cdm2, double white_cdm2, double noise_abs_cdm2, char *why, size_t len)
{
    if (!(white_cdm2 > 0) || !(lum_cdm2 > 1.1 * white_cdm2 + 4 * noise_abs_cdm2)) return 0;
    snprintf(why, len, "a patch darker than white read %.6g cd/m2, above white (%.6g cd/m2): the sensor "
             "moved onto something brighter, or the instrument changed its range", lum_cdm2, white_cdm2);
    return 1;
}
