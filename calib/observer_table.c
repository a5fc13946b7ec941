/* The end of an observer session (see observer_run.h): whether the person's data support a
 * table, the table and its metadata, the finished session and its plot. */
#include "calib/observer_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "calib/motion.h"
#include "calib/observer_checks.h"
#include "calib/trial_io.h"
#include "core/file_read.h"
#include "core/file_write.h"
#include "model/psychometric.h"
#include "results/csflut/csflut.h"
#include "results/plot.h"

/* Tables and plots are copied into the store as artifacts; anything larger is not ours. */
#define ARTIFACT_MAX_BYTES ((size_t)64 << 20)
#define FA_LIMIT 0.3 /* refuse a table when more catch trials than this were pressed */
#define FA_MIN_CATCH 4
#define INVALID_LIMIT 0.5   /* refuse when more than half the trials were invalid */
#define UNRELATED_LIMIT 0.2 /* refuse when > 20 % of presses were not caused by a grating */
/* Refuse when the wrong answers at 4x the estimated threshold say the person guessed on more than
 * half of those trials: > 25 % wrong with two intervals, > 37.5 % with four places. */
#define AFC_GUESS_LIMIT 0.5

/* The person's reliability, from the stored trials and the estimated thresholds. */
typedef struct {
    int n_afc_hi, n_afc_hi_wrong; /* clearly visible forced-choice trials, and the wrong ones */
    double afc_guesses;           /* guesses those wrong answers stand for */
    int n_unrelated;              /* presses the stimulus did not cause */
    int n_unknown;                /* cells without usable data */
    char unknown[256];            /* which */
} reliability;

/* Counts every main trial into the result and rel. Forced choice: wrong answers on clearly
 * visible trials (4x the estimated threshold, where a person who looks answers right but for
 * lapses). A person who guesses on a share g of them answers wrongly on g (1 - 1/m) of the
 * m-alternative ones: each wrong answer counts 1 / (1 - 1/m) guesses (2 with two intervals, 4/3
 * with four places). */
static void tally_trials(obs_run *R, reliability *rel)
{
    const session_res *S = &R->S;
    csf_obs_result *res = R->res;
    for (size_t i = 0; i < R->n_stored; i++) {
        const csf_trial *t = &S->stored[i];
        if (t->is_practice) {
            res->n_practice++;
            continue;
        }
        res->n_trials++;
        if (t->valid) res->n_valid++;
        if (t->frames_missed > 0) res->n_missed_frame_trials++;
        if (strstr(t->flags, "anticipation")) res->n_anticipations++;
        if (t->is_catch) {
            res->n_catch++;
            if (t->response == 1) res->n_false_alarms++;
            continue;
        }
        if (strstr(t->flags, "click_far")) res->n_invalid_click++;
        int cell = -1;
        for (int k = 0; k < R->n_cells; k++)
            if (S->cells[k].freq_cpd == t->freq_cpd && S->cells[k].ecc_deg == t->ecc_deg) cell = k;
        if (cell < 0 || !isfinite(S->est[cell].threshold)) continue;
        double th = S->est[cell].threshold;
        if (S->ops->task == CSF_TASK_FADE && t->n_alternatives == 0) {
            /* A lapse: a ramp that climbed well past the person's threshold without a press. */
            if (t->response == 0 && t->valid && t->contrast_requested > th * pow(10.0, 0.5)) res->n_lapses++;
        } else if (t->valid && t->contrast_shown_max >= 4 * th) {
            rel->n_afc_hi++;
            if (t->response != t->signal_interval) {
                int m = t->n_alternatives >= 2 ? t->n_alternatives : 2;
                rel->n_afc_hi_wrong++;
                rel->afc_guesses += 1.0 / (1.0 - 1.0 / m);
            }
        }
    }
    res->n_lapses += rel->n_afc_hi_wrong;
    res->fa_rate = res->n_catch ? (double)res->n_false_alarms / res->n_catch : NAN;
    /* Presses the stimulus did not cause: catch-trial presses, clicks far from the grating,
     * anticipations (an anticipation that also clicked far is counted once). */
    rel->n_unrelated = res->n_false_alarms;
    for (size_t i = 0; i < R->n_stored; i++)
        if (!S->stored[i].is_practice && !S->stored[i].is_catch &&
            (strstr(S->stored[i].flags, "click_far") || strstr(S->stored[i].flags, "anticipation")))
            rel->n_unrelated++;
}

/* Counts the cells by what was found (visible, never visible, no usable data) and the median
 * standard error of the visible ones. */
