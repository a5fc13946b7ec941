/* The simulated observer's spec (`--observer sim:key=value,...`) is outside input: any bytes
 * after "sim:" must either be refused with a message or give an observer whose every answer is
 * in range, for every decision model and session effect the keys can switch on. (table= is
 * stripped of file access: the table parser has its own target, fuzz_observer_table.) */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model/observer_sim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void exercise(const csf_observer_sim *o)
{
    /* view=frame keys: what a session hands to calib/observer_screen.c must be in range */
    const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
    if (p->view_frame != 0 && p->view_frame != 1) abort();
    if (!(p->frame_step >= 1 && p->frame_step <= 30) || p->frame_step != floor(p->frame_step)) abort();
    if (p->display_gamma != 0 && !(p->display_gamma >= 1 && p->display_gamma <= 4)) abort();
    if (!p->view_frame && (p->display[0] || p->display_gamma != 0)) abort();
    if (memchr(p->display, '\0', sizeof p->display) == NULL) abort();
    if (strlen(csf_observer_sim_describe(o)) == 0) abort();
    double th = csf_observer_sim_threshold(o, 2, 5);
    if (!(th > 0)) abort();
    double c = isfinite(th) ? th : 0.5;
    /* indices near the start, deep in a long session, and practice keys */
    static const uint64_t idx[] = {0, 1, 63, 64, 777, 5000, CSF_SIM_PRACTICE_INDEX + 2};
    for (size_t i = 0; i < sizeof idx / sizeof idx[0]; i++) {
        double rt = NAN, c2[2] = {c, 0}, c4[4] = {0, 0, c, 0};
        int a = csf_observer_sim_2afc(o, idx[i], 2, 5, c2, &rt);
        if (a < 0 || a > 1 || !(rt > 0)) abort();
        a = csf_observer_sim_afc(o, idx[i], 2, 5, c4, 4, &rt);
        if (a < 0 || a > 3 || !(rt > 0)) abort();
        if (isnan(csf_observer_sim_drift_log10(o, idx[i]))) abort();
        double tt = csf_observer_sim_trial_threshold(o, 2, 5, idx[i]);
        if (!(tt > 0)) abort();
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin(o, idx[i], 2, 5, 45, 0, 3, &tr);
        double press = NAN;
        for (int k = 0; k < 180; k++)
            if (csf_observer_sim_fade_frame(o, &tr, k / 60.0, c * pow(10.0, -1 + k / 90.0), &press)) {
                if (!(press >= 0) || isinf(press)) abort();
                double x, y;
                csf_observer_sim_click(o, &tr, &x, &y);
                if (!isfinite(x) || !isfinite(y)) abort();
                break;
            }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char spec[512];
    size_t n = size < sizeof spec - 5 ? size : sizeof spec - 5;
    memcpy(spec, "sim:", 4);
    memcpy(spec + 4, data, n);
    spec[4 + n] = '\0';
    if (strstr(spec, "table=")) return 0;
    csf_observer_sim *o = NULL;
    csf_error err;
    err.msg[0] = '\0';
    if (csf_observer_sim_create(spec, 1, &o, &err) == CSF_OK) {
        if (!o) abort();
        exercise(o);
        csf_observer_sim_free(o);
    } else if (o != NULL || err.msg[0] == '\0') {
        abort(); /* a refusal leaves no observer and says why */
    }
    return 0;
}
