/* Tidy CSV / JSON exports of a session (see results/store/export.h). */
#include "results/store/export.h"

#include <sqlite3.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "results/store/internal.h"

typedef enum { COL_INT, COL_REAL, COL_TEXT, COL_BOOL } col_type;

typedef struct {
    col_type type;
    long long i;
    double r;
    const char *s;
} cell;

static void put_text_csv(FILE *out, const char *s)
{
    if (!strpbrk(s, ",\"\n\r")) {
        fputs(s, out);
        return;
    }
    fputc('"', out);
    for (const char *p = s; *p; p++) {
        if (*p == '"') fputc('"', out);
        fputc(*p, out);
    }
    fputc('"', out);
}

/* A JSON string through jansson: text that is not UTF-8 (a row written past csfcal) goes out
 * in its escaped, printable form, so the export stays valid JSON whatever the store holds. */
static void put_text_json(FILE *out, const char *s)
{
    json_t *j = json_string(s ? s : "");
    if (!j) {
        size_t n = strlen(s);
        char *shown = malloc(4 * n + 1);
        if (shown) csf_store_printable(s, shown, 4 * n + 1);
        j = json_string(shown ? shown : "");
        free(shown);
    }
    if (j) json_dumpf(j, out, JSON_ENCODE_ANY); /* a failed write shows in ferror(out) */
    else fputs("null", out);
    json_decref(j);
}

/* The shortest decimal that reads back as the same double: exact like %.17g, but 0.3 stays 0.3
 * instead of 0.29999999999999999, which people reading a tidy table expect. */
static void shortest_real(char *buf, size_t len, double v)
{
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, len, "%.*g", digits, v);
        if (strtod(buf, NULL) == v) return;
    }
}

static void put_real(FILE *out, double v, int json)
{
    if (isnan(v)) {
        if (json) fputs("null", out);
    } else if (isinf(v)) {
        fputs(json ? "null" : (v > 0 ? "Inf" : "-Inf"), out);
    } else {
        char buf[40];
        shortest_real(buf, sizeof buf, v);
        fputs(buf, out);
    }
}

typedef struct {
    FILE *out;
    int json;
    int row;   /* rows written so far */
    int col;   /* column within the row */
    const char *const *names;
    int ncols;
} writer;

static void begin_table(writer *w)
{
    if (w->json) {
        fputs("[", w->out);
        return;
    }
    for (int c = 0; c < w->ncols; c++) {
        if (c) fputc(',', w->out);
        fputs(w->names[c], w->out);
    }
    fputs("\n", w->out);
}

static void begin_row(writer *w)
{
    w->col = 0;
    if (w->json) fputs(w->row ? ",\n {" : "\n {", w->out);
}

static void sep(writer *w)
{
    if (w->json) {
        if (w->col) fputs(", ", w->out);
        fprintf(w->out, "\"%s\": ", w->names[w->col]);
    } else if (w->col) {
        fputc(',', w->out);
    }
}

static void put_i(writer *w, long long v)
{
    sep(w);
    fprintf(w->out, "%lld", v);
    w->col++;
}

static void put_b(writer *w, int v)
{
    sep(w);
    /* CSV: 0/1 (R and pandas read it as integer); JSON: true/false. */
    fputs(w->json ? (v ? "true" : "false") : (v ? "1" : "0"), w->out);
    w->col++;
}

static void put_r(writer *w, double v)
{
    sep(w);
    put_real(w->out, v, w->json);
    w->col++;
}

static void put_s(writer *w, const char *s)
{
    sep(w);
    if (w->json) put_text_json(w->out, s);
    else put_text_csv(w->out, s);
    w->col++;
}

static void end_row(writer *w)
{
    fputs(w->json ? "}" : "\n", w->out);
    w->row++;
}

static void end_table(writer *w)
{
    if (w->json) fputs(w->row ? "\n]\n" : "]\n", w->out);
}

