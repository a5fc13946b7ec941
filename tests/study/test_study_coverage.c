/* Coverage over many seeds: the example studies with fixed levels
 * (examples/studies/contrast_2afc: two curves; yes_no: one curve with catch trials) are answered
 * by the simulated observer for many participants, each participant's curves fitted by the
 * report's own statistics (csf_study_row_finish: ML Weibull and its 95 % marginal-posterior
 * interval; yes/no with the participant's false-alarm rate as the guess), and the share of
 * intervals holding the observer's true threshold must be consistent with 95 %: the test fails
 * when the count is one that a 95 % interval reaches with probability below 0.1 % (binomial).
 *
 * The trials follow each study's own plan (csf_study_make_plan: conditions, levels, targets,
 * catch trials, practice left out) and the observer's own trial functions on the contrast the
 * plan asks for (model/observer_sim.h; yes/no through its fade-in model, 60 Hz frames, as
 * `csfcal study run` feeds it); the presenter and the store are left out so that 20 participants
 * x 3 curves fit in a CI budget. That this shortcut is the real pipeline is checked on one
 * participant per study: run end to end (presenter, store) and reported, it gives the same
 * counts (to the answers the display's contrast quantisation can flip) and the same fit.
 * argv[1]: the examples/studies folder. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/config.h"
#include "studies/study_plan.h"
#include "studies/study_report.h"
#include "studies/study_run.h"
#include "model/observer_sim.h"
#include "studies/study_stats.h"
#include "tests/check.h"

#define PARTICIPANTS 20

/* Yes/no: the observer's fade-in model fed `c` for the stimulus frames, then blank frames for
 * the response window; a press is "yes" (studies/study_run.c does the same with the shown frames). */
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

/* One participant of one study: fits its curves, counts intervals holding the truth. keep: the
 * curve rows are handed back (malloc'd, *n_kept of them) instead of freed. */
static void participant(const csf_study *s, int p, int *covered, int *total, csf_study_row **keep, int *n_kept)
{
    char code[32];
    snprintf(code, sizeof code, "C%02d", p);
    uint64_t seed = csf_study_participant_seed(s, code);
    csf_study_trial *plan = NULL;
    int n = 0;
    csf_error e;
    CHECK(csf_study_make_plan(s, seed, 0, &plan, &n, &e) == CSF_OK);
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
    if (keep) {
        *keep = rows;
        *n_kept = n_rows;
    } else {
        free(rows);
    }
    free(plan);
    csf_observer_sim_free(o);
}

/* The shortcut above is the real thing: participant C00 of each study run end to end
 * (csf_study_run headless: presenter, the contrast it recorded as shown, the store) and reported
 * (csf_study_report_build) gives the same counts per level, to one answer where the shown
 * contrast differs from the plan's by the display's quantisation, and the same fit. */
static void same_as_runner(const char *examples, const char *file, const csf_study *s)
{
    char dir[] = "/tmp/csf_study_cov_XXXXXX";
    if (!mkdtemp(dir)) return;
    char store[256], path[1024];
    snprintf(store, sizeof store, "%s/s.sqlite", dir);
    snprintf(path, sizeof path, "%s/%s", examples, file);
    csf_config cfg;
    csf_config_defaults(&cfg);
    csf_study_run_options o;
    memset(&o, 0, sizeof o);
    o.cfg = &cfg;
    o.study_path = path;
    o.participant = "C00";
    o.observer_spec = "sim";
    o.store_path = store;
    o.headless = 1;
    o.quiet = 1;
    csf_study_run_result res;
    csf_error e;
    CHECK_MSG(csf_study_run(&o, &res, &e) == CSF_OK, "%s: %s", file, e.msg);
    csf_study_report *r = NULL;
    CHECK_MSG(csf_study_report_build(store, path, 0, 0, &r, &e) == CSF_OK, "%s: %s", file, e.msg);
    csf_study_row *mine = NULL;
    int n_mine = 0, cov = 0, tot = 0, matched = 0;
    participant(s, 0, &cov, &tot, &mine, &n_mine);
    for (int i = 0; r && i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        if (w->is_curve != 1 || strcmp(w->scope, "C00")) continue;
        for (int j = 0; j < n_mine; j++) {
            const csf_study_row *m = &mine[j];
            if (strcmp(m->name, w->name)) continue;
            matched++;
            CHECK_INT_EQ(m->n_levels, w->n_levels);
            int off = 0;
            for (int a = 0; a < m->n_levels && a < w->n_levels; a++)
                for (int b = 0; b < w->n_levels; b++)
                    if (fabs(m->levels[a].x_log10 - w->levels[b].x_log10) < 1e-6) {
                        CHECK_INT_EQ(m->levels[a].n, w->levels[b].n);
                        off += abs(m->levels[a].k - w->levels[b].k);
                    }
            CHECK_INT_EQ(m->false_alarms, w->false_alarms);
            CHECK_MSG(off <= 2, "%s %s: %d answers differ between the runner and the shortcut", file, w->name, off);
            CHECK_MSG(fabs(m->fit.t_log10 - w->fit.t_log10) < 0.02, "%s %s: t %.3f (shortcut) vs %.3f (report)", file,
                      w->name, m->fit.t_log10, w->fit.t_log10);
            printf("%s %s: runner and shortcut differ by %d answers; t %.4f vs %.4f\n", file, w->name, off,
                   w->fit.t_log10, m->fit.t_log10);
        }
    }
    CHECK_INT_EQ(matched, n_mine);
    free(mine);
    csf_study_report_free(r);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
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
        for (int p = 0; p < PARTICIPANTS; p++) participant(s, p, &covered, &total, NULL, NULL);
        same_as_runner(argv[1], studies[i], s);
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
