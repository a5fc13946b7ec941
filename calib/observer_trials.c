/* An observer session's trials (see observer_trials.h). */
#include "calib/observer_trials.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/motion.h"
#include "calib/trial_io.h"
#include "core/rng.h"

static csf_status blank_frames(runner *r, double seconds, int fixation, int fade_listen, csf_error *err)
{
    int n = (int)lround(seconds / r->period_s);
    for (int i = 0; i < n; i++) {
        csf_frame_info fi;
        csf_status st = csf_presenter_draw(r->pres, NULL, fixation, &fi, err);
        if (st != CSF_OK) return st;
        if (fade_listen && obs_person_fade_frame(r->who, fi.t_s, 0.0)) break;
        if (!fade_listen && r->who->sim == NULL && r->who->resp) {
            csf_response ev;
            while (csf_responder_poll(r->who->resp, &ev))
                if (ev.kind == CSF_RESP_ESCAPE) r->who->paused = 1;
        }
        if (r->who->paused) break;
    }
    return CSF_OK;
}

void obs_make_stimulus(csf_stimulus *s, double freq, double ecc, double polar, double contrast,
                       double mean_lum)
{
    memset(s, 0, sizeof *s);
    s->kind = CSF_STIM_GABOR;
    s->freq_cpd = freq;
    s->orientation_deg = 0;
    s->sigma_deg = GABOR_SIGMA_DEG;
    s->ecc_deg = ecc;
    s->polar_deg = polar;
    s->contrast = contrast;
    s->mean_lum_cdm2 = mean_lum;
}

/* 1 when a Gabor of freq at ecc fits on screen, below the Nyquist limit there, at some whole-degree
 * polar angle (the first one into *polar if not NULL); else 0, with the presenter's reason for
 * polar angle 0 in *why (if not NULL). */
int obs_cell_fits(csf_presenter *pres, double freq, double ecc, double mean_lum, double *polar,
                  csf_error *why)
{
    csf_error e;
    for (int a = 0; a < 360; a++) {
        csf_stimulus s;
        obs_make_stimulus(&s, freq, ecc, a, 0.5, mean_lum);
        if (csf_presenter_validate(pres, &s, a == 0 && why ? why : &e) == CSF_OK) {
            if (polar) *polar = a;
            return 1;
        }
    }
    return 0;
}

/* A polar angle on the cell's eccentricity ring where the whole patch fits on screen: the plan's
 * own if it fits, else the nearest of 24 rotations that does (deterministic, so resume agrees). */
int obs_fit_polar(csf_presenter *pres, double freq, double ecc, double polar, double mean_lum, double *out)
{
    csf_error e;
    for (int j = 0; j < 24; j++) {
        double cand = fmod(polar + (j % 2 ? 1 : -1) * 15.0 * ((j + 1) / 2) + 720.0, 360.0);
        csf_stimulus s;
        obs_make_stimulus(&s, freq, ecc, cand, 0.5, mean_lum);
        if (csf_presenter_validate(pres, &s, &e) == CSF_OK) {
            *out = cand;
            return 0;
        }
    }
    /* Where only a narrow arc of the ring fits, every whole degree: the same search the checks
     * before the first trial make (obs_cell_fits), so a grid they accept can always be shown. */
    return obs_cell_fits(pres, freq, ecc, mean_lum, out, NULL) ? 0 : -1;
}

static void add_flag(char *flags, const char *f)
{
    size_t n = strlen(flags);
    snprintf(flags + n, 64 - n, "%s%s", n ? "," : "", f);
}

/* The presenter's record of the trial's stimulus frames (tr->rec, just filled) into the result. */
static void take_record(trial_result *tr)
{
    tr->have_rec = 1;
    tr->shown_mean = tr->rec.contrast_shown_mean;
    tr->shown_max = tr->rec.contrast_shown_max;
    tr->frames_planned = tr->rec.frames_planned;
    tr->frames_shown = tr->rec.frames_shown;
    tr->frames_missed = tr->rec.frames_missed;
    if (tr->rec.flags[0]) add_flag(tr->flags, tr->rec.flags);
}

/* The grating of a cell as a trial shows it: the carrier drifts at the cell's velocity in this
 * trial's direction inside the stationary envelope (the person fixates the mark, so the retinal
 * velocity is the screen velocity). */
