/* Trial pieces shared by observer calibration and user studies (see trial_io.h). */
#include "calib/trial_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

double csf_round9(double v)
{
    if (!isfinite(v) || v == 0) return v;
    char buf[40];
    snprintf(buf, sizeof buf, "%.9g", v);
    return strtod(buf, NULL);
}

csf_status csf_trial_io_store(csf_store *store, const csf_trial *t, csf_trial_record *rec,
                              int have_rec, csf_error *err)
{
    int n = have_rec && rec->frames_drawn > 1 ? rec->frames_drawn - 1 : 0;
    csf_status st = csf_store_add_trial_frames(store, t, n ? rec->interval_s : NULL, n, err);
    if (have_rec) csf_trial_record_free(rec);
    return st;
}

static int stop_now(const csf_trial_io *io)
{
    return io->stop && *io->stop;
}

csf_status csf_trial_io_blank(csf_trial_io *io, double seconds, int fixation, csf_error *err)
{
    double period = 1.0 / csf_presenter_refresh_hz(io->pres);
    int n = (int)lround(seconds / period);
    for (int i = 0; i < n && !io->paused; i++) {
        csf_frame_info fi;
        csf_status st = csf_presenter_draw(io->pres, NULL, fixation, &fi, err);
        if (st != CSF_OK) return st;
        if (!io->resp) continue;
        if (stop_now(io)) io->paused = 1;
        csf_response ev;
        while (csf_responder_poll(io->resp, &ev))
            if (ev.kind == CSF_RESP_ESCAPE) io->paused = 1;
    }
    return CSF_OK;
}

csf_status csf_trial_io_wait_choice(csf_trial_io *io, double t0, double window_s, int *choice,
                                    double *rt_s, csf_error *err)
{
    *choice = -1;
    *rt_s = NAN;
    for (;;) {
        csf_frame_info fi;
        csf_status st = csf_presenter_draw(io->pres, NULL, 1, &fi, err);
        if (st != CSF_OK) return st;
        if (window_s > 0 && csf_responder_now() - t0 > window_s) return CSF_OK;
        csf_response ev;
        if (stop_now(io)) ev.kind = CSF_RESP_ESCAPE;
        else if (!csf_responder_poll(io->resp, &ev)) continue;
        if (ev.kind == CSF_RESP_ESCAPE) {
            io->paused = 1;
            return CSF_OK;
        }
        /* Left / right mouse button answer too (the only answers a "mouse" responder has). */
        if (ev.kind == CSF_RESP_CLICK && (ev.choice == 0 || ev.choice == 1)) {
            ev.kind = CSF_RESP_CHOICE;
            ev.places = 2;
        }
        /* The four-place keys mean nothing in a two-way answer. */
        if (ev.kind == CSF_RESP_CHOICE && ev.places == 4) continue;
        if (ev.kind == CSF_RESP_CHOICE && ev.t_s >= t0) {
            *choice = ev.choice;
            *rt_s = ev.t_s - t0;
            return CSF_OK;
        }
    }
}

csf_status csf_trial_io_screen(csf_trial_io *io, const char *text, csf_error *err)
{
    if (!io->resp) return CSF_OK;
    csf_status st = csf_presenter_text_screen(io->pres, text, err);
    if (st != CSF_OK) return st;
    csf_response ev;
    for (;;) {
        if (stop_now(io)) {
            io->paused = 1;
            return CSF_OK;
        }
        if (csf_responder_poll(io->resp, &ev)) {
            if (ev.kind == CSF_RESP_ESCAPE) io->paused = 1;
            if (ev.kind != CSF_RESP_NONE) return CSF_OK;
        }
        st = csf_presenter_text_screen(io->pres, text, err);
        if (st != CSF_OK) return st;
    }
}
