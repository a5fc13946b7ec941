/* Per-user CSF calibration session (see observer_calib.h and observer_session.h). */
#include "calib/observer_calib.h"

#include <jansson.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "calib/afc_layout.h"
#include "calib/motion.h"
#include "calib/observer_checks.h"
#include "calib/observer_person.h"
#include "calib/observer_run.h"
#include "calib/observer_screen.h"
#include "calib/observer_session.h"
#include "calib/observer_settings.h"
#include "calib/observer_trials.h"
#include "calib/procedure.h"
#include "calib/trial_io.h"
#include "core/rng.h"
#include "devices/responder.h"
#include "model/observer_sim.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "stimuli/geometry.h"
#include "stimuli/presenter.h"

#define DEFAULT_TRIALS_PER_CELL 5 /* the static default's rate: 120 trials over 24 cells */
#define MIN_TRIALS_PER_CELL 4     /* fade and 2afc with a velocity axis: fewer estimate nothing */
#define PRECISION_CAP_PER_CELL 40 /* --precision without --trials: the cap (960 over 24 cells) */
#define PRECISION_MIN_TRIALS 10   /* no stop before this many trials: the prior alone is not a table */

enum { ST_PRACTICE_POLAR = 0x5e551, ST_POLAR_FIX, ST_ANCHOR_PRACTICE, ST_DEMO };

static void on_signal(int sig)
{
    (void)sig;
    obs_stop_requested = 1;
}

void csf_obs_options_defaults(csf_obs_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = "bayes";
    o->trials = 0; /* the default: 120, or 5 per cell shown with a velocity axis */
    o->practice = -1;
    o->break_every = 40;
    o->seed = 1;
    o->render_every = 0; /* 1, or -1 with view=frame (the person rasterises its own regions) */
    o->render_w = 64;
    o->render_h = 36;
    o->afc = 0; /* four places; 0 tells a fade session that --afc was not given */
}

/* ---- settings (stored with the session, read back on resume) --------------------------------- */

/* The default budget per cell: the static default's rate, or a cap when the session stops at a
 * precision instead. */
static int default_trials_per_cell(const session_settings *set)
{
    return set->precision > 0 ? PRECISION_CAP_PER_CELL : DEFAULT_TRIALS_PER_CELL;
}

/* ---- session -------------------------------------------------------------------------------- */

void obs_now_utc(char *buf, size_t len)
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

static void session_free(session_res *s)
{
    if (s->proc) s->ops->destroy(s->proc);
    free(s->stored);
    free(s->cells);
    free(s->est);
    free(s->layouts);
    free(s->n_alt);
    free(s->not_shown);
}

/* Commits a trial and its frame intervals in one transaction (a crash cannot leave a trial
 * without its timing), frees the frame record, and appends the trial to the session's copy. */
static csf_status store_trial(session_res *S, size_t *n_stored, const csf_trial *t, trial_result *tr,
                              csf_error *err)
{
    csf_status st = csf_trial_io_store(S->store, t, &tr->rec, tr->have_rec, err);
    tr->have_rec = 0;
    if (st != CSF_OK) return st;
    csf_trial *grown = realloc(S->stored, (*n_stored + 1) * sizeof *S->stored);
    if (!grown) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    S->stored = grown;
    S->stored[(*n_stored)++] = *t;
    return CSF_OK;
}

/* The forced-choice layout of every cell: four places (spatial 4AFC) when the session asks for
 * them, the method is a forced-choice one, csf_afc_choose_layout finds four places apart on the
 * screen, and the presenter accepts the cell's Gabor at each of them (on screen, below the
 * Nyquist limit there); two intervals otherwise. A function of the settings and the display
 * only, so a resumed session gets the layout it had. */
static csf_status choose_layouts(session_res *S, const csf_geometry *g, int n_cells, int afc,
                                 double mean_lum, csf_error *err)
{
    S->layouts = calloc((size_t)n_cells, sizeof *S->layouts);
    S->n_alt = calloc((size_t)n_cells, sizeof *S->n_alt);
    if (!S->layouts || !S->n_alt) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    int want = (afc == 4 && S->ops->task == CSF_TASK_2AFC) ? 4 : 2;
    for (int k = 0; k < n_cells; k++) {
        csf_afc_layout *l = &S->layouts[k];
        csf_afc_choose_layout(g, S->cells[k].ecc_deg, GABOR_SIGMA_DEG, want, l);
        for (int j = 0; j < 4 && l->n_alternatives == 4; j++) {
            csf_stimulus st;
            csf_error e;
            obs_make_stimulus(&st, S->cells[k].freq_cpd, S->cells[k].ecc_deg, l->polar_deg[j], 0.5, mean_lum);
            st.drift_hz = csf_motion_drift_hz(&S->cells[k], 1);
            if (csf_presenter_validate(S->pres, &st, &e) != CSF_OK) l->n_alternatives = 2;
        }
        S->n_alt[k] = l->n_alternatives == 4 ? 4 : 2;
    }
    return CSF_OK;
}

static double practice_latency(const csf_trial *t, size_t n)
{
    double sum = 0;
    int k = 0;
    for (size_t i = 0; i < n; i++)
        if (t[i].is_practice && t[i].response == 1 && t[i].rt_s >= ANTICIPATION_S && t[i].rt_s <= 1.5) {
            sum += t[i].rt_s;
            k++;
        }
    return k ? sum / k : NAN;
}

/* One practice trial, shown and stored as practice (the procedure never sees it). When the person
 * pauses nothing is stored and the caller looks at who->paused. */
static csf_status practice_trial(session_res *S, runner *run, int64_t sid, const char *method, uint64_t key,
                                 const csf_cell *cell, const csf_trial_plan *plan, const csf_afc_layout *layout,
                                 double mean_lum, int *seq, size_t *n_stored, csf_error *err)
{
    int four = plan->n_alternatives == 4;
    trial_result tr;
    csf_status st = plan->task == CSF_TASK_FADE ? obs_run_fade(run, key, cell, plan, 0, 1, &tr, err)
                    : four                      ? obs_run_4afc(run, key, cell, plan, layout, &tr, err)
                                                : obs_run_2afc(run, key, cell, plan, 0, &tr, err);
    if (st != CSF_OK) return st;
    if (run->who->paused) {
        if (tr.have_rec) csf_trial_record_free(&tr.rec);
        return CSF_OK;
    }
    csf_trial t;
    obs_fill_trial(&t, sid, *seq, method, cell, four ? layout->polar_deg[plan->signal_interval] : 0, mean_lum,
                   plan, 1, &tr);
    st = store_trial(S, n_stored, &t, &tr, err);
    if (st == CSF_OK) (*seq)++;
    return st;
}

/* Two suprathreshold two-interval practice trials before a fade session's forced-choice anchors:
 * the person has not done that task yet. A resumed session runs only the ones it does not have
 * yet. Returns CSF_OK also when the person paused: the caller looks at who->paused. */
#define ANCHOR_PRACTICE 2
static csf_status anchor_practice(session_res *S, runner *run, int64_t sid, const char *method, uint64_t seed,
                                  double mean_lum, int *seq, size_t *n_stored, csf_error *err)
{
    int have = 0;
    for (size_t i = 0; i < *n_stored; i++)
        have += S->stored[i].is_practice && S->stored[i].n_alternatives == 2;
    for (int k = have; k < ANCHOR_PRACTICE && !run->who->paused && !obs_stop_requested; k++) {
        csf_cell pc_cell = {PRACTICE_FREQ, 0, 0};
        csf_trial_plan plan;
        memset(&plan, 0, sizeof plan);
        plan.task = CSF_TASK_2AFC;
        plan.n_alternatives = 2;
        plan.contrast = PRACTICE_CONTRAST;
        plan.signal_interval = (int)(csf_rng_u64(seed, ST_ANCHOR_PRACTICE, (uint64_t)k) & 1);
        uint64_t key = 2000000u + (uint64_t)k; /* never collides with main or session practice draws */
        csf_status st = practice_trial(S, run, sid, method, key, &pc_cell, &plan, NULL, mean_lum, seq, n_stored, err);
        if (st != CSF_OK) return st;
    }
    return CSF_OK;
}

