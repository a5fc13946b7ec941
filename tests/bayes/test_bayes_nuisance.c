/* The bayes method does not assume the observer's psychometric slope and lapse: a person's are
 * unknown, and wrong assumed values bias the thresholds.
 * An observer with slope 2.2 and lapse 0.05 (an ordinary naive observer; the simulator of
 * sim_2afc.h, independent of the method) is measured on the same seeds by the method as sessions
 * set it up before (slope 3.5 and lapse 0.02 assumed) and by the method with slope and lapse
 * marginalised (the default now). The marginal method must be more accurate on the pooled error,
 * and its slope estimate must move from the prior's centre (3.0, the geometric middle of 1.5-6)
 * toward the truth, both for this shallow observer and for a steep one (slope 5.5, lapse 0.01;
 * at 120 trials placed near threshold the slope is only weakly identified, so the bounds are
 * modest: below 2.8 and above 3.0).
 * 120 trials, the default 6 x 4 grid, two intervals everywhere; argv[1] = observer_bumpy.csv.
 * Seeds 21 .. 32 (CSF_NUISANCE_SEEDS=N: 21 .. 20 + N). The slope read of one session spreads by
 * about 0.5, so over three seeds a person's mean moves by as much as the bound's margin from one
 * change of the trial sequence to the next; over twelve it moves by about 0.1. */
#include <stdlib.h>

#include "calib/method_bayes.h"
#include "tests/bayes/sim_2afc.h"
#include "tests/check.h"

/* One session; fills est and the method's slope / lapse read-out at the end. */
static int run(const sim2afc *o, const csf_cell *cells, int n, uint64_t proc_seed, csf_cell_estimate *est,
               double *slope, double *lapse)
{
    csf_procedure_setup setup = {.cells = cells, .n_cells = n, .trial_budget = 120, .seed = proc_seed,
                                 .max_contrast = 1.0, .min_contrast = 0.0005, .guess = 0.5,
                                 .slope_beta = 3.5, .lapse = 0.02,
                                 .fixed_psychometric = o->method_psychometric != 1};
    csf_error err = {0};
    void *st = NULL;
    if (csf_procedure_bayes.create(&setup, &st, &err) != CSF_OK) return -1;
    for (int k = 0; k < 120; k++) {
        csf_trial_plan plan;
        if (csf_procedure_bayes.next(st, k, &plan) != CSF_OK) break;
        csf_trial_outcome out = sim2afc_respond(o, &plan, cells[plan.cell].freq_cpd, cells[plan.cell].ecc_deg, k);
        csf_procedure_bayes.update(st, k, &plan, &out);
    }
    csf_bayes_psychometric(st, slope, lapse);
    csf_status rc = csf_procedure_bayes.estimate(st, est, &err);
    csf_procedure_bayes.destroy(st);
    return rc == CSF_OK ? 0 : -1;
}

static int make_observer(sim2afc *o, int kind, const char *table, uint64_t seed, double slope, double lapse)
{
    if (kind == 0) sim2afc_parametric(o, csf_model_default(), seed);
    else if (sim2afc_table(o, table, seed) != 0) return -1;
    o->slope = slope, o->lapse = lapse;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_bayes_nuisance bench/data/observer_bumpy.csv\n");
        return 2;
    }
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    const char *env_seeds = getenv("CSF_NUISANCE_SEEDS");
    int n_seeds = env_seeds ? atoi(env_seeds) : 12;
    if (n_seeds < 1 || n_seeds > 100) n_seeds = 12;
    const uint64_t last_seed = 20 + (uint64_t)n_seeds;
    double sq_fixed = 0.0, sq_marg = 0.0, log_slope_shallow = 0.0;
    int runs = 0;
    for (int kind = 0; kind < 2; kind++)
        for (uint64_t seed = 21; seed <= last_seed; seed++) {
            sim2afc o;
            if (make_observer(&o, kind, argv[1], seed, 2.2, 0.05) != 0) {
                CHECK_MSG(0, "cannot load %s", argv[1]);
                return CHECK_RESULT();
            }
            csf_cell_estimate est[24];
            double sl, la, sl_fixed, la_fixed;
            o.method_psychometric = 2; /* run() sets up the old session values 3.5 / 0.02 */
            CHECK_INT_EQ(run(&o, cells, n, 700 + seed, est, &sl_fixed, &la_fixed), 0);
            double rms_fixed = sim2afc_rms(&o, cells, n, est, 1.0, NULL);
            CHECK(fabs(sl_fixed - 3.5) < 1e-12 && fabs(la_fixed - 0.02) < 1e-12);
            o.method_psychometric = 1;
            CHECK_INT_EQ(run(&o, cells, n, 700 + seed, est, &sl, &la), 0);
            double rms_marg = sim2afc_rms(&o, cells, n, est, 1.0, NULL);
            printf("%s seed %llu: RMS fixed 3.5/0.02 %.3f, marginal %.3f (slope %.2f, lapse %.3f)\n",
                   kind ? "bumpy" : "parametric", (unsigned long long)seed, rms_fixed, rms_marg, sl, la);
            sq_fixed += rms_fixed * rms_fixed, sq_marg += rms_marg * rms_marg;
            log_slope_shallow += log(sl);
            runs++;
        }
    double rf = sqrt(sq_fixed / runs), rm = sqrt(sq_marg / runs), slope_shallow = exp(log_slope_shallow / runs);
    printf("slope 2.2 / lapse 0.05: pooled RMS fixed %.3f, marginal %.3f; slope estimate %.2f\n", rf, rm,
           slope_shallow);
    CHECK_MSG(rm < rf - 0.01, "marginal RMS %.3f is not below the fixed-slope RMS %.3f", rm, rf);
    CHECK_MSG(slope_shallow < 2.8, "slope estimate %.2f for a slope-2.2 observer did not move below 2.8", slope_shallow);

    double log_slope_steep = 0.0;
    for (uint64_t seed = 21; seed <= last_seed; seed++) {
        sim2afc o;
        make_observer(&o, 0, argv[1], seed, 5.5, 0.01);
        o.method_psychometric = 1;
        csf_cell_estimate est[24];
        double sl, la;
        CHECK_INT_EQ(run(&o, cells, n, 700 + seed, est, &sl, &la), 0);
        printf("steep observer seed %llu: RMS %.3f, slope %.2f, lapse %.3f\n", (unsigned long long)seed,
               sim2afc_rms(&o, cells, n, est, 1.0, NULL), sl, la);
        log_slope_steep += log(sl);
    }
    double slope_steep = exp(log_slope_steep / n_seeds);
    printf("slope 5.5 / lapse 0.01: slope estimate %.2f\n", slope_steep);
    CHECK_MSG(slope_steep > 3.0, "slope estimate %.2f for a slope-5.5 observer did not move above 3.0", slope_steep);
    return CHECK_RESULT();
}
