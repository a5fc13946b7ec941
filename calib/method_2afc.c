/* Two-interval forced choice with the Psi method (Kontsevich & Tyler 1999) per cell: a posterior
 * over the threshold t (log10 Michelson) on a grid; each trial shows the contrast that minimises
 * the expected entropy of the threshold's posterior. The person's slope and lapse are unknown
 * (psi-marginal, Prins 2013): one pair per person, shared by all cells, on the same grid as the
 * bayes method (slope 1.5-6 log-uniform x lapse 0.001-0.08); each cell keeps a posterior per
 * pair, the pair's posterior is the product over cells of their evidence (exact here: the cells
 * are independent a priori), and every read-out mixes the pairs by it. fixed_psychometric = 1
 * in the setup keeps one pair (slope_beta, lapse). Cells are
 * interleaved: every trial goes to the cell with the widest posterior (ties broken by a per-trial
 * random rotation), so the budget is spread where it buys the most.
 *
 * The threshold grid reaches 1 log10 unit above the display's highest contrast, so an invisible
 * cell shows up as posterior mass above the ceiling; when more than half the mass is there the
 * cell is reported as not visible (INFINITY).
 *
 * Cells the setup gives four places (setup.n_alternatives[c] == 4, spatial 4AFC) plan the place
 * 0-3 and use the four-place function of the same d' (csf_psy_p_afc, guess 1/4), so their
 * threshold is the table's task-independent one (model/psychometric.h); the others are
 * two-interval as before (their plans, draws and posteriors unchanged). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calib/procedure.h"
#include "model/csf_model.h"
#include "model/csf_velocity.h"
#include "model/psychometric.h"
#include "core/rng.h"

#define AFC_GRID_N 81
#define AFC_X_CANDIDATES 31
#define AFC_SD_STABLE 0.05
#define AFC_PRIOR_SD 0.7
/* Odds, on a cell's answers alone, that its threshold is beyond the display's reach: their mean
 * likelihood over thresholds up to AFC_ODDS_SPAN log10 above the reach against that over as far
 * below it (invisible_odds). Only thresholds near the reach are weighed on the visible side: a
 * person whose threshold is just inside the reach sees the top contrast barely above it and
 * answers wrong there more often than lapses explain, and averaged against the prior's visible
 * side (mostly far inside the reach, where every top-contrast answer is right) a few such wrong
 * answers would look like proof. A cell needs
 * AFC_INVISIBLE_BF before it is written never visible: one wrong answer at the top contrast is
 * about 6 times likelier from a threshold in the span above than from one in the span below
 * (slope 3, lapse 0.04), so that bar is evidence that survives a lapse. */
#define AFC_ODDS_SPAN 0.5
#define AFC_INVISIBLE_BF 20.0
/* ... and the odds up to which such a cell is still shown: ten times that */
#define AFC_RETEST_BF (10 * AFC_INVISIBLE_BF)

enum { ST_INTERVAL = 0x2afc1, ST_POLAR, ST_ROTATE };

static const double eta_slopes[] = {1.5, 1.89, 2.38, 3.0, 3.78, 4.76, 6.0};
static const double eta_lapses[] = {0.001, 0.02, 0.04, 0.06, 0.08};
enum { N_ETA_SLOPE = sizeof eta_slopes / sizeof eta_slopes[0],
       N_ETA_LAPSE = sizeof eta_lapses / sizeof eta_lapses[0] };

typedef struct {
    csf_procedure_setup s;
    csf_cell *cells;
    int n_eta;      /* (slope, lapse) pairs; 1 when fixed */
    csf_psy_grid *grid; /* [n_cells * n_eta] */
    double *log_ev; /* [n_eta] log evidence of all trials given the pair */
    double *eta_w;  /* [n_eta] normalised posterior of the pair */
    double *mix;    /* [AFC_GRID_N] scratch: a cell's mixed posterior */
    int *n_trials;
    int *n_alt;     /* per cell: 2 or 4 */
    double *prior_mean; /* per cell: the prior's mean threshold, log10 (sd AFC_PRIOR_SD) */
    double x_lo, x_hi;
} afc_state;

static void afc_destroy(void *state)
{
    afc_state *a = state;
    if (!a) return;
    if (a->grid)
        for (int i = 0; i < a->s.n_cells * a->n_eta; i++) csf_psy_grid_free(&a->grid[i]);
    free(a->grid);
    free(a->log_ev), free(a->eta_w), free(a->mix);
    free(a->cells);
    free(a->n_trials);
    free(a->n_alt);
    free(a->prior_mean);
    free(a);
}

