/* Row mapping shared by the store's two backends: the columns each reader selects and how one
 * result row becomes a csf_session_info, csf_trial, csf_reading or csf_threshold_row, written
 * once against a small column accessor that each backend fills from its own result type
 * (sqlite3_column_* in results/store/sqlite.c, PQgetvalue in results/store/pg.c). The SQL
 * around the column lists (placeholders ? or $1) stays with each backend. */
#ifndef CSF_STORE_ROWS_H
#define CSF_STORE_ROWS_H

#include <stdint.h>

#include "results/store/store.h"

/* One row of a result: the backend's result and row, and how to read a column of it. */
typedef struct csf_store_cols {
    void *res;
    int row;
    int (*is_null)(const struct csf_store_cols *c, int col);
    double (*dbl)(const struct csf_store_cols *c, int col);     /* NULL -> NaN */
    int64_t (*i64)(const struct csf_store_cols *c, int col);    /* NULL -> 0 */
    const char *(*txt)(const struct csf_store_cols *c, int col); /* NULL -> NULL */
} csf_store_cols;

/* A session with its trial and reading counts; the caller adds WHERE / ORDER BY. */
#define CSF_STORE_SESSION_SELECT                                                                             \
    "SELECT s.id, s.kind, s.state, s.observer, s.display, s.settings_json, s.seed,"                          \
    " s.tool_version, s.created_utc,"                                                                        \
    " (SELECT COUNT(*) FROM trials t WHERE t.session_id = s.id),"                                            \
    " (SELECT COUNT(*) FROM readings r WHERE r.session_id = s.id), s.profile_id, s.uuid,"                    \
    " s.person_s FROM sessions s"

#define CSF_STORE_TRIAL_COLS                                                                                 \
    "seq, method, freq_cpd, ecc_deg, polar_deg, orientation_deg, sigma_deg, velocity_dps,"                   \
    " mean_lum_cdm2, is_catch, is_practice, contrast_requested, contrast_shown_mean,"                        \
    " contrast_shown_max, frames_planned, frames_shown, frames_missed, signal_interval,"                     \
    " response, rt_s, click_x_deg, click_y_deg, valid, flags, n_alternatives, onset_s"

#define CSF_STORE_READING_COLS "seq, channel, drive01, lum_cdm2, X_cdm2, Y_cdm2, Z_cdm2, t_s, status"

#define CSF_STORE_THRESHOLD_COLS                                                             \
    "freq_cpd, ecc_deg, velocity_dps, lum_cdm2, threshold_michelson, stderr_log10, n_trials"

/* Fills o (zeroed first) from a CSF_STORE_SESSION_SELECT row; -1 when out of memory (the
 * settings are copied). */
int csf_store_row_session(const csf_store_cols *c, csf_session_info *o);
void csf_store_row_trial(const csf_store_cols *c, int64_t session_id, csf_trial *t);
void csf_store_row_reading(const csf_store_cols *c, int64_t session_id, csf_reading *r);
void csf_store_row_threshold(const csf_store_cols *c, csf_threshold_row *t);

/* The refusal of a change to the person time of session id, which is state (finished or
 * aborted) and so closed; both backends give it in the same words. */
csf_status csf_store_person_time_closed(csf_error *err, const char *path, int64_t id,
                                        csf_session_state state);

/* Unix seconds to ISO 8601 UTC; 0 with "" for a value that is no time of this era (a damaged
 * row: converting an out-of-range double to time_t is undefined). */
int csf_store_format_unix(double t, char out[32]);
/* Now as the rows store it: ISO 8601 UTC (created/updated) and Unix seconds (stored_s). */
void csf_store_utc_now(char out[32]);
double csf_store_unix_now_s(void);

#endif
