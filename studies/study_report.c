/* User-study analysis (see study_report.h). */
#include "studies/study_report.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "studies/study_plan.h"
#include "core/file_read.h"
#include "core/file_write.h"
#include "core/json_read.h"
#include "results/store/store.h"
#include "studies/study_plot.h"
#include "studies/study_sessions.h"

#define MAX_SCOPES 257 /* pooled + participants */

/* One session's material (studies/study_sessions.h) with who ran it, shown escaped: a stored
 * code is outside input by now and never shown as raw bytes. */
typedef struct {
    const csf_study_session_data *m;
    char participant[64];
    int finished;
} session_data;

/* Row lookup/creation: (scope, is_curve, name). */
static csf_study_row *row_for(csf_study_report *r, int cap, const char *scope, int is_curve, const char *name,
                             const csf_study_condition *c)
{
    for (int i = 0; i < r->n_rows; i++)
        if (r->rows[i].is_curve == is_curve && !strcmp(r->rows[i].scope, scope) && !strcmp(r->rows[i].name, name))
            return &r->rows[i];
    if (r->n_rows >= cap) return NULL;
    csf_study_row *w = &r->rows[r->n_rows++];
    memset(w, 0, sizeof *w);
    snprintf(w->scope, sizeof w->scope, "%s", scope);
    snprintf(w->name, sizeof w->name, "%s", name);
    w->is_curve = is_curve;
    w->freq_cpd = c->kind == CSF_COND_IMAGE ? NAN : c->freq_cpd;
    w->ecc_deg = c->ecc_deg;
    return w;
}

static void add_level(csf_study_row *w, double x, int ok)
{
    int best = -1;
    for (int i = 0; i < w->n_levels; i++)
        if (fabs(w->levels[i].x_log10 - x) < 1e-9) best = i;
    if (best < 0 && w->n_levels < CSF_REPORT_MAX_LEVELS) {
        best = w->n_levels++;
        w->levels[best].x_log10 = x;
    }
    if (best < 0) { /* full: the nearest level takes it */
        best = 0;
        for (int i = 1; i < w->n_levels; i++)
            if (fabs(w->levels[i].x_log10 - x) < fabs(w->levels[best].x_log10 - x)) best = i;
    }
    w->levels[best].n++;
    w->levels[best].k += ok;
}

/* Scores one trial into a row: forced choice counts correct answers; yes/no and same/different
 * count hits (response 1 when a target/difference was there) and false alarms. */
static void score(csf_study_row *w, csf_study_design d, const csf_trial *t, int curve)
{
    int forced = d == CSF_DESIGN_2AFC || d == CSF_DESIGN_2IFC;
    int correct = forced ? t->response == t->signal_interval : (t->response == 1) == !t->is_catch;
    if (!curve) {
        w->n++;
        w->k += correct;
    }
    if (!forced) {
        if (t->is_catch) {
            w->n_noise++;
            w->false_alarms += t->response == 1;
        } else {
            w->n_signal++;
            w->hits += t->response == 1;
        }
    }
    if (curve && t->contrast_requested > 0 && (forced || !t->is_catch))
        add_level(w, log10(t->contrast_requested), forced ? correct : t->response == 1);
}

/* Rates of 0 or 1 moved by 1/(2N) (Macmillan & Kaplan 1985) so that z stays finite. */
static double corrected_rate(int k, int n)
{
    if (n <= 0) return NAN;
    double r = (double)k / n;
    if (k == 0) r = 0.5 / n;
    if (k == n) r = 1 - 0.5 / n;
    return r;
}

/* Same/different d' by the design's model; h < f gives the swapped rates' d' negated, so a
 * negative d' reads as in yes/no (more "different" answers to same pairs than to different). */
static double sd_dprime(const csf_study *s, double h, double f)
{
    if (h == f) return 0;
    if (h < f) return -sd_dprime(s, f, h);
    return s->sd_differencing ? csf_stats_dprime_sd_differencing(h, f) : csf_stats_dprime_sd_independent(h, f);
}

/* Whether a design is scored by hits and false alarms (yes/no, same/different) rather than by
 * proportion correct against a chance of one half (forced choice). */
static int by_hits(csf_study_design d)
{
    return d == CSF_DESIGN_YES_NO || d == CSF_DESIGN_SAME_DIFF;
}

