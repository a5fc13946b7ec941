/* The anchors' runs against a simulated person, shared by the benches that set csfcal's methods
 * beside them (bench_observer --honest, bench_velocity, bench_efficiency): per-cell QUEST
 * (bench/quest_cell.h) with its allocation, and joint QUEST+ (bench/questplus.h, either family).
 * A run is scored at checkpoints (ascending trial counts, the last one its budget): the caller's
 * check sees the estimates there and may stop the run (bench_efficiency's oracle stop). */
#ifndef BENCH_ANCHOR_RUN_H
#define BENCH_ANCHOR_RUN_H

#include <stdint.h>

#include "calib/procedure.h"
#include "model/observer_sim.h"
#include "questplus.h"

/* One forced-choice answer at trial k, cell c, log10 contrast x: 1 = correct. */
typedef int (*anchor_answer_fn)(void *ctx, int trial, int cell, double x_log10);
/* At a checkpoint: the trials run and every cell's log10 estimate (INFINITY: never visible);
 * nonzero ends the run there. */
typedef int (*anchor_check_fn)(void *ctx, int trials, const double *est_log10);

typedef struct {
    const csf_cell *cells;
    int n_cells;
    const int *n_alt; /* 2 or 4 per cell: guess 1/2 or 1/4 */
    double log10_cmin, log10_cmax;
    uint64_t seed; /* QUEST's allocation rotation, QUEST+'s cell draws */
    anchor_answer_fn answer;
    void *answer_ctx;
    const int *checkpoints; /* ascending; the last is the budget */
    int n_checkpoints;
    anchor_check_fn check;
    void *check_ctx;
} anchor_run;

/* A simulated person answering on its own trial clock (anchor_answer_fn; cells may move:
 * velocity_dps). The signal's place is drawn from seed and trial. */
typedef struct {
    const csf_observer_sim *o;
    uint64_t seed;
    const csf_cell *cells;
    const int *n_alt;
} anchor_person;
int anchor_person_answer(void *person, int trial, int cell, double x_log10);

/* The person's psychometric function as the anchors are told it: a Weibull's own slope and lapse;
 * for a signal-detection person the Weibull that fits its 2AFC function (slope 1.21 k). */
void anchor_psychometric(const csf_observer_sim *o, double *slope, double *lapse);

/* The bayes prior's mean static surface (log10 threshold, at most 0): QUEST's per-cell guess, so
 * QUEST starts from the same population knowledge as the method (not from the person's truth). */
double anchor_static_guess_log10(const csf_cell *c);

/* Per-cell QUEST, each cell's prior N(guess_log10[c], sd_log10), told slope and lapse. Each trial
 * goes to the cell with the fewest trials among those whose posterior gives at least 20 % to
 * "visible" (t < log10 cmax), ties broken by a seeded rotation; if none qualifies, to the one most
 * likely visible. A cell more likely invisible than visible is estimated never visible. Returns
 * the trials run; est_log10 and trials_per_cell (may be NULL) as at the last checkpoint. */
int anchor_quest_cells(const anchor_run *r, const double *guess_log10, double sd_log10, double slope,
                       double lapse, double *est_log10, int *trials_per_cell);
/* Joint QUEST+ (q made by questplus_create or a family), run from its prior. Returns the trials run;
 * est_log10 as at the last checkpoint. */
int anchor_questplus(const anchor_run *r, questplus *q, double *est_log10);

#endif
