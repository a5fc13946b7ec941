/* Two-interval forced choice with the Psi method (Kontsevich & Tyler 1999) per cell: a posterior
 * over the threshold t (log10 Michelson) on a grid, slope, guess (0.5) and lapse fixed from the
 * setup; each trial shows the contrast that minimises the expected posterior entropy. Cells are
 * interleaved: every trial goes to the cell with the widest posterior (ties broken by a per-trial
 * random rotation), so the budget is spread where it buys the most.
 *
 * The threshold grid reaches 1 log10 unit above the display's highest contrast, so an invisible
 * cell shows up as posterior mass above the ceiling; when more than half the mass is there the
 * cell is reported as not visible (INFINITY).
 *
 * Cells the setup gives four places (setup.n_alternatives[c] == 4, spatial 4AFC) use guess rate
 * 1/4 in their posterior and plan the place 0-3; the others are two-interval as before (their
 * plans, draws and posteriors unchanged). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calib/procedure.h"
#include "results/csf_model.h"
#include "results/psychometric.h"
#include "results/rng.h"

#define AFC_GRID_N 81
#define AFC_X_CANDIDATES 31
#define AFC_SD_STABLE 0.05
#define AFC_PRIOR_SD 0.7

enum { ST_INTERVAL = 0x2afc1, ST_POLAR, ST_ROTATE };

typedef struct {
    csf_procedure_setup s;
    csf_cell *cells;
    csf_psy_grid *grid;
    int *n_trials;
    int *n_alt;     /* per cell: 2 or 4 */
    double x_lo, x_hi;
} afc_state;

static void afc_destroy(void *state)
{
    afc_state *a = state;
    if (!a) return;
    if (a->grid)
        for (int i = 0; i < a->s.n_cells; i++) csf_psy_grid_free(&a->grid[i]);
    free(a->grid);
    free(a->cells);
    free(a->n_trials);
    free(a->n_alt);
    free(a);
}

static csf_status afc_create(const csf_procedure_setup *setup, void **state, csf_error *err)
{
    if (!setup || setup->n_cells < 1 || !setup->cells)
        return csf_error_set(err, CSF_E_INVALID_ARG, "2afc: no cells to measure");
    if (!(setup->max_contrast > 0 && setup->max_contrast <= 1) ||
        !(setup->min_contrast > 0 && setup->min_contrast < setup->max_contrast))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "2afc: contrast range [%g, %g] must satisfy 0 < min < max <= 1",
                             setup->min_contrast, setup->max_contrast);
    afc_state *a = calloc(1, sizeof *a);
    if (!a) return csf_error_set(err, CSF_E_NOMEM, "2afc: out of memory");
    a->s = *setup;
    if (!(a->s.slope_beta > 0)) a->s.slope_beta = 3.5;
    if (!(a->s.lapse >= 0 && a->s.lapse < 0.5)) a->s.lapse = 0.02;
    a->s.guess = 0.5;
    a->x_lo = log10(setup->min_contrast);
    a->x_hi = log10(setup->max_contrast);
    int n = setup->n_cells;
    a->cells = malloc((size_t)n * sizeof *a->cells);
    a->grid = calloc((size_t)n, sizeof *a->grid);
    a->n_trials = calloc((size_t)n, sizeof *a->n_trials);
    a->n_alt = malloc((size_t)n * sizeof *a->n_alt);
    if (!a->cells || !a->grid || !a->n_trials || !a->n_alt) {
        afc_destroy(a);
        return csf_error_set(err, CSF_E_NOMEM, "2afc: out of memory");
    }
    memcpy(a->cells, setup->cells, (size_t)n * sizeof *a->cells);
    a->s.cells = a->cells;
    for (int i = 0; i < n; i++) a->n_alt[i] = setup->n_alternatives && setup->n_alternatives[i] == 4 ? 4 : 2;
    a->s.n_alternatives = a->n_alt;
    /* Prior per cell: the population-average observer (results/csf_model.h defaults, the same
     * guess a QUEST user would enter), sd 0.7 log10, so an invisible cell needs evidence only
     * where the population says it is hard to see. */
    csf_model_params pop = csf_model_default();
    for (int i = 0; i < n; i++) {
        double m = log10(csf_model_threshold(&pop, a->cells[i].freq_cpd, a->cells[i].ecc_deg));
        if (!(m < a->x_hi + 0.5)) m = a->x_hi + 0.5;
        if (m < a->x_lo) m = a->x_lo;
        if (csf_psy_grid_init(&a->grid[i], AFC_GRID_N, a->x_lo - 0.5, a->x_hi + 1.0, m,
                              AFC_PRIOR_SD, a->s.slope_beta, a->n_alt[i] == 4 ? 0.25 : 0.5,
                              a->s.lapse) != 0) {
            double slope = a->s.slope_beta, lapse = a->s.lapse;
            afc_destroy(a);
            return csf_error_set(err, CSF_E_INVALID_ARG, "2afc: bad psychometric parameters "
                                 "(slope %g, lapse %g)", slope, lapse);
        }
    }
    *state = a;
    return CSF_OK;
}

