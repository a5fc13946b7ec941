/* A small simulated 2AFC observer for the bayes tests and bench/bench_observer.c.
 * Why not devices/observer_sim: this one is independent of the observer area so the method can be
 * checked against a truth it did not help write. It is a model with noise: Weibull in log10
 * contrast with slope, guess 0.5 and lapse (docs/bayes-method.md's form) with two intervals; with four places
 * the signal-detection max rule of the same d' (the table's task-independent threshold, see
 * sim2afc_respond); every draw comes from
 * core/rng.h keyed by (seed, trial index), so runs are reproducible.
 * Truth: the parametric surface (model/csf_model.h) or a table (CSV freq_cpd,ecc_deg,threshold,
 * bilinear in log10 frequency x eccentricity on log10 threshold; threshold >= 1 = never visible). */
#ifndef CSF_TESTS_SIM_2AFC_H
#define CSF_TESTS_SIM_2AFC_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/afc_layout.h"
#include "calib/procedure.h"
#include "model/csf_model.h"
#include "core/rng.h"

typedef struct {
    int is_table;
    csf_model_params params;
    int n_f, n_e;
    double f[64], e[64];   /* sorted axes */
    double lt[64 * 64];    /* log10 threshold [ie*n_f + i_f] */
    double slope, lapse;   /* Weibull slope (log10 units) and lapse rate */
    /* How the method is set up: 0 (what memset gives) = told this observer's slope and lapse
     * (fixed_psychometric), i.e. the psychometric function is known and the test is about
     * something else; 1 = as a session sets it up: slope and lapse unknown (marginalised);
     * 2 = fixed at method_slope / method_lapse, whatever the observer's are. */
    int method_psychometric;
    double method_slope, method_lapse;
    uint64_t seed;
    /* Motion (NULL: the same threshold at every velocity): log10 threshold added at a drift of
     * velocity_dps, a shape of the test's choosing, so the method's motion prior is not the truth. */
    double (*motion_log10_raise)(double freq_cpd, double ecc_deg, double velocity_dps);
} sim2afc;

static inline void sim2afc_parametric(sim2afc *o, csf_model_params p, uint64_t seed)
{
    memset(o, 0, sizeof *o);
    o->params = p;
    o->slope = 3.5;
    o->lapse = 0.02;
    o->seed = seed;
}

static inline int sim2afc_axis_index(double *axis, int *n, double v)
{
    for (int i = 0; i < *n; i++)
        if (fabs(axis[i] - v) < 1e-9 * (1 + fabs(v))) return i;
    if (*n >= 64) return -1;
    int i = *n;
    while (i > 0 && axis[i - 1] > v) i--;
    memmove(&axis[i + 1], &axis[i], sizeof(double) * (size_t)(*n - i));
    axis[i] = v;
    (*n)++;
    return i;
}

/* Loads a table; returns 0 on success, -1 with a message on stderr. Every (f, e) pair of the
 * product grid must be present. */
static inline int sim2afc_table(sim2afc *o, const char *path, uint64_t seed)
{
    memset(o, 0, sizeof *o);
    o->is_table = 1;
    o->slope = 3.5;
    o->lapse = 0.02;
    o->seed = seed;
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "sim2afc: cannot open %s\n", path);
        return -1;
    }
    char line[256];
    double rf[4096], re[4096], rt[4096];
    int nr = 0;
    while (fgets(line, sizeof line, fp)) {
        double f, e, t;
        if (sscanf(line, "%lf,%lf,%lf", &f, &e, &t) != 3) continue; /* header */
        if (nr >= 4096 || !(f > 0) || !(e >= 0) || !(t > 0)) {
            fprintf(stderr, "sim2afc: %s: bad row '%s'\n", path, line);
            fclose(fp);
            return -1;
        }
        rf[nr] = f, re[nr] = e, rt[nr] = t, nr++;
    }
    fclose(fp);
    for (int r = 0; r < nr; r++) {
        if (sim2afc_axis_index(o->f, &o->n_f, log10(rf[r])) < 0 ||
            sim2afc_axis_index(o->e, &o->n_e, re[r]) < 0) {
            fprintf(stderr, "sim2afc: %s: more than 64 distinct axis values\n", path);
            return -1;
        }
    }
    if (nr != o->n_f * o->n_e || o->n_f < 2 || o->n_e < 2) {
        fprintf(stderr, "sim2afc: %s: %d rows do not fill a %d x %d grid\n", path, nr, o->n_f, o->n_e);
        return -1;
    }
    for (int r = 0; r < nr; r++) {
        int i = sim2afc_axis_index(o->f, &o->n_f, log10(rf[r]));
        int j = sim2afc_axis_index(o->e, &o->n_e, re[r]);
        o->lt[j * o->n_f + i] = log10(rt[r]);
    }
    return 0;
}

