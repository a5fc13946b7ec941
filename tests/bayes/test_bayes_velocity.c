/* The bayes procedure over a velocity axis: 6 frequencies x 4 eccentricities x 3 velocities
 * (0, 4, 12 deg/s) on a 120 Hz display, against a simulated person whose motion sensitivity is NOT
 * the method's prior (Kelly-Daly): a sustained + transient pair of temporal channels in temporal
 * frequency (after the two-channel account of Mantiuk et al. 2022), with its own peak and fall.
 *  - cells whose temporal frequency v f reaches 60 Hz (half the refresh rate) are never planned and
 *    come back finite (a prediction, not "never visible");
 *  - at 360 trials the RMS error over the visible cells that can be shown is well below what the
 *    prior alone gives, and below per-cell forced choice (2afc) at the same trials;
 *  - a static grid leaves the motion parameters at their prior values (pinned: the static method is
 *    unchanged). */
#include "tests/bayes/sim_2afc.h"
#include "calib/method_bayes.h"
#include "calib/motion.h"
#include "tests/check.h"

#define N_CELLS 72
#define REFRESH_HZ 120.0

/* A two-channel temporal sensitivity (sustained low-pass, transient band-pass around 8 Hz whose
 * weight falls with spatial frequency), as log10 threshold raised over the static grating. */
static double two_channel_raise(double freq_cpd, double ecc_deg, double velocity_dps)
{
    (void)ecc_deg;
    double tf = fabs(freq_cpd * velocity_dps);
    double w_trans = 1.4 * exp(-freq_cpd / 2.0);
    double sustained = exp(-pow(tf / 9.0, 1.8));
    double transient = w_trans * tf / 8.0 * exp(1.0 - tf / 8.0);
    double r = (sustained + transient) / 1.0;
    if (r < 1e-6) r = 1e-6;
    return -log10(r);
}

static int build_grid(csf_cell *cells)
{
    static const double vels[3] = {0, 4, 12};
    int n = 0;
    for (int v = 0; v < 3; v++) {
        csf_cell plane[24];
        int m = sim2afc_default_grid(plane);
        for (int k = 0; k < m; k++) {
            cells[n] = plane[k];
            cells[n++].velocity_dps = vels[v];
        }
    }
    return n;
}

/* One session through the procedure; counts plans that went to a cell that cannot be shown. */
static int run(const csf_procedure_ops *ops, const sim2afc *o, const csf_cell *cells, int n,
               const unsigned char *not_shown, int budget, uint64_t seed, csf_cell_estimate *est,
               int *n_bad_plans, double *theta)
{
    csf_procedure_setup setup = {.cells = cells,
                                 .n_cells = n,
                                 .trial_budget = budget,
                                 .seed = seed,
                                 .max_contrast = 0.95,
                                 .min_contrast = 0.0005,
                                 .slope_beta = 3.5,
                                 .lapse = 0.02,
                                 .guess = 0.5,
                                 .not_shown = not_shown};
    csf_error err = {0};
    void *st = NULL;
    if (ops->create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "%s: %s\n", ops->name, err.msg);
        return -1;
    }
    for (int k = 0; k < budget; k++) {
        csf_trial_plan plan;
        if (ops->next(st, k, &plan) != CSF_OK) break;
        if (not_shown && not_shown[plan.cell]) (*n_bad_plans)++;
        csf_trial_outcome out = sim2afc_respond_cell(o, &plan, &cells[plan.cell], k);
        ops->update(st, k, &plan, &out);
    }
    csf_status rc = ops->estimate(st, est, &err);
    if (theta) csf_bayes_surface_mean(st, theta);
    ops->destroy(st);
    return rc == CSF_OK ? 0 : -1;
}

/* RMS log10 error over cells that can be shown and are visible in truth. */
static double rms_shown(const sim2afc *o, const csf_cell *cells, int n, const unsigned char *not_shown,
                        const csf_cell_estimate *est)
{
    double se = 0;
    int m = 0;
    for (int c = 0; c < n; c++) {
        double t = sim2afc_log10_threshold_v(o, &cells[c]);
        if ((not_shown && not_shown[c]) || t >= log10(0.95)) continue;
        double e = isfinite(est[c].threshold) ? log10(est[c].threshold) : log10(0.95);
        se += (e - t) * (e - t);
        m++;
    }
    return m ? sqrt(se / m) : NAN;
}

