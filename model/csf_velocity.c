#include "model/csf_velocity.h"

#include <math.h>

csf_velocity_params csf_velocity_default(void)
{
    csf_velocity_params p = {.c1 = 0.67, .c2 = 1.7, .v_min_dps = 0.15, .steepness = 1.0};
    return p;
}

/* log of Kelly's S at (f, v) up to the constant c0 (cancels in the ratio). */
static double log_kelly_daly(const csf_velocity_params *p, double freq_cpd, double v_dps)
{
    double w = p->c2 * v_dps;
    double lk = fabs(log10(w / 3.0));
    double k = 6.1 + 7.3 * lk * lk * lk;
    double alpha = 2.0 * M_PI * p->c1 * freq_cpd;
    return log(k) + log(w) + 2.0 * log(alpha) - p->c1 * 4.0 * M_PI * freq_cpd * (w + 2.0) / 45.9;
}

double csf_velocity_log10_gain(const csf_velocity_params *p, double freq_cpd, double velocity_dps)
{
    if (isnan(freq_cpd) || isnan(velocity_dps)) return NAN;
    double v = fabs(velocity_dps);
    if (v <= p->v_min_dps || freq_cpd <= 0) return 0.0;
    double ln_ratio = log_kelly_daly(p, freq_cpd, v) - log_kelly_daly(p, freq_cpd, p->v_min_dps);
    return p->steepness * ln_ratio / M_LN10;
}

double csf_velocity_temporal_hz(double freq_cpd, double velocity_dps)
{
    return fabs(freq_cpd * velocity_dps);
}

double csf_velocity_warp(double velocity_dps)
{
    return log10(fabs(velocity_dps) + CSF_VELOCITY_WARP_V0_DPS);
}