/* Proportion correct with its exact interval; the test is against 0.5 in forced choice, and hits
 * against false alarms where there are both (chance in yes/no is the false-alarm rate, not 0.5). */
static void finish_counts(csf_study_row *w, const csf_study *s)
{
    w->p = w->ci_lo = w->ci_hi = w->p_greater = w->p_two_sided = NAN;
    if (w->n > 0) {
        w->p = (double)w->k / w->n;
        csf_stats_clopper_pearson(w->k, w->n, 0.95, &w->ci_lo, &w->ci_hi);
    }
    if (by_hits(s->design)) {
        if (w->n_signal && w->n_noise) {
            w->p_greater = csf_stats_fisher_greater(w->hits, w->n_signal, w->false_alarms, w->n_noise);
            w->p_two_sided = csf_stats_fisher_two_sided(w->hits, w->n_signal, w->false_alarms, w->n_noise);
        }
    } else if (w->n > 0) {
        w->p_greater = csf_stats_binom_p_greater(w->k, w->n, 0.5);
        w->p_two_sided = csf_stats_binom_p_two_sided(w->k, w->n, 0.5);
    }
}

void csf_study_row_finish(csf_study_row *w, const csf_study *s, int n_boot, uint64_t seed)
{
    finish_counts(w, s);
    w->hit_rate = w->n_signal ? (double)w->hits / w->n_signal : NAN;
    w->fa_rate = w->n_noise ? (double)w->false_alarms / w->n_noise : NAN;
    w->dprime = w->dprime_lo = w->dprime_hi = NAN;
    if (w->n_signal && w->n_noise) {
        double h = corrected_rate(w->hits, w->n_signal), f = corrected_rate(w->false_alarms, w->n_noise);
        if (s->design == CSF_DESIGN_YES_NO) {
            w->dprime = csf_stats_dprime_yesno(h, f);
            csf_stats_dprime_yesno_ci(h, f, w->n_signal, w->n_noise, 0.95, &w->dprime_lo, &w->dprime_hi);
        } else if (s->design == CSF_DESIGN_SAME_DIFF) {
            w->dprime = sd_dprime(s, h, f);
            csf_stats_dprime_sd_ci(h, f, w->n_signal, w->n_noise, s->sd_differencing, 0.95, &w->dprime_lo,
                                   &w->dprime_hi);
        }
    }
    w->t_lo = w->t_hi = w->beta_lo = w->beta_hi = NAN;
    w->tb_lo = w->tb_hi = w->bb_lo = w->bb_hi = NAN;
    if (w->is_curve != 1) return;
    double guess = 0.5;
    if (s->design == CSF_DESIGN_YES_NO) {
        guess = w->n_noise ? (double)w->false_alarms / w->n_noise : 0.02;
        guess = fmin(0.5, fmax(0.001, guess));
    }
    if (csf_weibull_fit_ml(w->levels, (size_t)w->n_levels, guess, s->max_lapse, &w->fit) == 0) {
        w->have_fit = 1;
        csf_weibull_marginal_ci(w->levels, (size_t)w->n_levels, &w->fit, s->max_lapse, 0.95, &w->t_lo, &w->t_hi,
                                &w->beta_lo, &w->beta_hi);
        if (n_boot > 1)
            w->n_boot_ok = csf_weibull_bootstrap(w->levels, (size_t)w->n_levels, &w->fit, s->max_lapse, n_boot,
                                                 seed, 0.95, &w->tb_lo, &w->tb_hi, &w->bb_lo, &w->bb_hi);
    }
}

static void add_participant(csf_study_report *r, const char *p)
{
    size_t n = strlen(r->participants);
    if (n + strlen(p) + 2 < sizeof r->participants)
        snprintf(r->participants + n, sizeof r->participants - n, "%s%s", n ? "," : "", p);
}

