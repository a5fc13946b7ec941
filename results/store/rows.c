/* Row mapping shared by the store's backends (results/store/rows.h). */
#include "results/store/rows.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void text(const csf_store_cols *c, int col, char *dst, size_t cap)
{
    const char *t = c->txt(c, col);
    snprintf(dst, cap, "%s", t ? t : "");
}

static int int_col(const csf_store_cols *c, int col) { return (int)c->i64(c, col); }

/* The words the store holds, indexed by enum value; index 0 (UNKNOWN) has none. These are the
 * words of the schema's CHECK constraints (migrations.c, pg_schema.c): a store keeps its text,
 * so a change here is a schema change. */
static const char *const kind_names[] = {NULL, "display", "observer", "study"};
static const char *const state_names[] = {NULL, "running", "paused", "finished", "aborted"};
static const char *const status_names[] = {NULL, "ok", "too_dark", "saturated", "timeout", "error"};

#define N_OF(a) (sizeof(a) / sizeof(a)[0])

static const char *name_of(const char *const *names, size_t n, int v)
{
    return v > 0 && (size_t)v < n ? names[v] : NULL;
}

static int value_of(const char *const *names, size_t n, const char *name)
{
    for (size_t i = 1; name && i < n; i++)
        if (!strcmp(names[i], name)) return (int)i;
    return 0;
}

const char *csf_session_kind_name(csf_session_kind k)
{
    return name_of(kind_names, N_OF(kind_names), (int)k);
}

const char *csf_session_state_name(csf_session_state st)
{
    return name_of(state_names, N_OF(state_names), (int)st);
}

const char *csf_reading_status_name(csf_reading_status st)
{
    return name_of(status_names, N_OF(status_names), (int)st);
}

csf_session_kind csf_session_kind_from_name(const char *name)
{
    return (csf_session_kind)value_of(kind_names, N_OF(kind_names), name);
}

csf_session_state csf_session_state_from_name(const char *name)
{
    return (csf_session_state)value_of(state_names, N_OF(state_names), name);
}

csf_reading_status csf_reading_status_from_name(const char *name)
{
    return (csf_reading_status)value_of(status_names, N_OF(status_names), name);
}

int csf_session_state_open(csf_session_state st)
{
    return st == CSF_SESSION_RUNNING || st == CSF_SESSION_PAUSED;
}

int csf_session_state_closed(csf_session_state st)
{
    return st == CSF_SESSION_FINISHED || st == CSF_SESSION_ABORTED;
}

int csf_store_row_session(const csf_store_cols *c, csf_session_info *o)
{
    memset(o, 0, sizeof *o);
    o->id = c->i64(c, 0);
    /* The value comes from the whole stored text, the display copy may be cut. */
    o->kind = csf_session_kind_from_name(c->txt(c, 1));
    o->state = csf_session_state_from_name(c->txt(c, 2));
    text(c, 1, o->kind_text, sizeof o->kind_text);
    text(c, 2, o->state_text, sizeof o->state_text);
    text(c, 3, o->observer, sizeof o->observer);
    text(c, 4, o->display, sizeof o->display);
    /* Rows written past csfcal can hold longer names than it stores: said, never hidden. */
    const char *ob = c->txt(c, 3), *di = c->txt(c, 4);
    o->names_cut = (ob && strlen(ob) >= sizeof o->observer) || (di && strlen(di) >= sizeof o->display);
    const char *js = c->txt(c, 5);
    o->settings_json = strdup(js ? js : "{}");
    o->seed = (uint64_t)c->i64(c, 6); /* stored as the same 64 bits, signed */
    text(c, 7, o->tool_version, sizeof o->tool_version);
    text(c, 8, o->created_utc, sizeof o->created_utc);
    o->n_trials = int_col(c, 9);
    o->n_readings = int_col(c, 10);
    text(c, 11, o->profile_id, sizeof o->profile_id);
    text(c, 12, o->uuid, sizeof o->uuid);
    o->person_s = c->dbl(c, 13); /* NULL (unknown) reads NaN */
    return o->settings_json ? 0 : -1;
}