static inline double sim2afc_log10_threshold(const sim2afc *o, double freq_cpd, double ecc_deg)
{
    if (!o->is_table) return -csf_model_log10_sensitivity(&o->params, freq_cpd, ecc_deg);
    double lf = log10(freq_cpd);
    int i = 0, j = 0;
    while (i < o->n_f - 2 && lf > o->f[i + 1]) i++;
    while (j < o->n_e - 2 && ecc_deg > o->e[j + 1]) j++;
    double a = (lf - o->f[i]) / (o->f[i + 1] - o->f[i]);
    double b = (ecc_deg - o->e[j]) / (o->e[j + 1] - o->e[j]);
    a = a < 0 ? 0 : a > 1 ? 1 : a;
    b = b < 0 ? 0 : b > 1 ? 1 : b;
    const double *t = o->lt;
    int nf = o->n_f;
    return (1 - a) * (1 - b) * t[j * nf + i] + a * (1 - b) * t[j * nf + i + 1] +
           (1 - a) * b * t[(j + 1) * nf + i] + a * b * t[(j + 1) * nf + i + 1];
}

/* The same for a grating drifting at velocity_dps. */
static inline double sim2afc_log10_threshold_v(const sim2afc *o, const csf_cell *c)
{
    double t = sim2afc_log10_threshold(o, c->freq_cpd, c->ecc_deg);
    if (o->motion_log10_raise && c->velocity_dps != 0.0)
        t += o->motion_log10_raise(c->freq_cpd, c->ecc_deg, c->velocity_dps);
    return t;
}

/* Answer to a 2AFC plan (trial number trial_index) for a cell (drifting or not). */
static inline csf_trial_outcome sim2afc_respond_cell(const sim2afc *o, const csf_trial_plan *plan,
                                                     const csf_cell *cell, int trial_index)
{
    csf_trial_outcome out = {.response = 0, .rt_s = 0.6, .contrast_at_response = NAN, .valid = 1};
    double t = sim2afc_log10_threshold_v(o, cell);
    /* Weibull in log10 contrast: P(correct) = guess + (1 - guess - lapse)(1 - exp(-10^(slope (x - t)))) */
    double seen = 0.0;
    if (plan->contrast > 0 && t < 0.0) /* threshold >= 1: never visible */
        seen = 1.0 - exp(-pow(10.0, o->slope * (log10(plan->contrast) - t)));
    /* two intervals, or four locations when the plan says so */
    int n_alt = plan->n_alternatives == 4 ? 4 : 2;
    if (n_alt == 4) {
        /* Four places: the person of the Weibull above is a signal-detection observer as far as
         * the task is concerned (one d' whatever the task; docs/observer-calibration.md): the
         * transducer d' = 1.2734 (c/t)^k with k = slope / 1.247 gives the two-interval Weibull,
         * and in four places the largest of four noisy responses is chosen. A lapse (probability
         * lapse * 4/3, upper asymptote 1 - lapse) is a uniform guess. Drawn, not looked up. */
        uint64_t base = (uint64_t)trial_index * 4;
        if (csf_rng_uniform(o->seed, 0x51a3, (uint64_t)trial_index) < o->lapse * 4.0 / 3.0) {
            out.response = (int)(csf_rng_uniform(o->seed, 0x51a4, (uint64_t)trial_index) * 4) % 4;
            return out;
        }
        double d = 0.0;
        if (plan->contrast > 0 && t < 0.0)
            d = 1.2734322744392470 * pow(10.0, fmin(o->slope / 1.247 * (log10(plan->contrast) - t), 3.0));
        double best = -INFINITY;
        for (int k = 0; k < 4; k++) {
            double r = (k == plan->signal_interval ? d : 0.0) + csf_rng_normal(o->seed, 0x51a5, base + (uint64_t)k);
            if (r > best) best = r, out.response = k;
        }
        return out;
    }
    double guess = 1.0 / n_alt;
    double p_correct = guess + (1.0 - guess - o->lapse) * seen;
    int correct = csf_rng_uniform(o->seed, 0x51a1, (uint64_t)trial_index) < p_correct;
    if (correct) out.response = plan->signal_interval;
    else { /* a wrong answer is one of the other alternatives, at random */
        int k = 1 + (int)(csf_rng_uniform(o->seed, 0x51a2, (uint64_t)trial_index) * (n_alt - 1)) % (n_alt - 1);
        out.response = (plan->signal_interval + k) % n_alt;
    }
    return out;
}

/* Answer to a 2AFC plan (trial number trial_index) for a static cell at (freq_cpd, ecc_deg). */
static inline csf_trial_outcome sim2afc_respond(const sim2afc *o, const csf_trial_plan *plan, double freq_cpd,
                                                double ecc_deg, int trial_index)
{
    csf_cell cell = {freq_cpd, ecc_deg, 0};
    return sim2afc_respond_cell(o, plan, &cell, trial_index);
}