static void cell_mix(afc_state *a, int i);
static void mix_moments(const afc_state *a, int i, double *mean, double *sd, double *p_above);

static csf_status afc_create(const csf_procedure_setup *setup, void **state, csf_error *err)
{
    if (!setup || setup->n_cells < 1 || !setup->cells)
        return csf_error_set(err, CSF_E_INVALID_ARG, "2afc: no cells to measure");
    for (int c = 0; setup->not_shown && c < setup->n_cells; c++)
        if (setup->not_shown[c])
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "2afc: cell %d (%g cpd at %g deg/s) cannot be shown and "
                                 "this method measures each cell on its own",
                                 c, setup->cells[c].freq_cpd, setup->cells[c].velocity_dps);
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
    a->n_eta = setup->fixed_psychometric ? 1 : N_ETA_SLOPE * N_ETA_LAPSE;
    a->grid = calloc((size_t)n * a->n_eta, sizeof *a->grid);
    a->log_ev = calloc((size_t)a->n_eta, sizeof *a->log_ev);
    a->eta_w = malloc((size_t)a->n_eta * sizeof *a->eta_w);
    a->mix = malloc(AFC_GRID_N * sizeof *a->mix);
    a->n_trials = calloc((size_t)n, sizeof *a->n_trials);
    a->n_alt = malloc((size_t)n * sizeof *a->n_alt);
    a->prior_mean = malloc((size_t)n * sizeof *a->prior_mean);
    if (!a->cells || !a->grid || !a->n_trials || !a->n_alt || !a->log_ev || !a->eta_w || !a->mix ||
        !a->prior_mean) {
        afc_destroy(a);
        return csf_error_set(err, CSF_E_NOMEM, "2afc: out of memory");
    }
    memcpy(a->cells, setup->cells, (size_t)n * sizeof *a->cells);
    a->s.cells = a->cells;
    for (int i = 0; i < n; i++) a->n_alt[i] = setup->n_alternatives && setup->n_alternatives[i] == 4 ? 4 : 2;
    a->s.n_alternatives = a->n_alt;
    /* Prior per cell: the population-average observer (model/csf_model.h defaults, the same
     * guess a QUEST user would enter), sd 0.7 log10, so an invisible cell needs evidence only
     * where the population says it is hard to see. */
    csf_model_params pop = csf_model_default();
    for (int i = 0; i < n; i++) {
        const csf_cell *cell = &a->cells[i];
        csf_velocity_params vel = csf_velocity_default();
        double m = log10(csf_model_threshold(&pop, cell->freq_cpd, cell->ecc_deg)) -
                   csf_velocity_log10_gain(&vel, cell->freq_cpd, cell->velocity_dps);
        if (!(m < a->x_hi + 0.5)) m = a->x_hi + 0.5;
        if (m < a->x_lo) m = a->x_lo;
        a->prior_mean[i] = m;
        int bad = 0;
        for (int e = 0; e < a->n_eta; e++) {
            double slope = a->n_eta == 1 ? a->s.slope_beta : eta_slopes[e / N_ETA_LAPSE];
            double lapse = a->n_eta == 1 ? a->s.lapse : eta_lapses[e % N_ETA_LAPSE];
            bad |= csf_psy_grid_init(&a->grid[(size_t)i * a->n_eta + e], AFC_GRID_N, a->x_lo - 0.5,
                                     a->x_hi + 1.0, m, AFC_PRIOR_SD, slope,
                                     a->n_alt[i] == 4 ? 0.25 : 0.5, lapse) != 0;
            /* four places: the SDT 4AFC function of the same d' (one threshold, whatever the task) */
            if (!bad && a->n_alt[i] == 4) a->grid[(size_t)i * a->n_eta + e].n_alt = 4;
        }
        if (bad) {
            double slope = a->s.slope_beta, lapse = a->s.lapse;
            afc_destroy(a);
            return csf_error_set(err, CSF_E_INVALID_ARG, "2afc: bad psychometric parameters "
                                 "(slope %g, lapse %g)", slope, lapse);
        }
    }
    for (int e = 0; e < a->n_eta; e++) a->eta_w[e] = 1.0 / a->n_eta;
    *state = a;
    return CSF_OK;
}

/* Normalised posterior of one (cell, pair) grid into w; returns nothing. */
static void grid_weights(const csf_psy_grid *g, double *w)
{
    double mx = -INFINITY, tot = 0.0;
    for (int k = 0; k < g->n; k++)
        if (g->log_post[k] > mx) mx = g->log_post[k];
    for (int k = 0; k < g->n; k++) tot += (w[k] = exp(g->log_post[k] - mx));
    for (int k = 0; k < g->n; k++) w[k] /= tot;
}

