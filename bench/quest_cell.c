#include "quest_cell.h"

#include <math.h>

static const double GRAIN = 0.01;

void quest_cell_init(quest_cell *q, double guess_log10, double sd_log10, double slope, double lapse,
                     double guess_rate)
{
    q->x0 = guess_log10 - GRAIN * (QUEST_CELL_N / 2);
    q->slope = slope, q->lapse = lapse, q->guess = guess_rate;
    for (int i = 0; i < QUEST_CELL_N; i++) {
        double z = (q->x0 + GRAIN * i - guess_log10) / sd_log10;
        q->logp[i] = -0.5 * z * z;
    }
}

void quest_cell_update(quest_cell *q, double x_log10, int correct)
{
    for (int i = 0; i < QUEST_CELL_N; i++) {
        double t = q->x0 + GRAIN * i;
        double p = q->guess + (1.0 - q->guess - q->lapse) * (1.0 - exp(-pow(10.0, q->slope * (x_log10 - t))));
        q->logp[i] += log(correct ? p : 1.0 - p);
    }
}

/* Normalised posterior into w; returns nothing (the max is subtracted so exp never overflows). */
static void posterior(const quest_cell *q, double *w)
{
    double mx = -INFINITY, sum = 0.0;
    for (int i = 0; i < QUEST_CELL_N; i++)
        if (q->logp[i] > mx) mx = q->logp[i];
    for (int i = 0; i < QUEST_CELL_N; i++) sum += w[i] = exp(q->logp[i] - mx);
    for (int i = 0; i < QUEST_CELL_N; i++) w[i] /= sum;
}

double quest_cell_quantile(const quest_cell *q, double p)
{
    double w[QUEST_CELL_N], cum = 0.0;
    posterior(q, w);
    for (int i = 0; i < QUEST_CELL_N; i++) {
        if (cum + w[i] >= p) return q->x0 + GRAIN * (i - 0.5 + (p - cum) / w[i]);
        cum += w[i];
    }
    return q->x0 + GRAIN * (QUEST_CELL_N - 1);
}

double quest_cell_mean(const quest_cell *q)
{
    double w[QUEST_CELL_N], m = 0.0;
    posterior(q, w);
    for (int i = 0; i < QUEST_CELL_N; i++) m += w[i] * (q->x0 + GRAIN * i);
    return m;
}

double quest_cell_prob_below(const quest_cell *q, double x_log10)
{
    double w[QUEST_CELL_N], s = 0.0;
    posterior(q, w);
    for (int i = 0; i < QUEST_CELL_N; i++)
        if (q->x0 + GRAIN * i < x_log10) s += w[i];
    return s;
}