int main(void)
{
    csf_cell cells[N_CELLS];
    int n = build_grid(cells);
    unsigned char not_shown[N_CELLS];
    int n_alias = csf_motion_mark_not_shown(cells, n, REFRESH_HZ, not_shown);
    CHECK_INT_EQ(n_alias, 12); /* 8 cpd at 12 deg/s, 16 cpd at 4 and 12 deg/s, at 4 eccentricities */

    /* the shown cells alone, for the per-cell method (which refuses cells it cannot show) */
    csf_cell shown[N_CELLS];
    int n_shown = 0;
    for (int c = 0; c < n; c++)
        if (!not_shown[c]) shown[n_shown++] = cells[c];

    double sum_bayes = 0, sum_afc = 0, sum_prior = 0;
    int runs = 0;
    for (uint64_t seed = 31; seed <= 33; seed++) {
        sim2afc o;
        csf_model_params p = csf_model_default();
        p.smax = 180 + 40 * (double)(seed - 31);
        p.fmax_cpd = 2.5;
        sim2afc_parametric(&o, p, seed);
        o.slope = 3.0;
        o.lapse = 0.03;
        o.motion_log10_raise = two_channel_raise;
        csf_cell_estimate est[N_CELLS], est0[N_CELLS], est_afc[N_CELLS];
        int bad = 0;
        CHECK(run(&csf_procedure_bayes, &o, cells, n, not_shown, 360, 700 + seed, est, &bad, NULL) == 0);
        CHECK(run(&csf_procedure_bayes, &o, cells, n, not_shown, 0, 700 + seed, est0, &bad, NULL) == 0);
        CHECK_INT_EQ(bad, 0);
        for (int c = 0; c < n; c++)
            if (not_shown[c]) {
                CHECK_MSG(isfinite(est[c].threshold) && est[c].n_trials == 0 && est[c].stderr_log10 > 0.1,
                          "cell %d (%g cpd, %g deg/s): threshold %g, %d trials, se %g", c, cells[c].freq_cpd,
                          cells[c].velocity_dps, est[c].threshold, est[c].n_trials, est[c].stderr_log10);
            }
        int dummy = 0;
        CHECK(run(&csf_procedure_2afc, &o, shown, n_shown, NULL, 360, 700 + seed, est_afc, &dummy, NULL) ==
              0);
        double rb = rms_shown(&o, cells, n, not_shown, est), r0 = rms_shown(&o, cells, n, not_shown, est0);
        double ra = rms_shown(&o, shown, n_shown, NULL, est_afc);
        printf("seed %llu: bayes %.3f, prior only %.3f, 2afc per cell %.3f (log10 RMS, %d shown cells)\n",
               (unsigned long long)seed, rb, r0, ra, n_shown);
        sum_bayes += rb, sum_afc += ra, sum_prior += r0;
        runs++;
    }
    double mb = sum_bayes / runs, ma = sum_afc / runs, m0 = sum_prior / runs;
    printf("mean: bayes %.3f, prior only %.3f, 2afc %.3f\n", mb, m0, ma);
    CHECK_MSG(mb < 0.6 * m0, "bayes %.3f is not well below its prior %.3f", mb, m0);
    CHECK_MSG(mb < ma, "bayes %.3f is not below per-cell 2afc %.3f", mb, ma);
    CHECK_MSG(mb < 0.15, "bayes %.3f above 0.15 log10", mb);

    /* a static grid: the motion parameters stay pinned at the prior's centre */
    csf_cell still[24];
    int n_still = sim2afc_default_grid(still);
    sim2afc o;
    sim2afc_parametric(&o, csf_model_default(), 5);
    csf_cell_estimate est[24];
    double th[CSF_BAYES_NPAR];
    int bad = 0;
    CHECK(run(&csf_procedure_bayes, &o, still, n_still, NULL, 40, 9, est, &bad, th) == 0);
    CHECK_NEAR(th[8], 0.0, 0);
    CHECK_NEAR(th[9], 1.0, 0);

    /* refusals: per-cell methods with a cell they cannot show; a negative or NaN velocity */
    csf_procedure_setup setup = {.cells = cells,
                                 .n_cells = n,
                                 .trial_budget = 10,
                                 .seed = 1,
                                 .max_contrast = 0.95,
                                 .min_contrast = 0.0005,
                                 .not_shown = not_shown};
    csf_error err = {0};
    void *st = NULL;
    CHECK(csf_procedure_fade.create(&setup, &st, &err) == CSF_E_INVALID_ARG);
    CHECK(strstr(err.msg, "cannot be shown") != NULL);
    CHECK(csf_procedure_2afc.create(&setup, &st, &err) == CSF_E_INVALID_ARG);
    csf_cell bad_cell[1] = {{2.0, 0.0, -3.0}};
    csf_procedure_setup bs = {.cells = bad_cell,
                              .n_cells = 1,
                              .trial_budget = 10,
                              .seed = 1,
                              .max_contrast = 0.95,
                              .min_contrast = 0.0005};
    CHECK(csf_procedure_bayes.create(&bs, &st, &err) == CSF_E_INVALID_ARG);
    CHECK(strstr(err.msg, "velocity") != NULL);
    bad_cell[0].velocity_dps = NAN;
    CHECK(csf_procedure_bayes.create(&bs, &st, &err) == CSF_E_INVALID_ARG);
    return CHECK_RESULT();
}
