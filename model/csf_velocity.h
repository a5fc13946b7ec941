/* How contrast sensitivity changes when a grating drifts: the spatio-velocity CSF of Kelly (1979)
 * as scaled by Daly (1998), used as a ratio to the same grating seen static, so that it can
 * multiply any static surface (model/csf_model.h, a measured table):
 *     gain(f, v) = S_KD(f, max(v, v_min)) / S_KD(f, v_min)
 *     S_KD(f, v) = k(c2 v) c2 v (2 pi c1 f)^2 exp(-c1 4 pi f (c2 v + 2) / 45.9),
 *     k(w) = 6.1 + 7.3 |log10(w / 3)|^3
 * (Daly's c0 cancels in the ratio). v_min is the eye's fixational drift: a "static" grating still
 * moves on the retina at about 0.15 deg/s, so v = 0 and v = v_min are the same stimulus, and gain
 * is exactly 1 there. Low frequencies gain sensitivity when they move (their temporal frequency
 * f v climbs towards the transient channel's peak), high frequencies lose it steeply.
 *
 * Real people depart from Kelly's stabilised-image fits (measured curves differ from it by about
 * 0.2 log10, and the fall at high temporal frequency varies between people), so the shape has
 * knobs: c1 scales frequency, c2 velocity, and `steepness` multiplies the log gain as a whole
 * (1 = Kelly-Daly). */
#ifndef CSF_VELOCITY_H
#define CSF_VELOCITY_H

typedef struct {
    double c1;        /* frequency scale (Daly 1998: 0.67) */
    double c2;        /* velocity scale (Daly 1998: 1.7) */
    double v_min_dps; /* fixational drift floor (Daly 1998: 0.15 deg/s) */
    double steepness; /* multiplies log10 gain (1 = the published model) */
} csf_velocity_params;

csf_velocity_params csf_velocity_default(void);

/* log10 of the sensitivity at velocity_dps over the static sensitivity at the same frequency;
 * 0 at velocity 0 (and at any |v| <= v_min). The sign of the velocity (drift direction) does not
 * matter. NaN arguments give NaN. */
double csf_velocity_log10_gain(const csf_velocity_params *p, double freq_cpd, double velocity_dps);

/* Temporal frequency (Hz) of a grating of freq_cpd drifting at velocity_dps. */
double csf_velocity_temporal_hz(double freq_cpd, double velocity_dps);

/* The warp in which velocity axes are interpolated and compared: log10(|v| + v0) with
 * v0 = CSF_VELOCITY_WARP_V0_DPS, finite at v = 0 and logarithmic where sensitivity changes by
 * octaves of velocity. */
#define CSF_VELOCITY_WARP_V0_DPS 0.5
double csf_velocity_warp(double velocity_dps);

#endif
