/* `display calibrate --resume ID` replays a session's stored readings through the calibration
 * (calib/display_calib.c) before it measures anything new; the store may come from another
 * station, a backup or a damaged disk, so those readings are outside input. The input is a store
 * file; every display session in it (at most 3; finished ones are marked paused first) is resumed
 * with the simulated LCD photometer: the replay must refuse with a message or finish with a
 * usable profile. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib/display_calib.h"
#include "devices/photometer.h"
#include "results/store/store.h"
#include "fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void resume(csf_store *s, int64_t id)
{
    csf_error err = {0};
    csf_photometer *ph = NULL;
    if (csf_photometer_open("sim:display=lcd", 7, &ph, &err) != CSF_OK) abort();
    csf_display_calib_opts o;
    csf_display_calib_defaults(&o);
    o.budget = 12;
    o.warmup_max = 4;
    o.progress = 0;
    csf_display_profile *p = NULL;
    csf_display_calib_result res;
    int64_t sid = id;
    csf_status st = csf_display_calibrate(ph, &o, s, &sid, 7, &p, &res, &err);
    if (st == CSF_OK) {
        if (!p) abort();
        double prev = -INFINITY;
        for (int i = 0; i <= 16; i++) {
            double L = csf_profile_grey_lum(p, i / 16.0);
            if (!(L >= prev) || !isfinite(L)) abort(); /* a finished profile is usable */
            prev = L;
        }
        csf_profile_free(p);
    } else if (p != NULL || err.msg[0] == '\0') {
        abort(); /* a refusal leaves no profile and says why */
    }
    csf_photometer_close(ph);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    if (fuzz_file_write("resume", data, size, path)) return 0;
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) == CSF_OK) {
        csf_session_info *list = NULL;
        size_t n = 0;
        if (csf_store_list_sessions(s, &list, &n, &err) == CSF_OK) {
            int done = 0;
            for (size_t i = 0; i < n && done < 3; i++)
                if (list[i].kind == CSF_SESSION_DISPLAY) {
                    /* a finished session is refused before its readings are read: reopen it */
                    if (list[i].state == CSF_SESSION_FINISHED &&
                        csf_store_set_session_state(s, list[i].id, CSF_SESSION_PAUSED, &err) != CSF_OK)
                        continue;
                    resume(s, list[i].id);
                    done++;
                }
            csf_session_list_free(list, n);
        }
        csf_store_close(s);
    }
    fuzz_file_remove(path);
    return 0;
}
