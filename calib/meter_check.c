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

/* Margins. A spot meter is aimed through its viewfinder, whose measuring circle lands on the patch
 * to within about its own radius, and its field has no sharp edge (light from just outside the
 * nominal circle still reaches the sensor); a patch twice the field keeps a field's radius of the
 * patch round the circle on every side. A contact meter is put on the target mark by hand, good to
 * about 5 mm either way: 10 mm more than its face. A patch much larger than needed buys nothing:
 * the reading is still the light under the meter, and a large bright area lets an LCD's
 * non-uniformity and its dimming under load (and an OLED's automatic brightness limit) decide what
 * that light is. */
int csf_patch_for_meter(double patch_deg, double distance_mm, double screen_min_mm, double field_deg,
                        double field_mm, char *why, size_t len)
{
    const double deg = M_PI / 180;
    if (why && len) why[0] = 0;
    if (!(distance_mm > 0) || (!(field_deg > 0) && !(field_mm > 0))) return 0;
    double patch_mm = patch_deg > 0 ? 2 * distance_mm * tan(0.5 * patch_deg * deg) : screen_min_mm;
    double shown_deg = patch_deg > 0 ? patch_deg : 2 * atan(0.5 * screen_min_mm / distance_mm) / deg;
    double need_mm, need_deg;
    char meter[160];
    if (field_deg > 0) {
        need_deg = CSF_SPOT_MARGIN * field_deg;
        need_mm = 2 * distance_mm * tan(0.5 * need_deg * deg);
        snprintf(meter, sizeof meter,
                 "a %.3g deg field (a spot meter at the eye's %.0f mm; %.3g x the field "
                 "for aiming)",
                 field_deg, distance_mm, CSF_SPOT_MARGIN);
    } else {
        need_mm = field_mm + CSF_CONTACT_MARGIN_MM;
        need_deg = 2 * atan(0.5 * need_mm / distance_mm) / deg;
        snprintf(meter, sizeof meter, "a %.3g mm face (a contact meter; %.0f mm more for placing it by hand)",
                 field_mm, CSF_CONTACT_MARGIN_MM);
    }
    if (patch_mm < need_mm * (1 - 1e-9)) {
        if (why)
            snprintf(why, len,
                     "the %.3g deg patch (%.1f mm at %.0f mm) is too small for the meter: it has %s, "
                     "so the patch must be at least %.3g deg (%.1f mm); give --patch-deg %.3g or more",
                     shown_deg, patch_mm, distance_mm, meter, need_deg, need_mm, ceil(need_deg * 10) / 10);
        return 2;
    }
    if (patch_mm > CSF_PATCH_LARGE_FACTOR * need_mm) {
        if (why)
            snprintf(why, len,
                     "the %.3g deg patch (%.1f mm) is %.0f x what the meter needs (%.3g deg, %.1f mm, "
                     "for %s); a large bright patch lets the panel's non-uniformity and dimming under load "
                     "change the reading; about %.3g deg is enough",
                     shown_deg, patch_mm, patch_mm / need_mm, need_deg, need_mm, meter,
                     ceil(need_deg * 2 * 10) / 10);
        return 1;
    }
    return 0;
}
