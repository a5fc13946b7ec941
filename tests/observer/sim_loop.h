/* Test helper: runs a procedure against the simulated observer without the presenter, frame by
 * frame at 60 Hz on the planned ramp (what a perfect display would show), so method tests stay
 * fast and independent of GL. The session test (test_session.sh) covers the real pipeline. */
#ifndef CSF_TESTS_OBSERVER_SIM_LOOP_H
#define CSF_TESTS_OBSERVER_SIM_LOOP_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calib/procedure.h"
#include "model/observer_sim.h"

/* Runs up to budget trials; returns the number run. est must hold n_cells entries. */
static int sim_loop_run(const csf_procedure_ops *ops, const csf_procedure_setup *setup,
                        csf_observer_sim *obs, csf_cell_estimate *est)
{
    void *st = NULL;
    csf_error err;
    if (ops->create(setup, &st, &err) != CSF_OK) return -1;
    const double dt = 1.0 / 60;
    int done = 0;
    double clock_s = 0;
    for (int i = 0; i < setup->trial_budget; i++) {
        csf_trial_plan plan;
        if (ops->next(st, i, &plan) != CSF_OK) break;
        const csf_cell *c = &setup->cells[plan.cell];
        csf_trial_outcome out = {0, NAN, NAN, 1};
        if (plan.task == CSF_TASK_FADE) {
            csf_sim_fade_trial tr;
            double window = plan.ramp_s + 1.5;
            csf_observer_sim_fade_begin(obs, (uint64_t)i, c->freq_cpd, c->ecc_deg, plan.polar_deg,
                                        clock_s, window, &tr);
            double xe = log10(plan.contrast), rate = (xe - plan.ramp_start_log10) / plan.ramp_s;
            double shown = 0;
            int nf = (int)ceil(window / dt);
            for (int k = 0; k < nf; k++) {
                double t = k * dt;
                double x = t <= plan.ramp_s ? plan.ramp_start_log10 + rate * t : -INFINITY;
                double cs = plan.is_catch ? 0 : (isfinite(x) ? pow(10.0, x) : 0);
                if (cs > 0) shown = cs;
                double press;
                if (csf_observer_sim_fade_frame(obs, &tr, clock_s + t, cs, &press)) {
                    out.response = 1;
                    out.rt_s = press - clock_s;
                    out.contrast_at_response = shown;
                    double cx, cy;
                    csf_observer_sim_click(obs, &tr, &cx, &cy);
                    double a = plan.polar_deg * M_PI / 180;
                    double dx = cx - c->ecc_deg * cos(a), dy = cy - c->ecc_deg * sin(a);
                    if (plan.is_catch || hypot(dx, dy) > 2.0 + 0.3 * c->ecc_deg || out.rt_s < 0.15)
                        out.valid = 0;
                    break;
                }
            }
            clock_s += window + 1;
        } else {
            /* Two intervals, or four places shown at once (plan.n_alternatives == 4). */
            int m = plan.n_alternatives == 4 ? 4 : 2;
            double cs[4] = {0, 0, 0, 0};
            if (plan.signal_interval < 0 || plan.signal_interval >= m) break;
            cs[plan.signal_interval] = plan.contrast;
            double rt;
            out.response = m == 4 ? csf_observer_sim_afc(obs, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, 4, &rt)
                                  : csf_observer_sim_2afc(obs, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, &rt);
            out.rt_s = rt;
            out.contrast_at_response = plan.contrast;
        }
        ops->update(st, i, &plan, &out);
        done++;
    }
    ops->estimate(st, est, &err);
    ops->destroy(st);
    return done;
}

/* The fade method's anchor share for the sessions below (0: the method's default; negative: none). */
static double sim_loop_fade_anchor_share = 0;

static csf_procedure_setup sim_loop_setup(const csf_cell *cells, int n, int budget, uint64_t seed,
                                          csf_task task)
{
    csf_procedure_setup s = {0};
    s.cells = cells;
    s.n_cells = n;
    s.trial_budget = budget;
    s.seed = seed;
    s.max_contrast = 1.0;
    s.min_contrast = 0.0005;
    s.slope_beta = 3.5;
    s.lapse = 0.02;
    s.guess = task == CSF_TASK_2AFC ? 0.5 : 0.02;
    s.ramp_start_log10 = -3.0;
    s.ramp_end_log10 = 0.0;
    s.ramp_s = 6.0;
    s.reaction_latency_s = 0.37;
    s.fade_anchor_share = sim_loop_fade_anchor_share;
    return s;
}

/* One seeded session of ops on the simulated person spec (person seed 1000 + seed, method seed
 * seed) over cells: err_log10[i] is log10 of the estimate over the person's true threshold (not
 * finite where either is). layout: alternatives per cell (NULL: the method's own); fixed_slope > 0
 * gives the method that slope and lapse 0.02 instead of leaving them unknown. Returns 0, or -1
 * (said on stderr) when the person or the method cannot start. */
static inline int sim_loop_errors(const csf_procedure_ops *ops, const char *spec, const csf_cell *cells, int n,
                                  int budget, uint64_t seed, const int *layout, double fixed_slope, double *err_log10)
{
    csf_observer_sim *obs;
    csf_error err;
    if (csf_observer_sim_create(spec, 1000 + seed, &obs, &err) != CSF_OK) {
        fprintf(stderr, "observer %s: %s\n", spec, err.msg);
        return -1;
    }
    csf_procedure_setup s = sim_loop_setup(cells, n, budget, seed, ops->task);
    s.n_alternatives = layout;
    if (fixed_slope > 0) s.fixed_psychometric = 1, s.slope_beta = fixed_slope, s.lapse = 0.02;
    csf_cell_estimate *est = calloc((size_t)n, sizeof *est);
    int rc = est && sim_loop_run(ops, &s, obs, est) >= 0 ? 0 : -1;
    for (int i = 0; rc == 0 && i < n; i++)
        err_log10[i] = log10(est[i].threshold) - log10(csf_observer_sim_threshold(obs, cells[i].freq_cpd, cells[i].ecc_deg));
    if (rc) fprintf(stderr, "%s could not start on %s\n", ops->name, spec);
    free(est);
    csf_observer_sim_free(obs);
    return rc;
}

#endif