/* ---- one observer session, in phases -------------------------------------------------------- */

/* A resumed session's settings, from the store; a session that cannot be resumed says why. */
static csf_status resumed_settings(obs_run *R, csf_error *err)
{
    session_settings *set = &R->set;
    int64_t sid = R->sid;
    csf_session_info info;
    memset(&info, 0, sizeof info);
    csf_status st = csf_store_get_session(R->S.store, sid, &info, err);
    if (st != CSF_OK) return st;
    /* A kind or state this build does not know is never taken for a known one. */
    int wrong = info.kind != CSF_SESSION_OBSERVER || !csf_session_state_open(info.state);
    char kind[64], state[64]; /* as stored, escaped: the row may hold any bytes */
    csf_store_printable(info.kind_text, kind, sizeof kind);
    csf_store_printable(info.state_text, state, sizeof state);
    R->seed = info.seed;
    R->resume_n_stored = info.n_trials;
    int unreadable = !wrong && csf_obs_settings_from_json(info.settings_json, set) != 0;
    csf_error why;
    csf_error_clear(&why);
    int invalid = !wrong && !unreadable && obs_check_settings(set, 0, &why) != CSF_OK;
    /* Sessions stored before the settings carried the profile id: the store's profile_id
     * (schema 5 moved it there from the display column). */
    if (!wrong && !set->profile_id[0]) snprintf(set->profile_id, sizeof set->profile_id, "%s", info.profile_id);
    csf_session_info_free(&info);
    if (wrong)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--resume %lld: session is a %s session in state '%s'; only running or "
                             "paused observer sessions can be resumed", (long long)sid, kind, state);
    if (unreadable || invalid) {
        /* Replaying them would fail the same way at every attempt: say so once, and take the
         * session off the resumable list; its trials stay in the store. */
        csf_error e2;
        csf_store_set_session_state(R->S.store, sid, CSF_SESSION_ABORTED, &e2);
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--resume %lld: the session's stored settings %s%s. It cannot be resumed "
                             "and is now marked aborted; its %d trials stay in the store (csfcal "
                             "sessions export %lld); start a new session", (long long)sid,
                             unreadable ? "cannot be read" : "are not valid: ", unreadable ? "" : why.msg,
                             R->resume_n_stored, (long long)sid);
    }
    return CSF_OK;
}

/* A new session's settings, from the options, the configuration and the display's defaults. */
static csf_status new_settings(obs_run *R, csf_error *err)
{
    const csf_obs_options *opt = R->opt;
    session_settings *set = &R->set;
    snprintf(set->method, sizeof set->method, "%s", opt->method ? opt->method : "bayes");
    const char *spec = opt->observer_spec ? opt->observer_spec : (R->cfg->observer[0] ? R->cfg->observer : "sim");
    if (strchr(spec, '"') || strchr(spec, '\\'))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: quotes and backslashes are not allowed");
    snprintf(set->observer, sizeof set->observer, "%s", spec);
    /* With a velocity axis the default budget grows with the grid (5 trials per cell shown: the
     * static default's rate); the cells a display cannot show are taken off once it is open. */
    set->trials = opt->trials > 0 ? opt->trials : (opt->n_vels > 0 || opt->precision_log10 > 0) ? 0 : 120;
    set->precision = opt->precision_log10;
    if (opt->precision_log10 != 0 && !(opt->precision_log10 >= 0.001 && opt->precision_log10 <= 2.0))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--precision %g: expected a predicted RMS error from 0.001 "
                             "to 2 log10 units",
                             opt->precision_log10);
    set->n_vels = opt->n_vels;
    set->drift_direction = opt->drift_direction;
    if (opt->n_vels < 0 || opt->n_vels > CSF_OBS_MAX_AXIS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--velocities: at most %d values", CSF_OBS_MAX_AXIS);
    memcpy(set->vels, opt->vels_dps, sizeof set->vels);
    set->practice = opt->practice >= 0 ? opt->practice : 3;
    set->break_every = opt->break_every > 0 ? opt->break_every : 40;
    set->afc = opt->afc ? opt->afc : 4;
    set->fade_anchors = opt->fade_anchor_share == 0 ? CSF_FADE_ANCHOR_SHARE_DEFAULT : opt->fade_anchor_share;
    if (!(set->fade_anchors <= CSF_FADE_ANCHOR_SHARE_MAX))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--fade-anchors %g: above the limit %g", opt->fade_anchor_share,
                             CSF_FADE_ANCHOR_SHARE_MAX);
    if (strcmp(set->method, "fade") != 0) {
        if (opt->fade_anchor_share != 0 && !opt->quiet)
            fprintf(stderr, "csfcal: observer: --fade-anchors applies to --method fade only; "
                            "ignored for --method %s\n", set->method);
        set->fade_anchors = 0;
    }
    if (set->fade_anchors < 0) set->fade_anchors = 0;
    if (set->afc != 2 && set->afc != 4)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--afc %d: expected 2 (two intervals) or 4 "
                             "(four places where they fit)", opt->afc);
    /* A fade session's only forced-choice trials are its anchors, two-interval at every cell;
     * storing the layout it did not use would mislead a report or a resume. */
    if (strcmp(set->method, "fade") == 0) {
        if (opt->afc && !opt->quiet)
            fprintf(stderr, "csfcal: observer: --afc applies to --method bayes and 2afc; a fade "
                            "session's anchor trials are two-interval\n");
        set->afc = 2;
    }
    if (opt->n_freqs < 0 || opt->n_freqs > CSF_OBS_MAX_AXIS || opt->n_eccs < 0 || opt->n_eccs > CSF_OBS_MAX_AXIS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--freqs/--eccs: at most %d values each", CSF_OBS_MAX_AXIS);
    memcpy(set->freqs, opt->freqs_cpd, sizeof set->freqs);
    memcpy(set->eccs, opt->eccs_deg, sizeof set->eccs);
    set->n_freqs = opt->n_freqs;
    set->n_eccs = opt->n_eccs;
    obs_default_axes(&R->geom, set, opt->quiet);
    if (set->n_freqs == 0 || set->n_eccs == 0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer: no frequency or eccentricity fits this display");
    if (set->trials == 0) {
        R->default_budget = 1;
        int n_vel = set->n_vels > 0 ? set->n_vels : 1;
        set->trials = default_trials_per_cell(set) * set->n_freqs * set->n_eccs * n_vel;
        if (set->trials > 5000) set->trials = 5000;
    }
    /* Any order is accepted and sorted (the table's axes increase); a value given twice is
     * refused. */
    return obs_check_settings(set, 1, err);
}

/* The method, and which person answers: a simulated one (its resources give it) or a human, who
 * needs a window. */
static csf_status choose_method_and_person(obs_run *R, csf_error *err)
{
    const session_settings *set = &R->set;
    R->S.ops = csf_procedure_find(set->method);
    if (!R->S.ops) {
        if (strcmp(set->method, "bayes") == 0)
            return csf_error_set(err, CSF_E_UNSUPPORTED,
                                 "--method bayes: the joint Bayesian method is not in this build; use "
                                 "--method fade or --method 2afc");
        return csf_error_set(err, CSF_E_INVALID_ARG, "--method %s: unknown (fade, 2afc, bayes)", set->method);
    }
    snprintf(R->res->method, sizeof R->res->method, "%s", set->method);
    R->is_sim = strncmp(set->observer, "sim", 3) == 0 && (set->observer[3] == '\0' || set->observer[3] == ':');
    R->is_human = strncmp(set->observer, "human", 5) == 0;
    if (!R->is_sim && !R->is_human)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer %s: expected sim[:key=value,...] or human",
                             set->observer);
    if (R->is_human && R->opt->headless)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "--observer human needs a display: no window can be opened headless "
                             "(use --observer sim for a simulated session)");
    return CSF_OK;
}