/* clang-format off */
static const char *const trial_cols[] = {
    "session_id", "seq", "method", "freq_cpd", "ecc_deg", "polar_deg", "orientation_deg",
    "sigma_deg", "velocity_dps", "mean_lum_cdm2", "is_catch", "is_practice",
    "contrast_requested", "contrast_shown_mean", "contrast_shown_max", "frames_planned",
    "frames_shown", "frames_missed", "signal_interval", "response", "rt_s", "click_x_deg",
    "click_y_deg", "valid", "flags", "n_alternatives", "onset_s"};
/* clang-format on */

static const char *const reading_cols[] = {
    "session_id", "seq", "channel", "drive01", "lum_cdm2", "X_cdm2", "Y_cdm2", "Z_cdm2", "t_s", "status"};

static const char *const threshold_cols[] = {
    "session_id", "freq_cpd", "ecc_deg", "velocity_dps", "lum_cdm2", "threshold_michelson",
    "threshold_infinite", "sensitivity", "stderr_log10", "n_trials"};

static const char *const frame_cols[] = {"session_id", "trial_seq", "frame", "interval_s"};

#define NCOLS(a) ((int)(sizeof(a) / sizeof((a)[0])))

static csf_status export_trials(csf_store *s, int64_t session_id, writer *w, csf_error *err)
{
    csf_trial *t = NULL;
    size_t n = 0;
    csf_status st = csf_store_get_trials(s, session_id, &t, &n, err);
    if (st != CSF_OK) return st;
    w->names = trial_cols;
    w->ncols = NCOLS(trial_cols);
    begin_table(w);
    for (size_t i = 0; i < n; i++) {
        const csf_trial *x = &t[i];
        begin_row(w);
        put_i(w, x->session_id);
        put_i(w, x->seq);
        put_s(w, x->method);
        put_r(w, x->freq_cpd);
        put_r(w, x->ecc_deg);
        put_r(w, x->polar_deg);
        put_r(w, x->orientation_deg);
        put_r(w, x->sigma_deg);
        put_r(w, x->velocity_dps);
        put_r(w, x->mean_lum_cdm2);
        put_b(w, x->is_catch);
        put_b(w, x->is_practice);
        put_r(w, x->contrast_requested);
        put_r(w, x->contrast_shown_mean);
        put_r(w, x->contrast_shown_max);
        put_i(w, x->frames_planned);
        put_i(w, x->frames_shown);
        put_i(w, x->frames_missed);
        put_i(w, x->signal_interval);
        put_i(w, x->response);
        put_r(w, x->rt_s);
        put_r(w, x->click_x_deg);
        put_r(w, x->click_y_deg);
        put_b(w, x->valid);
        put_s(w, x->flags);
        put_i(w, x->n_alternatives);
        put_r(w, x->has_onset ? x->onset_s : NAN);
        end_row(w);
    }
    end_table(w);
    free(t);
    return CSF_OK;
}

static csf_status export_readings(csf_store *s, int64_t session_id, writer *w, csf_error *err)
{
    csf_reading *r = NULL;
    size_t n = 0;
    csf_status st = csf_store_get_readings(s, session_id, &r, &n, err);
    if (st != CSF_OK) return st;
    w->names = reading_cols;
    w->ncols = NCOLS(reading_cols);
    begin_table(w);
    for (size_t i = 0; i < n; i++) {
        const csf_reading *x = &r[i];
        begin_row(w);
        put_i(w, x->session_id);
        put_i(w, x->seq);
        put_s(w, x->channel);
        put_r(w, x->drive01);
        put_r(w, x->lum_cdm2);
        put_r(w, x->has_xyz ? x->X : NAN);
        put_r(w, x->has_xyz ? x->Y : NAN);
        put_r(w, x->has_xyz ? x->Z : NAN);
        put_r(w, x->t_s);
        put_s(w, x->status_text); /* as stored, a word this build may not know */
        end_row(w);
    }
    end_table(w);
    free(r);
    return CSF_OK;
}