static void cell_stimulus(csf_stimulus *s, const runner *r, const csf_cell *c, double polar, double contrast,
                          trial_result *tr)
{
    obs_make_stimulus(s, c->freq_cpd, c->ecc_deg, polar, contrast, r->mean_lum);
    s->drift_hz = csf_motion_drift_hz(c, r->drift_sign);
    tr->velocity_dps = r->drift_sign * c->velocity_dps;
}

/* One fade trial: fixation, ramp (or blank frames for a catch trial), response window, click. */
csf_status obs_run_fade(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        double polar, int is_practice, trial_result *tr, csf_error *err)
{
    person *p = r->who;
    memset(tr, 0, sizeof *tr);
    tr->rt_s = tr->contrast_at_response = tr->click_x = tr->click_y = NAN;
    csf_status st = blank_frames(r, FIXATION_S, 1, 0, err);
    if (st != CSF_OK || p->paused) return st;
    double duration = is_practice ? PRACTICE_S : plan->ramp_s;
    p->pressed = 0;
    p->contrast_at_press = 0;
    p->first_frame = 1;
    p->period_s = r->period_s;
    p->catch_trial = plan->is_catch;
    if (p->sim)
        csf_observer_sim_fade_begin_v(p->sim, trial_key, c->freq_cpd, c->ecc_deg, c->velocity_dps, polar, 0.0,
                                      duration + RESPONSE_WINDOW_S, &p->tr);
    if (p->eyes) {
        st = csf_obs_screen_look_v(p->eyes, c->freq_cpd, c->ecc_deg, c->velocity_dps, &polar, 1, 0, err);
        if (st != CSF_OK) return st;
    }
    if (plan->is_catch) {
        tr->frames_planned = (int)lround(duration / r->period_s);
        st = blank_frames(r, duration, 1, 1, err);
        tr->frames_shown = tr->frames_planned;
    } else {
        csf_stimulus s;
        cell_stimulus(&s, r, c, polar, plan->contrast, tr);
        csf_envelope env = {CSF_ENV_FADE_LOG, duration, 0, pow(10.0, plan->ramp_start_log10)};
        if (is_practice) env = (csf_envelope){CSF_ENV_FIXED, duration, 0, 0};
        st = csf_presenter_run_trial(r->pres, &s, &env, 1, obs_fade_stop_cb, p, &tr->rec, err);
        if (st != CSF_OK) return st;
        take_record(tr);
        if (!p->pressed && !p->paused) p->contrast_at_press = tr->rec.contrast_shown_last;
    }
    if (st != CSF_OK || p->paused) return st;
    if (!p->pressed) {
        double keep = p->contrast_at_press;
        st = blank_frames(r, RESPONSE_WINDOW_S, 1, 1, err);
        if (st != CSF_OK || p->paused) return st;
        if (p->pressed) p->contrast_at_press = keep; /* pressed after the ramp: its last contrast */
    }
    if (p->eyes) {
        st = csf_obs_screen_stop(p->eyes, NULL, err);
        if (st != CSF_OK) return st;
    }
    tr->valid = 1;
    if (p->pressed) {
        tr->response = 1;
        tr->rt_s = csf_round9(p->press_rel_s);
        tr->contrast_at_response = csf_round9(p->contrast_at_press);
        st = obs_person_click(p, &tr->click_x, &tr->click_y, err);
        if (st != CSF_OK || p->paused) return st;
        tr->click_x = csf_round9(tr->click_x);
        tr->click_y = csf_round9(tr->click_y);
        if (tr->rt_s < ANTICIPATION_S) {
            tr->valid = 0;
            add_flag(tr->flags, "anticipation");
        }
        if (plan->is_catch) {
            add_flag(tr->flags, "false_alarm");
        } else {
            double a = polar * M_PI / 180;
            double dx = tr->click_x - c->ecc_deg * cos(a), dy = tr->click_y - c->ecc_deg * sin(a);
            /* Tolerance grows with eccentricity: pointing without looking is coarse out there. */
            if (hypot(dx, dy) > 2.0 + 0.3 * c->ecc_deg) {
                tr->valid = 0;
                add_flag(tr->flags, "click_far");
            }
        }
    }
    if (tr->frames_missed > 0) tr->valid = 0; /* the ramp was not the planned ramp */
    return CSF_OK;
}

