/* A cell whose threshold sits at the display's reach: when bayes reports it visible, its
 * threshold is the posterior mean of the thresholds the display can show (t <= log10 max
 * contrast), not the mean over every threshold clipped at the reach. The mass above the reach
 * means "never visible" whatever its value (the grid runs 1 log10 above it), so letting it into
 * the mean pulled edge cells up to exactly the max contrast (inflating the error over the visible
 * cells of observers who are less sensitive than the prior).
 * One cell (12 cpd at 10 deg: the prior puts it near the reach; 16 cpd at 10 deg was the cell before
 * the surface's frequency scaling, whose prior puts that cell deeper, so that 7 of 8 at the reach
 * and 4 of 4 below it no longer outweigh it), slope and lapse fixed, k of 8
 * two-interval trials correct at the max contrast and all 4 correct at 0.3 log10 below it: for
 * every k whose table calls the cell visible, the estimate lies below the reach by at least half
 * the posterior sd it reports, and with 7 of 8 correct at the reach (and 4 of 4 below) it is at
 * least 0.2 log10 below the reach. Before the fix, k = 7 gave exactly the max contrast. */
#include <math.h>
#include <stdio.h>

#include "calib/procedure.h"
#include "tests/check.h"

static int run(int k_correct, double cmax, csf_cell_estimate *est)
{
    csf_cell cell = {.freq_cpd = 12.0, .ecc_deg = 10.0};
    csf_procedure_setup setup = {.cells = &cell, .n_cells = 1, .trial_budget = 0, .seed = 7,
                                 .max_contrast = cmax, .min_contrast = 0.0005, .slope_beta = 3.5,
                                 .lapse = 0.02, .guess = 0.5, .fixed_psychometric = 1};
    csf_error err = {0};
    void *st = NULL;
    if (csf_procedure_bayes.create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "create: %s\n", err.msg);
        return -1;
    }
    for (int i = 0; i < 12; i++) {
        int at_max = i < 8;
        csf_trial_plan plan = {.cell = 0, .contrast = at_max ? cmax : cmax * pow(10.0, -0.3),
                               .n_alternatives = 2, .signal_interval = i % 2, .task = CSF_TASK_2AFC};
        int correct = at_max ? i < k_correct : 1;
        csf_trial_outcome out = {.valid = 1, .rt_s = 0.6, .contrast_at_response = plan.contrast,
                                 .response = correct ? plan.signal_interval : 1 - plan.signal_interval};
        csf_procedure_bayes.update(st, i, &plan, &out);
    }
    csf_status rc = csf_procedure_bayes.estimate(st, est, &err);
    csf_procedure_bayes.destroy(st);
    return rc == CSF_OK ? 0 : -1;
}

int main(void)
{
    const double cmax = 0.1;
    int n_visible = 0;
    for (int k = 0; k <= 8; k++) {
        csf_cell_estimate est;
        CHECK_INT_EQ(run(k, cmax, &est), 0);
        if (!isfinite(est.threshold)) continue;
        n_visible++;
        double lt = log10(est.threshold);
        printf("k=%2d: log10 threshold %.3f (reach %.3f), sd %.3f\n", k, lt, log10(cmax), est.stderr_log10);
        CHECK_MSG(lt < log10(cmax) - 0.5 * est.stderr_log10,
                  "%d of 8 correct at the reach: estimate %.3f log10, reach %.3f, sd %.3f", k, lt,
                  log10(cmax), est.stderr_log10);
        if (k == 7) CHECK_MSG(lt < log10(cmax) - 0.2, "7 of 8 at the reach: estimate %.3f log10", lt);
    }
    /* the edge cases are there: some k are visible (7 and 8 at least), some not */
    CHECK(n_visible >= 2 && n_visible <= 8);
    return CHECK_RESULT();
}
