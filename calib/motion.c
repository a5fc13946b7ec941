#include "calib/motion.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rng.h"

enum { ST_DRIFT_DIRECTION = 0x5e5d1 };

int csf_motion_aliases(const csf_cell *c, double refresh_hz)
{
    return fabs(c->velocity_dps * c->freq_cpd) >= 0.5 * refresh_hz;
}

int csf_motion_mark_not_shown(const csf_cell *cells, int n_cells, double refresh_hz, unsigned char *out)
{
    int n = 0;
    for (int k = 0; k < n_cells; k++) {
        out[k] = (unsigned char)csf_motion_aliases(&cells[k], refresh_hz);
        n += out[k];
    }
    return n;
}

double csf_motion_max_velocity_dps(double freq_cpd, double refresh_hz)
{
    return 0.5 * refresh_hz / freq_cpd;
}

void csf_motion_limits_text(const double *freqs_cpd, int n_freqs, const double *vels_dps, int n_vels,
                            double refresh_hz, char *buf, size_t len)
{
    size_t used = (size_t)snprintf(buf, len, "at %g Hz", refresh_hz);
    int any = 0;
    for (int f = 0; f < n_freqs && used < len; f++) {
        double vmax = csf_motion_max_velocity_dps(freqs_cpd[f], refresh_hz);
        int aliased = 0;
        for (int v = 0; v < n_vels; v++) aliased |= vels_dps[v] >= vmax;
        if (!aliased) continue;
        used += (size_t)snprintf(buf + used, len - used, "%s %g cpd allows velocities below %.3g deg/s",
                                 any ? "," : "", freqs_cpd[f], vmax);
        any = 1;
    }
}

int csf_motion_direction(uint64_t seed, uint64_t trial_key, int fixed_direction)
{
    if (fixed_direction) return fixed_direction > 0 ? 1 : -1;
    return (csf_rng_u64(seed, ST_DRIFT_DIRECTION, trial_key) & 1) ? 1 : -1;
}

double csf_motion_drift_hz(const csf_cell *c, int direction)
{
    return direction * c->velocity_dps * c->freq_cpd;
}
