/* The photometer spec (--photometer, the station configuration's photometer key, the spec stored
 * with a session and replayed on --resume) is outside input: "sim:key=value,..." with the display
 * model's keys, the instrument's and a fault. Opening must refuse with a message or give a meter
 * whose readings are finite and non-negative (or refused with a message) at any drive value,
 * except the absurd answers a fault= asks for, which the calibration's checks must catch.
 * Specs that name a file (display=file=PATH.csv, PATH.csv) are skipped: that parser has its
 * own target (fuzz_display_csv) and the fuzzer must not read files. Real instruments' specs are
 * skipped too (they open serial ports or run spotread; fuzz_*_reply cover their protocols). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "calib/meter_check.h"
#include "devices/photometer_driver.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char spec[700];
    if (size >= sizeof spec) return 0;
    memcpy(spec, data, size);
    spec[size] = '\0';
    if (strstr(spec, "file=") || strstr(spec, ".csv") || strstr(spec, ".CSV") || strchr(spec, '/'))
        return 0;
    /* real instruments open ports and run programs (spotread): their replies have their own targets */
    size_t nlen = strcspn(spec, ":");
    for (const csf_photometer_driver *const *d = csf_photometer_drivers(); *d; d++)
        if (strlen((*d)->name) == nlen && !strncmp((*d)->name, spec, nlen) && !((*d)->caps & CSF_PHOT_CAP_SIMULATED))
            return 0;
    csf_photometer *p = NULL;
    csf_error err = {0};
    if (csf_photometer_open(spec, 7, &p, &err) != CSF_OK) {
        if (p != NULL || err.msg[0] == '\0') abort(); /* refusal leaves nothing and says why */
        return 0;
    }
    char id[256];
    if (csf_photometer_identify(p, id, sizeof id, &err) == CSF_OK && !memchr(id, '\0', sizeof id)) abort();
    /* Sweep grey and the three channels the way a calibration does; a fault may refuse a reading
     * (with a message), an accepted one must be usable. */
    for (int i = 0; i < 24; i++) {
        double v = (i % 6) / 5.0;
        int ch = i / 6;
        csf_photometer_show_patch(p, ch == 0 || ch == 1 ? v : 0, ch == 0 || ch == 2 ? v : 0,
                                  ch == 0 || ch == 3 ? v : 0);
        csf_photometer_reading r;
        err.msg[0] = '\0';
        if (csf_photometer_measure(p, &r, &err) != CSF_OK) {
            if (err.msg[0] == '\0') abort();
            continue;
        }
        if (!isfinite(r.t_s)) abort();
        /* the simulator's absurd-answer faults (fault=negative|nan|huge|badxyz) give readings that
         * cannot be light on purpose: the calibration's check (calib/meter_check.h) must refuse
         * them, and nothing else may give one */
        int unusable = !isfinite(r.lum_cdm2) || r.lum_cdm2 < 0 ||
                       (r.has_xyz && !(isfinite(r.xyz[0]) && isfinite(r.xyz[1]) && isfinite(r.xyz[2])));
        csf_meter_limits lim;
        csf_meter_limits_default(&lim);
        char why[400];
        if (unusable && !csf_meter_absurd(&r, &lim, why, sizeof why)) abort();
    }
    csf_photometer_wait(p, 30);
    csf_photometer_resume_at(p, 3, 12.5);
    csf_photometer_reading r;
    csf_photometer_measure(p, &r, &err);
    csf_photometer_close(p);
    return 0;
}