/* The fixation period of a forced-choice trial with its place cues: rings at the n places for
 * CUE_S, then fixation alone for CUE_GAP_S. The rings are removed on every way out (a pause
 * included), so they are never on during a grating, the answer or a pause screen. */
static csf_status cued_fixation(runner *r, int n, double ecc, const double *polar, csf_error *err)
{
    double eccs[4] = {ecc, ecc, ecc, ecc};
    csf_status st = csf_presenter_set_marks(r->pres, n, eccs, polar, CUE_RADIUS_DEG, err);
    if (st != CSF_OK) return st;
    st = blank_frames(r, CUE_S, 1, 0, err);
    csf_error e;
    csf_presenter_set_marks(r->pres, 0, NULL, NULL, 0, &e); /* clearing cannot fail */
    if (st != CSF_OK || r->who->paused) return st;
    return blank_frames(r, CUE_GAP_S, 1, 0, err);
}

/* One forced-choice interval with the grating at polar_deg: its frames go into tr, and *shown is
 * the mean contrast the presenter actually put on screen (what the person could see). */
static csf_status show_afc_interval(runner *r, const csf_cell *c, double polar_deg, double contrast,
                                    trial_result *tr, double *shown, csf_error *err)
{
    csf_stimulus s;
    cell_stimulus(&s, r, c, polar_deg, contrast, tr);
    csf_envelope env = {CSF_ENV_FIXED, AFC_INTERVAL_S, 0, 0};
    csf_status st = csf_presenter_run_trial(r->pres, &s, &env, 1, NULL, NULL, &tr->rec, err);
    if (st != CSF_OK) return st;
    take_record(tr);
    *shown = csf_round9(tr->rec.contrast_shown_mean);
    return CSF_OK;
}

/* view=frame: the person looks at the n places for the next forced-choice interval (it knows
 * where the places are and how long an interval lasts, not where the grating will be). */
static csf_status eyes_look(runner *r, const csf_cell *c, const double *polar, int n, csf_error *err)
{
    if (!r->who->eyes) return CSF_OK;
    return csf_obs_screen_look_v(r->who->eyes, c->freq_cpd, c->ecc_deg, c->velocity_dps, polar, n,
                                 (int)lround(AFC_INTERVAL_S / r->period_s), err);
}

/* One 2AFC trial: place cue, two intervals, the grating in one of them; the person picks one. */
csf_status obs_run_2afc(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        double polar, trial_result *tr, csf_error *err)
{
    person *p = r->who;
    memset(tr, 0, sizeof *tr);
    tr->rt_s = tr->contrast_at_response = tr->click_x = tr->click_y = NAN;
    /* one ring: the grating appears at the same place in both intervals */
    csf_status st = cued_fixation(r, 1, c->ecc_deg, &polar, err);
    if (st != CSF_OK || p->paused) return st;
    double shown[2] = {0, 0}, seen[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        if (k == 1) {
            st = blank_frames(r, AFC_ISI_S, 1, 0, err);
            if (st != CSF_OK || p->paused) return st;
        }
        st = eyes_look(r, c, &polar, 1, err);
        if (st != CSF_OK) return st;
        if (k != plan->signal_interval) {
            st = blank_frames(r, AFC_INTERVAL_S, 1, 0, err);
            if (st == CSF_OK && p->eyes) st = csf_obs_screen_stop(p->eyes, &seen[k], err);
            if (st != CSF_OK || p->paused) return st;
            continue;
        }
        st = show_afc_interval(r, c, polar, plan->contrast, tr, &shown[k], err);
        if (st == CSF_OK && p->eyes) st = csf_obs_screen_stop(p->eyes, &seen[k], err);
        if (st != CSF_OK) return st;
    }
    tr->valid = 1;
    tr->contrast_at_response = shown[plan->signal_interval];
    if (p->sim) {
        double rt;
        tr->response = csf_observer_sim_2afc_v(p->sim, trial_key, c->freq_cpd, c->ecc_deg, c->velocity_dps,
                                               p->eyes ? seen : shown, &rt);
        if (p->eyes && p->seen_hook) p->seen_hook(p->seen_hook_ctx, 2, seen, shown);
        tr->rt_s = csf_round9(rt);
        p->sim_rt_total_s += rt;
        return CSF_OK;
    }
    csf_trial_io io = {r->pres, p->resp, &obs_stop_requested, 0};
    int choice;
    double rt;
    st = csf_trial_io_wait_choice(&io, csf_responder_now(), 0, &choice, &rt, err);
    if (io.paused) p->paused = 1;
    if (st != CSF_OK || p->paused) return st;
    tr->response = choice;
    tr->rt_s = rt;
    return CSF_OK;
}

