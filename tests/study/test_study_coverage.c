/* Coverage over many seeds (issue 14, "Done when"): the example studies with fixed levels
 * (examples/studies/contrast_2afc: two curves; yes_no: one curve with catch trials) are answered
 * by the simulated observer for many participants, each participant's curves fitted by the
 * report's own statistics (csf_study_row_finish: ML Weibull and its 95 % marginal-posterior
 * interval; yes/no with the participant's false-alarm rate as the guess), and the share of
 * intervals holding the observer's true threshold must be consistent with 95 %: the test fails
 * when the count is one that a 95 % interval reaches with probability below 0.1 % (binomial).
 *
 * The trials follow each study's own plan (csf_study_make_plan: conditions, levels, targets,
 * catch trials, practice left out) and the observer's own trial functions on the contrast the
 * plan asks for (devices/observer_sim.h; yes/no through its fade-in model, 60 Hz frames, as
 * `csfcal study run` feeds it); the presenter and the store are left out so that 20 participants
 * x 3 curves fit in a CI budget (tests/study/test_study_sim runs the examples end to end).
 * argv[1]: the examples/studies folder. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/study_plan.h"
#include "calib/study_report.h"
#include "devices/observer_sim.h"
#include "results/study_stats.h"
#include "tests/check.h"

#define PARTICIPANTS 20

/* Yes/no: the observer's fade-in model fed `c` for the stimulus frames, then blank frames for
 * the response window; a press is "yes" (calib/study_run.c does the same with the shown frames). */
static int yes_no_answer(const csf_observer_sim *o, uint64_t key, const csf_study *s, const csf_study_condition *c,
                         int present)
{
    const double period = 1.0 / 60;
    int n_stim = (int)lround(s->stimulus_s / period);
    int n_total = n_stim + (int)lround((s->response_window_s > 0 ? s->response_window_s : 1.0) / period);
    csf_sim_fade_trial tr;
    csf_observer_sim_fade_begin(o, key, c->freq_cpd, c->ecc_deg, c->polar_deg, 0, n_total * period, &tr);
    for (int i = 0; i < n_total; i++) {
        double press;
        if (csf_observer_sim_fade_frame(o, &tr, i * period, present && i < n_stim ? c->contrast : 0, &press))
            return 1;
    }
    return 0;
}

static void add_level(csf_study_row *w, double x, int ok)
{
    int i = 0;
    while (i < w->n_levels && fabs(w->levels[i].x_log10 - x) > 1e-9) i++;
    if (i == w->n_levels) {
        if (i >= CSF_REPORT_MAX_LEVELS) return;
        w->levels[w->n_levels++] = (csf_psy_level){x, 0, 0};
    }
    w->levels[i].n++;
    w->levels[i].k += ok;
}

/* One participant of one study: fits its curves, counts intervals holding the truth. */
static void participant(const csf_study *s, int p, int *covered, int *total)
{
    char code[32];
    snprintf(code, sizeof code, "C%02d", p);
    uint64_t seed = csf_study_participant_seed(s, code);
    csf_study_trial *plan = NULL;
    int n = 0;
    csf_error e;
    CHECK(csf_study_make_plan(s, seed, &plan, &n, &e) == CSF_OK);
    csf_observer_sim *o = NULL;
    CHECK(csf_observer_sim_create("sim", seed, &o, &e) == CSF_OK);
    if (!plan || !o) {
        free(plan);
        csf_observer_sim_free(o);
        return;
    }
    csf_study_row *rows = calloc((size_t)s->n_conds, sizeof *rows);
    int n_rows = 0;
    for (int i = 0; i < n; i++) {
        const csf_study_trial *t = &plan[i];
        const csf_study_condition *c = &s->conds[t->cond];
        if (t->practice || c->adaptive || c->kind == CSF_COND_IMAGE) continue;
        csf_study_row *w = NULL;
        for (int r = 0; r < n_rows && !w; r++)
            if (!strcmp(rows[r].name, c->curve)) w = &rows[r];
        if (!w) {
            w = &rows[n_rows++];
            w->is_curve = 1;
            snprintf(w->scope, sizeof w->scope, "%s", code);
            snprintf(w->name, sizeof w->name, "%s", c->curve);
            w->freq_cpd = c->freq_cpd;
            w->ecc_deg = c->ecc_deg;
        }
        if (s->design == CSF_DESIGN_YES_NO) {
            int yes = yes_no_answer(o, (uint64_t)i, s, c, t->target);
            if (t->target) {
                w->n_signal++;
                w->hits += yes;
                add_level(w, log10(c->contrast), yes);
            } else {
                w->n_noise++;
                w->false_alarms += yes;
            }
        } else {
            double shown[2] = {0, 0}, rt;
            shown[t->target] = c->contrast;
            add_level(w, log10(c->contrast),
                      csf_observer_sim_2afc(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, shown, &rt) == t->target);
        }
    }
    for (int r = 0; r < n_rows; r++) {
        csf_study_row *w = &rows[r];
        csf_study_row_finish(w, s, 0, seed);
        double truth = log10(csf_observer_sim_threshold(o, w->freq_cpd, w->ecc_deg));
        CHECK_MSG(w->have_fit && isfinite(w->t_lo) && isfinite(w->t_hi), "%s %s %s: no fit or interval", s->name,
                  code, w->name);
        int in = w->t_lo <= truth && truth <= w->t_hi;
        *covered += in;
        (*total)++;
        if (!in)
            printf("%s %s %s: true t %.3f outside [%.3f, %.3f] (fit %.3f)\n", s->name, code, w->name, truth, w->t_lo,
                   w->t_hi, w->fit.t_log10);
    }
    free(rows);
    free(plan);
    csf_observer_sim_free(o);
}

/* P(X <= k) for X ~ Binomial(n, p). */
static double binom_cdf(int k, int n, double p)
{
    return k >= n ? 1 : 1 - csf_stats_binom_p_greater(k + 1, n, p);
}

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    static const char *studies[] = {"contrast_2afc.conf", "yes_no.conf"};
    int covered = 0, total = 0;
    for (int i = 0; i < 2; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", argv[1], studies[i]);
        csf_study *s = NULL;
        csf_error e;
        CHECK_MSG(csf_study_load(path, &s, &e) == CSF_OK, "%s: %s", path, e.msg);
        if (!s) continue;
        int c0 = covered, t0 = total;
        for (int p = 0; p < PARTICIPANTS; p++) participant(s, p, &covered, &total);
        printf("%s: %d of %d thresholds inside their 95 %% intervals\n", s->name, covered - c0, total - t0);
        csf_study_free(s);
    }
    CHECK_INT_EQ(total, 3 * PARTICIPANTS);
    /* the smallest count a 95 % interval reaches with probability >= 0.1 % */
    int k_min = 0;
    while (k_min < total && binom_cdf(k_min, total, 0.95) < 1e-3) k_min++;
    printf("all: %d of %d (%.1f %%); fails below %d (P(X < %d) < 0.1 %% for a 95 %% interval)\n", covered, total,
           total ? 100.0 * covered / total : 0, k_min, k_min);
    CHECK_MSG(covered >= k_min, "coverage %d of %d is below %d: the intervals are too narrow", covered, total, k_min);
    return CHECK_RESULT();
}