/* Cell i's threshold posterior with the pair marginalised, into a->mix. */
static void cell_mix(afc_state *a, int i)
{
    double w[AFC_GRID_N];
    for (int k = 0; k < AFC_GRID_N; k++) a->mix[k] = 0.0;
    for (int e = 0; e < a->n_eta; e++) {
        if (a->eta_w[e] < 1e-9) continue;
        grid_weights(&a->grid[(size_t)i * a->n_eta + e], w);
        for (int k = 0; k < AFC_GRID_N; k++) a->mix[k] += a->eta_w[e] * w[k];
    }
}

static void mix_moments(const afc_state *a, int i, double *mean, double *sd, double *p_above)
{
    const csf_psy_grid *g = &a->grid[(size_t)i * a->n_eta];
    double m = 0.0, m2 = 0.0, pa = 0.0;
    for (int k = 0; k < g->n; k++) {
        double t = g->t_lo + k * g->t_step;
        m += a->mix[k] * t, m2 += a->mix[k] * t * t;
        if (t > a->x_hi) pa += a->mix[k];
    }
    if (mean) *mean = m;
    if (sd) *sd = sqrt(fmax(m2 - m * m, 0.0));
    if (p_above) *p_above = pa;
}

static double h_of(const double *q, int n)
{
    double tot = 0.0, h = 0.0;
    for (int k = 0; k < n; k++) tot += q[k];
    if (!(tot > 0.0)) return 0.0;
    for (int k = 0; k < n; k++)
        if (q[k] > 0.0) h -= q[k] / tot * log(q[k] / tot);
    return h;
}

/* Psi with the pair marginalised: the x minimising the expected entropy of the threshold's
 * marginal posterior (information about t only, not about slope or lapse). */
static double mix_best_x(afc_state *a, int i)
{
    double wts[AFC_GRID_N], qc[AFC_GRID_N], qw[AFC_GRID_N];
    double best_x = a->x_hi, best_h = INFINITY;
    for (int j = 0; j < AFC_X_CANDIDATES; j++) {
        double x = a->x_lo + (a->x_hi - a->x_lo) * j / (AFC_X_CANDIDATES - 1);
        for (int k = 0; k < AFC_GRID_N; k++) qc[k] = qw[k] = 0.0;
        for (int e = 0; e < a->n_eta; e++) {
            if (a->eta_w[e] < 1e-6) continue;
            const csf_psy_grid *g = &a->grid[(size_t)i * a->n_eta + e];
            grid_weights(g, wts);
            for (int k = 0; k < g->n; k++) {
                double pc = csf_psy_grid_p(g, x, g->t_lo + k * g->t_step);
                qc[k] += a->eta_w[e] * wts[k] * pc;
                qw[k] += a->eta_w[e] * wts[k] * (1.0 - pc);
            }
        }
        double pc = 0.0, pw = 0.0;
        for (int k = 0; k < AFC_GRID_N; k++) pc += qc[k], pw += qw[k];
        double h = pc * h_of(qc, AFC_GRID_N) + pw * h_of(qw, AFC_GRID_N);
        if (h < best_h - 1e-12) best_h = h, best_x = x;
    }
    return best_x;
}

static double invisible_odds(const afc_state *a, int i);