/* One four-place trial (spatial 4AFC): fixation with the four places cued, then one interval as
 * long as a 2AFC interval with the grating at place plan->signal_interval of the layout (the
 * plan's polar_deg is not used), then the answer: a click (the nearest place) or a place key. */
csf_status obs_run_4afc(runner *r, uint64_t trial_key, const csf_cell *c, const csf_trial_plan *plan,
                        const csf_afc_layout *lay, trial_result *tr, csf_error *err)
{
    person *p = r->who;
    memset(tr, 0, sizeof *tr);
    tr->rt_s = tr->contrast_at_response = tr->click_x = tr->click_y = NAN;
    if (lay->n_alternatives != 4 || plan->signal_interval < 0 || plan->signal_interval > 3)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "four-place trial at %g cpd, %g deg: place %d of "
                             "a %d-alternative layout",
                             c->freq_cpd, c->ecc_deg, plan->signal_interval, lay->n_alternatives);
    csf_status st = cued_fixation(r, 4, c->ecc_deg, lay->polar_deg, err);
    if (st != CSF_OK || p->paused) return st;
    double shown[4] = {0, 0, 0, 0}, seen[4] = {0, 0, 0, 0};
    int sig = plan->signal_interval;
    st = eyes_look(r, c, lay->polar_deg, 4, err);
    if (st != CSF_OK) return st;
    st = show_afc_interval(r, c, lay->polar_deg[sig], plan->contrast, tr, &shown[sig], err);
    if (st == CSF_OK && p->eyes) st = csf_obs_screen_stop(p->eyes, seen, err);
    if (st != CSF_OK) return st;
    tr->valid = 1;
    tr->contrast_at_response = shown[sig];
    if (p->sim) {
        double rt;
        tr->response = csf_observer_sim_afc_v(p->sim, trial_key, c->freq_cpd, c->ecc_deg, c->velocity_dps,
                                              p->eyes ? seen : shown, 4, &rt);
        if (p->eyes && p->seen_hook) p->seen_hook(p->seen_hook_ctx, 4, seen, shown);
        tr->rt_s = csf_round9(rt);
        p->sim_rt_total_s += rt;
        return CSF_OK;
    }
    double t0 = csf_responder_now();
    csf_presenter_show_cursor(p->pres, 1);
    for (;;) {
        csf_frame_info fi;
        st = csf_presenter_draw(r->pres, NULL, 1, &fi, err);
        if (st != CSF_OK) break;
        csf_response ev;
        if (obs_stop_requested) ev.kind = CSF_RESP_ESCAPE;
        else if (!csf_responder_poll(p->resp, &ev)) continue;
        if (ev.kind == CSF_RESP_ESCAPE) {
            p->paused = 1;
            break;
        }
        /* As in obs_run_2afc, answers count from the end of the interval. */
        if (ev.t_s < t0) continue;
        if (ev.kind == CSF_RESP_CLICK) {
            double ecc, polar;
            obs_click_direction(p, &ev, &ecc, &polar);
            tr->click_x = csf_round9(ecc * cos(polar * M_PI / 180));
            tr->click_y = csf_round9(ecc * sin(polar * M_PI / 180));
            tr->response = csf_afc_nearest_place(lay, ecc, polar, c->ecc_deg);
            tr->rt_s = ev.t_s - t0;
            break;
        }
        if (ev.kind == CSF_RESP_CHOICE && ev.places == 4 && ev.choice >= 0 && ev.choice <= 3) {
            tr->response = ev.choice;
            tr->rt_s = ev.t_s - t0;
            break;
        }
    }
    csf_presenter_show_cursor(p->pres, 0);
    return st;
}

