/* A method's session against a simulated person as `observer calibrate` runs it, with the
 * precision stop (calib/observer_calib.c: after every trial from the 10th, stop when the predicted
 * RMS, the root mean stated variance over the cells reported visible, is at or below the target),
 * and the scores of its stated errors against the truth: shared by bench_coverage and
 * bench_efficiency. The default 6 x 4 grid, max contrast 1. */
#ifndef BENCH_PRECISION_RUN_H
#define BENCH_PRECISION_RUN_H

#include "calib/procedure.h"

enum { PR_CELLS = 24, PR_N_SHIFTS = 9, PR_MAX_LEVELS = 4 };
#define PR_CMAX 1.0
#define PR_MIN_TRIALS 10   /* as calib/observer_calib.c */
#define PR_CAP_PER_CELL 40 /* --precision's cap: 960 trials over 24 cells */

/* The conservative shifts scored (standard errors); PR_SHIFTS[6] = 2.0. */
extern const double PR_SHIFTS[PR_N_SHIFTS];

typedef struct {
    double truth[PR_CELLS], est[PR_CELLS], se[PR_CELLS]; /* log10; est INFINITY = never visible */
    int trials;
    int reached; /* the level was reached (a fixed budget: 1) */
} session_out;

/* One session of ops against the person of spec (person seed `seed`, method seed 1000 + seed).
 * n_levels == 0: a fixed budget of `trials`, into out[0]. Otherwise levels[] descending: out[i] is
 * the table as the session stood when its predicted RMS first reached levels[i] (one session
 * serves every level: the stop only ends it), the session ending at the last level or at `trials`
 * (the cap; a level not reached then gets the cap's table, reached 0). 0, or -1 on failure. */
int precision_session(const csf_procedure_ops *ops, const char *spec, int seed, const csf_cell *cells,
                      const int *n_alt, int trials, const double *levels, int n_levels, session_out *out);

/* The predicted RMS of a table: over cells reported visible with a stated error. */
double precision_predicted_rms(const csf_cell_estimate *e, int n);

/* RMS error of log10 threshold over the truly visible cells (truth below log10 PR_CMAX); a visible
 * cell reported never visible (or with no estimate) counts with log10 PR_CMAX as its estimate. */
double precision_achieved_rms(const double *truth_log10, const double *est_log10, int n);

/* csflut's conservative view at shift k (results/csflut/csflut.c compute_conservative) on the
 * 6 x 4 grid (frequency fastest), into cons (log10). */
void precision_conservative(const session_out *so, double k, double *cons);

/* Stated errors against the truth, summed over sessions. */
typedef struct {
    long n_vis, covered, called_inv, inv_wrong, vis_nan;
    long fail_open[PR_N_SHIFTS];
    double pred_sq, ach_sq, ratio_sum; /* sums over sessions */
    double matched_sq;                 /* stated variance over the cells in ach_sq, summed RMS^2 */
    int n_sess, n_ratio;
    long trials;
    double cell_err_sq[PR_CELLS], cell_se_sq[PR_CELLS];
    int cell_cov[PR_CELLS], cell_n[PR_CELLS];
} coverage_tally;

/* Adds one session: coverage of the 95 % interval over the truly visible cells it estimates, its
 * predicted RMS (every cell reported visible) and achieved RMS (the truly visible ones among them),
 * fail-open of the conservative view at every PR_SHIFTS, the never-visible calls; per_cell: each
 * cell's error and stated error too. */
void coverage_tally_add(coverage_tally *t, const session_out *so, int per_cell);

#endif
