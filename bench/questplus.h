/* Joint QUEST+ (Watson 2017, J. Vision 17(3):10) over a parametric CSF surface, for the honest
 * benchmark (bench_observer --honest): the anchor a vision scientist would pick instead of our
 * bayes method. The surface is qCSF's truncated log-parabola (Lesmes et al. 2010: Smax, fmax,
 * bandwidth, truncation) extended to eccentricity with the stelaCSF factor 10^-((a + b f) e)
 * (Mantiuk et al. 2022), i.e. model/csf_model.h. The Weibull slope is a parameter too and is marginalised
 * in the estimate; the lapse and the guess rate per cell (1/2 or 1/4) are given.
 *
 * Grids (documented in BENCHMARKS.md): log10 Smax 1.5..2.9 step 0.2 (8), log10 fmax -0.1..0.8
 * step 0.15 (7), bandwidth 2, 3, 4.5 octaves, truncation delta 0.25, 0.75 log10, a 0, 0.02,
 * 0.04, 0.07 /deg, b 0, 0.012, 0.025, 0.045 /(cpd deg): 5376 surfaces; slope 2, 3.2, 5: 16128
 * hypotheses. Prior: normal on log10 Smax (2.25, sd 0.35) and log10 fmax (0.45, sd 0.25), the
 * population the bayes method's prior centres on, flat on the rest.
 * Stimuli: cell x log10 contrast -3.3..0 step 0.15 (23 levels, clamped to the display); each
 * trial scores a random subset of QP_CELLS_PER_TRIAL cells (keyed by seed and trial) and picks
 * the stimulus of least expected entropy of the joint posterior. Hypotheses whose posterior falls
 * below 1e-7 of the largest are dropped from the sums (they cannot matter at 120 trials).
 * Estimate per cell: the posterior mean of min(t, log10 cmax); "never visible" (INFINITY) when the
 * posterior gives more than half its mass to t >= log10 cmax. */
#ifndef BENCH_QUESTPLUS_H
#define BENCH_QUESTPLUS_H

#include <stdint.h>

#include "calib/procedure.h"
#include "model/csf_model.h"

enum { QP_CELLS_PER_TRIAL = 6, QP_N_STATIC = 5376 /* the static grid's surfaces */ };

typedef struct questplus questplus;

/* The static family (the grids above). NULL when out of memory. */
questplus *questplus_create(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                            double log10_cmin, double log10_cmax);
/* Surface s of a family: each cell's log10 threshold into t_log10[n_cells]; returns its prior
 * weight (any positive scale). */
typedef double (*questplus_surface_fn)(void *ctx, int s, const csf_cell *cells, int n_cells, float *t_log10);
/* Another family of n_surf surfaces (bench/questplus_v.h: the static one times a velocity gain);
 * placement, pruning and estimate as the static anchor's. */
questplus *questplus_create_family(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                                   double log10_cmin, double log10_cmax, int n_surf,
                                   questplus_surface_fn surface, void *ctx);
/* The static grid's surface number s (log10 Smax slowest, b fastest) and its prior weight. */
csf_model_params questplus_static_surface(int s, double *prior);
void questplus_free(questplus *q);
void questplus_next(questplus *q, uint64_t seed, int trial, int *cell, double *x_log10);
void questplus_update(questplus *q, int cell, double x_log10, int correct);
/* log10 threshold per cell, INFINITY where the posterior says never visible. */
void questplus_estimate(const questplus *q, double *log10_t);
/* The best the surface family can do: min over the grid's surfaces of the RMS over the cells whose
 * truth is below log10 cmax (the others are left out). */
double questplus_best_fit_rms(const questplus *q, const double *truth_log10);

#endif