/* The lent resources into the session: a simulated person needs its own, a human a responder. */
static csf_status take_resources(obs_run *R, const csf_obs_resources *r, csf_error *err)
{
    session_res *S = &R->S;
    if (!r->pres || !r->profile || (R->is_sim ? !r->sim : !r->resp))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "observer session: a presenter, a display profile and %s "
                             "are needed",
                             R->is_sim ? "the simulated person" : "a responder");
    if (r->store) S->store = r->store;
    S->pres = r->pres;
    S->profile = r->profile;
    S->sim = r->sim;
    S->resp = r->resp;
    S->screen = r->eyes;
    double lb, lm;
    csf_presenter_lum_range(S->pres, &lb, &lm);
    R->mean_lum_cdm2 = 0.5 * (lb + lm);
    R->max_contrast = floor(0.98 * (lm - lb) / (lm + lb) * 1000) / 1000;
    return CSF_OK;
}

/* This screen can show the session's grid (and, resumed, with the profile it began with). */
static csf_status check_display_side(obs_run *R, csf_error *err)
{
    const csf_obs_options *opt = R->opt;
    session_res *S = &R->S;
    csf_status st =
        obs_check_grid_on_screen(S->pres, R->cfg, &R->set, R->set.practice, R->mean_lum_cdm2, err);
    if (st != CSF_OK) {
        if (R->sid) {
            char m[sizeof err->msg];
            snprintf(m, sizeof m, "%s", err->msg);
            csf_error_set(err, CSF_E_INVALID_ARG, "--resume %lld: %s (this screen cannot show the session's "
                          "grid: resume with the screen settings it began with)", (long long)R->sid, m);
        }
        return st;
    }
    if (R->sid)
        return obs_check_profile_on_resume(S->store, R->sid, R->set.profile_id, R->resume_n_stored,
                                           S->profile, R->cfg, opt->allow_profile_change, opt->quiet, err);
    return CSF_OK;
}

static double expected_trial_s(const obs_run *R, int four)
{
    return obs_trial_expected_s(R->S.ops->task, four);
}

/* Told before a fade session's forced-choice anchors. */
#define ANCHOR_INSTRUCTIONS                                                                                  \
    "Last part: the pattern now appears in one of two intervals,\n"                                          \
    "at the place a ring marks just before.\n"                                                               \
    "Press 1 or Left for the first interval, 2 or Right for the second.\n"                                   \
    "Two easy practice trials first. When unsure, guess.\n"                                                  \
    "Escape pauses. Press a key to go on."

static const char *instructions(const obs_run *R);

/* Whether this run shows the instructions: not on a resume with trials stored, which goes
 * straight to the trials (run_practice). */
static int shows_instructions(const obs_run *R)
{
    return !R->opt->resume_id || R->n_stored == 0;
}

/* The time to read what a run shows around its trials: the instructions when it shows them
 * (shows_instructions), and for fade the anchors' whenever it plans
 * them (every run tells them before its first forced-choice trial). */
static double expected_reading_s(const obs_run *R, int instructions_shown)
{
    int anchors = R->S.ops->task == CSF_TASK_FADE && R->set.fade_anchors > 0;
    return (instructions_shown ? obs_reading_s(instructions(R)) : 0.0) +
           (anchors ? obs_reading_s(ANCHOR_INSTRUCTIONS) : 0.0);
}

/* A run's expected person time, share_four of its trials with four places: reading, the practice
 * trials it still runs and its main trials. */
static double expected_session_s(const obs_run *R, int trials, double share_four, int instructions_shown,
                                 int practice)
{
    double per = (1.0 - share_four) * expected_trial_s(R, 0) + share_four * expected_trial_s(R, 1);
    return expected_reading_s(R, instructions_shown) + practice * expected_trial_s(R, 0) + trials * per;
}

/* A drifting grid on this display: the cells it cannot show (their temporal frequency would
 * alias), refused for the per-cell methods with the limit per frequency; the default budget for
 * the cells it can show, and a budget too small for the grid refused with the time it would need.
 * Before anything is stored. */
static csf_status check_motion_grid(obs_run *R, csf_error *err)
{
    session_settings *set = &R->set;
    if (set->n_vels == 0) return CSF_OK;
    double refresh_hz = csf_presenter_refresh_hz(R->S.pres);
    int n_cells = set->n_freqs * set->n_eccs * set->n_vels, n_alias = 0;
    for (int v = 0; v < set->n_vels; v++)
        for (int f = 0; f < set->n_freqs; f++)
            n_alias +=
                csf_motion_aliases(&(csf_cell){set->freqs[f], 0, set->vels[v]}, refresh_hz) * set->n_eccs;
    int per_cell = strcmp(set->method, "bayes") != 0;
    char limits[700];
    csf_motion_limits_text(set->freqs, set->n_freqs, set->vels, set->n_vels, refresh_hz, limits,
                           sizeof limits);
    if (n_alias > 0 && per_cell)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--velocities: %d of %d cells drift too fast for this display (a temporal "
                             "frequency v*f at or above half the refresh rate aliases): %s. --method %s "
                             "measures each cell on its own and cannot predict them: drop those velocities "
                             "or frequencies, or use --method bayes, which predicts them",
                             n_alias, n_cells, limits, set->method);
    int n_shown = n_cells - n_alias;
    R->n_not_shown = n_alias;
    if (n_shown == 0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--velocities: no cell can be shown on this display: %s",
                             limits);
    if (R->default_budget) {
        int per = default_trials_per_cell(set);
        set->trials = per * n_shown > 5000 ? 5000 : per * n_shown;
    }
    int need = (per_cell ? MIN_TRIALS_PER_CELL : 1) * n_shown;
    if (set->trials < need)
        return csf_error_set(
            err, CSF_E_INVALID_ARG,
            "--trials %d: the grid has %d cells this display can show and --method %s needs at "
            "least %d trials for it (about %.1f minutes of the person's time); give --trials %d "
            "or fewer cells",
            set->trials, n_shown, set->method, need,
            expected_session_s(R, need, 0.0, 1, set->practice) / 60.0, need);
    if (n_alias > 0 && !R->opt->quiet)
        fprintf(stderr,
                "csfcal: observer: %d of %d cells cannot be shown (%s); the table holds the "
                "method's prediction there, with its stated error\n",
                n_alias, n_cells, limits);
    return CSF_OK;
}

/* A --precision the cap cannot be expected to reach is said, with the estimate, and run anyway:
 * the person's answers decide, and the table is written either way. */
static void warn_precision_reach(const obs_run *R)
{
    const session_settings *set = &R->set;
    int n_shown = set->n_freqs * set->n_eccs * (set->n_vels > 0 ? set->n_vels : 1) - R->n_not_shown;
    if (set->precision <= 0 || n_shown <= 0 || R->opt->quiet) return;
    double reach = csf_precision_expected_rms(R->S.ops, n_shown, set->trials);
    if (set->precision < reach)
        fprintf(stderr,
                "csfcal: observer: --precision %g log10 is probably out of reach of the cap of %d trials "
                "over %d cells (expect about %.2f log10 there); running to the cap\n",
                set->precision, set->trials, n_shown, reach);
}

/* The session's row in the store: a new one now that every check has passed, or the resumed one
 * set running again. */
static csf_status open_session_row(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    session_settings *set = &R->set;
    csf_status st;
    if (R->sid) {
        st = csf_store_set_session_state(S->store, R->sid, CSF_SESSION_RUNNING, err);
        if (st == CSF_OK) R->res->session_id = R->sid;
        return st;
    }
    snprintf(set->profile_id, sizeof set->profile_id, "%s", csf_profile_id(S->profile));
    if (!S->store)
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer session: no results store was given");
    char json[4096];
    if (csf_obs_settings_to_json(set, GABOR_SIGMA_DEG, json, sizeof json) != 0)
        return csf_error_set(err, CSF_E_NOMEM, "observer: the session's settings do not fit in %zu bytes", sizeof json);
    char obs_name[64];
    snprintf(obs_name, sizeof obs_name, "%.60s",
             R->is_sim ? "sim" : (set->observer[5] == ':' ? set->observer + 6 : "human"));
    st = csf_store_begin_session_profile(S->store, CSF_SESSION_OBSERVER, obs_name,
                                         csf_profile_display(S->profile), csf_profile_id(S->profile), json,
                                         R->seed, &R->sid, err);
    if (st == CSF_OK) R->res->session_id = R->sid;
    return st;
}

