/* bayes with the session's default layout: four places (guess 1/4) off the fovea, two intervals at
 * the fovea (calib/afc_layout on the default station). Checks that plans carry the cell's layout
 * and a signal place in range and spread over all four places, that the method recovers the
 * model's own parametric observer and the two table-defined observers (not of the model's form;
 * paths in argv[1], argv[2]) at 120 trials, with at most one cell's visibility wrong per session,
 * and that on the same seeds it is more accurate than with two intervals everywhere
 * (BENCHMARKS.md: about 0.08-0.09 against 0.09-0.11 log10 over 20 seeds). The parametric observer
 * is here because a change to the surface that the mixed layout tolerates may cost the model's
 * own form, which test_bayes_recovery checks with two intervals only. */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_bayes_four_places BUMPY.csv MSCALED.csv\n");
        return 2;
    }
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    csf_error err;
    int n_alt[24];
    CHECK_INT_EQ(sim2afc_default_layouts(cells, n, 4, n_alt), 0);
    for (int c = 0; c < n; c++) CHECK_INT_EQ(n_alt[c], cells[c].ecc_deg > 0 ? 4 : 2);

    /* plans: the layout of their cell, the signal place in range and used evenly */
    csf_procedure_setup setup = {.cells = cells, .n_cells = n, .trial_budget = 200, .seed = 7,
                                 .max_contrast = 1.0, .min_contrast = 0.0005, .slope_beta = 3.5,
                                 .lapse = 0.02, .guess = 0.5, .n_alternatives = n_alt};
    void *st = NULL;
    CHECK(csf_procedure_bayes.create(&setup, &st, &err) == CSF_OK);
    sim2afc o;
    if (sim2afc_table(&o, argv[2], 3) != 0) return 1;
    int place_count[4] = {0}, n_four = 0;
    for (int k = 0; st && k < 200; k++) {
        csf_trial_plan plan;
        CHECK(csf_procedure_bayes.next(st, k, &plan) == CSF_OK);
        CHECK_INT_EQ(plan.n_alternatives, n_alt[plan.cell]);
        CHECK(plan.signal_interval >= 0 && plan.signal_interval < plan.n_alternatives);
        if (plan.n_alternatives == 4) place_count[plan.signal_interval]++, n_four++;
        csf_trial_outcome out = sim2afc_respond(&o, &plan, cells[plan.cell].freq_cpd, cells[plan.cell].ecc_deg, k);
        CHECK(out.response >= 0 && out.response < plan.n_alternatives);
        csf_procedure_bayes.update(st, k, &plan, &out);
    }
    if (st) csf_procedure_bayes.destroy(st);
    CHECK(n_four > 100);
    for (int p = 0; p < 4; p++)
        CHECK_MSG(place_count[p] > n_four / 8, "place %d chosen %d of %d times", p, place_count[p], n_four);

    /* accuracy on the parametric observer (0) and both table observers, against two intervals
     * everywhere on the same seeds */
    double pooled4 = 0.0, pooled2 = 0.0;
    const int n_observers = 3;
    for (int table = 0; table < n_observers; table++) {
        const char *name = table ? argv[table] : "parametric";
        double sq4 = 0.0, sq2 = 0.0;
        int runs = 0;
        for (uint64_t seed = 21; seed <= 26; seed++) {
            if (table == 0) sim2afc_parametric(&o, csf_model_default(), seed);
            else if (sim2afc_table(&o, argv[table], seed) != 0) return 1;
            csf_cell_estimate e4[24], e2[24];
            CHECK_INT_EQ(sim2afc_run_alt(&csf_procedure_bayes, &o, cells, n, n_alt, 120, 900 + seed, 1.0, e4), 0);
            CHECK_INT_EQ(sim2afc_run_alt(&csf_procedure_bayes, &o, cells, n, NULL, 120, 900 + seed, 1.0, e2), 0);
            int wrong4 = 0;
            double r4 = sim2afc_rms(&o, cells, n, e4, 1.0, &wrong4), r2 = sim2afc_rms(&o, cells, n, e2, 1.0, NULL);
            printf("%s seed %llu: RMS four places %.3f (visibility wrong in %d cells), two intervals %.3f\n",
                   name, (unsigned long long)seed, r4, wrong4, r2);
            CHECK_MSG(r4 < 0.17, "%s seed %llu RMS %.3f", name, (unsigned long long)seed, r4);
            CHECK_MSG(wrong4 <= 1, "%s seed %llu: %d cells with the wrong visibility", name,
                      (unsigned long long)seed, wrong4);
            sq4 += r4 * r4, sq2 += r2 * r2, runs++;
        }
        double rms4 = sqrt(sq4 / runs), rms2 = sqrt(sq2 / runs);
        printf("%s: RMS over seeds: four places %.3f, two intervals %.3f\n", name, rms4, rms2);
        CHECK_MSG(rms4 < 0.12, "%s: four places RMS %.3f", name, rms4);
        /* the layout comparison stays over the two table observers it was written for: the
         * parametric one's gain on these six seeds (0.065 against 0.068) is inside the seed
         * spread (20 seeds in BENCHMARKS.md: 0.082 against 0.093) */
        if (table) pooled4 += rms4 * rms4 / 2, pooled2 += rms2 * rms2 / 2;
    }
    /* over both table observers (per observer the gain is larger than the seed spread only over
     * more seeds than a unit test runs) */
    CHECK_MSG(sqrt(pooled4) < 0.95 * sqrt(pooled2), "four places %.3f not better than two intervals %.3f",
              sqrt(pooled4), sqrt(pooled2));
    return CHECK_RESULT();
}
