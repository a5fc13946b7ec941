#include "precision_run.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "calib/observer_trials.h"
#include "model/observer_sim.h"

const double PR_SHIFTS[PR_N_SHIFTS] = {0, 0.5, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0};

/* One fade trial against the simulated person, frame by frame at 60 Hz on the planned ramp
 * (tests/observer/sim_loop.h does the same; here a trial at a time, for the precision stop). */
static void fade_trial(csf_observer_sim *o, int i, const csf_cell *c, const csf_trial_plan *plan,
                       double *clock_s, csf_trial_outcome *out)
{
    const double dt = 1.0 / 60;
    csf_sim_fade_trial tr;
    double window = plan->ramp_s + 1.5;
    csf_observer_sim_fade_begin(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, plan->polar_deg, *clock_s, window,
                                &tr);
    double xe = log10(plan->contrast), rate = (xe - plan->ramp_start_log10) / plan->ramp_s;
    double shown = 0;
    int nf = (int)ceil(window / dt);
    for (int k = 0; k < nf; k++) {
        double t = k * dt;
        double x = t <= plan->ramp_s ? plan->ramp_start_log10 + rate * t : -INFINITY;
        double cs = plan->is_catch ? 0 : (isfinite(x) ? pow(10.0, x) : 0);
        if (cs > 0) shown = cs;
        double press;
        if (csf_observer_sim_fade_frame(o, &tr, *clock_s + t, cs, &press)) {
            out->response = 1;
            out->rt_s = press - *clock_s;
            out->contrast_at_response = shown;
            double cx, cy, a = plan->polar_deg * M_PI / 180;
            csf_observer_sim_click(o, &tr, &cx, &cy);
            double dx = cx - c->ecc_deg * cos(a), dy = cy - c->ecc_deg * sin(a);
            if (plan->is_catch || hypot(dx, dy) > 2.0 + 0.3 * c->ecc_deg || out->rt_s < 0.15) out->valid = 0;
            break;
        }
    }
    *clock_s += window + 1;
}

static void answer(csf_observer_sim *o, int i, const csf_cell *c, const csf_trial_plan *plan, double *clock_s,
                   csf_trial_outcome *out)
{
    *out = (csf_trial_outcome){0, NAN, NAN, 1};
    if (plan->task == CSF_TASK_FADE) {
        fade_trial(o, i, c, plan, clock_s, out);
        return;
    }
    int m = plan->n_alternatives == 4 ? 4 : 2;
    double cs[4] = {0, 0, 0, 0}, rt;
    cs[plan->signal_interval] = plan->contrast;
    out->response = m == 4 ? csf_observer_sim_afc(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, 4, &rt)
                           : csf_observer_sim_2afc(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, &rt);
    out->rt_s = rt;
    out->contrast_at_response = plan->contrast;
}

double precision_predicted_rms(const csf_cell_estimate *e, int n)
{
    double sum = 0;
    int k = 0;
    for (int c = 0; c < n; c++)
        if (isfinite(e[c].threshold) && isfinite(e[c].stderr_log10))
            sum += e[c].stderr_log10 * e[c].stderr_log10, k++;
    return k ? sqrt(sum / k) : NAN;
}

double precision_achieved_rms(const double *truth_log10, const double *est_log10, int n)
{
    double lc = log10(PR_CMAX), se = 0;
    int k = 0;
    for (int c = 0; c < n; c++) {
        if (!(truth_log10[c] < lc)) continue;
        double e = est_log10[c] < lc ? est_log10[c] : lc; /* NaN and INFINITY: the max contrast */
        se += (e - truth_log10[c]) * (e - truth_log10[c]), k++;
    }
    return k ? sqrt(se / k) : NAN;
}

/* The table as the method states it now, into out. */
static void snapshot(const csf_cell_estimate *est, int trials, int reached, session_out *out)
{
    for (int c = 0; c < PR_CELLS; c++)
        out->est[c] = log10(est[c].threshold), out->se[c] = est[c].stderr_log10;
    out->trials = trials, out->reached = reached;
}

static void *create_method(const csf_procedure_ops *ops, int seed, const csf_cell *cells, const int *n_alt,
                           int cap, double precision)
{
    int fade = ops->task == CSF_TASK_FADE;
    double trial_s[PR_CELLS]; /* as the session prices a trial (calib/observer_trials.c) */
    for (int c = 0; c < PR_CELLS; c++)
        trial_s[c] = obs_trial_expected_s(ops->task, !fade && n_alt && n_alt[c] == 4);
    csf_procedure_setup s = {
        .cells = cells,
        .n_cells = PR_CELLS,
        .trial_budget = cap,
        .seed = 1000 + (uint64_t)seed,
        .max_contrast = PR_CMAX,
        .min_contrast = 0.0005,
        .slope_beta = 3.5,
        .lapse = 0.02,
        .guess = fade ? 0.02 : 0.5,
        .ramp_start_log10 = -3.0,
        .ramp_end_log10 = 0.0,
        .ramp_s = 6.0,
        .reaction_latency_s = 0.37,
        .n_alternatives = fade ? NULL : n_alt,
        /* as the session plans a precision stop (calib/observer_calib.c) */
        .planned_trials = precision > 0 ? csf_precision_planned_trials(ops, PR_CELLS, precision, cap) : 0,
        .trial_s = trial_s};
    void *st = NULL;
    csf_error err = {0};
    if (ops->create(&s, &st, &err) != CSF_OK) {
        fprintf(stderr, "precision_session: %s: %s\n", ops->name, err.msg);
        return NULL;
    }
    return st;
}