/* The person the trials are run with, on the session's presenter. */
static void init_person(obs_run *R)
{
    session_res *S = &R->S;
    person *who = &R->who;
    memset(who, 0, sizeof *who);
    who->sim = S->sim;
    who->eyes = S->screen;
    who->seen_hook = R->opt->seen_hook;
    who->seen_hook_ctx = R->opt->seen_hook_ctx;
    who->resp = S->resp;
    who->pres = S->pres;
    who->geom = csf_presenter_geometry(S->pres);
    R->run = (runner){S->pres, who, R->mean_lum_cdm2, 1.0 / csf_presenter_refresh_hz(S->pres), 1};
}

/* The cells, the trials already stored (resume), each cell's layout, and the layout of the
 * four-place practice grating: at the smallest eccentricity that has four places, checked like
 * the cells'. Then the person the trials will be run with. */
static csf_status prepare_cells(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    const session_settings *set = &R->set;
    csf_obs_result *res = R->res;
    int n_vel = set->n_vels > 0 ? set->n_vels : 1;
    int n_cells = R->n_cells = set->n_freqs * set->n_eccs * n_vel;
    S->cells = malloc((size_t)n_cells * sizeof *S->cells);
    S->est = malloc((size_t)n_cells * sizeof *S->est);
    S->not_shown = calloc((size_t)n_cells, 1);
    if (!S->cells || !S->est || !S->not_shown) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    /* the table's node order: velocity, then eccentricity, then frequency */
    for (int v = 0; v < n_vel; v++)
        for (int e = 0; e < set->n_eccs; e++)
            for (int f = 0; f < set->n_freqs; f++)
                S->cells[(v * set->n_eccs + e) * set->n_freqs + f] =
                    (csf_cell){set->freqs[f], set->eccs[e], set->n_vels > 0 ? set->vels[v] : 0};
    R->n_not_shown =
        csf_motion_mark_not_shown(S->cells, n_cells, csf_presenter_refresh_hz(S->pres), S->not_shown);
    csf_status st = csf_store_get_trials(S->store, R->sid, &S->stored, &R->n_stored, err);
    if (st != CSF_OK) return st;
    res->n_stored = (int)R->n_stored;
    st = choose_layouts(S, csf_presenter_geometry(S->pres), n_cells, set->afc, R->mean_lum_cdm2, err);
    if (st != CSF_OK) return st;
    res->afc = set->afc;
    for (int k = 0; k < n_cells; k++) res->n_cells_four_place += S->n_alt[k] == 4;
    R->prac_layout = (csf_afc_layout){2, {0, 0, 0, 0}};
    R->prac_ecc_deg = INFINITY;
    for (int k = 0; k < n_cells; k++)
        if (S->n_alt[k] == 4 && S->cells[k].ecc_deg < R->prac_ecc_deg) {
            R->prac_ecc_deg = S->cells[k].ecc_deg;
            R->prac_layout = S->layouts[k];
        }
    for (int j = 0; j < 4 && R->prac_layout.n_alternatives == 4; j++) {
        csf_stimulus ps;
        csf_error e;
        obs_make_stimulus(&ps, PRACTICE_FREQ, R->prac_ecc_deg, R->prac_layout.polar_deg[j], PRACTICE_CONTRAST,
                          R->mean_lum_cdm2);
        if (csf_presenter_validate(S->pres, &ps, &e) != CSF_OK) R->prac_layout.n_alternatives = 2;
    }
    init_person(R);
    return CSF_OK;
}

/* What the person is told before the first trial: depends on the task and the layouts. */
static const char *instructions(const obs_run *R)
{
    if (R->S.ops->task == CSF_TASK_2AFC && R->res->n_cells_four_place > 0)
        return "Look at the central mark and keep your eyes on it.\n"
               "Rings mark the places just before the pattern appears.\n"
               "One ring: the pattern appears there in one of two intervals:\n"
               "press 1 or Left for the first, 2 or Right for the second.\n"
               "Four rings: it appears once, at one of the four places:\n"
               "click that place, or press keypad 9 7 1 3 or I U J K\n"
               "(upper right, upper left, lower left, lower right).\n"
               "When unsure, guess. Escape pauses. Press a key to start.";
    if (R->S.ops->task == CSF_TASK_2AFC)
        return "Look at the central mark.\n"
               "A ring marks the place just before the pattern appears.\n"
               "The pattern appears there in one of two intervals.\n"
               "Press 1 or Left for the first, 2 or Right for the second.\n"
               "Escape pauses. Press a key to start.";
    return "Look at the central mark and keep your eyes on it.\n"
           "A faint pattern slowly appears somewhere.\n"
           "Press Space or click as soon as you see anything,\n"
           "then click where it was without moving your eyes.\n"
           "Escape pauses. Press a key to start.";
}

/* The instructions (not again on a resume with trials stored) and the practice trials not yet
 * stored: suprathreshold; for fade they measure the simple reaction time. */
static csf_status run_practice(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    const session_settings *set = &R->set;
    person *who = &R->who;
    size_t n_prac_stored = 0;
    R->seq = 0;
    for (size_t i = 0; i < R->n_stored; i++) {
        if (S->stored[i].is_practice) n_prac_stored++;
        if (S->stored[i].seq >= R->seq) R->seq = S->stored[i].seq + 1;
    }
    csf_status st;
    if (shows_instructions(R)) {
        st = obs_person_screen(who, instructions(R), err);
        if (st != CSF_OK) return st;
        if (who->paused) obs_ask_resume(who, 0, set->trials);
    }
    for (int k = (int)n_prac_stored; k < set->practice && !who->paused && !obs_stop_requested; k++) {
        csf_cell pc_cell = {PRACTICE_FREQ, 0, 0};
        csf_trial_plan plan;
        memset(&plan, 0, sizeof plan);
        plan.task = S->ops->task;
        plan.contrast = PRACTICE_CONTRAST;
        plan.signal_interval = (int)(csf_rng_u64(R->seed, ST_PRACTICE_POLAR, (uint64_t)k) & 1);
        plan.n_alternatives = plan.task == CSF_TASK_2AFC ? 2 : 0;
        /* With four-place cells every second practice trial shows four places. */
        int four = plan.task == CSF_TASK_2AFC && R->prac_layout.n_alternatives == 4 && k % 2 == 1;
        if (four) {
            pc_cell.ecc_deg = R->prac_ecc_deg;
            plan.n_alternatives = 4;
            plan.signal_interval = (int)(csf_rng_u64(R->seed, ST_PRACTICE_POLAR, (uint64_t)k) & 3);
        }
        uint64_t key = 1000000u + (uint64_t)k; /* practice draws never collide with main trials */
        st = practice_trial(S, &R->run, R->sid, set->method, key, &pc_cell, &plan, &R->prac_layout,
                            R->mean_lum_cdm2, &R->seq, &R->n_stored, err);
        if (st != CSF_OK) return st;
        if (who->paused) {
            if (obs_ask_resume(who, 0, set->trials)) {
                k--; /* the practice trial again */
                continue;
            }
            break;
        }
        R->res->n_stored = (int)R->n_stored;
    }
    if (S->ops->task == CSF_TASK_FADE) R->res->latency_s = practice_latency(S->stored, R->n_stored);
    return CSF_OK;
}

/* Whether the replayed plan is for the stored trial's cell: the method replans every stored trial and
 * the stored answer goes to the plan's cell, so a method that plans differently since the session
 * started (a newer csfcal) would put answers on the wrong cells without this check. */