static csf_status afc_next(void *state, int trial_index, csf_trial_plan *plan)
{
    afc_state *a = state;
    int n = a->s.n_cells, best = -1;
    double best_sd = -1;
    int rot = (int)(csf_rng_u64(a->s.seed, ST_ROTATE, (uint64_t)trial_index) % (uint64_t)n);
    for (int k = 0; k < n; k++) {
        int i = (k + rot) % n;
        cell_mix(a, i);
        double sd, p_above;
        mix_moments(a, i, NULL, &sd, &p_above);
        /* A cell settled as never visible draws no more trials: its spread stays wide however
         * often it is shown (no answer tells apart thresholds beyond the display's reach), so by
         * that alone it would take most of a long session. Settled means evidence well past what
         * writing it never visible takes: a streak of lapses at a visible cell near the reach can
         * reach that bar, and the trials that follow undo it. */
        if (p_above > 0.5 && invisible_odds(a, i) >= AFC_RETEST_BF) continue;
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
    double x = a->n_eta == 1 ? csf_psy_grid_best_x(&a->grid[best], a->x_lo, a->x_hi, AFC_X_CANDIDATES)
                             : mix_best_x(a, best);
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
    int correct = o->response == plan->signal_interval;
    double w[AFC_GRID_N], mx = -INFINITY, tot = 0.0;
    for (int e = 0; e < a->n_eta; e++) {
        csf_psy_grid *g = &a->grid[(size_t)plan->cell * a->n_eta + e];
        if (a->n_eta > 1) { /* evidence: the predictive probability of this answer given the pair */
            double pr = 0.0;
            grid_weights(g, w);
            for (int k = 0; k < g->n; k++) {
                double pc = csf_psy_grid_p(g, log10(c), g->t_lo + k * g->t_step);
                pr += w[k] * (correct ? pc : 1.0 - pc);
            }
            a->log_ev[e] += log(pr > 1e-300 ? pr : 1e-300);
        }
        csf_psy_grid_update(g, log10(c), correct);
    }
    for (int e = 0; e < a->n_eta; e++)
        if (a->log_ev[e] > mx) mx = a->log_ev[e];
    for (int e = 0; e < a->n_eta; e++) tot += (a->eta_w[e] = exp(a->log_ev[e] - mx));
    for (int e = 0; e < a->n_eta; e++) a->eta_w[e] /= tot;
    a->n_trials[plan->cell]++;
}

/* The odds of "never visible" on cell i's answers alone (see AFC_INVISIBLE_BF; a->mix must hold
 * the cell's posterior): the posterior over the prior is the answers' likelihood, the pairs mixed
 * by their posterior. 1 when the cell has no answers. The population prior puts a high-frequency
 * peripheral cell near the reach, so "never visible" is written only where the answers themselves
 * say so (the renderer drops what the table calls never visible, the one error it cannot afford). */
static double invisible_odds(const afc_state *a, int i)
{
    if (!a->n_trials[i]) return 1.0;
    const csf_psy_grid *g = &a->grid[(size_t)i * a->n_eta];
    double above = 0.0, below = 0.0;
    int n_above = 0, n_below = 0;
    for (int k = 0; k < g->n; k++) {
        double t = g->t_lo + k * g->t_step, z = (t - a->prior_mean[i]) / AFC_PRIOR_SD;
        if (fabs(t - a->x_hi) > AFC_ODDS_SPAN) continue;
        double lik = a->mix[k] * exp(0.5 * z * z);
        if (t > a->x_hi) above += lik, n_above++;
        else below += lik, n_below++;
    }
    if (!n_above || !n_below) return 1.0;
    if (!(below > 0.0)) return above > 0.0 ? INFINITY : 1.0;
    return (above / n_above) / (below / n_below);
}

/* Mean and sd of the cell's threshold given that it is visible (a->mix must hold the cell's
 * posterior): what the table says for a cell not shown to be never visible. */
static void visible_part(const afc_state *a, int i, double *mean, double *sd)
{
    const csf_psy_grid *g = &a->grid[(size_t)i * a->n_eta];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    for (int k = 0; k < g->n; k++) {
        double t = g->t_lo + k * g->t_step;
        if (t > a->x_hi) break;
        s0 += a->mix[k], s1 += a->mix[k] * t, s2 += a->mix[k] * t * t;
    }
    double m = s0 > 1e-12 ? s1 / s0 : a->x_hi;
    *mean = m;
    *sd = s0 > 1e-12 ? sqrt(fmax(s2 / s0 - m * m, 0.0)) : NAN;
}

static csf_status afc_estimate(void *state, csf_cell_estimate *out, csf_error *err)
{
    afc_state *a = state;
    (void)err;
    for (int i = 0; i < a->s.n_cells; i++) {
        double m, sd, p_above;
        cell_mix(a, i);
        mix_moments(a, i, &m, &sd, &p_above);
        out[i].n_trials = a->n_trials[i];
        if (a->n_trials[i] == 0) {
            out[i].threshold = NAN;
            out[i].stderr_log10 = NAN;
        } else if (p_above > 0.5 && invisible_odds(a, i) >= AFC_INVISIBLE_BF) {
            out[i].threshold = INFINITY;
            out[i].stderr_log10 = NAN;
        } else if (p_above > 0.5) {
            visible_part(a, i, &m, &sd);
            out[i].threshold = pow(10.0, m);
            out[i].stderr_log10 = sd;
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
    .reach_log10 = 0.45,    /* each cell on its own */
    .time_spread_lo = 0.79, /* BENCHMARKS.md, "Person time" (20 people) */
    .time_spread_hi = 1.37,
};