static csf_status analyse(csf_study_report *r, session_data *ds, int nd, int cap, int n_boot, csf_error *err)
{
    const csf_study *s = ds[0].m->study;
    /* rows in a fixed order: pooled, then each participant; conditions in file order, then curves */
    for (int i = -1; i < nd; i++) {
        const char *scope = i < 0 ? "pooled" : ds[i].participant;
        for (int c = 0; c < s->n_conds; c++)
            if (!row_for(r, cap, scope, 0, s->conds[c].label, &s->conds[c]))
                return csf_error_set(err, CSF_E_NOMEM, "study report: too many rows");
        /* gratings: psychometric curves (1); images: groups pooled by their curve name (2) */
        for (int c = 0; c < s->n_conds; c++)
            if (!row_for(r, cap, scope, s->conds[c].kind == CSF_COND_IMAGE ? 2 : 1, s->conds[c].curve, &s->conds[c]))
                return csf_error_set(err, CSF_E_NOMEM, "study report: too many rows");
    }
    for (int i = 0; i < nd; i++) {
        const session_data *d = &ds[i];
        const csf_study_session_data *m = d->m;
        add_participant(r, d->participant);
        r->n_finished += d->finished;
        for (size_t j = 0; j < m->n_trials; j++) {
            const csf_trial *t = &m->trials[j];
            if (t->seq < 0 || t->seq >= m->n_plan) continue;
            const csf_study_trial *pt = &m->plan[t->seq];
            if (t->is_practice || pt->practice) continue;
            if (!t->valid) {
                r->n_excluded++;
                continue;
            }
            r->n_trials++;
            const csf_study_condition *c = &s->conds[pt->cond];
            const char *scopes[2] = {"pooled", d->participant};
            for (int k = 0; k < 2; k++) {
                csf_study_row *w = row_for(r, cap, scopes[k], 0, c->label, c);
                if (!w) return csf_error_set(err, CSF_E_NOMEM, "study report: too many rows");
                score(w, s->design, t, 0);
                if (c->kind == CSF_COND_IMAGE) {
                    w = row_for(r, cap, scopes[k], 2, c->curve, c);
                    if (!w) return csf_error_set(err, CSF_E_NOMEM, "study report: too many rows");
                    score(w, s->design, t, 0);
                    continue;
                }
                w = row_for(r, cap, scopes[k], 1, c->curve, c);
                if (!w) return csf_error_set(err, CSF_E_NOMEM, "study report: too many rows");
                score(w, s->design, t, 1);
            }
        }
    }
    for (int i = 0; i < r->n_rows; i++) csf_study_row_finish(&r->rows[i], s, n_boot, s->hash ^ (uint64_t)(i + 1));
    return CSF_OK;
}

/* err's message behind "who: " (the walk names the session; the report names itself). */
static void prefix_error(csf_error *err, csf_status st, const char *who)
{
    char m[sizeof err->msg];
    snprintf(m, sizeof m, "%s", err->msg);
    csf_error_set(err, st, "%s: %s", who, m);
}

/* Per session: who, which version, whether it finished; and the versions not analysed. */
static csf_status note_sessions(csf_study_report *r, const csf_study_selection *sel, const session_data *ds,
                                int nd, csf_error *err)
{
    r->version = sel->version;
    snprintf(r->sha256, sizeof r->sha256, "%s", sel->key);
    r->legacy = sel->legacy;
    csf_study_versions_text(sel->all, sel->n_all, sel->key, r->other_versions, sizeof r->other_versions);
    r->sessions = calloc((size_t)nd + 1, sizeof *r->sessions);
    if (!r->sessions) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int i = 0; i < nd; i++) {
        csf_study_session_row *w = &r->sessions[i];
        w->id = ds[i].m->x->id;
        w->version = ds[i].m->x->version;
        w->finished = ds[i].finished;
        w->n_trials = (int)ds[i].m->n_trials;
        snprintf(w->participant, sizeof w->participant, "%s", ds[i].participant);
        w->participant_index = ds[i].m->x->participant_index;
        w->latin_row =
            ds[i].m->study->latin ? csf_study_latin_row(ds[i].m->study, w->participant_index, NULL) : -1;
        snprintf(w->experimenter, sizeof w->experimenter, "%s", ds[i].m->x->experimenter);
        snprintf(w->notes, sizeof w->notes, "%s", ds[i].m->x->notes);
    }
    r->n_session_rows = nd;
    return CSF_OK;
}