static int replay_matches(const csf_cell *cells, int n_cells, const csf_trial_plan *plan, const csf_trial *t)
{
    if (plan->cell < 0 || plan->cell >= n_cells) return 0;
    const csf_cell *c = &cells[plan->cell];
    return fabs(c->freq_cpd - t->freq_cpd) <= 1e-6 * c->freq_cpd && fabs(c->ecc_deg - t->ecc_deg) <= 1e-6 &&
           fabs(c->velocity_dps - fabs(t->velocity_dps)) <= 1e-6; /* a trial stores its drift's direction */
}

/* The procedure, rebuilt by replaying every stored main trial through update(). */
static csf_status replay_stored(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    const session_settings *set = &R->set;
    csf_obs_result *res = R->res;
    csf_procedure_setup setup;
    memset(&setup, 0, sizeof setup);
    setup.cells = S->cells;
    setup.n_cells = R->n_cells;
    setup.trial_budget = set->trials;
    if (set->precision > 0)
        setup.planned_trials =
            csf_precision_planned_trials(S->ops, R->n_cells - R->n_not_shown, set->precision, set->trials);
    setup.seed = R->seed;
    setup.max_contrast = R->max_contrast;
    setup.min_contrast = 0.0005;
    setup.slope_beta = 3.5;
    setup.lapse = 0.02;
    setup.guess = S->ops->task == CSF_TASK_2AFC ? 0.5 : 0.02;
    setup.ramp_start_log10 = -3.0;
    setup.ramp_end_log10 = log10(R->max_contrast);
    setup.ramp_s = (setup.ramp_end_log10 - setup.ramp_start_log10) / 0.5; /* 0.5 log10 per second */
    setup.reaction_latency_s = isfinite(res->latency_s) ? res->latency_s : 0;
    setup.n_alternatives = res->n_cells_four_place > 0 ? S->n_alt : NULL;
    setup.fade_anchor_share = set->fade_anchors > 0 ? set->fade_anchors : -1;
    setup.not_shown = R->n_not_shown > 0 ? S->not_shown : NULL;
    double *trial_s = malloc(sizeof(double) * (size_t)R->n_cells);
    for (int k = 0; trial_s && k < R->n_cells; k++)
        trial_s[k] = expected_trial_s(R, setup.n_alternatives && S->n_alt[k] == 4);
    setup.trial_s = trial_s;
    csf_status st = S->ops->create(&setup, &S->proc, err);
    free(trial_s);
    if (st != CSF_OK) return st;
    R->trial_index = 0;
    for (size_t i = 0; i < R->n_stored; i++) {
        if (S->stored[i].is_practice) continue;
        csf_trial_plan plan;
        if (S->ops->next(S->proc, R->trial_index, &plan) != CSF_OK) break;
        if (S->stored[i].n_alternatives != obs_plan_alternatives(&plan))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--resume %lld: stored trial %d had %d alternatives, the replayed plan "
                                 "has %d (the display or the layout rule changed since the session "
                                 "started); start a new session",
                                 (long long)R->sid, S->stored[i].seq, S->stored[i].n_alternatives,
                                 obs_plan_alternatives(&plan));
        if (!replay_matches(S->cells, R->n_cells, &plan, &S->stored[i]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--resume %lld: stored trial %d was at %g cpd, %g deg, %g deg/s, the "
                                 "replayed plan asks for another cell (the method changed since the session "
                                 "started); its trials are kept, start a new session",
                                 (long long)R->sid, S->stored[i].seq, S->stored[i].freq_cpd,
                                 S->stored[i].ecc_deg, S->stored[i].velocity_dps);
        if (obs_plan_alternatives(&plan) == 4) res->n_four_place++;
        csf_trial_outcome o = obs_outcome_of(&S->stored[i], S->ops->task);
        S->ops->update(S->proc, R->trial_index, &plan, &o);
        R->trial_index++;
    }
    R->resume_done = R->trial_index;
    return CSF_OK;
}

/* Where a planned main trial's grating goes (polar angle, deg), after checking the plan against
 * the cell's layout; *four says whether it is a four-place trial. */
static csf_status place_trial(obs_run *R, const csf_trial_plan *plan, int *four, double *polar, csf_error *err)
{
    const session_res *S = &R->S;
    const char *method = R->set.method;
    if (plan->cell < 0 || plan->cell >= R->n_cells)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: planned cell %d of %d", method, plan->cell, R->n_cells);
    const csf_cell *c = &S->cells[plan->cell];
    *four = obs_plan_alternatives(plan) == 4;
    if (*four && S->n_alt[plan->cell] != 4)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: planned four places for %g cpd at %g deg, "
                             "which has two intervals", method, c->freq_cpd, c->ecc_deg);
    if (*four) {
        if (plan->signal_interval < 0 || plan->signal_interval > 3)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: planned place %d of 4", method, plan->signal_interval);
        *polar = S->layouts[plan->cell].polar_deg[plan->signal_interval];
        return CSF_OK;
    }
    if (obs_fit_polar(S->pres, c->freq_cpd, c->ecc_deg, plan->polar_deg, R->mean_lum_cdm2, polar) != 0)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%g cpd at %g deg cannot be shown anywhere on this screen", c->freq_cpd, c->ecc_deg);
    return CSF_OK;
}

/* What may come before a main trial: a break every break_every trials (people only), and before a
 * fade session's first forced-choice anchor the new task's instructions and its practice.
 * *again: the person paused and went on, so the trial is planned again (the anchors' screen and
 * practice included); *stop: the person paused and stopped. */
static csf_status before_trial(obs_run *R, const csf_trial_plan *plan, int *told_anchors, int *again, int *stop,
                               csf_error *err)
{
    const session_settings *set = &R->set;
    person *who = &R->who;
    int ti = R->trial_index;
    csf_status st;
    *again = *stop = 0;
    if (set->break_every > 0 && ti > 0 && ti % set->break_every == 0 && !R->S.sim) {
        char msg[160];
        snprintf(msg, sizeof msg, "Break. %d of %d trials done.\nPress a key to go on.", ti, set->trials);
        st = obs_person_screen(who, msg, err);
        if (st != CSF_OK) return st;
        if (who->paused && !obs_ask_resume(who, ti, set->trials)) return *stop = 1, CSF_OK;
    }
    if (R->S.ops->task != CSF_TASK_FADE || plan->task != CSF_TASK_2AFC || *told_anchors) return CSF_OK;
    /* The fade method's forced-choice anchors: a new task, so the person is told. */
    *told_anchors = 1;
    st = obs_person_screen(who, ANCHOR_INSTRUCTIONS, err);
    if (st != CSF_OK) return st;
    if (who->paused && !obs_ask_resume(who, ti, set->trials)) return *stop = 1, CSF_OK;
    st = anchor_practice(&R->S, &R->run, R->sid, set->method, R->seed, R->mean_lum_cdm2, &R->seq, &R->n_stored, err);
    if (st != CSF_OK) return st;
    R->res->n_stored = (int)R->n_stored;
    if (who->paused) {
        if (obs_ask_resume(who, ti, set->trials)) {
            *told_anchors = 0; /* the screen and the rest of the practice again */
            *again = 1;
        } else {
            *stop = 1;
        }
    }
    return CSF_OK;
}

/* The person's time in this run so far: the session's clock from the first screen, plus the
 * simulated answer times (the virtual clock does not run for them; 0 for a real person). */
static double person_time_so_far(const obs_run *R)
{
    return csf_presenter_time(R->S.pres) - R->person_t0_s + R->who.sim_rt_total_s;
}

/* The table's predicted RMS error: the root mean square of the method's stated errors over the
 * cells it would write as visible and the display can show (NaN when none has one). */
double obs_rms_of_estimates(const obs_run *R)
{
    double sum = 0;
    int n = 0;
    for (int k = 0; k < R->n_cells; k++) {
        const csf_cell_estimate *c = &R->S.est[k];
        if (R->S.not_shown[k] || !isfinite(c->threshold) || !isfinite(c->stderr_log10)) continue;
        sum += c->stderr_log10 * c->stderr_log10;
        n++;
    }
    return n ? sqrt(sum / n) : NAN;
}

