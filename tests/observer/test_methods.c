/* The fade and 2AFC procedures recover a known simulated observer within their expected error,
 * report invisible cells as +inf, and are reproducible (the resume contract: the same seed gives
 * the same plans and estimates). */
#include <math.h>
#include <stdio.h>

#include "calib/procedure.h"
#include "devices/observer_sim.h"
#include "tests/check.h"
#include "tests/observer/sim_loop.h"

static const csf_cell cells[] = {{1.0, 0}, {4.0, 0}, {1.0, 10}, {4.0, 10}, {40.0, 20}};
#define N_CELLS 5
#define INVISIBLE 4

static double rms_error(const csf_procedure_ops *ops, int budget, int n_seeds, double *max_bias,
                        int *invisible_ok)
{
    double se2 = 0, bias = 0;
    int n = 0;
    *invisible_ok = 1;
    for (int seed = 1; seed <= n_seeds; seed++) {
        csf_observer_sim *obs;
        csf_error err;
        if (csf_observer_sim_create("sim", (uint64_t)seed * 7919, &obs, &err) != CSF_OK) return NAN;
        csf_procedure_setup s = sim_loop_setup(cells, N_CELLS, budget, (uint64_t)seed, ops->task);
        csf_cell_estimate est[N_CELLS];
        sim_loop_run(ops, &s, obs, est);
        for (int i = 0; i < N_CELLS; i++) {
            double truth = csf_observer_sim_threshold(obs, cells[i].freq_cpd, cells[i].ecc_deg);
            if (i == INVISIBLE) {
                if (!isinf(est[i].threshold)) *invisible_ok = 0;
                continue;
            }
            double e = log10(est[i].threshold) - log10(truth);
            if (!isfinite(e)) e = 10;
            se2 += e * e;
            bias += e;
            n++;
        }
        csf_observer_sim_free(obs);
    }
    *max_bias = bias / n;
    return sqrt(se2 / n);
}

static void test_method(const char *name, int budget, double rms_limit, double bias_limit)
{
    const csf_procedure_ops *ops = csf_procedure_find(name);
    CHECK(ops != NULL);
    if (!ops) return;
    double bias;
    int inv_ok;
    double rms = rms_error(ops, budget, 8, &bias, &inv_ok);
    fprintf(stderr, "%s: budget %d, RMS log10 error %.3f, mean bias %+.3f\n", name, budget, rms, bias);
    CHECK_MSG(rms <= rms_limit, "%s RMS %.3f > %.3f", name, rms, rms_limit);
    CHECK_MSG(fabs(bias) <= bias_limit, "%s bias %.3f", name, bias);
    CHECK_MSG(inv_ok, "%s: invisible cell not reported as +inf", name);
}

static void test_reproducible(const char *name)
{
    const csf_procedure_ops *ops = csf_procedure_find(name);
    csf_cell_estimate a[N_CELLS], b[N_CELLS];
    for (int k = 0; k < 2; k++) {
        csf_observer_sim *obs;
        csf_error err;
        csf_observer_sim_create("sim", 99, &obs, &err);
        csf_procedure_setup s = sim_loop_setup(cells, N_CELLS, 40, 5, ops->task);
        sim_loop_run(ops, &s, obs, k ? b : a);
        csf_observer_sim_free(obs);
    }
    for (int i = 0; i < N_CELLS; i++) {
        CHECK(a[i].threshold == b[i].threshold || (isnan(a[i].threshold) && isnan(b[i].threshold)));
        CHECK_INT_EQ(a[i].n_trials, b[i].n_trials);
    }
}

int main(void)
{
    CHECK(csf_procedure_find("nope") == NULL);
    CHECK(csf_procedure_find("fade") == &csf_procedure_fade);
    /* Fade: 4-6 detections per cell (posterior sd <= 0.06) plus reaction-time correction error. */
    test_method("fade", 60, 0.10, 0.06);
    /* 2AFC Psi: 40 trials per cell. */
    test_method("2afc", 200, 0.15, 0.08);
    test_reproducible("fade");
    test_reproducible("2afc");
    return CHECK_RESULT();
}
