/* The example studies run end to end with the simulated observer, and the report recovers what
 * the observer is known to be:
 *   - contrast_2afc (method of constant stimuli): each participant's fitted Weibull threshold has
 *     a bootstrap interval holding the observer's true threshold (csf_observer_sim_threshold) in
 *     most cases over several participants (seeds): 95 % intervals, at least 10 of 12;
 *   - adaptive_2ifc (staircases through calib/procedure.h): the same, pooled per curve;
 *   - same_different (images): the identical pair at chance, the perceptible pair far above it.
 * argv[1]: the examples/studies folder. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/config.h"
#include "studies/study_report.h"
#include "studies/study_run.h"
#include "model/observer_sim.h"
#include "tests/check.h"

static int run(const char *examples, const char *study, const char *store, const char *participant)
{
    csf_config cfg;
    csf_config_defaults(&cfg);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", examples, study);
    csf_study_run_options o;
    memset(&o, 0, sizeof o);
    o.cfg = &cfg;
    o.study_path = path;
    o.participant = participant;
    o.observer_spec = "sim";
    o.store_path = store;
    o.headless = 1;
    o.quiet = 1;
    csf_study_run_result res;
    csf_error e;
    csf_status st = csf_study_run(&o, &res, &e);
    if (st != CSF_OK) fprintf(stderr, "%s %s: %s\n", study, participant, e.msg);
    CHECK(st == CSF_OK);
    CHECK(res.finished);
    CHECK_INT_EQ(res.n_stored, res.n_planned);
    return st == CSF_OK;
}

static double true_t(double f, double ecc)
{
    csf_observer_sim *o = NULL;
    csf_error e;
    if (csf_observer_sim_create("sim", 1, &o, &e) != CSF_OK) return NAN;
    double t = log10(csf_observer_sim_threshold(o, f, ecc));
    csf_observer_sim_free(o);
    return t;
}

/* Counts curve rows (of the given scope, or every participant's when scope is NULL) whose t
 * interval holds the truth. */
static void coverage(const csf_study_report *r, const char *scope, int *covered, int *total)
{
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        if (!w->is_curve) continue;
        int pooled = !strcmp(w->scope, "pooled");
        if (scope ? strcmp(w->scope, scope) : pooled) continue;
        double t = true_t(w->freq_cpd, w->ecc_deg);
        CHECK(w->have_fit);
        (*total)++;
        int in = w->t_lo <= t && t <= w->t_hi;
        *covered += in;
        printf("%-8s %-6s true %.3f fit %.3f [%.3f, %.3f] %s\n", w->scope, w->name, t, w->fit.t_log10, w->t_lo,
               w->t_hi, in ? "" : "MISSED");
        /* and never far off: within 0.15 log10 */
        CHECK_MSG(fabs(w->fit.t_log10 - t) < 0.15, "%s %s: t %.3f vs true %.3f", w->scope, w->name,
                  w->fit.t_log10, t);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    char dir[] = "/tmp/csf_study_sim_XXXXXX";
    if (!mkdtemp(dir)) return 1;
    char store[256];
    csf_error e;

    /* constant stimuli, six participants */
    snprintf(store, sizeof store, "%s/a.sqlite", dir);
    const char *ps[] = {"P1", "P2", "P3", "P4", "P5", "P6"};
    for (int i = 0; i < 6; i++) run(argv[1], "contrast_2afc.conf", store, ps[i]);
    csf_study_report *r = NULL;
    CHECK(csf_study_report_build(store, "contrast_2afc", 0, 200, &r, &e) == CSF_OK);
    if (r) {
        int cov = 0, tot = 0;
        coverage(r, NULL, &cov, &tot);
        CHECK_INT_EQ(tot, 12);
        CHECK_MSG(cov >= 10, "thresholds inside their 95%% intervals: %d of %d", cov, tot);
        CHECK_INT_EQ(r->n_sessions, 6);
        CHECK_INT_EQ(r->n_trials, 6 * 480);
        csf_study_report_free(r);
    }

    /* adaptive staircases (two intervals), pooled over three participants */
    snprintf(store, sizeof store, "%s/b.sqlite", dir);
    for (int i = 0; i < 3; i++) run(argv[1], "adaptive_2ifc.conf", store, ps[i]);
    r = NULL;
    CHECK(csf_study_report_build(store, "adaptive_2ifc", 0, 200, &r, &e) == CSF_OK);
    if (r) {
        int cov = 0, tot = 0;
        coverage(r, "pooled", &cov, &tot);
        CHECK_INT_EQ(tot, 3);
        CHECK_MSG(cov >= 2, "pooled adaptive thresholds inside their intervals: %d of %d", cov, tot);
        csf_study_report_free(r);
    }

    /* image pairs, same/different */
    snprintf(store, sizeof store, "%s/c.sqlite", dir);
    for (int i = 0; i < 2; i++) run(argv[1], "same_different.conf", store, ps[i]);
    r = NULL;
    CHECK(csf_study_report_build(store, "same_different", 0, 0, &r, &e) == CSF_OK);
    if (r) {
        int groups = 0;
        for (int i = 0; i < r->n_rows; i++) {
            const csf_study_row *w = &r->rows[i];
            if (w->is_curve == 2 && !strcmp(w->scope, "pooled")) {
                /* the groups the curve column makes: one condition each here, the same counts */
                if (!strcmp(w->name, "perceptible")) CHECK(w->p_greater < 1e-6);
                if (!strcmp(w->name, "baseline")) CHECK(w->p_greater > 0.01);
                groups++;
            }
            if (w->is_curve || strcmp(w->scope, "pooled")) continue;
            printf("%s: p %.3f [%.3f, %.3f] p(>chance) %.3g d' %.2f\n", w->name, w->p, w->ci_lo, w->ci_hi,
                   w->p_greater, w->dprime);
            if (!strcmp(w->name, "identical")) CHECK_MSG(w->p_greater > 0.01, "identical pair: p = %g", w->p_greater);
            if (!strcmp(w->name, "blob")) {
                CHECK_MSG(w->p_greater < 1e-6, "perceptible pair: p = %g", w->p_greater);
                CHECK(w->dprime > 2);
            }
        }
        CHECK_INT_EQ(groups, 3);
        csf_study_report_free(r);
    }
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return CHECK_RESULT();
}