csf_status csf_study_report_build(const char *store_path, const char *study, int version, int n_boot,
                                  csf_study_report **out, csf_error *err)
{
    *out = NULL;
    csf_store *store = NULL;
    csf_status st = csf_store_open_readonly(store_path, &store, err);
    if (st != CSF_OK) return st;
    csf_study_selection sel;
    st = csf_study_select(store, study, version, &sel, err);
    if (st != CSF_OK) {
        csf_store_close(store);
        return st;
    }
    csf_study_session_data *loaded = NULL;
    int nd = 0;
    csf_study_report *r = calloc(1, sizeof *r);
    if (!r) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    if (st == CSF_OK) {
        snprintf(r->name, sizeof r->name, "%s", sel.name);
        st = csf_study_sessions_load(store, &sel, 0, "study report", &loaded, &nd, err);
        if (st != CSF_OK) prefix_error(err, st, "study report");
    }
    session_data *ds = st == CSF_OK ? calloc(nd > 0 ? (size_t)nd : 1, sizeof *ds) : NULL;
    if (st == CSF_OK && !ds) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int i = 0; st == CSF_OK && i < nd; i++) {
        ds[i].m = &loaded[i];
        csf_store_printable(loaded[i].x->participant, ds[i].participant, sizeof ds[i].participant);
        ds[i].finished = loaded[i].x->state == CSF_SESSION_FINISHED;
    }
    if (st == CSF_OK && nd == 0)
        st = csf_error_set(err, CSF_E_NOT_FOUND,
                           "study report: the store %s holds no complete session of study "
                           "'%s'",
                           store_path, sel.name);
    if (st == CSF_OK) st = note_sessions(r, &sel, ds, nd, err);
    if (st == CSF_OK && nd > 0) {
        const csf_study *s = ds[0].m->study;
        r->design = s->design;
        r->sd_differencing = s->sd_differencing;
        r->hash = s->hash;
        r->n_sessions = nd;
        int cap = 2 * s->n_conds * (nd + 1);
        r->rows = calloc((size_t)cap, sizeof *r->rows);
        if (!r->rows) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
        else st = analyse(r, ds, nd, cap, n_boot >= 0 ? n_boot : s->bootstrap, err);
    }
    free(ds);
    csf_study_session_data_free(loaded, nd);
    csf_study_selection_free(&sel);
    csf_store_close(store);
    if (st != CSF_OK) {
        csf_study_report_free(r);
        return st;
    }
    *out = r;
    return CSF_OK;
}

void csf_study_report_free(csf_study_report *r)
{
    if (!r) return;
    free(r->rows);
    free(r->sessions);
    free(r);
}

static const char *sd_model_name(const csf_study_report *r)
{
    if (r->design == CSF_DESIGN_YES_NO) return "yes/no: z(H) - z(F)";
    if (r->design == CSF_DESIGN_SAME_DIFF)
        return r->sd_differencing ? "same/different, differencing model" : "same/different, independent observations";
    return "";
}

/* A session's counterbalancing row and metadata, when it has them (stored text: escaped). */
static void print_session_extras(const csf_study_session_row *x, FILE *fp)
{
    char shown[800];
    if (x->latin_row >= 0)
        fprintf(fp, ", Latin-square row %d (participant index %d)", x->latin_row, x->participant_index);
    if (x->experimenter[0]) {
        csf_store_printable(x->experimenter, shown, sizeof shown);
        fprintf(fp, ", experimenter %s", shown);
    }
    if (x->notes[0]) {
        csf_store_printable(x->notes, shown, sizeof shown);
        fprintf(fp, ", notes: %s", shown);
    }
}

/* The same in a session's JSON entry (only what it has: older reports read the same). */
static void json_session_extras(const csf_study_session_row *x, json_t *o)
{
    if (x->latin_row >= 0) {
        json_object_set_new(o, "participant_index", json_integer(x->participant_index));
        json_object_set_new(o, "counterbalance_row", json_integer(x->latin_row));
    }
    if (x->experimenter[0]) json_object_set_new(o, "experimenter", json_string(x->experimenter));
    if (x->notes[0]) json_object_set_new(o, "notes", json_string(x->notes));
}