/* How many alternatives a planned trial has: 2 or 4 for forced choice, 0 for fade. */
int obs_plan_alternatives(const csf_trial_plan *plan)
{
    if (plan->task != CSF_TASK_2AFC) return 0;
    return plan->n_alternatives == 4 ? 4 : 2;
}

void obs_fill_trial(csf_trial *t, int64_t sid, int seq, const char *method, const csf_cell *c, double polar,
                    double mean_lum, const csf_trial_plan *plan, int practice, const trial_result *tr)
{
    memset(t, 0, sizeof *t);
    t->session_id = sid;
    t->seq = seq;
    snprintf(t->method, sizeof t->method, "%s", method);
    t->freq_cpd = c->freq_cpd;
    t->ecc_deg = c->ecc_deg;
    t->polar_deg = csf_round9(polar);
    t->orientation_deg = 0;
    t->sigma_deg = GABOR_SIGMA_DEG;
    t->velocity_dps = csf_round9(tr->velocity_dps);
    t->mean_lum_cdm2 = csf_round9(mean_lum);
    t->is_catch = plan->is_catch;
    t->is_practice = practice;
    t->contrast_requested = csf_round9(plan->contrast);
    t->contrast_shown_mean = csf_round9(tr->shown_mean);
    /* For fade trials contrast_shown_max holds the contrast on screen at the press: what the
     * procedure's update() needs back on resume (the highest contrast shown up to the press). */
    t->contrast_shown_max =
        plan->task == CSF_TASK_FADE ? tr->contrast_at_response : csf_round9(tr->shown_max);
    if (plan->task == CSF_TASK_2AFC) t->contrast_shown_max = tr->contrast_at_response;
    t->frames_planned = tr->frames_planned;
    t->frames_shown = tr->frames_shown;
    t->frames_missed = tr->frames_missed;
    t->signal_interval = plan->task == CSF_TASK_2AFC ? plan->signal_interval + 1 : 0;
    t->n_alternatives = obs_plan_alternatives(plan);
    t->response = plan->task == CSF_TASK_2AFC ? tr->response + 1 : tr->response;
    t->rt_s = tr->rt_s;
    t->click_x_deg = tr->click_x;
    t->click_y_deg = tr->click_y;
    t->valid = tr->valid;
    snprintf(t->flags, sizeof t->flags, "%s", tr->flags);
}

/* The outcome update() saw, rebuilt from a stored trial (the resume path and the live path use
 * this same function, so they cannot disagree). */
csf_trial_outcome obs_outcome_of(const csf_trial *t, csf_task task)
{
    csf_trial_outcome o;
    /* A fade session's forced-choice anchors are stored with their alternatives (2). */
    if (t->n_alternatives > 0) task = CSF_TASK_2AFC;
    o.response = task == CSF_TASK_2AFC ? t->response - 1 : t->response;
    o.rt_s = t->rt_s;
    o.contrast_at_response = t->contrast_shown_max;
    o.valid = t->valid;
    return o;
}

/* Seconds of the person's time one trial takes: fixation, the stimulus, the answer (a typical
 * response time; a fade ramp starts 0.8 log10 below the cell's estimate once it has one, so the
 * press comes about 1.6 s in at 0.5 log10/s, then a click: 2.9 s, where simulated sessions at
 * --precision 0.10 spent 2.8 s a trial). */
#define EXPECT_AFC_ANSWER_S 0.6
#define EXPECT_FOUR_ANSWER_S 0.7
#define EXPECT_CLICK_S 1.0
#define EXPECT_FADE_PRESS_S 1.6
double obs_trial_expected_s(csf_task task, int four)
{
    if (task == CSF_TASK_FADE) {
        return FIXATION_S + EXPECT_FADE_PRESS_S + EXPECT_CLICK_S;
    }
    if (four) return FIXATION_S + AFC_INTERVAL_S + EXPECT_FOUR_ANSWER_S;
    return FIXATION_S + 2 * AFC_INTERVAL_S + AFC_ISI_S + EXPECT_AFC_ANSWER_S;
}