static void tally_cells(obs_run *R, reliability *rel)
{
    const session_res *S = &R->S;
    csf_obs_result *res = R->res;
    res->n_cells = R->n_cells;
    res->n_vels = R->set.n_vels;
    res->n_not_shown = R->n_not_shown;
    double *ses = malloc((size_t)R->n_cells * sizeof *ses);
    int n_se = 0;
    for (int k = 0; k < R->n_cells; k++) {
        if (isinf(S->est[k].threshold)) res->n_invisible++;
        else if (isfinite(S->est[k].threshold)) {
            res->n_visible++;
            if (ses && isfinite(S->est[k].stderr_log10)) ses[n_se++] = S->est[k].stderr_log10;
        } else {
            rel->n_unknown++;
            size_t l = strlen(rel->unknown);
            if (l < sizeof rel->unknown - 40)
                snprintf(rel->unknown + l, sizeof rel->unknown - l, "%s%g cpd/%g deg", l ? ", " : "",
                         S->cells[k].freq_cpd, S->cells[k].ecc_deg);
        }
    }
    if (ses && n_se) {
        qsort(ses, (size_t)n_se, sizeof *ses, obs_cmp_d);
        res->median_se_log10 = ses[n_se / 2];
    }
    free(ses);
}

/* Why the data do not support a table (NULL: they do), written into buf. */
static const char *table_refusal(const obs_run *R, const reliability *rel, char *buf, size_t len)
{
    const csf_obs_result *res = R->res;
    if (res->n_catch >= FA_MIN_CATCH && res->fa_rate > FA_LIMIT)
        snprintf(buf, len,
                 "the observer pressed on %d of %d catch trials (%.0f %%, limit %.0f %%): responses "
                 "do not follow the stimulus",
                 res->n_false_alarms, res->n_catch, 100 * res->fa_rate, 100 * FA_LIMIT);
    else if (res->n_trials >= 10 && rel->n_unrelated > UNRELATED_LIMIT * res->n_trials)
        snprintf(buf, len,
                 "%d of %d presses were not caused by a grating (%d on catch trials, %d clicks far "
                 "from it, %d anticipations; limit %.0f %% of trials): the observer is guessing",
                 rel->n_unrelated, res->n_trials, res->n_false_alarms, res->n_invalid_click,
                 res->n_anticipations, 100 * UNRELATED_LIMIT);
    else if (res->n_trials > 0 &&
             (res->n_trials - res->n_valid - res->n_catch) > INVALID_LIMIT * (res->n_trials - res->n_catch))
        snprintf(buf, len,
                 "%d of %d trials were invalid (clicks far from the grating, "
                 "anticipations, missed frames; limit %.0f %%)",
                 res->n_trials - res->n_valid - res->n_catch, res->n_trials - res->n_catch,
                 100 * INVALID_LIMIT);
    else if (rel->n_afc_hi >= 8 && rel->afc_guesses > AFC_GUESS_LIMIT * rel->n_afc_hi)
        snprintf(buf, len,
                 "%d of %d clearly visible forced-choice trials were answered "
                 "wrongly, as if guessed on %.0f %% of them (limit %.0f %%; a guess is wrong on 1/2 of "
                 "two-interval and 3/4 of four-place trials): inconsistent responses",
                 rel->n_afc_hi_wrong, rel->n_afc_hi, 100 * rel->afc_guesses / rel->n_afc_hi,
                 100 * AFC_GUESS_LIMIT);
    else if (rel->n_unknown > 0)
        snprintf(buf, len,
                 "%d of %d cells have no usable data (%s); give more --trials "
                 "(now %d) or fewer --freqs/--eccs",
                 rel->n_unknown, R->n_cells, rel->unknown, R->set.trials);
    else if (res->n_visible == 0)
        snprintf(buf, len, "no cell was visible at any contrast the display can show");
    else return NULL;
    return buf;
}

/* The estimates, the person's reliability, and the thresholds into the store in every case (they
 * are the session's data); a refusal of the data ends the session aborted. */
