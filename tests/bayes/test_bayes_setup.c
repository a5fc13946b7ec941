/* Setup checks (each bad value refused with a message naming the value and its limit), the model
 * check (a cell the surface cannot explain is flagged and estimated from its own trials), and the
 * extra read-outs of calib/method_bayes.h. */
#include "calib/method_bayes.h"
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

static void expect_refused(csf_procedure_setup setup, const char *needle)
{
    csf_error err = {0};
    void *st = (void *)1;
    csf_status rc = csf_procedure_bayes.create(&setup, &st, &err);
    CHECK_MSG(rc == CSF_E_INVALID_ARG, "expected refusal mentioning '%s', got %d", needle, rc);
    CHECK(st == NULL);
    CHECK_STR_CONTAINS(err.msg, needle);
}

int main(void)
{
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    const csf_procedure_setup good = {.cells = cells, .n_cells = n, .trial_budget = 120, .seed = 1,
                                      .max_contrast = 1.0, .min_contrast = 0.0005, .slope_beta = 3.5,
                                      .lapse = 0.02, .guess = 0.5};
    csf_procedure_setup s;
    s = good, s.n_cells = 0;
    expect_refused(s, "1 to 4096");
    s = good, s.max_contrast = 1.5;
    expect_refused(s, "(0, 1]");
    s = good, s.min_contrast = 2.0;
    expect_refused(s, "below the max contrast");
    s = good, s.lapse = 0.5;
    expect_refused(s, "0-0.2");
    s = good, s.slope_beta = -1;
    expect_refused(s, "0.3-20");
    s = good, s.trial_budget = -5;
    expect_refused(s, "0-100000");
    csf_cell bad_cells[2] = {{1.0, 0.0, 0}, {-2.0, 5.0, 0}};
    s = good, s.cells = bad_cells, s.n_cells = 2;
    expect_refused(s, "frequency -2 cpd");
    bad_cells[1] = (csf_cell){2.0, NAN, 0};
    expect_refused(s, "eccentricity");

    /* a one-cell grid (a single foveal staircase) works: 40 trials recover its threshold */
    {
        csf_cell one = {4.0, 0.0, 0};
        sim2afc o1;
        sim2afc_parametric(&o1, csf_model_default(), 21);
        csf_cell_estimate e1;
        CHECK_INT_EQ(sim2afc_run(&csf_procedure_bayes, &o1, &one, 1, 40, 5, 1.0, &e1), 0);
        double t1 = sim2afc_log10_threshold(&o1, 4.0, 0.0);
        CHECK_MSG(isfinite(e1.threshold) && fabs(log10(e1.threshold) - t1) < 0.3, "one cell: %g vs %g",
                  log10(e1.threshold), t1);
        CHECK_INT_EQ(e1.n_trials, 40);
    }

    /* model check: the default surface except one cell 0.7 log10 less sensitive (a local
     * loss, as near a scotoma) */
    const int odd = 14; /* 2 cpd at 10 deg */
    sim2afc o;
    sim2afc_parametric(&o, csf_model_default(), 3);
    csf_model_params p = csf_model_default();
    o.is_table = 1;
    o.n_f = 6, o.n_e = 4;
    for (int c = 0; c < n; c++) {
        o.f[c % 6] = log10(cells[c].freq_cpd);
        o.e[c / 6] = cells[c].ecc_deg;
        o.lt[c] = -csf_model_log10_sensitivity(&p, cells[c].freq_cpd, cells[c].ecc_deg) + (c == odd ? 0.7 : 0.0);
    }
    /* A 240-trial session per seed; the odd cell must be flagged and recovered (within 0.25 log10)
     * in at least 12 of 20 seeds: with few trials there (3-8 in the seeds that miss it), chance can
     * hide a local loss. Measured: 14 of 20 (16 of 20 with the frequency scaling pinned at 0; with
     * 5 seeds the count moved between 3 and 5 of 5 on such changes, too coarse to check). A method
     * that stops flagging misfits finds it in none. */
    int n_found = 0;
    for (uint64_t seed = 77; seed < 97; seed++) {
        /* told the observer's slope and lapse: with them marginalised (the default) the odd
         * cell was found in only 3 of the first 5 seeds (in two it got 4-7 trials:
         * its wrong answers pass for lapses); docs/bayes-method.md, Limits */
        s = good, s.seed = seed, s.trial_budget = 240, s.fixed_psychometric = 1;
        o.seed = seed;
        void *st = NULL;
        csf_error err = {0};
        CHECK(csf_procedure_bayes.create(&s, &st, &err) == CSF_OK);
        for (int k = 0; k < 240; k++) {
            csf_trial_plan plan;
            CHECK(csf_procedure_bayes.next(st, k, &plan) == CSF_OK);
            csf_trial_outcome out = sim2afc_respond(&o, &plan, cells[plan.cell].freq_cpd, cells[plan.cell].ecc_deg, k);
            csf_procedure_bayes.update(st, k, &plan, &out);
        }
        csf_bayes_cell_check chk[24];
        csf_cell_estimate est[24];
        CHECK(csf_bayes_check(st, chk, &err) == CSF_OK);
        CHECK(csf_procedure_bayes.estimate(st, est, &err) == CSF_OK);
        double truth = o.lt[odd];
        printf("seed %llu odd cell: %d trials, log10 BF %.2f, misfit %d, estimate %.3f (truth %.3f, surface %.3f)\n",
               (unsigned long long)seed, chk[odd].n_trials, chk[odd].log10_bayes_factor, chk[odd].misfit,
               log10(est[odd].threshold), truth, chk[odd].surface_log10);
        n_found += chk[odd].misfit == 1 && fabs(log10(est[odd].threshold) - truth) < 0.25;
        int other_misfits = 0;
        for (int c = 0; c < n; c++) {
            if (c != odd) other_misfits += chk[c].misfit;
            CHECK_INT_EQ(chk[c].n_trials, est[c].n_trials);
        }
        CHECK_MSG(other_misfits <= 2, "%d other cells flagged", other_misfits);
        /* the surface itself still describes the rest: its mean parameters are near the truth */
        double th[CSF_BAYES_NPAR];
        csf_bayes_surface_mean(st, th);
        printf("  surface: log10 Smax %.2f, log10 fmax %.2f, beta %.2f oct, delta %.2f, a %.4f, b %.4f; ESS %.0f\n",
               th[0], th[1], th[2], th[3], th[4], th[5], csf_bayes_effective_particles(st));
        CHECK_NEAR(th[0], log10(p.smax), 0.2);
        CHECK_NEAR(th[1], log10(p.fmax_cpd), 0.25);
        CHECK(csf_bayes_effective_particles(st) > 10.0);
        csf_procedure_bayes.destroy(st);
    }
    CHECK_MSG(n_found >= 12, "odd cell found in %d of 20 seeds", n_found);
    return CHECK_RESULT();
}