csf_status csf_store_person_time_closed(csf_error *err, const char *path, int64_t id, csf_session_state state)
{
    return csf_error_set(err, CSF_E_STORE,
                         "store %s: session %lld is %s and closed: its person "
                         "time does not change (a run adds its person time before it finishes "
                         "or aborts the session)",
                         path, (long long)id, csf_session_state_name(state));
}

void csf_store_row_trial(const csf_store_cols *c, int64_t session_id, csf_trial *t)
{
    int k = 0;
    t->session_id = session_id;
    t->seq = int_col(c, k++);
    text(c, k++, t->method, sizeof t->method);
    t->freq_cpd = c->dbl(c, k++);
    t->ecc_deg = c->dbl(c, k++);
    t->polar_deg = c->dbl(c, k++);
    t->orientation_deg = c->dbl(c, k++);
    t->sigma_deg = c->dbl(c, k++);
    t->velocity_dps = c->dbl(c, k++);
    t->mean_lum_cdm2 = c->dbl(c, k++);
    t->is_catch = int_col(c, k++);
    t->is_practice = int_col(c, k++);
    t->contrast_requested = c->dbl(c, k++);
    t->contrast_shown_mean = c->dbl(c, k++);
    t->contrast_shown_max = c->dbl(c, k++);
    t->frames_planned = int_col(c, k++);
    t->frames_shown = int_col(c, k++);
    t->frames_missed = int_col(c, k++);
    t->signal_interval = int_col(c, k++);
    t->response = int_col(c, k++);
    t->rt_s = c->dbl(c, k++);
    t->click_x_deg = c->dbl(c, k++);
    t->click_y_deg = c->dbl(c, k++);
    t->valid = int_col(c, k++);
    text(c, k++, t->flags, sizeof t->flags);
    t->n_alternatives = int_col(c, k++);
    t->has_onset = !c->is_null(c, k);
    t->onset_s = t->has_onset ? c->dbl(c, k) : 0.0;
    k++;
}

void csf_store_row_reading(const csf_store_cols *c, int64_t session_id, csf_reading *r)
{
    r->session_id = session_id;
    r->seq = int_col(c, 0);
    text(c, 1, r->channel, sizeof r->channel);
    r->drive01 = c->dbl(c, 2);
    r->lum_cdm2 = c->dbl(c, 3);
    r->has_xyz = !c->is_null(c, 4);
    r->X = c->dbl(c, 4);
    r->Y = c->dbl(c, 5);
    r->Z = c->dbl(c, 6);
    r->t_s = c->dbl(c, 7);
    r->status = csf_reading_status_from_name(c->txt(c, 8));
    text(c, 8, r->status_text, sizeof r->status_text);
}

void csf_store_row_threshold(const csf_store_cols *c, csf_threshold_row *t)
{
    t->freq_cpd = c->dbl(c, 0);
    t->ecc_deg = c->dbl(c, 1);
    t->velocity_dps = c->dbl(c, 2);
    t->lum_cdm2 = c->dbl(c, 3);
    t->threshold = c->dbl(c, 4);
    t->stderr_log10 = c->dbl(c, 5);
    t->n_trials = int_col(c, 6);
}

int csf_store_format_unix(double t, char out[32])
{
    out[0] = '\0';
    /* 1970 to the end of year 9999, the range ISO 8601's four-digit year can write. */
    if (!(t >= 0.0 && t < 253402300800.0)) return 0;
    time_t tt = (time_t)floor(t);
    struct tm tm;
    gmtime_r(&tt, &tm);
    strftime(out, 32, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return 1;
}

void csf_store_utc_now(char out[32])
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(out, 32, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

double csf_store_unix_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}
