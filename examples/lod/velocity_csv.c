/* velocity_csv: a model observer's threshold grid with a velocity axis, as the CSV that
 * `csfcal lut import` reads (docs/csflut.md), for the lod example's moving sequence and its test
 * when no measured 3-D table is at hand. Thresholds are the default static CSF
 * (model/csf_model.h: Lesmes et al. 2010 log-parabola x Mantiuk et al. 2022 eccentricity) times
 * the Kelly (1979) / Daly (1998) velocity gain (model/csf_velocity.h).
 * --no-low-frequency-gain keeps only the losses: Kelly's gain is a ratio to a stabilised image
 * (0.15 deg/s), whose low frequencies are far less visible than those of a static grating seen
 * with the eye's natural drift, which the static CSF already describes (its truncation below the
 * peak, Lesmes et al. 2010); multiplying the static CSF by the full ratio counts that recovery
 * twice, so this variant caps the gain at 1.
 *   usage: velocity_csv [--velocities 0,4,12] [--steepness S] [--no-low-frequency-gain]
 *   (CSV on stdout) */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_model.h"
#include "model/csf_velocity.h"

#define MAX_VELS 32

static int parse_velocities(const char *list, double *vel_dps, int *n)
{
    char buf[512], *save = NULL;
    snprintf(buf, sizeof buf, "%s", list);
    *n = 0;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *end;
        errno = 0;
        double v = strtod(tok, &end);
        if (end == tok || *end || errno || !(v >= 0 && v <= 200) || *n == MAX_VELS ||
            (*n > 0 && !(v > vel_dps[*n - 1]))) {
            fprintf(
                stderr,
                "velocity_csv: --velocities %s: expected up to %d increasing speeds from 0 to 200 deg/s\n",
                list, MAX_VELS);
            return 2;
        }
        vel_dps[(*n)++] = v;
    }
    return *n ? 0 : 2;
}

int main(int argc, char **argv)
{
    double vel_dps[MAX_VELS] = {0, 1, 2, 4, 8, 12, 24};
    int n_vel = 7, losses_only = 0;
    csf_velocity_params vp = csf_velocity_default();
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(argv[i], "--no-low-frequency-gain")) {
            losses_only = 1;
            continue;
        }
        if (!strcmp(argv[i], "--velocities") && val) {
            if (parse_velocities(val, vel_dps, &n_vel)) return 2;
        } else if (!strcmp(argv[i], "--steepness") && val) {
            char *end;
            vp.steepness = strtod(val, &end);
            if (*end || !(vp.steepness >= 0 && vp.steepness <= 4)) {
                fprintf(stderr, "velocity_csv: --steepness %s: expected 0 to 4\n", val);
                return 2;
            }
        } else {
            fprintf(stderr,
                    "usage: velocity_csv [--velocities 0,4,12] [--steepness S] [--no-low-frequency-gain]\n");
            return 2;
        }
        i++;
    }
    static const double freq_cpd[] = {0.25, 0.5, 1, 2, 4, 8, 16, 32};
    static const double ecc_deg[] = {0, 2, 5, 10, 20, 40};
    csf_model_params mp = csf_model_default();
    printf("# observer: model (Lesmes 2010 x Mantiuk 2022 eccentricity x Kelly 1979 / Daly 1998 velocity%s)\n"
           "# method: model\nfreq_cpd,ecc_deg,velocity_dps,threshold\n",
           losses_only ? ", losses only" : "");
    for (int v = 0; v < n_vel; v++)
        for (size_t e = 0; e < sizeof ecc_deg / sizeof *ecc_deg; e++)
            for (size_t f = 0; f < sizeof freq_cpd / sizeof *freq_cpd; f++) {
                double gain = csf_velocity_log10_gain(&vp, freq_cpd[f], vel_dps[v]);
                double log_s = csf_model_log10_sensitivity(&mp, freq_cpd[f], ecc_deg[e]) +
                               (losses_only ? fmin(gain, 0) : gain);
                printf("%g,%g,%g,%.6g\n", freq_cpd[f], ecc_deg[e], vel_dps[v], pow(10, -log_s));
            }
    return 0;
}