void csf_study_report_print(const csf_study_report *r, FILE *fp)
{
    fprintf(fp, "study %s (%s): %d session(s), %d finished; participants %s; %d trials scored, %d invalid left "
                "out\n", r->name, csf_study_design_name(r->design), r->n_sessions, r->n_finished, r->participants,
            r->n_trials, r->n_excluded);
    fprintf(fp, "version %d, %s %s\n", r->version, r->legacy ? "files hash" : "sha256", r->sha256);
    for (int i = 0; i < r->n_session_rows; i++) {
        const csf_study_session_row *x = &r->sessions[i];
        fprintf(fp, "  session %lld: participant %s, version %d, %d trials, %s", (long long)x->id,
                x->participant, x->version, x->n_trials, x->finished ? "finished" : "NOT finished");
        print_session_extras(x, fp);
        fputc('\n', fp);
    }
    if (r->other_versions[0])
        fprintf(fp, "other versions in the store (not analysed): %s\n", r->other_versions);
    if (r->design == CSF_DESIGN_YES_NO || r->design == CSF_DESIGN_SAME_DIFF) fprintf(fp, "d': %s\n", sd_model_name(r));
    if (by_hits(r->design))
        fputs("p(H>F): Fisher's exact test of hits against false alarms (one-sided)\n", fp);
    fprintf(fp, "%-10s %-16s %5s %5s %6s %15s %9s", "scope", "condition", "n", "k", "p", "95% CI (exact)",
            by_hits(r->design) ? "p(H>F)" : "p(>chance)");
    if (by_hits(r->design)) fprintf(fp, " %6s %6s %6s", "H", "F", "d'");
    if (by_hits(r->design)) fprintf(fp, " %15s", "d' 95% CI");
    fputc('\n', fp);
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        if (w->is_curve == 1) continue;
        char nm[80];
        snprintf(nm, sizeof nm, "%s%s", w->is_curve == 2 ? "group " : "", w->name);
        fprintf(fp, "%-10.10s %-16.16s %5d %5d %6.3f [%5.3f, %5.3f] %10.3g", w->scope, nm, w->n, w->k, w->p,
                w->ci_lo, w->ci_hi, w->p_greater);
        if (by_hits(r->design)) fprintf(fp, " %6.3f %6.3f %6.2f", w->hit_rate, w->fa_rate, w->dprime);
        if (by_hits(r->design)) fprintf(fp, " [%5.2f, %5.2f]", w->dprime_lo, w->dprime_hi);
        fputc('\n', fp);
    }
    int any = 0;
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        if (w->is_curve != 1) continue;
        if (!any++)
            fprintf(fp, "\npsychometric fits (Weibull, ML; 95%% intervals from the marginal posterior, flat priors):\n%-10s %-16s %8s %19s %6s "
                        "%15s %6s\n", "scope", "curve", "t log10", "t 95% CI", "beta", "beta 95% CI", "lapse");
        if (!w->have_fit) {
            fprintf(fp, "%-10.10s %-16.16s  (no fit: fewer than two levels)\n", w->scope, w->name);
            continue;
        }
        fprintf(fp, "%-10.10s %-16.16s %8.3f [%7.3f, %7.3f] %6.2f [%5.2f, %5.2f] %6.3f\n", w->scope, w->name,
                w->fit.t_log10, w->t_lo, w->t_hi, w->fit.beta, w->beta_lo, w->beta_hi, w->fit.lapse);
    }
}

static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