csf_status obs_judge_session(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    csf_obs_result *res = R->res;
    res->precision_log10 = R->set.precision;
    csf_status st = S->ops->estimate(S->proc, S->est, err);
    if (st != CSF_OK) return st;
    res->predicted_rms_log10 = obs_rms_of_estimates(R);
    /* The stop waits for PRECISION_MIN_TRIALS (the prior alone is not a table), so a session whose
     * cap came first can end below the target without having stopped on it: what it reached is
     * what its table's predicted error says. */
    if (R->set.precision > 0 && res->predicted_rms_log10 <= R->set.precision) res->reached_precision = 1;
    if (!S->ops->task_offset || !S->ops->task_offset(S->proc, &res->n_fade_anchors, &res->fade_offset_log10,
                                                     &res->fade_offset_sd_log10))
        res->fade_offset_log10 = res->fade_offset_sd_log10 = NAN;
    reliability rel;
    memset(&rel, 0, sizeof rel);
    tally_trials(R, &rel);
    tally_cells(R, &rel);
    char whybuf[400];
    const char *why = table_refusal(R, &rel, whybuf, sizeof whybuf);

    csf_threshold_row *rows = calloc((size_t)R->n_cells, sizeof *rows);
    if (!rows) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int k = 0; k < R->n_cells; k++)
        rows[k] = (csf_threshold_row){S->cells[k].freq_cpd,     S->cells[k].ecc_deg,
                                      S->cells[k].velocity_dps, csf_round9(R->mean_lum_cdm2),
                                      S->est[k].threshold,      S->est[k].stderr_log10,
                                      S->est[k].n_trials};
    st = csf_store_put_thresholds(S->store, R->sid, rows, (size_t)R->n_cells, err);
    free(rows);
    if (st != CSF_OK) return st;
    if (why) {
        csf_store_set_session_state(S->store, R->sid, CSF_SESSION_ABORTED, NULL);
        return csf_error_set(err, CSF_E_INSUFFICIENT, "session %lld: no table written: %s", (long long)R->sid,
                             why);
    }
    return CSF_OK;
}

/* The table's method line: the method and the threshold's task-independent definition; for fade also
 * how the yes/no thresholds were tied to that definition, and by how much. */
static void method_line(const obs_run *R, char *buf, size_t len)
{
    const csf_obs_result *res = R->res;
    const char *method = R->set.method;
    if (R->S.ops->task == CSF_TASK_FADE && isfinite(res->fade_offset_log10))
        snprintf(buf, len, "%s; anchored by %d two-interval trials, yes/no offset %+.3f log10; %s", method,
                 res->n_fade_anchors, res->fade_offset_log10, CSF_PSY_THRESHOLD_DEFINITION);
    else if (R->S.ops->task == CSF_TASK_FADE)
        snprintf(buf, len, "%s; yes/no only, the criterion not measured; %s", method,
                 CSF_PSY_THRESHOLD_DEFINITION);
    else snprintf(buf, len, "%s; %s", method, CSF_PSY_THRESHOLD_DEFINITION);
}

/* The shift (standard errors, csflut's conservative view lowered by K stderr) at which a method's
 * table fails open in at most 2.5 % of visible cells on held-out people at the default budget
 * (bench/bench_coverage over held-out sets 5-14, confirmed on set 15): 2.0 for bayes and fade, 2.5
 * for 2afc, whose per-cell errors are the least even (docs/observer-calibration.md). */
static const char *recommended_shift(const char *method)
{
    return strcmp(method, "2afc") == 0 ? "2.5" : "2.0";
}

/* Every table names its recommended conservative shift; a table with a velocity axis also says
 * what its velocities are and which cells were never shown (the method's prediction stands there,
 * with its stated error). */
static size_t table_metadata(const obs_run *R, csflut_meta *meta, char *buf, size_t len)
{
    const session_settings *set = &R->set;
    meta[0] = (csflut_meta){"recommended_shift_se", recommended_shift(set->method)};
    if (set->n_vels == 0) return 1;
    meta[1] =
        (csflut_meta){"velocity_meaning", "retinal velocity of the carrier drifting in a stationary "
                                          "envelope, with the eyes on the fixation mark (= screen velocity)"};
    if (R->n_not_shown == 0) return 2;
    double refresh_hz = csf_presenter_refresh_hz(R->S.pres);
    size_t used = 0;
    for (int v = 0; v < set->n_vels && used < len; v++)
        for (int f = 0; f < set->n_freqs && used < len; f++)
            if (csf_motion_aliases(&(csf_cell){set->freqs[f], 0, set->vels[v]}, refresh_hz))
                used += (size_t)snprintf(buf + used, len - used, "%s%g cpd at %g deg/s", used ? ", " : "",
                                         set->freqs[f], set->vels[v]);
    if (used < len)
        snprintf(buf + used, len - used,
                 " (every eccentricity): temporal frequency at or above half the %g Hz "
                 "refresh rate, never shown; the %s method's prediction with its stated error",
                 refresh_hz, set->method);
    meta[2] = (csflut_meta){"cells_not_shown", buf};
    return 3;
}