static csf_status afc_next(void *state, int trial_index, csf_trial_plan *plan)
{
    afc_state *a = state;
    int n = a->s.n_cells, best = -1;
    double best_sd = -1;
    int rot = (int)(csf_rng_u64(a->s.seed, ST_ROTATE, (uint64_t)trial_index) % (uint64_t)n);
    for (int k = 0; k < n; k++) {
        int i = (k + rot) % n;
        double sd;
        csf_psy_grid_moments(&a->grid[i], NULL, &sd);
        if (sd <= AFC_SD_STABLE) continue;
        if (sd > best_sd + 1e-12) {
            best_sd = sd;
            best = i;
        }
    }
    if (best < 0) return CSF_E_ABORTED;
    memset(plan, 0, sizeof *plan);
    plan->task = CSF_TASK_2AFC;
    plan->cell = best;
    double x = csf_psy_grid_best_x(&a->grid[best], a->x_lo, a->x_hi, AFC_X_CANDIDATES);
    plan->contrast = pow(10.0, x);
    double u = csf_rng_uniform(a->s.seed, ST_INTERVAL, (uint64_t)trial_index);
    plan->n_alternatives = a->n_alt[best];
    if (plan->n_alternatives == 4) plan->signal_interval = (int)(u * 4.0) % 4;
    else plan->signal_interval = u < 0.5 ? 0 : 1;
    plan->polar_deg = 360.0 * csf_rng_uniform(a->s.seed, ST_POLAR, (uint64_t)trial_index);
    return CSF_OK;
}

static void afc_update(void *state, int trial_index, const csf_trial_plan *plan,
                       const csf_trial_outcome *o)
{
    afc_state *a = state;
    (void)trial_index;
    if (!o->valid || plan->cell < 0 || plan->cell >= a->s.n_cells || !(plan->contrast > 0)) return;
    /* Use the contrast actually shown when the caller measured it (missed frames lower it). */
    double c = (o->contrast_at_response > 0) ? o->contrast_at_response : plan->contrast;
    csf_psy_grid_update(&a->grid[plan->cell], log10(c), o->response == plan->signal_interval);
    a->n_trials[plan->cell]++;
}

static csf_status afc_estimate(void *state, csf_cell_estimate *out, csf_error *err)
{
    afc_state *a = state;
    (void)err;
    for (int i = 0; i < a->s.n_cells; i++) {
        double m, sd;
        csf_psy_grid_moments(&a->grid[i], &m, &sd);
        out[i].n_trials = a->n_trials[i];
        if (a->n_trials[i] == 0) {
            out[i].threshold = NAN;
            out[i].stderr_log10 = NAN;
        } else if (csf_psy_grid_prob_above(&a->grid[i], a->x_hi) > 0.5) {
            out[i].threshold = INFINITY;
            out[i].stderr_log10 = NAN;
        } else {
            out[i].threshold = pow(10.0, m);
            out[i].stderr_log10 = sd;
        }
    }
    return CSF_OK;
}

const csf_procedure_ops csf_procedure_2afc = {
    .name = "2afc",
    .task = CSF_TASK_2AFC,
    .create = afc_create,
    .next = afc_next,
    .update = afc_update,
    .estimate = afc_estimate,
    .destroy = afc_destroy,
};