char *csf_study_report_json(const csf_study_report *r)
{
    json_t *root = json_object();
    char hash[32];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)r->hash);
    json_object_set_new(root, "study", json_string(r->name));
    json_object_set_new(root, "design", json_string(csf_study_design_name(r->design)));
    json_object_set_new(root, "hash", json_string(hash));
    json_object_set_new(root, "version", json_integer(r->version));
    json_object_set_new(root, r->legacy ? "files_hash" : "sha256", json_string(r->sha256));
    json_t *sl = json_array();
    for (int i = 0; i < r->n_session_rows; i++) {
        const csf_study_session_row *x = &r->sessions[i];
        json_t *o =
            json_pack("{s:I,s:s,s:i,s:b,s:i}", "session", (json_int_t)x->id, "participant", x->participant,
                      "version", x->version, "finished", x->finished, "trials", x->n_trials);
        if (o) json_session_extras(x, o);
        json_array_append_new(sl, o);
    }
    json_object_set_new(root, "session_list", sl);
    json_object_set_new(root, "other_versions", json_string(r->other_versions));
    json_object_set_new(root, "dprime_model", json_string(sd_model_name(r)));
    json_object_set_new(root, "sessions", json_integer(r->n_sessions));
    json_object_set_new(root, "sessions_finished", json_integer(r->n_finished));
    json_object_set_new(root, "trials_scored", json_integer(r->n_trials));
    json_object_set_new(root, "trials_invalid", json_integer(r->n_excluded));
    json_object_set_new(root, "participants", json_string(r->participants));
    json_t *conds = json_array(), *curves = json_array(), *groups = json_array();
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        json_t *o = json_object();
        json_object_set_new(o, "scope", json_string(w->scope));
        json_object_set_new(o, w->is_curve == 1 ? "curve" : w->is_curve == 2 ? "group" : "condition",
                            json_string(w->name));
        json_object_set_new(o, "freq_cpd", num(w->freq_cpd));
        json_object_set_new(o, "ecc_deg", num(w->ecc_deg));
        if (w->is_curve != 1) {
            json_object_set_new(o, "n", json_integer(w->n));
            json_object_set_new(o, "correct", json_integer(w->k));
            json_object_set_new(o, "p_correct", num(w->p));
            json_object_set_new(o, "ci95", json_pack("[o,o]", num(w->ci_lo), num(w->ci_hi)));
            json_object_set_new(o, "test", json_string(by_hits(r->design)
                                                           ? "Fisher exact, hits against false alarms"
                                                           : "exact binomial against 0.5"));
            json_object_set_new(o, "p_value_above_chance", num(w->p_greater));
            json_object_set_new(o, "p_value_two_sided", num(w->p_two_sided));
            if (w->n_signal || w->n_noise) {
                json_object_set_new(o, "hits", json_integer(w->hits));
                json_object_set_new(o, "n_signal", json_integer(w->n_signal));
                json_object_set_new(o, "false_alarms", json_integer(w->false_alarms));
                json_object_set_new(o, "n_noise", json_integer(w->n_noise));
                json_object_set_new(o, "hit_rate", num(w->hit_rate));
                json_object_set_new(o, "fa_rate", num(w->fa_rate));
                json_object_set_new(o, "dprime", num(w->dprime));
                if (by_hits(r->design))
                    json_object_set_new(o, "dprime_ci95", json_pack("[o,o]", num(w->dprime_lo), num(w->dprime_hi)));
            }
            json_array_append_new(w->is_curve == 2 ? groups : conds, o);
            continue;
        }
        json_t *lv = json_array();
        for (int j = 0; j < w->n_levels; j++)
            json_array_append_new(lv, json_pack("{s:o,s:i,s:i}", "log10_contrast", num(w->levels[j].x_log10), "n",
                                                w->levels[j].n, "k", w->levels[j].k));
        json_object_set_new(o, "levels", lv);
        json_object_set_new(o, "fitted", json_boolean(w->have_fit));
        if (w->have_fit) {
            json_object_set_new(o, "t_log10", num(w->fit.t_log10));
            json_object_set_new(o, "threshold", num(pow(10.0, w->fit.t_log10)));
            json_object_set_new(o, "t_log10_ci95", json_pack("[o,o]", num(w->t_lo), num(w->t_hi)));
            json_object_set_new(o, "beta", num(w->fit.beta));
            json_object_set_new(o, "beta_ci95", json_pack("[o,o]", num(w->beta_lo), num(w->beta_hi)));
            json_object_set_new(o, "lapse", num(w->fit.lapse));
            json_object_set_new(o, "guess", num(w->fit.guess));
            json_object_set_new(o, "ci95_method", json_string("marginal posterior, flat priors on t, 1/beta (width) and lapse"));
            json_object_set_new(o, "t_log10_ci95_bootstrap", json_pack("[o,o]", num(w->tb_lo), num(w->tb_hi)));
            json_object_set_new(o, "beta_ci95_bootstrap", json_pack("[o,o]", num(w->bb_lo), num(w->bb_hi)));
            json_object_set_new(o, "bootstrap_ok", json_integer(w->n_boot_ok));
        }
        json_array_append_new(curves, o);
    }
    json_object_set_new(root, "conditions", conds);
    json_object_set_new(root, "curves", curves);
    json_object_set_new(root, "groups", groups);
    char *s = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER);
    json_decref(root);
    return s;
}

static void csv_num(FILE *fp, double v)
{
    if (isfinite(v)) fprintf(fp, ",%.9g", v);
    else fputs(",NA", fp);
}

/* A participant's session (a participant has one per version); NULL for the pooled scope. */
static const csf_study_session_row *session_of(const csf_study_report *r, const char *scope)
{
    for (int i = 0; i < r->n_session_rows; i++)
        if (!strcmp(r->sessions[i].participant, scope)) return &r->sessions[i];
    return NULL;
}