/* Runs a whole simulated session of `budget` trials through a procedure. The observer's seed is
 * o->seed, the procedure's is proc_seed. Fills est[n_cells]. Returns 0, or -1 with a message. */
static inline int sim2afc_run_alt(const csf_procedure_ops *ops, const sim2afc *o, const csf_cell *cells,
                                  int n_cells, const int *n_alternatives, int budget, uint64_t proc_seed,
                                  double max_contrast, csf_cell_estimate *est)
{
    csf_procedure_setup setup = {.cells = cells, .n_cells = n_cells, .trial_budget = budget,
                                 .seed = proc_seed, .max_contrast = max_contrast,
                                 .min_contrast = 0.0005, .slope_beta = o->slope, .lapse = o->lapse,
                                 .guess = 0.5, .n_alternatives = n_alternatives,
                                 .fixed_psychometric = o->method_psychometric != 1};
    if (o->method_psychometric == 2) setup.slope_beta = o->method_slope, setup.lapse = o->method_lapse;
    csf_error err = {0};
    void *st = NULL;
    if (ops->create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "%s: create: %s\n", ops->name, err.msg);
        return -1;
    }
    for (int k = 0; k < budget; k++) {
        csf_trial_plan plan;
        csf_status rc = ops->next(st, k, &plan);
        if (rc == CSF_E_ABORTED) break;
        if (rc != CSF_OK || plan.cell < 0 || plan.cell >= n_cells) {
            fprintf(stderr, "%s: next failed at trial %d\n", ops->name, k);
            ops->destroy(st);
            return -1;
        }
        csf_trial_outcome out = sim2afc_respond_cell(o, &plan, &cells[plan.cell], k);
        ops->update(st, k, &plan, &out);
    }
    csf_status rc = ops->estimate(st, est, &err);
    ops->destroy(st);
    if (rc != CSF_OK) {
        fprintf(stderr, "%s: estimate: %s\n", ops->name, err.msg);
        return -1;
    }
    return 0;
}

/* Two intervals everywhere (the classic 2IFC). */
static inline int sim2afc_run(const csf_procedure_ops *ops, const sim2afc *o, const csf_cell *cells,
                              int n_cells, int budget, uint64_t proc_seed, double max_contrast,
                              csf_cell_estimate *est)
{
    return sim2afc_run_alt(ops, o, cells, n_cells, NULL, budget, proc_seed, max_contrast, est);
}

/* RMS error of log10 threshold over the cells that are visible in truth (threshold below
 * max_contrast). A visible cell reported invisible counts with the max contrast as its estimate
 * (so it is penalised, not skipped); *n_wrong_vis counts cells whose visibility is wrong. */
static inline double sim2afc_rms(const sim2afc *o, const csf_cell *cells, int n_cells,
                                 const csf_cell_estimate *est, double max_contrast, int *n_wrong_vis)
{
    double se = 0.0;
    int n = 0, wrong = 0;
    for (int c = 0; c < n_cells; c++) {
        double t = sim2afc_log10_threshold_v(o, &cells[c]);
        int vis = t < log10(max_contrast);
        int est_vis = isfinite(est[c].threshold);
        if (vis != est_vis) wrong++;
        if (!vis) continue;
        double e = est_vis ? log10(est[c].threshold) : log10(max_contrast);
        se += (e - t) * (e - t);
        n++;
    }
    if (n_wrong_vis) *n_wrong_vis = wrong;
    return n ? sqrt(se / n) : NAN;
}

/* The session's default grid (docs/observer-calibration.md): 6 frequencies log-spaced 0.5-16 cpd
 * x eccentricities 0, 5, 10, 20. */
static inline int sim2afc_default_grid(csf_cell *cells)
{
    static const double eccs[4] = {0, 5, 10, 20};
    int n = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 6; i++) cells[n++] = (csf_cell){0.5 * pow(2.0, i), eccs[j], 0};
    return n;
}

/* Each cell's layout on a session's default station (531 x 299 mm, 1920 x 1080 pixels, seen from
 * 570 mm; docs/observer-calibration.md) with up to max_alternatives places: 4 is the session
 * default (four places off the fovea, two intervals at it), 2 is two intervals everywhere.
 * Fills n_alt[n_cells]; returns 0, or -1 with a message if the station is refused. */
static inline int sim2afc_default_layouts(const csf_cell *cells, int n_cells, int max_alternatives, int *n_alt)
{
    csf_geometry g;
    csf_error err = {0};
    if (csf_geometry_init(&g, 531.0, 299.0, 1920, 1080, 570.0, 0.0, 0.0, &err) != CSF_OK) {
        fprintf(stderr, "default station: %s\n", err.msg);
        return -1;
    }
    for (int c = 0; c < n_cells; c++) {
        csf_afc_layout l;
        csf_afc_choose_layout(&g, cells[c].ecc_deg, 1.0, max_alternatives, &l);
        n_alt[c] = l.n_alternatives;
    }
    return 0;
}

#endif
