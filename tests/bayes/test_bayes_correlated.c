/* The correlated offset prior (docs/bayes-method.md): a deviation from the parametric surface
 * that neighbouring cells share is predicted for a cell from its neighbours' trials.
 * Observer: the default parametric surface plus a loss of +0.25 log10 in threshold at 4 cpd (a
 * bump 0.5 octave wide in log2 f) at every eccentricity, as a notch in the foveal curve would
 * give. Every cell except the probe (4 cpd, 0 deg) gets 30 trials around its true threshold; the
 * probe gets none, so its estimate is the model's prediction from the other cells alone. With
 * independent offsets that prediction is the parametric surface, pulled a little by theta
 * (measured: half of the deviation, 0.12 of 0.25; 0.115 with the surface's frequency scaling);
 * with the correlated prior the other 4 cpd cells' shared deviation must carry it further
 * (measured: 0.17 when the prior came; 0.162 before the frequency scaling, 0.142 with it, which
 * lets the surface itself bend a little towards the neighbours, less of it left to share). The
 * bound, 0.13, sits halfway between the independent and the correlated prediction. Without a
 * deviation the same procedure must keep predicting the surface. Deterministic (seeded). */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

enum { PER_CELL = 30 };

static double bump(const csf_cell *c, double height)
{
    double u = log2(c->freq_cpd / 4.0) / 0.5;
    return height * exp(-0.5 * u * u);
}

/* Runs the fixed design; returns the probe's estimated log10 threshold. */
static double probe_estimate(double height, const csf_cell *cells, int n, int probe, double *truth)
{
    sim2afc o;
    sim2afc_parametric(&o, csf_model_default(), 5);
    csf_procedure_setup setup = {.cells = cells, .n_cells = n, .trial_budget = 0, .seed = 9,
                                 .max_contrast = 1.0, .min_contrast = 0.0005, .slope_beta = 3.5,
                                 .lapse = 0.02, .guess = 0.5};
    csf_error err = {0};
    void *st = NULL;
    CHECK(csf_procedure_bayes.create(&setup, &st, &err) == CSF_OK);
    if (!st) return NAN;
    int k = 0;
    for (int rep = 0; rep < PER_CELL; rep++)
        for (int c = 0; c < n; c++) {
            if (c == probe) continue;
            double t = sim2afc_log10_threshold(&o, cells[c].freq_cpd, cells[c].ecc_deg) + bump(&cells[c], height);
            if (t > -0.1) continue; /* not visible (or barely) on this display: leave it out */
            double x = t + 0.15 * ((rep % 3) - 1);
            csf_trial_plan plan = {.cell = c, .task = CSF_TASK_2AFC, .contrast = pow(10.0, x),
                                   .signal_interval = (rep + c) & 1};
            /* the simulated observer, with the bump folded into its threshold */
            double seen = 1.0 - exp(-pow(10.0, o.slope * (x - t)));
            double pc = 0.5 + (0.5 - o.lapse) * seen;
            int correct = csf_rng_uniform(77, 0x51a1, (uint64_t)k) < pc;
            csf_trial_outcome out = {.response = correct ? plan.signal_interval : 1 - plan.signal_interval,
                                     .rt_s = 0.6, .contrast_at_response = NAN, .valid = 1};
            csf_procedure_bayes.update(st, k++, &plan, &out);
        }
    csf_cell_estimate est[24];
    CHECK(csf_procedure_bayes.estimate(st, est, &err) == CSF_OK);
    csf_procedure_bayes.destroy(st);
    *truth = sim2afc_log10_threshold(&o, cells[probe].freq_cpd, cells[probe].ecc_deg) + bump(&cells[probe], height);
    CHECK_INT_EQ(est[probe].n_trials, 0);
    return isfinite(est[probe].threshold) ? log10(est[probe].threshold) : 0.0;
}

int main(void)
{
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    int probe = 3; /* 4 cpd, 0 deg */
    CHECK(cells[probe].freq_cpd == 4.0 && cells[probe].ecc_deg == 0.0);

    double truth0, truth1;
    double e0 = probe_estimate(0.0, cells, n, probe, &truth0);
    double e1 = probe_estimate(0.25, cells, n, probe, &truth1);
    printf("no deviation: probe true %.3f, predicted %.3f\n", truth0, e0);
    printf("shared +0.25 bump: probe true %.3f, predicted %.3f (surface alone %.3f)\n", truth1, e1, truth0);
    CHECK_MSG(fabs(e0 - truth0) < 0.08, "no deviation: predicted %.3f, true %.3f", e0, truth0);
    /* most of the neighbours' shared deviation reaches the probe */
    CHECK_MSG(e1 - truth0 > 0.13, "bump: predicted %.3f, surface %.3f", e1, truth0);
    CHECK_MSG(fabs(e1 - truth1) < 0.25 - 0.13, "bump: predicted %.3f, true %.3f", e1, truth1);
    return CHECK_RESULT();
}
