#include "anchor_run.h"

#include <math.h>

#include "core/rng.h"
#include "quest_cell.h"

enum { MAX_CELLS = 256 };

int anchor_person_answer(void *person, int trial, int cell, double x_log10)
{
    const anchor_person *p = person;
    const csf_cell *c = &p->cells[cell];
    int m = p->n_alt[cell];
    double shown[4] = {0, 0, 0, 0}, rt;
    int sig = (int)(csf_rng_u64(p->seed, 0x9e5, (uint64_t)trial) % (uint64_t)m);
    shown[sig] = pow(10.0, x_log10);
    int r = m == 4 ? csf_observer_sim_afc_v(p->o, (uint64_t)trial, c->freq_cpd, c->ecc_deg, c->velocity_dps,
                                            shown, 4, &rt)
                   : csf_observer_sim_2afc_v(p->o, (uint64_t)trial, c->freq_cpd, c->ecc_deg, c->velocity_dps,
                                             shown, &rt);
    return r == sig;
}

void anchor_psychometric(const csf_observer_sim *o, double *slope, double *lapse)
{
    const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
    *slope = p->decision == CSF_SIM_SDT ? 1.21 * p->k_transducer : p->slope;
    *lapse = p->lapse < 0.001 ? 0.001 : p->lapse;
}

double anchor_static_guess_log10(const csf_cell *c)
{
    csf_model_params p = {.smax = pow(10.0, 2.25),
                          .fmax_cpd = pow(10.0, 0.45),
                          .beta_oct = 3.0,
                          .delta_log10 = 0.5,
                          .ecc_a = 0.03,
                          .ecc_b = 0.02};
    double t = -csf_model_log10_sensitivity(&p, c->freq_cpd, c->ecc_deg);
    return t > 0.0 ? 0.0 : t;
}

static void quest_estimate(const quest_cell *q, int n, double lcmax, double *est_log10)
{
    for (int c = 0; c < n; c++) {
        double m = quest_cell_mean(&q[c]);
        est_log10[c] = quest_cell_prob_below(&q[c], lcmax) < 0.5 ? INFINITY : fmin(m, lcmax);
    }
}

/* The cell QUEST's allocation gives the next trial (see anchor_quest_cells). */
static int quest_pick(const quest_cell *q, const int *trials, int n, int rot, double lcmax)
{
    int best = -1, best_any = 0;
    double pv_any = -1.0;
    for (int i = 0; i < n; i++) {
        int c = (i + rot) % n;
        double pv = quest_cell_prob_below(&q[c], lcmax);
        if (pv > pv_any) pv_any = pv, best_any = c;
        if (pv >= 0.2 && (best < 0 || trials[c] < trials[best])) best = c;
    }
    return best >= 0 ? best : best_any;
}

int anchor_quest_cells(const anchor_run *r, const double *guess_log10, double sd_log10, double slope,
                       double lapse, double *est_log10, int *trials_per_cell)
{
    static quest_cell q[MAX_CELLS]; /* 1 MB: not on the stack */
    int trials[MAX_CELLS] = {0}, n = r->n_cells < MAX_CELLS ? r->n_cells : MAX_CELLS, k = 0;
    for (int c = 0; c < n; c++)
        quest_cell_init(&q[c], guess_log10[c], sd_log10, slope, lapse, 1.0 / r->n_alt[c]);
    int rot = (int)(csf_rng_u64(r->seed, 0x9e6, 0) % (uint64_t)n);
    for (int cp = 0; cp < r->n_checkpoints; cp++) {
        for (; k < r->checkpoints[cp]; k++) {
            int c = quest_pick(q, trials, n, rot, r->log10_cmax);
            double x = fmax(r->log10_cmin, fmin(r->log10_cmax, quest_cell_quantile(&q[c], 0.5)));
            quest_cell_update(&q[c], x, r->answer(r->answer_ctx, k, c, x));
            trials[c]++;
        }
        quest_estimate(q, n, r->log10_cmax, est_log10);
        if (r->check && r->check(r->check_ctx, k, est_log10)) break;
    }
    for (int c = 0; c < n && trials_per_cell; c++) trials_per_cell[c] = trials[c];
    return k;
}

int anchor_questplus(const anchor_run *r, questplus *q, double *est_log10)
{
    int k = 0;
    for (int cp = 0; cp < r->n_checkpoints; cp++) {
        for (; k < r->checkpoints[cp]; k++) {
            int c;
            double x;
            questplus_next(q, r->seed, k, &c, &x);
            questplus_update(q, c, x, r->answer(r->answer_ctx, k, c, x));
        }
        questplus_estimate(q, est_log10);
        if (r->check && r->check(r->check_ctx, k, est_log10)) break;
    }
    return k;
}