csf_status csf_study_report_csv(const csf_study_report *r, const char *path, csf_error *err)
{
    csf_atomic_file af = {0};
    csf_status st = csf_atomic_open(&af, path, "study report CSV", err);
    if (st != CSF_OK) return st;
    FILE *fp = af.fp;
    fputs("study,version,session,finished,design,scope,kind,name,freq_cpd,ecc_deg,n,correct,p_correct,ci_lo,"
          "ci_hi,p_above_chance,"
          "p_two_sided,hits,n_signal,false_alarms,n_noise,hit_rate,fa_rate,dprime,t_log10,t_lo,t_hi,beta,"
          "beta_lo,beta_hi,lapse,guess,dprime_lo,dprime_hi\n",
          fp);
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        const csf_study_session_row *x = session_of(r, w->scope);
        fprintf(fp, "%s,%d", r->name, r->version);
        if (x) fprintf(fp, ",%lld,%d", (long long)x->id, x->finished);
        else fputs(",NA,NA", fp);
        fprintf(fp, ",%s,%s,%s,%s", csf_study_design_name(r->design), w->scope,
                w->is_curve == 1   ? "curve"
                : w->is_curve == 2 ? "group"
                                   : "condition",
                w->name);
        csv_num(fp, w->freq_cpd);
        csv_num(fp, w->ecc_deg);
        if (w->is_curve == 1) fputs(",NA,NA,NA,NA,NA,NA,NA", fp);
        else {
            fprintf(fp, ",%d,%d", w->n, w->k);
            csv_num(fp, w->p);
            csv_num(fp, w->ci_lo);
            csv_num(fp, w->ci_hi);
            csv_num(fp, w->p_greater);
            csv_num(fp, w->p_two_sided);
        }
        if (w->is_curve != 1 && (w->n_signal || w->n_noise)) {
            fprintf(fp, ",%d,%d,%d,%d", w->hits, w->n_signal, w->false_alarms, w->n_noise);
            csv_num(fp, w->hit_rate);
            csv_num(fp, w->fa_rate);
            csv_num(fp, w->dprime);
        } else {
            fputs(",NA,NA,NA,NA,NA,NA,NA", fp);
        }
        if (w->is_curve == 1 && w->have_fit) {
            csv_num(fp, w->fit.t_log10);
            csv_num(fp, w->t_lo);
            csv_num(fp, w->t_hi);
            csv_num(fp, w->fit.beta);
            csv_num(fp, w->beta_lo);
            csv_num(fp, w->beta_hi);
            csv_num(fp, w->fit.lapse);
            csv_num(fp, w->fit.guess);
        } else {
            fputs(",NA,NA,NA,NA,NA,NA,NA,NA", fp);
        }
        csv_num(fp, w->dprime_lo);
        csv_num(fp, w->dprime_hi);
        fputc('\n', fp);
    }
    return csf_atomic_commit(&af, err);
}

/* A bar page's row from a condition (or group) row: the point, its chance line and the table. */
static void bar_of(const csf_study_report *r, const csf_study_row *w, csf_study_plot_bar *b)
{
    memset(b, 0, sizeof *b);
    snprintf(b->label, sizeof b->label, "%s%s", w->is_curve == 2 ? "group " : "", w->name);
    snprintf(b->cells[0], sizeof b->cells[0], "%s", b->label);
    b->chance = NAN;
    if (!by_hits(r->design) || !w->n_signal || !w->n_noise) {
        b->p = w->p;
        b->lo = w->ci_lo;
        b->hi = w->ci_hi;
        b->chance = 0.5;
        snprintf(b->cells[1], sizeof b->cells[1], "%d", w->n);
        snprintf(b->cells[2], sizeof b->cells[2], "%.3f", w->p);
        snprintf(b->cells[3], sizeof b->cells[3], "[%.3f, %.3f]", w->ci_lo, w->ci_hi);
        snprintf(b->cells[4], sizeof b->cells[4], "%.2g", w->p_greater);
        return;
    }
    b->p = w->hit_rate;
    csf_stats_clopper_pearson(w->hits, w->n_signal, 0.95, &b->lo, &b->hi);
    if (r->design == CSF_DESIGN_YES_NO) {
        b->chance = w->fa_rate; /* "yes" to a signal against "yes" to nothing */
    } else {
        b->second = 1;
        b->p2 = w->fa_rate;
        csf_stats_clopper_pearson(w->false_alarms, w->n_noise, 0.95, &b->lo2, &b->hi2);
    }
    snprintf(b->cells[1], sizeof b->cells[1], "%.2f (%d/%d)", w->hit_rate, w->hits, w->n_signal);
    snprintf(b->cells[2], sizeof b->cells[2], "%.2f (%d/%d)", w->fa_rate, w->false_alarms, w->n_noise);
    snprintf(b->cells[3], sizeof b->cells[3], "%.2f", w->dprime);
    snprintf(b->cells[4], sizeof b->cells[4], "[%.2f, %.2f]", w->dprime_lo, w->dprime_hi);
    snprintf(b->cells[5], sizeof b->cells[5], "%.2g", w->p_greater);
}

