/* A cell is written never visible only on its own answers at the display's highest contrast. A person like
 * the model's own but who sees 8 cpd at 20 deg at contrast 0.5, where the surface puts the threshold 1.5
 * log10 beyond the display's reach: once the person's answers are above chance, the cell is checked at the
 * top contrast beside its visible neighbours, found visible and measured, in every seed, under a precision
 * stop (trials priced by the person's time) and at a fixed budget alike; the surface alone would give it
 * no trial and write it never visible. The model's own person keeps its invisible cells (16 cpd at 10 and
 * 20 deg) never visible, and a person who sees nothing is still written never visible everywhere. Answers
 * lower down are no check: a cell with 14 of them is still checked at the top. */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

enum { N_CELLS = 24, TRIALS = 200 };
static const double ECCS[4] = {0, 5, 10, 20};

/* The model's own person on the default grid as a table, with cell (fi, ei) at log10 threshold
 * over (NAN: none changed). */
static void person(sim2afc *o, int fi, int ei, double over, uint64_t seed)
{
    sim2afc model;
    sim2afc_parametric(&model, csf_model_default(), seed);
    memset(o, 0, sizeof *o);
    o->is_table = 1;
    o->slope = 3.5;
    o->lapse = 0.02;
    o->seed = seed;
    o->method_psychometric = 1; /* as a session: slope and lapse unknown */
    o->n_f = 6, o->n_e = 4;
    for (int i = 0; i < 6; i++) o->f[i] = log10(0.5 * pow(2.0, i));
    for (int j = 0; j < 4; j++) o->e[j] = ECCS[j];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 6; i++)
            o->lt[j * 6 + i] = sim2afc_log10_threshold(&model, 0.5 * pow(2.0, i), ECCS[j]);
    if (!isnan(over)) o->lt[ei * 6 + fi] = over;
}

/* TRIALS trials of bayes on o, under a precision plan (priced) or a fixed budget; est gets the
 * table. The first n_lapsed trials are on cell c at contrast 0.5, all answered wrong (a block of
 * lapses), the rest as the procedure plans them. Returns the trials at the display's highest
 * contrast in cell c. */
static int run(const sim2afc *o, const csf_cell *cells, int priced, uint64_t seed, int c, int n_lapsed,
               csf_cell_estimate *est)
{
    double trial_s[N_CELLS];
    for (int k = 0; k < N_CELLS; k++) trial_s[k] = 2.4;
    csf_procedure_setup setup = {.cells = cells,
                                 .n_cells = N_CELLS,
                                 .trial_budget = priced ? 960 : TRIALS,
                                 .seed = 100 + seed,
                                 .max_contrast = 1.0,
                                 .min_contrast = 0.0005,
                                 .slope_beta = 3.5,
                                 .lapse = 0.02,
                                 .guess = 0.5,
                                 .fixed_psychometric = 0,
                                 .trial_s = priced ? trial_s : NULL,
                                 .planned_trials = priced ? TRIALS : 0};
    csf_error err = {0};
    void *st = NULL;
    CHECK_INT_EQ(csf_procedure_bayes.create(&setup, &st, &err), CSF_OK);
    if (!st) return -1;
    int at_top = 0;
    for (int k = 0; k < TRIALS; k++) {
        csf_trial_plan plan;
        csf_trial_outcome out;
        if (k < n_lapsed) {
            memset(&plan, 0, sizeof plan);
            plan.cell = c, plan.contrast = 0.5, plan.n_alternatives = 2, plan.signal_interval = k % 2;
            out = (csf_trial_outcome){.response = 1 - plan.signal_interval, .rt_s = 0.6, .valid = 1};
        } else {
            if (csf_procedure_bayes.next(st, k, &plan) != CSF_OK) break;
            out = sim2afc_respond_cell(o, &plan, &cells[plan.cell], k);
        }
        at_top += plan.cell == c && plan.contrast >= 1.0;
        csf_procedure_bayes.update(st, k, &plan, &out);
    }
    CHECK_INT_EQ(csf_procedure_bayes.estimate(st, est, &err), CSF_OK);
    csf_procedure_bayes.destroy(st);
    return at_top;
}

