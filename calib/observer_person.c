/* The person of an observer session (see observer_person.h). */
#include "calib/observer_person.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/trial_io.h"

volatile sig_atomic_t obs_stop_requested;

/* Time since onset on the refresh grid: the virtual clock makes it an exact multiple of the
 * period; rounding keeps a resumed run identical to an uninterrupted one. */
static double rel_time(const person *p, double t_s)
{
    return p->period_s * floor((t_s - p->onset_s) / p->period_s + 0.5);
}

/* Called for every frame of a fade trial (presenter callback or our own blank frames). */
int obs_person_fade_frame(person *p, double t_s, double contrast_shown)
{
    if (p->first_frame) {
        p->onset_s = t_s;
        p->first_frame = 0;
    }
    double rel = rel_time(p, t_s);
    if (p->sim) {
        double press, seen = p->eyes ? csf_obs_screen_latest(p->eyes) : contrast_shown;
        if (csf_observer_sim_fade_frame(p->sim, &p->tr, rel, csf_round9(seen), &press)) {
            p->pressed = 1;
            p->press_rel_s = press;
            p->contrast_at_press = contrast_shown;
            return 1;
        }
        return 0;
    }
    csf_response ev;
    if (obs_stop_requested) { /* SIGINT/SIGTERM: pause as Escape + stop would */
        p->paused = 1;
        return 1;
    }
    while (p->resp && csf_responder_poll(p->resp, &ev)) {
        if (ev.kind == CSF_RESP_ESCAPE) {
            p->paused = 1;
            return 1;
        }
        if (ev.kind == CSF_RESP_PRESS || ev.kind == CSF_RESP_CLICK) {
            p->pressed = 1;
            /* Events are stamped on raw CLOCK_MONOTONIC, frames on the presenter's clock (zero
             * at its first frame): move the event onto the presenter's clock first. */
            double offset = csf_responder_now() - csf_presenter_time(p->pres);
            p->press_rel_s = (ev.t_s - offset) - p->onset_s;
            p->contrast_at_press = contrast_shown;
            return 1;
        }
    }
    return 0;
}

int obs_fade_stop_cb(void *ctx, const csf_frame_info *f)
{
    return obs_person_fade_frame(ctx, f->t_s, f->contrast_shown);
}

/* The direction (eccentricity, polar angle) of a click from the line of sight. */
void obs_click_direction(const person *p, const csf_response *ev, double *ecc, double *polar)
{
    double xm, ym;
    /* The click is in window framebuffer pixels; the geometry is in the configured resolution,
     * which the window may not have (the presenter then draws the configured screen scaled to
     * the window). */
    int rw, rh;
    csf_presenter_render_size(p->pres, &rw, &rh);
    double sx = rw > 0 ? (double)p->geom->width_px / rw : 1.0;
    double sy = rh > 0 ? (double)p->geom->height_px / rh : 1.0;
    csf_geometry_px_to_mm(p->geom, ev->x_px * sx, ev->y_px * sy, &xm, &ym);
    csf_geometry_mm_to_deg(p->geom, xm, ym, ecc, polar);
}

/* Waits for the click that says where the grating was; returns visual-angle x, y. */
csf_status obs_person_click(person *p, double *x_deg, double *y_deg, csf_error *err)
{
    if (p->sim) {
        csf_observer_sim_click(p->sim, &p->tr, x_deg, y_deg);
        return CSF_OK;
    }
    csf_presenter_show_cursor(p->pres, 1);
    csf_response ev;
    for (;;) {
        csf_frame_info fi;
        csf_status st = csf_presenter_draw(p->pres, NULL, 1, &fi, err);
        if (st != CSF_OK) return st;
        if (obs_stop_requested) ev.kind = CSF_RESP_ESCAPE;
        else if (!csf_responder_poll(p->resp, &ev)) continue;
        if (ev.kind == CSF_RESP_ESCAPE) {
            p->paused = 1;
            *x_deg = *y_deg = NAN;
            break;
        }
        if (ev.kind == CSF_RESP_CLICK) {
            double ecc, polar;
            obs_click_direction(p, &ev, &ecc, &polar);
            *x_deg = ecc * cos(polar * M_PI / 180);
            *y_deg = ecc * sin(polar * M_PI / 180);
            break;
        }
    }
    csf_presenter_show_cursor(p->pres, 0);
    return CSF_OK;
}

#define READING_WORDS_PER_MIN 238.0
double obs_reading_s(const char *text)
{
    int words = 0;
    for (const char *c = text; c && *c; c++)
        if (!isspace((unsigned char)*c) && (c == text || isspace((unsigned char)c[-1]))) words++;
    return words * 60.0 / READING_WORDS_PER_MIN;
}

/* Text screen; a human reads it and presses a key (Escape = pause); a simulated person takes the
 * time to read it, and nothing is drawn (cairo's font machinery is skipped). */
csf_status obs_person_screen(person *p, const char *text, csf_error *err)
{
    if (p->sim) {
        p->sim_rt_total_s += obs_reading_s(text);
        return CSF_OK;
    }
    csf_trial_io io = {p->pres, p->resp, &obs_stop_requested, 0};
    csf_status st = csf_trial_io_screen(&io, text, err);
    if (io.paused) p->paused = 1;
    return st;
}

/* Escape during a human session: offer to resume or stop (data kept either way). Returns 1 to
 * resume (the interrupted trial is shown again), 0 to stop (the session is stored as paused). */
int obs_ask_resume(person *p, int done, int total)
{
    if (p->sim || !p->resp) return 0;
    char msg[200];
    snprintf(msg, sizeof msg,
             "Paused after %d of %d trials; everything so far is saved.\n"
             "R: resume now.  S or Escape: stop (continue later with --resume).",
             done, total);
    csf_error e;
    for (;;) {
        if (obs_stop_requested) return 0;
        if (csf_presenter_text_screen(p->pres, msg, &e) != CSF_OK) return 0;
        csf_response ev;
        while (csf_responder_poll(p->resp, &ev)) {
            if (ev.kind == CSF_RESP_ESCAPE) return 0;
            if (ev.kind == CSF_RESP_KEY && (ev.key == 'S' || ev.key == 's')) return 0;
            if (ev.kind == CSF_RESP_KEY && (ev.key == 'R' || ev.key == 'r')) {
                p->paused = 0;
                return 1;
            }
        }
    }
}
