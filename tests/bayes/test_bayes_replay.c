/* Determinism contract of calib/procedure.h for bayes: the same seed gives the same plans; a
 * state rebuilt by replaying stored trials through update() plans exactly what the uninterrupted
 * run planned next; next() does not change the state; a different seed plans differently;
 * invalid trials are ignored. */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

enum { N_TRIALS = 50 };

static int same_plan(const csf_trial_plan *a, const csf_trial_plan *b)
{
    return a->cell == b->cell && a->contrast == b->contrast && a->signal_interval == b->signal_interval &&
           a->polar_deg == b->polar_deg && a->task == b->task;
}

static void *make(uint64_t seed, const csf_cell *cells, int n)
{
    csf_procedure_setup setup = {.cells = cells, .n_cells = n, .trial_budget = 120, .seed = seed,
                                 .max_contrast = 1.0, .min_contrast = 0.0005, .slope_beta = 3.5,
                                 .lapse = 0.02, .guess = 0.5};
    csf_error err = {0};
    void *st = NULL;
    CHECK(csf_procedure_bayes.create(&setup, &st, &err) == CSF_OK);
    return st;
}

int main(void)
{
    const csf_procedure_ops *ops = &csf_procedure_bayes;
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    sim2afc o;
    sim2afc_parametric(&o, csf_model_default(), 7);

    /* the uninterrupted run, trials kept as a store would keep them */
    csf_trial_plan plans[N_TRIALS + 1];
    csf_trial_outcome outs[N_TRIALS];
    void *a = make(42, cells, n);
    int distinct_cells = 0, used[24] = {0}, interval1 = 0;
    for (int k = 0; k < N_TRIALS; k++) {
        CHECK(ops->next(a, k, &plans[k]) == CSF_OK);
        csf_trial_plan again;
        CHECK(ops->next(a, k, &again) == CSF_OK);
        CHECK_MSG(same_plan(&plans[k], &again), "next() twice differs at trial %d", k);
        CHECK(plans[k].task == CSF_TASK_2AFC);
        CHECK(plans[k].contrast > 0.0 && plans[k].contrast <= 1.0);
        CHECK(plans[k].polar_deg >= 0.0 && plans[k].polar_deg < 360.0);
        if (!used[plans[k].cell]++) distinct_cells++;
        interval1 += plans[k].signal_interval;
        outs[k] = sim2afc_respond(&o, &plans[k], cells[plans[k].cell].freq_cpd, cells[plans[k].cell].ecc_deg, k);
        ops->update(a, k, &plans[k], &outs[k]);
    }
    CHECK(ops->next(a, N_TRIALS, &plans[N_TRIALS]) == CSF_OK);
    /* stimuli spread over the grid, signal interval balanced */
    CHECK_MSG(distinct_cells >= 12, "only %d cells tested in %d trials", distinct_cells, N_TRIALS);
    CHECK_MSG(interval1 > N_TRIALS / 4 && interval1 < 3 * N_TRIALS / 4, "interval 1 in %d of %d", interval1, N_TRIALS);

    /* resume: a fresh state fed the stored trials, interleaved with invalid trials that must not count */
    void *b = make(42, cells, n);
    for (int k = 0; k < N_TRIALS; k++) {
        csf_trial_outcome bad = outs[k];
        bad.valid = 0;
        bad.response = 1 - outs[k].response;
        ops->update(b, k, &plans[k], &bad);
        ops->update(b, k, &plans[k], &outs[k]);
    }
    csf_trial_plan resumed;
    CHECK(ops->next(b, N_TRIALS, &resumed) == CSF_OK);
    CHECK_MSG(same_plan(&resumed, &plans[N_TRIALS]), "resumed plan differs: cell %d vs %d, contrast %g vs %g",
              resumed.cell, plans[N_TRIALS].cell, resumed.contrast, plans[N_TRIALS].contrast);
    csf_cell_estimate ea[24], eb[24];
    csf_error err = {0};
    CHECK(ops->estimate(a, ea, &err) == CSF_OK);
    CHECK(ops->estimate(b, eb, &err) == CSF_OK);
    int identical = 1;
    for (int c = 0; c < n; c++)
        identical &= ea[c].n_trials == eb[c].n_trials &&
                     (ea[c].threshold == eb[c].threshold || (isinf(ea[c].threshold) && isinf(eb[c].threshold)));
    CHECK_MSG(identical, "estimates of the resumed state differ");

    /* another seed plans differently (the random parts at least) */
    void *c2 = make(43, cells, n);
    int differ = 0;
    for (int k = 0; k < 10; k++) {
        csf_trial_plan p;
        CHECK(ops->next(c2, k, &p) == CSF_OK);
        differ += !same_plan(&p, &plans[k]);
        ops->update(c2, k, &p, &outs[k]);
    }
    CHECK_MSG(differ >= 5, "seed 43 repeated %d of 10 plans of seed 42", 10 - differ);

    /* the budget ends the procedure */
    csf_trial_plan end;
    CHECK(ops->next(a, 120, &end) == CSF_E_ABORTED);
    ops->destroy(a);
    ops->destroy(b);
    ops->destroy(c2);
    return CHECK_RESULT();
}