/* The same from a fresh estimate. */
static double predicted_rms(obs_run *R)
{
    csf_error e;
    if (R->S.ops->estimate(R->S.proc, R->S.est, &e) != CSF_OK) return NAN;
    return obs_rms_of_estimates(R);
}

/* --precision: whether the predicted error has reached the target after n main trials; progress on
 * the experimenter's terminal (people: every 10 trials; simulations: every 50). */
static int precision_reached(obs_run *R, int n)
{
    double rms = predicted_rms(R);
    int reached = n >= PRECISION_MIN_TRIALS && rms <= R->set.precision;
    int every = R->S.sim ? 50 : 10;
    if (!R->opt->quiet && !R->progress.live && (n % every == 0 || reached)) {
        double spent = person_time_so_far(R);
        int left = obs_progress_trials_left(n, rms, R->set.precision, R->set.trials),
            run_done = n - R->resume_done;
        char left_s[64] = "";
        if (left > 0 && run_done > 0)
            snprintf(left_s, sizeof left_s, ", about %.1f min (%d trials) left",
                     spent / run_done * left / 60.0, left);
        fprintf(stderr,
                "csfcal: observer: trial %d (cap %d): predicted error %.3f log10, target %.3f; %.1f min "
                "so far%s\n",
                n, R->set.trials, rms, R->set.precision, spent / 60.0, left_s);
    }
    if (reached) R->res->reached_precision = 1;
    return reached;
}

/* The person's time in this run (the session's clock from the first screen to the last answer,
 * simulated answer times added: the virtual clock does not run for them), into the result and
 * added to the session's in the store, once per run, before the session is paused or finished. */
static csf_status record_person_time(obs_run *R, csf_error *err)
{
    if (R->person_recorded) return CSF_OK;
    R->person_recorded = 1;
    R->res->person_s = person_time_so_far(R);
    csf_error e;
    return csf_store_add_person_time(R->S.store, R->sid, R->res->person_s, err ? err : &e);
}

/* The latest flagged trial (a false alarm, an anticipation, a click far from the grating, missed
 * frames) for the experimenter's line. */
static void note_trial(obs_run *R, const csf_trial *t)
{
    if (t->flags[0]) obs_progress_event(&R->progress, "trial %d %s", R->trial_index + 1, t->flags);
    else if (!t->valid) obs_progress_event(&R->progress, "trial %d not valid", R->trial_index + 1);
}

/* The stated error at or below which a cell counts as settled on the experimenter's line: the
 * --precision target, or 0.15 log10 with a fixed budget. */
#define PROGRESS_SETTLE_LOG10 0.15

/* The experimenter's line after n main trials: after each of a person's trials, after every tenth
 * of a simulated person's (their trials take no time to watch). */
static void show_progress(obs_run *R, int n, int last)
{
    const session_settings *set = &R->set;
    if (!R->progress.live || (R->S.sim && n % 10 != 0 && n != set->trials && !last)) return;
    obs_progress_state ps = {n, set->trials, NAN, set->precision, 0, 0, 0, NAN, NAN};
    ps.settle_log10 = set->precision > 0 ? set->precision : PROGRESS_SETTLE_LOG10;
    /* with --precision the estimate is this trial's already (precision_reached) */
    csf_error e;
    if (set->precision > 0 || R->S.ops->estimate(R->S.proc, R->S.est, &e) == CSF_OK) {
        ps.rms_log10 = obs_rms_of_estimates(R);
        for (int k = 0; k < R->n_cells; k++) {
            if (R->S.not_shown[k]) continue;
            ps.cells++;
            ps.cells_settled +=
                isfinite(R->S.est[k].stderr_log10) && R->S.est[k].stderr_log10 <= ps.settle_log10;
        }
    }
    ps.spent_s = person_time_so_far(R);
    int run_done = n - R->resume_done, left = set->trials - n;
    if (set->precision > 0) left = obs_progress_trials_left(n, ps.rms_log10, set->precision, set->trials);
    if (run_done > 0 && left >= 0) ps.left_s = ps.spent_s / run_done * left;
    obs_progress_show(&R->progress, &ps);
}

/* The main trials, each stored (durably) before the procedure sees it and before the next is
 * shown. A pause or a signal leaves the session paused, resumable. */
static csf_status run_main_trials(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    const session_settings *set = &R->set;
    csf_obs_result *res = R->res;
    person *who = &R->who;
    int told_anchors = 0;
    csf_status st;
    for (; R->trial_index < set->trials && !who->paused && !obs_stop_requested; R->trial_index++) {
        int ti = R->trial_index;
        csf_trial_plan plan;
        csf_status nst = S->ops->next(S->proc, ti, &plan);
        if (nst == CSF_E_ABORTED) {
            res->finished_early = 1;
            break;
        }
        if (nst != CSF_OK) return csf_error_set(err, nst, "%s: could not plan trial %d", set->method, ti);
        int four = 0, again = 0, stop = 0;
        double polar = 0.0;
        st = place_trial(R, &plan, &four, &polar, err);
        if (st != CSF_OK) return st;
        st = before_trial(R, &plan, &told_anchors, &again, &stop, err);
        if (st != CSF_OK) return st;
        if (stop) break;
        if (again) {
            R->trial_index--;
            continue;
        }
        const csf_cell *c = &S->cells[plan.cell];
        trial_result tr;
        R->run.drift_sign = csf_motion_direction(R->seed, (uint64_t)ti, set->drift_direction);
        st = plan.task == CSF_TASK_FADE ? obs_run_fade(&R->run, (uint64_t)ti, c, &plan, polar, 0, &tr, err)
             : four ? obs_run_4afc(&R->run, (uint64_t)ti, c, &plan, &S->layouts[plan.cell], &tr, err)
                    : obs_run_2afc(&R->run, (uint64_t)ti, c, &plan, polar, &tr, err);
        if (st != CSF_OK) return st;
        if (who->paused) {
            if (tr.have_rec) csf_trial_record_free(&tr.rec);
            /* The interrupted trial is not stored: it is shown again, now or on --resume
             * (next() is a function of the state and the index, so it plans the same trial). */
            if (obs_ask_resume(who, ti, set->trials)) {
                obs_progress_event(&R->progress, "paused at trial %d, went on", ti + 1);
                R->trial_index--;
                continue;
            }
            break;
        }
        csf_trial t;
        obs_fill_trial(&t, R->sid, R->seq, set->method, c, polar, R->mean_lum_cdm2, &plan, 0, &tr);
        st = store_trial(S, &R->n_stored, &t, &tr, err);
        if (st != CSF_OK) return st;
        res->n_stored = (int)R->n_stored;
        R->seq++;
        if (four) res->n_four_place++;
        csf_trial_outcome o = obs_outcome_of(&t, S->ops->task);
        S->ops->update(S->proc, ti, &plan, &o);
        int reached = set->precision > 0 && precision_reached(R, ti + 1);
        note_trial(R, &t);
        show_progress(R, ti + 1, reached);
        if (reached) {
            R->trial_index++;
            break;
        }
        if (!R->opt->quiet && !R->progress.live && !S->sim && (ti + 1) % 10 == 0 && set->precision <= 0) {
            /* time left at this run's own pace so far */
            double spent = person_time_so_far(R);
            int run_done = ti + 1 - R->resume_done;
            double left_s = run_done > 0 ? spent / run_done * (set->trials - ti - 1) : NAN;
            fprintf(stderr, "csfcal: observer: %d of %d trials, about %.1f min left\n", ti + 1, set->trials,
                    left_s / 60.0);
        }
    }
    if (who->paused || obs_stop_requested) {
        record_person_time(R, NULL);
        csf_store_set_session_state(S->store, R->sid, CSF_SESSION_PAUSED, NULL);
        R->said_paused = 1;
        return csf_error_set(err, CSF_E_ABORTED, "session %lld paused after %d trials; continue with --resume %lld",
                             (long long)R->sid, R->trial_index, (long long)R->sid);
    }
    return CSF_OK;
}