int precision_session(const csf_procedure_ops *ops, const char *spec, int seed, const csf_cell *cells,
                      const int *n_alt, int trials, const double *levels, int n_levels, session_out *out)
{
    csf_observer_sim *o;
    csf_error err = {0};
    if (csf_observer_sim_create(spec, (uint64_t)seed, &o, &err) != CSF_OK) {
        fprintf(stderr, "precision_session: %s: %s\n", spec, err.msg);
        return -1;
    }
    double finest = 0; /* the session stops at the last (finest) level, and plans for it */
    for (int i = 0; i < n_levels; i++)
        if (!(finest > 0) || levels[i] < finest) finest = levels[i];
    void *st = create_method(ops, seed, cells, n_alt, trials, finest);
    if (!st) {
        csf_observer_sim_free(o);
        return -1;
    }
    csf_cell_estimate est[PR_CELLS];
    double clock_s = 0;
    int k = 0, next_level = 0;
    for (; k < trials && next_level < (n_levels ? n_levels : 1); k++) {
        csf_trial_plan plan;
        if (ops->next(st, k, &plan) != CSF_OK) break;
        csf_trial_outcome res;
        answer(o, k, &cells[plan.cell], &plan, &clock_s, &res);
        ops->update(st, k, &plan, &res);
        if (!n_levels || k + 1 < PR_MIN_TRIALS || ops->estimate(st, est, &err) != CSF_OK) continue;
        double pred = precision_predicted_rms(est, PR_CELLS);
        for (; next_level < n_levels && pred <= levels[next_level]; next_level++)
            snapshot(est, k + 1, 1, &out[next_level]);
    }
    ops->estimate(st, est, &err);
    ops->destroy(st);
    if (!n_levels) snapshot(est, k, 1, &out[0]);
    for (int i = next_level; i < n_levels; i++) snapshot(est, k, 0, &out[i]);
    for (int i = 0; i < (n_levels ? n_levels : 1); i++)
        for (int c = 0; c < PR_CELLS; c++)
            out[i].truth[c] = log10(csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg));
    csf_observer_sim_free(o);
    return 0;
}

void precision_conservative(const session_out *so, double k, double *cons)
{
    for (int c = 0; c < PR_CELLS; c++)
        cons[c] = so->est[c] - (isfinite(so->est[c]) && isfinite(so->se[c]) ? k * so->se[c] : 0);
    for (int e = 3; e >= 0; e--)
        for (int f = 5; f >= 0; f--) {
            double *v = &cons[e * 6 + f];
            if (f < 5 && cons[e * 6 + f + 1] < *v) *v = cons[e * 6 + f + 1];
            if (e < 3 && cons[(e + 1) * 6 + f] < *v) *v = cons[(e + 1) * 6 + f];
        }
}

void coverage_tally_add(coverage_tally *t, const session_out *so, int per_cell)
{
    double lc = log10(PR_CMAX), pred = 0, ach = 0, matched = 0;
    int np = 0, na = 0;
    for (int c = 0; c < PR_CELLS; c++) {
        int vis = so->truth[c] < lc, est_vis = so->est[c] < INFINITY,
            ok = isfinite(so->est[c]) && isfinite(so->se[c]);
        if (so->est[c] == INFINITY) t->called_inv++, t->inv_wrong += vis;
        if (ok) pred += so->se[c] * so->se[c], np++;
        if (!vis) continue;
        t->n_vis++;
        if (!est_vis || isnan(so->est[c])) {
            t->vis_nan += isnan(so->est[c]);
            continue;
        }
        if (!ok) continue;
        double d = so->est[c] - so->truth[c];
        int cov = fabs(d) <= 1.96 * so->se[c];
        t->covered += cov;
        ach += d * d, matched += so->se[c] * so->se[c], na++;
        if (per_cell) {
            t->cell_err_sq[c] += d * d, t->cell_se_sq[c] += so->se[c] * so->se[c];
            t->cell_cov[c] += cov, t->cell_n[c]++;
        }
    }
    for (int j = 0; j < PR_N_SHIFTS; j++) {
        double cons[PR_CELLS];
        precision_conservative(so, PR_SHIFTS[j], cons);
        for (int c = 0; c < PR_CELLS; c++)
            t->fail_open[j] += so->truth[c] < lc && cons[c] > so->truth[c] + 1e-12;
    }
    if (np && na) {
        pred = sqrt(pred / np), ach = sqrt(ach / na);
        t->pred_sq += pred * pred, t->ach_sq += ach * ach, t->matched_sq += matched / na;
        if (ach > 0) t->ratio_sum += pred / ach, t->n_ratio++;
    }
    t->n_sess++;
    t->trials += so->trials;
}
