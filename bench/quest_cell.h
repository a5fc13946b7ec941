/* Per-cell QUEST (Watson & Pelli 1983) as Psychtoolbox-3's Quest toolbox does it, for the honest
 * benchmark (bench_observer --honest): a posterior over the log10 threshold t on a grid (grain
 * 0.01 log10, range 5 log10 centred on the guess, as QuestCreate's defaults), a Gaussian prior
 * N(guess, sd), the Weibull P = g + (1 - g - lapse)(1 - exp(-10^(slope (x - t)))) (Psychtoolbox's
 * form with gamma = g, delta = lapse / (1 - g) and pThreshold at x = t), placement at the
 * posterior median (QuestQuantile) clamped to the display range, estimate = posterior mean
 * (QuestMean). */
#ifndef BENCH_QUEST_CELL_H
#define BENCH_QUEST_CELL_H

enum { QUEST_CELL_N = 501 };

typedef struct {
    double x0;                   /* log10 t of grid point 0 */
    double slope, lapse, guess;  /* psychometric function */
    double logp[QUEST_CELL_N];   /* unnormalised log posterior */
} quest_cell;

void quest_cell_init(quest_cell *q, double guess_log10, double sd_log10, double slope, double lapse,
                     double guess_rate);
void quest_cell_update(quest_cell *q, double x_log10, int correct);
/* Posterior quantile (0.5: the median), mean, and the probability that t < x_log10. */
double quest_cell_quantile(const quest_cell *q, double p);
double quest_cell_mean(const quest_cell *q);
double quest_cell_prob_below(const quest_cell *q, double x_log10);

#endif