/* Before the first trial: how long the trials still to run should take the person. */
static void say_expected_time(obs_run *R)
{
    int done = 0, practice_done = 0;
    for (size_t i = 0; i < R->n_stored; i++) {
        done += !R->S.stored[i].is_practice;
        practice_done += R->S.stored[i].is_practice;
    }
    int left = R->set.trials - done;
    if (R->set.precision > 0) {
        /* the trials the precision should take, within the cap */
        int need = csf_precision_planned_trials(R->S.ops, R->n_cells - R->n_not_shown, R->set.precision,
                                                R->set.trials);
        if (need - done < left) left = need - done;
    }
    if (left < 0) left = 0;
    double share_four = R->n_cells > 0 ? (double)R->res->n_cells_four_place / R->n_cells : 0.0;
    int practice_left = R->set.practice > practice_done ? R->set.practice - practice_done : 0;
    R->res->expected_person_s = expected_session_s(R, left, share_four, shows_instructions(R), practice_left);
    /* a precision stop's length is the person's: how steep their psychometric function is shows
     * only in their answers, so the range most people fall in is said beside the plan */
    const csf_procedure_ops *ops = R->S.ops;
    int spread = R->set.precision > 0 && ops->time_spread_lo > 0 && ops->time_spread_hi > ops->time_spread_lo;
    R->res->expected_person_lo_s = spread ? ops->time_spread_lo * R->res->expected_person_s : NAN;
    R->res->expected_person_hi_s = spread ? ops->time_spread_hi * R->res->expected_person_s : NAN;
    if (R->opt->quiet) return;
    char cells[96] = "";
    if (R->n_not_shown > 0) snprintf(cells, sizeof cells, ", %d of them predicted only", R->n_not_shown);
    char cap[64] = "", range[64] = "";
    if (R->set.precision > 0) snprintf(cap, sizeof cap, " (cap %d)", R->set.trials);
    if (spread)
        snprintf(range, sizeof range, " (8 in 10 people: %.1f to %.1f)", R->res->expected_person_lo_s / 60.0,
                 R->res->expected_person_hi_s / 60.0);
    fprintf(stderr,
            "csfcal: observer: %s%d trials%s over %d cells%s: about %.1f minutes of the person's time%s\n",
            R->set.precision > 0 ? "about " : "", left, cap, R->n_cells, cells,
            R->res->expected_person_s / 60.0, range);
}

/* The trials and what follows them, with SIGINT/SIGTERM turned into a pause meanwhile. */
static csf_status run_trials_and_table(obs_run *R, csf_error *err)
{
    struct sigaction sa, old_int, old_term;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    obs_stop_requested = 0;
    obs_progress_init(&R->progress, !R->opt->quiet && isatty(STDERR_FILENO));
    say_expected_time(R);
    R->person_t0_s = csf_presenter_time(R->S.pres);
    R->person_started = 1;
    csf_status st = run_practice(R, err);
    if (st == CSF_OK) st = replay_stored(R, err);
    if (st == CSF_OK) st = run_main_trials(R, err);
    obs_progress_end(&R->progress);
    if (st == CSF_OK) st = record_person_time(R, err);
    if (st == CSF_OK) st = obs_judge_session(R, err);
    if (st == CSF_OK) st = obs_write_table(R, err);
    if (st == CSF_OK) st = obs_finish_session(R, err);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    return st;
}

/* The one-line summary of a finished session. */
static void summarise(const obs_run *R)
{
    const csf_obs_result *res = R->res;
    const csf_obs_options *opt = R->opt;
    char four_note[48] = "", offset_note[120] = "", precision_note[200];
    if (res->n_cells_four_place > 0)
        snprintf(four_note, sizeof four_note, " (%d with four places)", res->n_cells_four_place);
    if (isfinite(res->fade_offset_log10))
        snprintf(offset_note, sizeof offset_note, ", yes/no - forced choice %+.3f +- %.3f log10 (%d anchors)",
                 res->fade_offset_log10, res->fade_offset_sd_log10, res->n_fade_anchors);
    snprintf(precision_note, sizeof precision_note,
             ", predicted RMS error %.3f log10%s, person time %.1f min", res->predicted_rms_log10,
             res->precision_log10 > 0
                 ? (res->reached_precision ? " (--precision reached)" : " (--precision not reached)")
                 : "",
             res->person_s / 60.0);
    snprintf(R->res->summary, sizeof R->res->summary,
             "observer session %lld: %s, %d trials (%d valid, %d catch with %d false alarms, %d invalid "
             "clicks, %d lapses), %d cells%s: %d visible, %d not visible, median se %.3f log10%s%s -> %s%s%s",
             (long long)res->session_id, res->method, res->n_trials, res->n_valid, res->n_catch,
             res->n_false_alarms, res->n_invalid_click, res->n_lapses, res->n_cells, four_note,
             res->n_visible, res->n_invisible, res->median_se_log10, offset_note, precision_note,
             opt->out_path, opt->plot_path && *opt->plot_path ? ", " : "",
             opt->plot_path ? opt->plot_path : "");
}

/* --demo: the task shown to a participant before the session, the practice grating at falling
 * contrasts (drifting at the session's highest velocity every other trial when it has a velocity
 * axis), each answer followed by what was right. Nothing is stored or written. */
#define DEMO_TRIALS 6
static csf_status run_demo(obs_run *R, csf_error *err)
{
    static const double contrast[DEMO_TRIALS] = {0.3, 0.1, 0.03, 0.3, 0.1, 0.03};
    person *who = &R->who;
    csf_status st = obs_person_screen(who, instructions(R), err);
    for (int k = 0; k < DEMO_TRIALS && st == CSF_OK && !who->paused && !obs_stop_requested; k++) {
        double v = R->set.n_vels > 0 && k % 2 ? R->set.vels[R->set.n_vels - 1] : 0.0;
        csf_cell cell = {PRACTICE_FREQ, 0,
                         csf_motion_aliases(&(csf_cell){PRACTICE_FREQ, 0, v}, 1.0 / R->run.period_s) ? 0.0
                                                                                                     : v};
        csf_trial_plan plan;
        memset(&plan, 0, sizeof plan);
        plan.task = R->S.ops->task;
        plan.contrast = contrast[k];
        plan.n_alternatives = plan.task == CSF_TASK_2AFC ? 2 : 0;
        plan.signal_interval = (int)(csf_rng_u64(R->seed, ST_DEMO, (uint64_t)k) & 1);
        plan.ramp_start_log10 = -3.0;
        plan.ramp_s = 4.0;
        trial_result tr;
        R->run.drift_sign = csf_motion_direction(R->seed, 3000000u + (uint64_t)k, 0);
        st = plan.task == CSF_TASK_FADE
                 ? obs_run_fade(&R->run, 3000000u + (uint64_t)k, &cell, &plan, 0, 1, &tr, err)
                 : obs_run_2afc(&R->run, 3000000u + (uint64_t)k, &cell, &plan, 0, &tr, err);
        if (tr.have_rec) csf_trial_record_free(&tr.rec);
        if (st != CSF_OK || who->paused) break;
        int right = plan.task == CSF_TASK_FADE ? tr.response == 1 : tr.response == plan.signal_interval;
        R->res->n_practice++;
        R->res->n_valid += right;
        char msg[200];
        if (plan.task == CSF_TASK_FADE)
            snprintf(msg, sizeof msg,
                     "%s A pattern of contrast %.0f %% was there.\nPress a key for the next one.",
                     right ? "Seen." : "Missed.", 100 * contrast[k]);
        else
            snprintf(msg, sizeof msg,
                     "%s The pattern was in interval %d (contrast %.0f %%).\nPress a key for the "
                     "next one.",
                     right ? "Right." : "Not this time.", plan.signal_interval + 1, 100 * contrast[k]);
        st = obs_person_screen(who, msg, err);
    }
    snprintf(R->res->summary, sizeof R->res->summary,
             "demo: %d practice trials with feedback, %d right; nothing was stored or written",
             R->res->n_practice, R->res->n_valid);
    return st;
}

