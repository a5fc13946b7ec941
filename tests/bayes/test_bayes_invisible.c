/* Cells the display cannot make visible are reported as INFINITY when the data say so, and only
 * then: (1) the default observer on a low-contrast display (max Michelson 0.1): cells whose true
 * threshold lies well above 0.1 must come out INFINITY, cells well below it finite and accurate;
 * (2) an observer who sees nothing at all: every cell INFINITY, even where the prior surface
 * predicted a visible threshold. */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

int main(void)
{
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);

    /* (1) display with max contrast 0.1 */
    const double cmax = 0.1;
    int n_far_above = 0, n_far_below = 0;
    for (uint64_t seed = 1; seed <= 2; seed++) {
        sim2afc o;
        sim2afc_parametric(&o, csf_model_default(), seed);
        csf_cell_estimate est[24];
        CHECK_INT_EQ(sim2afc_run(&csf_procedure_bayes, &o, cells, n, 120, 70 + seed, cmax, est), 0);
        for (int c = 0; c < n; c++) {
            double t = sim2afc_log10_threshold(&o, cells[c].freq_cpd, cells[c].ecc_deg);
            if (t > log10(cmax) + 0.3) {
                n_far_above++;
                CHECK_MSG(isinf(est[c].threshold) && est[c].threshold > 0,
                          "cell %d (%.1f cpd, %.0f deg) true %.2f log10, estimate %g", c,
                          cells[c].freq_cpd, cells[c].ecc_deg, t, est[c].threshold);
                CHECK(isnan(est[c].stderr_log10));
            } else if (t < log10(cmax) - 0.3) {
                n_far_below++;
                CHECK_MSG(isfinite(est[c].threshold) && fabs(log10(est[c].threshold) - t) < 0.35,
                          "cell %d true %.2f log10, estimate %g", c, t, est[c].threshold);
            }
            if (isfinite(est[c].threshold)) CHECK(est[c].threshold <= cmax);
        }
    }
    /* the default observer has both kinds of cell on this display */
    CHECK(n_far_above >= 6);
    CHECK(n_far_below >= 20);

    /* (2) an observer who sees nothing (thresholds 10 = never) */
    sim2afc blind;
    sim2afc_parametric(&blind, csf_model_default(), 5);
    blind.is_table = 1;
    blind.n_f = 2, blind.n_e = 2;
    blind.f[0] = log10(0.1), blind.f[1] = log10(100.0);
    blind.e[0] = 0.0, blind.e[1] = 90.0;
    for (int k = 0; k < 4; k++) blind.lt[k] = 1.0;
    csf_cell_estimate est[24];
    CHECK_INT_EQ(sim2afc_run(&csf_procedure_bayes, &blind, cells, n, 120, 9, 1.0, est), 0);
    int n_inf = 0;
    for (int c = 0; c < n; c++) n_inf += isinf(est[c].threshold) != 0;
    CHECK_MSG(n_inf == n, "blind observer: only %d of %d cells reported invisible", n_inf, n);
    return CHECK_RESULT();
}
