/* bayes on a person whose fovea is poorer than the rings predict (a central loss: early macular
 * degeneration, or the rod-free fovea at scotopic levels), with the session's default layout:
 * two intervals at the fovea, four places on the rings. The truth is the model's own parametric
 * surface with its foveal term set (log10 S loses 0.3 exp(-(e / 2 deg)^2)); slope and lapse are
 * unknown to the method, as in a session. The shipped surface pins that term at 0 (every way of
 * freeing it has cost ordinary people more than it gained; calib/method_bayes.c), so it
 * extrapolates the fovea from the rings and reads the foveal row too sensitive, by about 0.1
 * log10 here, which the foveal trials' own offsets keep from being the full 0.3. This bounds that
 * known bias and what it drags along: a change that reads central losses worse, or lets them pull
 * the rings, fails here. */
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

static void row_errors(const sim2afc *o, const csf_cell *cells, int n, const csf_cell_estimate *est,
                       double *fovea_sum, int *fovea_n, double *ring_sq, int *ring_n)
{
    for (int c = 0; c < n; c++) {
        double t = sim2afc_log10_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg);
        if (t >= 0.0 || !isfinite(est[c].threshold)) continue; /* visibility: sim2afc_rms counts it */
        double e = log10(est[c].threshold) - t;
        if (cells[c].ecc_deg < 1.0) *fovea_sum += e, (*fovea_n)++;
        else *ring_sq += e * e, (*ring_n)++;
    }
}

int main(void)
{
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    int n_alt[24];
    CHECK_INT_EQ(sim2afc_default_layouts(cells, n, 4, n_alt), 0);
    csf_model_params truth = csf_model_default();
    truth.fovea_dip_log10 = 0.3;

    double fovea_sum = 0.0, ring_sq = 0.0, all_sq = 0.0;
    int fovea_n = 0, ring_n = 0, runs = 0;
    for (uint64_t seed = 31; seed <= 36; seed++) {
        sim2afc o;
        sim2afc_parametric(&o, truth, seed);
        o.method_psychometric = 1;
        csf_cell_estimate est[24];
        CHECK_INT_EQ(sim2afc_run_alt(&csf_procedure_bayes, &o, cells, n, n_alt, 120, 700 + seed, 1.0, est), 0);
        int wrong = 0;
        double rms = sim2afc_rms(&o, cells, n, est, 1.0, &wrong);
        double fs = 0.0, rs = 0.0;
        int fn = 0, rn = 0;
        row_errors(&o, cells, n, est, &fs, &fn, &rs, &rn);
        printf("seed %llu: RMS %.3f (visibility wrong in %d cells), foveal row mean error %+.3f (%d cells), "
               "rings RMS %.3f\n", (unsigned long long)seed, rms, wrong, fn ? fs / fn : NAN, fn,
               rn ? sqrt(rs / rn) : NAN);
        CHECK_MSG(wrong <= 1, "seed %llu: %d cells with the wrong visibility", (unsigned long long)seed, wrong);
        fovea_sum += fs, fovea_n += fn, ring_sq += rs, ring_n += rn, all_sq += rms * rms, runs++;
    }
    double fovea_bias = fovea_sum / fovea_n, ring_rms = sqrt(ring_sq / ring_n), rms = sqrt(all_sq / runs);
    printf("over seeds: foveal row mean error %+.3f, rings RMS %.3f, all RMS %.3f\n", fovea_bias, ring_rms, rms);
    CHECK_INT_EQ(fovea_n > 6 * 4, 1);
    /* On these seeds: foveal row -0.104, rings 0.084, all cells 0.109 (with the term freed,
     * FOVEA_DIP_MIXED: -0.057, 0.060, 0.084). The bounds leave room for seed spread only. */
    CHECK_MSG(fabs(fovea_bias) < 0.15, "foveal row biased by %+.3f log10", fovea_bias);
    CHECK_MSG(ring_rms < 0.10, "rings RMS %.3f", ring_rms);
    CHECK_MSG(rms < 0.13, "RMS %.3f", rms);
    return CHECK_RESULT();
}
