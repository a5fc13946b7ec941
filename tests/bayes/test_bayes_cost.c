/* bayes under a precision stop weighs a trial's expected gain by the person's time it costs
 * (csf_procedure_setup.trial_s): a two-interval trial at the fovea takes longer than four places
 * shown at once. On the model's own person the fovea then gets fewer of the same number of
 * trials, and the trials cost less time. But not where the surface may be wrong: each cell keeps
 * its gain at face value until it has trials of its own to show a misfit, so on a person whose
 * fovea is poorer than the rings predict every foveal cell still gets them, and the foveal row's
 * bias stays within what the method shows without the weighting (test_bayes_fovea). */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

enum { N = 24, TRIALS = 200 };
#define FOVEA_S 2.4 /* two intervals: fixation, two intervals, the gap, the answer */
#define RING_S 1.5  /* four places: fixation, one interval, the answer */

/* One session of TRIALS trials planned as a precision stop would plan it, with or without the
 * trials' costs; trials per cell into n_trials, the person's time into *time_s. */
static void session(const sim2afc *o, const csf_cell *cells, const int *n_alt, uint64_t seed, int weigh,
                    csf_cell_estimate *est, double *time_s)
{
    double trial_s[N];
    for (int c = 0; c < N; c++) trial_s[c] = n_alt[c] == 4 ? RING_S : FOVEA_S;
    csf_procedure_setup setup = {.cells = cells,
                                 .n_cells = N,
                                 .trial_budget = 960,
                                 .seed = seed,
                                 .max_contrast = 1.0,
                                 .min_contrast = 0.0005,
                                 .slope_beta = o->slope,
                                 .lapse = o->lapse,
                                 .guess = 0.5,
                                 .n_alternatives = n_alt,
                                 .planned_trials = TRIALS,
                                 .trial_s = weigh ? trial_s : NULL};
    csf_error err = {0};
    void *st = NULL;
    CHECK(csf_procedure_bayes.create(&setup, &st, &err) == CSF_OK);
    *time_s = 0;
    for (int k = 0; st && k < TRIALS; k++) {
        csf_trial_plan plan;
        if (csf_procedure_bayes.next(st, k, &plan) != CSF_OK) break;
        csf_trial_outcome out = sim2afc_respond_cell(o, &plan, &cells[plan.cell], k);
        csf_procedure_bayes.update(st, k, &plan, &out);
        *time_s += trial_s[plan.cell];
    }
    if (st) CHECK(csf_procedure_bayes.estimate(st, est, &err) == CSF_OK);
    csf_procedure_bayes.destroy(st);
}

static int foveal_trials(const csf_cell *cells, const csf_cell_estimate *est, int *fewest)
{
    int n = 0;
    *fewest = TRIALS;
    for (int c = 0; c < N; c++)
        if (cells[c].ecc_deg < 1.0) {
            n += est[c].n_trials;
            if (est[c].n_trials < *fewest) *fewest = est[c].n_trials;
        }
    return n;
}

int main(void)
{
    csf_cell cells[N];
    int n_alt[N];
    CHECK_INT_EQ(sim2afc_default_grid(cells), N);
    CHECK_INT_EQ(sim2afc_default_layouts(cells, N, 4, n_alt), 0);

    /* the model's own person: fewer foveal trials, less time for the same trials */
    int fovea_plain = 0, fovea_weighed = 0;
    double time_plain = 0, time_weighed = 0;
    for (uint64_t seed = 41; seed <= 42; seed++) {
        sim2afc o;
        sim2afc_parametric(&o, csf_model_default(), seed);
        o.method_psychometric = 1;
        csf_cell_estimate est[N];
        double t;
        int fewest;
        session(&o, cells, n_alt, 800 + seed, 0, est, &t);
        fovea_plain += foveal_trials(cells, est, &fewest), time_plain += t;
        session(&o, cells, n_alt, 800 + seed, 1, est, &t);
        fovea_weighed += foveal_trials(cells, est, &fewest), time_weighed += t;
    }
    printf("model person, 2 x %d trials: foveal trials %d -> %d, person time %.0f -> %.0f s\n", TRIALS,
           fovea_plain, fovea_weighed, time_plain, time_weighed);
    CHECK(fovea_weighed < fovea_plain);
    CHECK(time_weighed < time_plain);

    /* a fovea 0.3 log10 poorer than the rings predict: every foveal cell keeps its own trials */
    csf_model_params poor = csf_model_default();
    poor.fovea_dip_log10 = 0.3;
    for (uint64_t seed = 31; seed <= 32; seed++) {
        sim2afc o;
        sim2afc_parametric(&o, poor, seed);
        o.method_psychometric = 1;
        csf_cell_estimate est[N];
        double t, bias = 0;
        int fewest, n_bias = 0;
        session(&o, cells, n_alt, 700 + seed, 1, est, &t);
        int fov = foveal_trials(cells, est, &fewest);
        for (int c = 0; c < N; c++) {
            double truth = sim2afc_log10_threshold(&o, cells[c].freq_cpd, cells[c].ecc_deg);
            if (cells[c].ecc_deg >= 1.0 || !(truth < 0) || !isfinite(est[c].threshold)) continue;
            bias += log10(est[c].threshold) - truth, n_bias++;
        }
        bias = n_bias ? bias / n_bias : NAN;
        printf("poor fovea, seed %llu: %d foveal trials, fewest on a foveal cell %d; foveal row mean error "
               "%+.3f\n",
               (unsigned long long)seed, fov, fewest, bias);
        CHECK_MSG(fewest >= 5, "a foveal cell got %d trials", fewest);
        CHECK_MSG(fabs(bias) < 0.15, "foveal row biased by %+.3f log10", bias);
    }
    return CHECK_RESULT();
}