/* The bar page of one scope: forced choice pooled only; yes/no and same/different per scope. */
static void bar_page(const csf_study_report *r, const char *scope, csf_study_plot_bar_page *pg)
{
    static const char *const fc[] = {"condition", "trials", "p correct", "95% exact CI", "p (> 0.5)"};
    static const char *const hf[] = {"condition", "hits (H)",  "false alarms (F)",
                                     "d'",        "d' 95% CI", "p (H > F)"};
    int hits = by_hits(r->design);
    pg->n_columns = hits ? 6 : 5;
    for (int j = 0; j < pg->n_columns; j++) pg->columns[j] = hits ? hf[j] : fc[j];
    const char *what = r->design == CSF_DESIGN_SAME_DIFF ? "hits and false alarms"
                       : hits                            ? "hits against the false-alarm rate"
                                                         : "proportion correct";
    snprintf(pg->title, sizeof pg->title, "%s v%d (%s): %s, %s", r->name, r->version,
             csf_study_design_name(r->design), what, scope);
    pg->axis = r->design == CSF_DESIGN_SAME_DIFF ? "proportion \"different\" (95% exact CI)"
               : hits                            ? "hit rate (95% exact CI)"
                                                 : "proportion correct (95% exact CI)";
    pg->legend =
        r->design == CSF_DESIGN_SAME_DIFF
            ? "Circles: hits, \"different\" to different pairs; squares: false alarms, \"different\" "
              "to same pairs (95 % exact intervals). d': see the report's model; its interval is "
              "the profile likelihood's (differencing) or the yes/no interval mapped (independent)."
        : hits ? "Circles: hit rate (95 % exact interval); dashed: chance, the condition's false-alarm "
                 "rate (catch trials answered yes). d' = z(H) - z(F), interval after Gourevitch & "
                 "Galanter (1967). p: Fisher's exact test of hits against false alarms."
               : "Circles: proportion correct (95 % exact interval); dashed: chance (0.5). p: exact "
                 "binomial test against 0.5, one-sided.";
}

csf_status csf_study_report_plot(const csf_study_report *r, const char *path, csf_error *err)
{
    size_t cap = (size_t)(r->n_rows ? r->n_rows : 1);
    csf_study_plot_curve *cv = calloc(cap, sizeof *cv);
    csf_study_plot_bar *bars = calloc(cap, sizeof *bars);
    csf_study_plot_bar_page *pages = calloc(cap, sizeof *pages);
    if (!cv || !bars || !pages) {
        free(cv);
        free(bars);
        free(pages);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    int nc = 0, nb = 0, np = 0;
    const char *scope = NULL;
    for (int i = 0; i < r->n_rows; i++) {
        const csf_study_row *w = &r->rows[i];
        if (w->is_curve == 1) {
            csf_study_plot_curve *c = &cv[nc++];
            snprintf(c->title, sizeof c->title, "%s: curve %s (%s)", r->name, w->name, w->scope);
            snprintf(c->scope, sizeof c->scope, "%s", w->scope);
            snprintf(c->name, sizeof c->name, "%s", w->name);
            c->levels = w->levels;
            c->n_levels = w->n_levels;
            c->fit = w->fit;
            c->have_fit = w->have_fit;
            c->t_lo = w->t_lo;
            c->t_hi = w->t_hi;
            continue;
        }
        if (!by_hits(r->design) && strcmp(w->scope, "pooled")) continue;
        /* rows come scope by scope (pooled, then each participant): a new scope starts a page */
        if (!scope || strcmp(scope, w->scope)) {
            scope = w->scope;
            bar_page(r, scope, &pages[np]);
            pages[np++].bars = &bars[nb];
        }
        bar_of(r, w, &bars[nb++]);
        pages[np - 1].n_bars++;
    }
    csf_status st = csf_study_plot_write(path, cv, nc, pages, np, err);
    free(cv);
    free(bars);
    free(pages);
    return st;
}