int main(void)
{
    csf_cell cells[N_CELLS];
    CHECK_INT_EQ(sim2afc_default_grid(cells), N_CELLS);
    const int fi = 4, ei = 3, c = ei * 6 + fi; /* 8 cpd, 20 deg */
    double err[4];
    for (uint64_t seed = 1; seed <= 4; seed++) {
        sim2afc o;
        person(&o, fi, ei, -0.3, seed);
        csf_cell_estimate est[N_CELLS];
        int top = run(&o, cells, 1, seed, c, 0, est);
        CHECK_MSG(isfinite(est[c].threshold),
                  "seed %d: 8 cpd 20 deg (truth -0.30) written never visible after %d "
                  "trials at the top",
                  (int)seed, top);
        CHECK_MSG(top >= 4, "seed %d: %d checks at the top contrast", (int)seed, top);
        err[seed - 1] = isfinite(est[c].threshold) ? fabs(log10(est[c].threshold) + 0.3) : INFINITY;
        printf("seed %d: checked %d at the top, written %.3f (truth -0.30) +- %.3f from %d trials\n",
               (int)seed, top, log10(est[c].threshold), est[c].stderr_log10, est[c].n_trials);
        int fixed_top = run(&o, cells, 0, seed, c, 0, est);
        CHECK_MSG(fixed_top >= 4 && isfinite(est[c].threshold),
                  "seed %d, fixed budget: %d checks at the top, written %g", (int)seed, fixed_top,
                  est[c].threshold);
    }
    /* A cell with many answers below the top contrast before the surface moves it past the reach:
     * a person who sees 16 cpd at 5 deg just inside or just beyond the reach (truth -0.05 or +0.05;
     * the model's person +0.05) has answered it wrong 14 times at contrast 0.5 (the session's first
     * trials: a block of lapses). Whatever those answers say, the documented rule holds: no cell
     * beside a visible one is written never visible before CHECK_MIN answers at the top contrast. */
    int right = 0;
    for (int beyond = 0; beyond <= 1; beyond++)
        for (uint64_t seed = 1; seed <= 4; seed++) {
            const int lower = 1 * 6 + 5; /* 16 cpd, 5 deg */
            const double truth = beyond ? 0.05 : -0.05;
            sim2afc o;
            person(&o, lower % 6, lower / 6, truth, seed);
            csf_cell_estimate est[N_CELLS];
            int top = run(&o, cells, 0, seed, lower, 14, est);
            printf("seed %d: 16 cpd 5 deg (truth %+.2f) after 14 wrong answers at 0.5: %d at the top, "
                   "written %.3f\n",
                   (int)seed, truth, top, log10(est[lower].threshold));
            CHECK_MSG(
                isfinite(est[lower].threshold) || top >= 4,
                "seed %d, truth %+.2f: written never visible after %d answers at the top (14 lower down)",
                (int)seed, truth, top);
            right += isinf(est[lower].threshold) == beyond;
        }
    /* the checks at the top tell the two apart where the answers lower down cannot */
    CHECK_MSG(right >= 7,
              "16 cpd 5 deg, truth 0.05 inside or beyond the reach: %d of 8 written on the right side",
              right);
    double sorted[4];
    memcpy(sorted, err, sizeof sorted);
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++)
            if (sorted[j] < sorted[i]) {
                double t = sorted[i];
                sorted[i] = sorted[j], sorted[j] = t;
            }
    CHECK_MSG(sorted[1] < 0.15, "checked cell's error, second smallest of 4 seeds: %.3f log10", sorted[1]);

    /* the model's own person: its cells beyond the reach stay never visible */
    for (uint64_t seed = 1; seed <= 2; seed++) {
        sim2afc o;
        person(&o, 0, 0, NAN, seed);
        csf_cell_estimate est[N_CELLS];
        run(&o, cells, 1, seed, c, 0, est);
        for (int k = 0; k < N_CELLS; k++) {
            double t = o.lt[(k / 6) * 6 + k % 6];
            if (t > 0.3)
                CHECK_MSG(isinf(est[k].threshold), "seed %d: cell %d (truth %.2f) written %g", (int)seed, k,
                          t, est[k].threshold);
            if (t < -0.3)
                CHECK_MSG(isfinite(est[k].threshold), "seed %d: cell %d (truth %.2f) never visible",
                          (int)seed, k, t);
        }
    }

    /* a person who sees nothing: never visible everywhere, under either plan (their answers are at
     * chance, so no check takes the trials that move the surface past the reach) */
    sim2afc blind;
    person(&blind, 0, 0, NAN, 5);
    for (int k = 0; k < 6 * 4; k++) blind.lt[k] = 1.0;
    for (int priced = 1; priced >= 0; priced--) {
        csf_cell_estimate est[N_CELLS];
        run(&blind, cells, priced, 5, c, 0, est);
        int n_inf = 0;
        for (int k = 0; k < N_CELLS; k++) n_inf += isinf(est[k].threshold) != 0;
        CHECK_MSG(n_inf == N_CELLS, "blind person (%s): only %d of %d cells never visible",
                  priced ? "precision" : "fixed budget", n_inf, N_CELLS);
    }
    return CHECK_RESULT();
}