/* Streamed straight from the table: a long session has many thousands of frames. */
static csf_status export_frames(csf_store *s, int64_t session_id, writer *w, csf_error *err)
{
    sqlite3_stmt *q = NULL;
    int rc = sqlite3_prepare_v2(csf_store_db(s), "SELECT trial_seq, idx, interval_s FROM "
                                "frame_intervals WHERE session_id = ? ORDER BY trial_seq, idx",
                                -1, &q, NULL);
    if (rc != SQLITE_OK)
        return csf_error_set(err, CSF_E_STORE, "export: reading frame intervals failed (%s)",
                             sqlite3_errmsg(csf_store_db(s)));
    sqlite3_bind_int64(q, 1, session_id);
    w->names = frame_cols;
    w->ncols = NCOLS(frame_cols);
    begin_table(w);
    while ((rc = sqlite3_step(q)) == SQLITE_ROW) {
        begin_row(w);
        put_i(w, session_id);
        put_i(w, sqlite3_column_int64(q, 0));
        put_i(w, sqlite3_column_int64(q, 1));
        put_r(w, sqlite3_column_type(q, 2) == SQLITE_NULL ? NAN : sqlite3_column_double(q, 2));
        end_row(w);
    }
    sqlite3_finalize(q);
    end_table(w);
    if (rc != SQLITE_DONE)
        return csf_error_set(err, CSF_E_STORE, "export: reading frame intervals failed (%s)", sqlite3_errstr(rc));
    return CSF_OK;
}

static csf_status export_thresholds(csf_store *s, int64_t session_id, writer *w, csf_error *err)
{
    csf_threshold_row *r = NULL;
    size_t n = 0;
    csf_status st = csf_store_get_thresholds(s, session_id, &r, &n, err);
    if (st != CSF_OK) return st;
    w->names = threshold_cols;
    w->ncols = NCOLS(threshold_cols);
    begin_table(w);
    for (size_t i = 0; i < n; i++) {
        const csf_threshold_row *x = &r[i];
        begin_row(w);
        put_i(w, session_id);
        put_r(w, x->freq_cpd);
        put_r(w, x->ecc_deg);
        put_r(w, x->velocity_dps);
        put_r(w, x->lum_cdm2);
        put_r(w, x->threshold);
        put_b(w, isinf(x->threshold) && x->threshold > 0);
        put_r(w, x->threshold > 0 ? 1.0 / x->threshold : NAN);
        put_r(w, x->stderr_log10);
        put_i(w, x->n_trials);
        end_row(w);
    }
    end_table(w);
    free(r);
    return CSF_OK;
}

csf_status csf_store_export(csf_store *s, int64_t session_id, csf_export_table table,
                            csf_export_format format, FILE *out, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "export: no store or output");
    csf_session_info info;
    csf_status st = csf_store_get_session(s, session_id, &info, err);
    if (st != CSF_OK) return st;
    if (table == CSF_TABLE_AUTO)
        table = info.kind == CSF_SESSION_DISPLAY ? CSF_TABLE_READINGS : CSF_TABLE_TRIALS;
    csf_session_info_free(&info);
    writer w = {out, format == CSF_EXPORT_JSON, 0, 0, NULL, 0};
    errno = 0;
    st = table == CSF_TABLE_TRIALS     ? export_trials(s, session_id, &w, err)
         : table == CSF_TABLE_READINGS ? export_readings(s, session_id, &w, err)
         : table == CSF_TABLE_FRAMES   ? export_frames(s, session_id, &w, err)
                                       : export_thresholds(s, session_id, &w, err);
    if (st != CSF_OK) return st;
    if (fflush(out) != 0 || ferror(out))
        return csf_error_set(err, CSF_E_IO, "export: write failed (%s)", strerror(errno ? errno : EIO));
    return CSF_OK;
}