/* The threshold table, written and kept in the store as an artifact. */
csf_status obs_write_table(obs_run *R, csf_error *err)
{
    session_res *S = &R->S;
    const session_settings *set = &R->set;
    int n_cells = R->n_cells;
    double *thr = malloc((size_t)n_cells * sizeof *thr), *se = malloc((size_t)n_cells * sizeof *se);
    if (!thr || !se) {
        free(thr);
        free(se);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    for (int k = 0; k < n_cells; k++) {
        thr[k] = S->est[k].threshold;
        se[k] = S->est[k].stderr_log10;
    }
    char date[32], obs_desc[300], profile_ids[1024], method_desc[256];
    obs_now_utc(date, sizeof date);
    snprintf(obs_desc, sizeof obs_desc, "%s", S->sim ? csf_observer_sim_describe(S->sim) : set->observer);
    obs_table_profile_id(S->store, R->sid, csf_profile_id(S->profile), profile_ids, sizeof profile_ids);
    method_line(R, method_desc, sizeof method_desc);
    csflut_build b;
    memset(&b, 0, sizeof b);
    b.n_freq = set->n_freqs;
    b.n_ecc = set->n_eccs;
    b.freq_cpd = set->freqs;
    b.ecc_deg = set->eccs;
    b.n_vel = set->n_vels;
    b.vel_dps = set->n_vels > 0 ? set->vels : NULL;
    b.threshold = thr;
    b.stderr_log10 = se;
    b.observer = obs_desc;
    b.display_profile_id = profile_ids;
    b.method = method_desc;
    b.date_utc = date;
    b.tool_version = CSF_VERSION;
    b.viewing_distance_mm = R->cfg->viewing_distance_mm;
    b.mean_lum_cdm2 = csf_round9(R->mean_lum_cdm2);
    b.trials = R->res->n_trials;
    csflut_diag diag;
    memset(&diag, 0, sizeof diag);
    unsigned char *blob = NULL;
    size_t blen = 0;
    char not_shown[4096];
    csflut_meta meta[3];
    size_t n_meta = table_metadata(R, meta, not_shown, sizeof not_shown);
    csflut_status ls = n_meta ? csflut_write_memory_meta(&b, meta, n_meta, &blob, &blen, &diag)
                              : csflut_write_memory_diag(&b, &blob, &blen, &diag);
    free(thr);
    free(se);
    if (ls != CSFLUT_OK)
        return csf_error_set(err, ls == CSFLUT_E_NOMEM ? CSF_E_NOMEM : CSF_E_IO,
                             "writing the threshold table %s: %s", R->opt->out_path,
                             diag.message[0] ? diag.message : csflut_strerror(ls));
    /* The store keeps the bytes that were written, not a read-back of the path: the path may be a
     * FIFO or a device that gives nothing back. */
    csf_error werr;
    csf_status st = csf_write_file_atomic(R->opt->out_path, "threshold table", blob, blen, &werr);
    if (st != CSF_OK)
        st = csf_error_set(err, st, "writing the threshold table %s: %s", R->opt->out_path, werr.msg);
    else {
        R->res->table_written = 1;
        st = csf_store_add_artifact(S->store, R->sid, "csflut", R->opt->out_path, blob, blen, err);
    }
    free(blob);
    return st;
}

/* The session finished; its plot, when asked for, written and kept as an artifact. */
csf_status obs_finish_session(obs_run *R, csf_error *err)
{
    const csf_obs_options *opt = R->opt;
    csf_status st = csf_store_set_session_state(R->S.store, R->sid, CSF_SESSION_FINISHED, err);
    if (st != CSF_OK || !opt->plot_path || !*opt->plot_path) return st;
    st = csf_report_write(R->S.store, R->sid, opt->plot_path, err);
    if (st != CSF_OK) return st;
    /* Kept only when it went to a file: a FIFO or a device at the path gives nothing back. */
    struct stat sb;
    if (stat(opt->plot_path, &sb) != 0 || !S_ISREG(sb.st_mode)) return CSF_OK;
    char *blob = NULL;
    size_t blen = 0;
    if (csf_read_file(opt->plot_path, "report plot", ARTIFACT_MAX_BYTES, &blob, &blen, NULL) == CSF_OK)
        csf_store_add_artifact(R->S.store, R->sid, "plot", opt->plot_path, blob, blen, NULL);
    free(blob);
    return CSF_OK;
}