csf_status csf_obs_session_begin(const csf_obs_options *opt, csf_store *store, csf_obs_result *res,
                                 csf_obs_session **out, csf_error *err)
{
    *out = NULL;
    memset(res, 0, sizeof *res);
    res->fade_offset_log10 = res->fade_offset_sd_log10 = NAN;
    res->fa_rate = res->latency_s = res->median_se_log10 = res->predicted_rms_log10 = NAN;
    res->expected_person_lo_s = res->expected_person_hi_s = NAN;
    if (!opt->demo && (!opt->out_path || !*opt->out_path))
        return csf_error_set(err, CSF_E_INVALID_ARG, "observer calibrate: --out FILE.csflut is required");
    if (opt->resume_id && !store)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--resume %lld: the session's store is needed",
                             (long long)opt->resume_id);
    csf_status st = opt->demo ? CSF_OK : obs_check_outputs(opt, err);
    if (st != CSF_OK) return st;
    obs_run *R = calloc(1, sizeof *R);
    if (!R) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    clock_gettime(CLOCK_MONOTONIC, &R->wall0);
    R->opt = opt;
    R->cfg = opt->cfg;
    R->res = res;
    R->sid = opt->demo ? 0 : opt->resume_id;
    R->seed = opt->seed;
    R->S.store = store;
    st = csf_geometry_init(&R->geom, CSF_GEOMETRY_FROM_CONFIG(*R->cfg), err);
    if (st == CSF_OK) st = R->sid ? resumed_settings(R, err) : new_settings(R, err);
    if (st == CSF_OK) st = choose_method_and_person(R, err);
    if (st != CSF_OK) {
        free(R);
        return st;
    }
    *out = R;
    return CSF_OK;
}

const csf_obs_settings *csf_obs_session_settings(const csf_obs_session *R, uint64_t *seed, int *is_sim)
{
    if (seed) *seed = R->seed;
    if (is_sim) *is_sim = R->is_sim;
    return &R->set;
}

const csf_geometry *csf_obs_session_geometry(const csf_obs_session *R)
{
    return &R->geom;
}

csf_status csf_obs_session_check(csf_obs_session *R, const csf_obs_resources *r, csf_error *err)
{
    csf_status st = take_resources(R, r, err);
    if (st == CSF_OK) st = check_display_side(R, err);
    if (st == CSF_OK && !R->sid && !R->opt->demo) st = check_motion_grid(R, err);
    if (st == CSF_OK && !R->sid && !R->opt->demo) warn_precision_reach(R);
    return st;
}

csf_status csf_obs_session_demo(csf_obs_session *R, csf_error *err)
{
    init_person(R);
    return run_demo(R, err);
}

csf_status csf_obs_session_run(csf_obs_session *R, csf_store *store, csf_error *err)
{
    csf_obs_result *res = R->res;
    if (store) R->S.store = store;
    csf_status st = open_session_row(R, err);
    if (st == CSF_OK) st = prepare_cells(R, err);
    if (st == CSF_OK) st = run_trials_and_table(R, err);
    /* A failure after the session began (the store or the disk refused a write, the table or the
     * plot could not be written) keeps every stored trial: the session is left paused so that
     * --resume finishes it (the store may refuse that too on a full disk; a running session is
     * resumable as well); so is a closed window. Pauses already said so, refusals of the data
     * (aborted) end it. */
    if (st != CSF_OK && !R->said_paused && st != CSF_E_INSUFFICIENT && res->session_id) {
        csf_error e2;
        if (R->person_started) record_person_time(R, NULL);
        csf_store_set_session_state(R->S.store, res->session_id, CSF_SESSION_PAUSED, &e2);
        res->resumable = 1;
    }
    struct timespec w1;
    clock_gettime(CLOCK_MONOTONIC, &w1);
    res->wall_s = (double)(w1.tv_sec - R->wall0.tv_sec) + (w1.tv_nsec - R->wall0.tv_nsec) * 1e-9;
    if (st == CSF_OK) summarise(R);
    return st;
}

void csf_obs_session_free(csf_obs_session *R)
{
    if (!R) return;
    session_free(&R->S);
    free(R);
}

/* A number, or null where it is not finite (NaN: not measured). */
static json_t *num_or_null(double v) { return isfinite(v) ? json_real(v) : json_null(); }

void csf_obs_result_json(const csf_obs_result *r, const char *out_path, const char *plot_path,
                         char *buf, unsigned long len)
{
    /* jansson writes it, so paths and names with quotes stay valid JSON */
    json_t *o = json_object();
    json_object_set_new(o, "session", json_integer((json_int_t)r->session_id));
    json_object_set_new(o, "method", json_string(r->method));
    json_object_set_new(o, "trials", json_integer(r->n_trials));
    json_object_set_new(o, "valid", json_integer(r->n_valid));
    json_object_set_new(o, "practice", json_integer(r->n_practice));
    json_object_set_new(o, "catch", json_integer(r->n_catch));
    json_object_set_new(o, "false_alarms", json_integer(r->n_false_alarms));
    json_object_set_new(o, "fa_rate", num_or_null(r->fa_rate));
    json_object_set_new(o, "invalid_clicks", json_integer(r->n_invalid_click));
    json_object_set_new(o, "anticipations", json_integer(r->n_anticipations));
    json_object_set_new(o, "lapses", json_integer(r->n_lapses));
    json_object_set_new(o, "missed_frame_trials", json_integer(r->n_missed_frame_trials));
    json_object_set_new(o, "reaction_latency_s", num_or_null(r->latency_s));
    json_object_set_new(o, "cells", json_integer(r->n_cells));
    json_object_set_new(o, "visible", json_integer(r->n_visible));
    json_object_set_new(o, "not_visible", json_integer(r->n_invisible));
    json_object_set_new(o, "median_se_log10", num_or_null(r->median_se_log10));
    json_object_set_new(o, "finished_early", json_boolean(r->finished_early));
    json_object_set_new(o, "table", json_string(out_path ? out_path : ""));
    json_object_set_new(o, "plot", plot_path ? json_string(plot_path) : json_null());
    json_object_set_new(o, "afc", json_integer(r->afc));
    json_object_set_new(o, "four_place_cells", json_integer(r->n_cells_four_place));
    json_object_set_new(o, "four_place_trials", json_integer(r->n_four_place));
    json_object_set_new(o, "velocities", json_integer(r->n_vels));
    json_object_set_new(o, "cells_not_shown", json_integer(r->n_not_shown));
    json_object_set_new(o, "expected_person_s", num_or_null(r->expected_person_s));
    json_t *range = json_null();
    if (isfinite(r->expected_person_lo_s) && isfinite(r->expected_person_hi_s))
        range = json_pack("[ff]", r->expected_person_lo_s, r->expected_person_hi_s);
    json_object_set_new(o, "expected_person_s_range", range ? range : json_null());
    json_object_set_new(o, "person_s", num_or_null(r->person_s));
    json_object_set_new(o, "precision_log10",
                        r->precision_log10 > 0 ? json_real(r->precision_log10) : json_null());
    json_object_set_new(o, "reached_precision", json_boolean(r->reached_precision));
    json_object_set_new(o, "predicted_rms_log10", num_or_null(r->predicted_rms_log10));
    json_object_set_new(o, "fade_anchor_trials", json_integer(r->n_fade_anchors));
    json_object_set_new(o, "fade_offset_log10", num_or_null(r->fade_offset_log10));
    json_object_set_new(o, "fade_offset_sd_log10", num_or_null(r->fade_offset_sd_log10));
    json_object_set_new(o, "resumable", json_boolean(r->resumable));
    json_object_set_new(o, "wall_s", json_real(r->wall_s));
    char *text = json_dumps(o, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6));
    json_decref(o);
    if (text && strlen(text) < len) memcpy(buf, text, strlen(text) + 1);
    else if (len) snprintf(buf, len, "{\"session\":%lld}", (long long)r->session_id);
    free(text);
}
