/* The results store's front: checks every argument at the API boundary, picks the backend from
 * the location and calls through its table (results/store_backend.h). The SQLite backend is in
 * results/store_sqlite.c, the PostgreSQL one in results/store_pg.c. */
#include "results/store.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include "results/store_backend.h"

/* ---- locations ------------------------------------------------------------------------------ */

int csf_store_is_server(const char *location)
{
    if (!location) return 0;
    return !strncmp(location, "postgresql://", 13) || !strncmp(location, "postgres://", 11) ||
           !strncmp(location, "service=", 8);
}

/* Copies n bytes of src (n may exceed what is left: clipped) into out at *o. */
static void put(char *out, size_t cap, size_t *o, const char *src, size_t n)
{
    while (n-- > 0 && *o + 1 < cap) out[(*o)++] = *src++;
    out[*o] = '\0';
}

/* postgresql://user:secret@host/db -> postgresql://user@host/db (the userinfo is the part of
 * the authority before the last '@'; the authority ends at the first '/', '?' or '#'). */
static void redact_uri(const char *in, char *out, size_t cap)
{
    const char *auth = strstr(in, "://") + 3;
    size_t alen = strcspn(auth, "/?#");
    const char *at = NULL;
    for (const char *p = auth; p < auth + alen; p++)
        if (*p == '@') at = p;
    const char *colon = at ? memchr(auth, ':', (size_t)(at - auth)) : NULL;
    size_t o = 0;
    out[0] = '\0';
    put(out, cap, &o, in, colon ? (size_t)(colon - in) : (size_t)(auth + alen - in));
    if (colon) put(out, cap, &o, at, (size_t)(auth + alen - at));
    /* The path, then the query without its password parameter, then any fragment. */
    const char *rest = auth + alen;
    size_t plen = strcspn(rest, "?#");
    put(out, cap, &o, rest, plen);
    rest += plen;
    int first = 1;
    while (*rest == '?' || *rest == '&') {
        size_t seg = strcspn(rest + 1, "&#");
        if (strncmp(rest + 1, "password=", 9) != 0) {
            put(out, cap, &o, first ? "?" : "&", 1);
            put(out, cap, &o, rest + 1, seg);
            first = 0;
        }
        rest += seg + 1;
    }
    put(out, cap, &o, rest, strlen(rest));
}

/* Where a key = value pair of a libpq connection string ends, read as libpq reads it: spaces
 * may surround '='; a value is quoted only when it starts with a quote (a quote inside a bare
 * value is an ordinary character); a backslash escapes the next character. Sets *is_password
 * when the key is "password" (a "password" without '=' takes the next word as its value, so a
 * malformed string still loses the secret). */
static const char *conninfo_pair_end(const char *p, int *is_password)
{
    const char *key = p;
    while (*p && *p != '=' && !isspace((unsigned char)*p)) p++;
    *is_password = (size_t)(p - key) == 8 && !strncmp(key, "password", 8);
    const char *after_key = p;
    while (isspace((unsigned char)*p)) p++;
    if (*p == '=') {
        p++;
        while (isspace((unsigned char)*p)) p++;
    } else if (!*is_password) {
        return after_key; /* a lone word: libpq refuses it; nothing of a value to take along */
    }
    if (*p == '\'') {
        for (p++; *p && *p != '\''; p++)
            if (*p == '\\' && p[1]) p++;
        if (*p) p++;
    } else {
        for (; *p && !isspace((unsigned char)*p); p++)
            if (*p == '\\' && p[1]) p++;
    }
    return p;
}

/* service=lab password=x host=h -> service=lab host=h. Everything but the password pairs (and
 * the blanks before them) is copied unchanged, so a string without a password comes out equal. */
static void redact_conninfo(const char *in, char *out, size_t cap)
{
    size_t o = 0;
    out[0] = '\0';
    const char *p = in;
    while (*p) {
        const char *blank = p;
        while (isspace((unsigned char)*p)) p++;
        if (!*p) {
            put(out, cap, &o, blank, (size_t)(p - blank));
            break;
        }
        int is_password = 0;
        const char *end = conninfo_pair_end(p, &is_password);
        if (end == p) end = p + 1; /* a stray '=': one character at a time */
        if (!is_password) put(out, cap, &o, blank, (size_t)(end - blank));
        /* libpq needs no blank after a quoted value: keep the next pair apart from the previous. */
        else if (*end && !isspace((unsigned char)*end) && o > 0) put(out, cap, &o, " ", 1);
        p = end;
    }
}

void csf_store_redact(const char *location, char *out, size_t cap)
{
    if (!out || cap == 0) return;
    out[0] = '\0';
    if (!location) return;
    if (strstr(location, "://") && csf_store_is_server(location)) redact_uri(location, out, cap);
    else if (csf_store_is_server(location)) redact_conninfo(location, out, cap);
    else snprintf(out, cap, "%s", location);
}

int csf_store_has_password(const char *location)
{
    char red[2048];
    if (!location || strlen(location) >= sizeof red) return 0;
    csf_store_redact(location, red, sizeof red);
    return strcmp(red, location) != 0;
}

/* ---- open and close ----------------------------------------------------------------------- */

static csf_status open_any(const char *path, int readonly, csf_store **out, csf_error *err)
{
    csf_error_clear(err);
    if (!out) return csf_error_set(err, CSF_E_INVALID_ARG, "store: no output pointer");
    *out = NULL;
    if (!path || !*path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: empty path (give --store PATH)");
    if (strlen(path) >= 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: path longer than 1023 characters");
    csf_status cs;
    if (csf_store_is_server(path)) {
        /* A password in the location would end up in shell history, process lists and any
         * message that names the store: libpq reads it from its own files instead. */
        if (csf_store_has_password(path)) {
            char red[1024];
            csf_store_redact(path, red, sizeof red);
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "store %s: a password in the store location is refused; put it "
                                 "in ~/.pgpass (or the file PGPASSFILE names) or a service file "
                                 "(PGSERVICEFILE), see docs/store.md", red);
        }
        cs = csf_store_pg_open(path, readonly, out, err);
    } else {
        cs = csf_store_sqlite_open(path, readonly, out, err);
    }
    if (cs == CSF_OK) (*out)->readonly = readonly;
    return cs;
}

csf_status csf_store_open(const char *path, csf_store **out, csf_error *err)
{
    return open_any(path, 0, out, err);
}

csf_status csf_store_open_readonly(const char *path, csf_store **out, csf_error *err)
{
    return open_any(path, 1, out, err);
}

void csf_store_close(csf_store *s)
{
    if (s) s->ops->close(s);
}

const char *csf_store_path(const csf_store *s) { return s ? s->path : ""; }

const char *csf_store_backend(const csf_store *s) { return s ? s->ops->name : ""; }

int csf_store_schema_version(csf_store *s) { return s ? s->ops->schema_version(s) : -1; }

/* ---- argument checks ---------------------------------------------------------------------- */

static csf_status not_open(csf_error *err)
{
    return csf_error_set(err, CSF_E_INVALID_ARG, "store: not open");
}

static csf_status read_only(const csf_store *s, const char *what, csf_error *err)
{
    return csf_error_set(err, CSF_E_STORE, "store %s: opened read-only, cannot store %s", s->path,
                         what);
}

static int one_of(const char *v, const char *const *ok, size_t n)
{
    for (size_t i = 0; v && i < n; i++)
        if (!strcmp(v, ok[i])) return 1;
    return 0;
}

#define ONE_OF(v, ...)                                                                       \
    one_of(v, (const char *const[]){__VA_ARGS__},                                            \
           sizeof((const char *const[]){__VA_ARGS__}) / sizeof(const char *))

/* Fixed-size text fields in the structs must be NUL-terminated within their size. */
static int terminated(const char *f, size_t cap) { return memchr(f, '\0', cap) != NULL; }

static csf_status check_trial(const csf_store *s, const csf_trial *t, csf_error *err)
{
    if (!s || !t) return not_open(err);
    if (t->seq < 0) return csf_error_set(err, CSF_E_INVALID_ARG, "store: trial seq %d < 0", t->seq);
    if (!terminated(t->method, sizeof t->method) || !terminated(t->flags, sizeof t->flags))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: trial method or flags not terminated");
    if (!isfinite(t->freq_cpd) || !isfinite(t->ecc_deg) || !isfinite(t->contrast_requested))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: trial %d has a non-finite frequency, "
                             "eccentricity or contrast", t->seq);
    if (t->n_alternatives != 0 && (t->n_alternatives < 2 || t->n_alternatives > 16))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: trial %d has %d alternatives (0 = not "
                             "forced choice, else 2-16)", t->seq, t->n_alternatives);
    if (s->readonly) return read_only(s, "a trial", err);
    return CSF_OK;
}

static csf_status check_name(const char *v, const char *what, size_t max, int required,
                             csf_error *err)
{
    if ((required && (!v || !*v)) || (v && strlen(v) > max))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: %s must be %s%zu characters", what,
                             required ? "1 to " : "at most ", max);
    return CSF_OK;
}

/* ---- sessions ------------------------------------------------------------------------------ */

int csf_store_new_uuid(char out[40])
{
    unsigned char b[16];
    size_t got = 0;
    while (got < sizeof b) {
        ssize_t n = getrandom(b + got, sizeof b - got, 0);
        if (n <= 0) return -1;
        got += (size_t)n;
    }
    b[6] = (unsigned char)((b[6] & 0x0f) | 0x40); /* version 4: random */
    b[8] = (unsigned char)((b[8] & 0x3f) | 0x80); /* RFC 4122 variant */
    snprintf(out, 40, "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x",
             b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12],
             b[13], b[14], b[15]);
    return 0;
}

csf_status csf_store_begin_session(csf_store *s, const char *kind, const char *observer,
                                   const char *display, const char *settings_json, uint64_t seed,
                                   int64_t *id, csf_error *err)
{
    return csf_store_begin_session_profile(s, kind, observer, display, NULL, settings_json, seed,
                                           id, err);
}

csf_status csf_store_begin_session_profile(csf_store *s, const char *kind, const char *observer,
                                           const char *display, const char *profile_id,
                                           const char *settings_json, uint64_t seed, int64_t *id,
                                           csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!ONE_OF(kind, "display", "observer", "study"))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: session kind '%s' unknown (allowed display, observer, study)",
                             kind ? kind : "(null)");
    /* Stored in full; csf_session_info shows the first 63 characters. */
    if (observer && strlen(observer) > 255)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: observer name longer than 255 characters");
    if (display && strlen(display) > 255)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: display name longer than 255 characters");
    if (profile_id && strlen(profile_id) > 127)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: profile id longer than 127 characters");
    if (s->readonly) return read_only(s, "a session", err);
    if (profile_id && !*profile_id) profile_id = NULL;
    char uuid[40];
    if (csf_store_new_uuid(uuid) < 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: no random bytes for the session's uuid",
                             s->path);
    csf_store_session_new nw = {.kind = kind, .observer = observer, .display = display,
                                .profile_id = profile_id, .settings_json = settings_json,
                                .seed = seed, .uuid = uuid};
    return s->ops->begin_session(s, &nw, id, err);
}

csf_status csf_store_get_session(csf_store *s, int64_t id, csf_session_info *out, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out) return not_open(err);
    memset(out, 0, sizeof *out);
    return s->ops->get_session(s, id, out, err);
}

csf_status csf_store_set_session_state(csf_store *s, int64_t id, const char *state, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!ONE_OF(state, "running", "paused", "finished", "aborted"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: session state '%s' unknown (allowed "
                             "running, paused, finished, aborted)", state ? state : "(null)");
    if (s->readonly) return read_only(s, "a session state", err);
    return s->ops->set_session_state(s, id, state, err);
}

csf_status csf_store_list_sessions(csf_store *s, csf_session_info **out, size_t *n, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return not_open(err);
    *out = NULL;
    *n = 0;
    return s->ops->list_sessions(s, out, n, err);
}

void csf_session_info_free(csf_session_info *s)
{
    if (!s) return;
    free(s->settings_json);
    s->settings_json = NULL;
}

void csf_session_list_free(csf_session_info *list, size_t n)
{
    if (!list) return;
    for (size_t i = 0; i < n; i++) csf_session_info_free(&list[i]);
    free(list);
}

csf_status csf_store_session_times(csf_store *s, int64_t id, char created_utc[32],
                                   char updated_utc[32], csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    return s->ops->session_times(s, id, created_utc, updated_utc, err);
}

/* ---- readings, trials, frames, thresholds ------------------------------------------------ */

csf_status csf_store_add_reading(csf_store *s, const csf_reading *r, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !r) return not_open(err);
    if (!terminated(r->channel, sizeof r->channel) ||
        !ONE_OF(r->channel, "dark", "white", "grey", "r", "g", "b"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: reading channel must be dark, white, "
                             "grey, r, g or b");
    if (!terminated(r->status, sizeof r->status) ||
        !ONE_OF(r->status, "ok", "too_dark", "saturated", "timeout", "error"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: reading status must be ok, too_dark, "
                             "saturated, timeout or error");
    if (r->seq < 0) return csf_error_set(err, CSF_E_INVALID_ARG, "store: reading seq %d < 0", r->seq);
    if (!(r->drive01 >= 0.0 && r->drive01 <= 1.0))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: reading drive01 %g outside [0, 1]", r->drive01);
    if (s->readonly) return read_only(s, "a reading", err);
    return s->ops->add_reading(s, r, err);
}

csf_status csf_store_get_readings(csf_store *s, int64_t session_id, csf_reading **out, size_t *n,
                                  csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return not_open(err);
    *out = NULL;
    *n = 0;
    return s->ops->get_readings(s, session_id, out, n, err);
}

csf_status csf_store_add_trial(csf_store *s, const csf_trial *t, csf_error *err)
{
    csf_error_clear(err);
    csf_status cs = check_trial(s, t, err);
    return cs != CSF_OK ? cs : s->ops->add_trial_frames(s, t, NULL, 0, err);
}

csf_status csf_store_add_trial_frames(csf_store *s, const csf_trial *t, const double *interval_s,
                                      int n, csf_error *err)
{
    csf_error_clear(err);
    csf_status cs = check_trial(s, t, err);
    if (cs != CSF_OK) return cs;
    if (n < 0 || (n > 0 && !interval_s))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: frame interval count %d invalid", n);
    return s->ops->add_trial_frames(s, t, interval_s, n, err);
}

csf_status csf_store_get_trials(csf_store *s, int64_t session_id, csf_trial **out, size_t *n,
                                csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return not_open(err);
    *out = NULL;
    *n = 0;
    return s->ops->get_trials(s, session_id, out, n, err);
}

csf_status csf_store_add_frame_intervals(csf_store *s, int64_t session_id, int trial_seq,
                                         const double *interval_s, int n, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (n < 0 || (n > 0 && !interval_s))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: frame interval count %d invalid", n);
    if (n == 0) return CSF_OK;
    if (s->readonly) return read_only(s, "frame intervals", err);
    return s->ops->add_frame_intervals(s, session_id, trial_seq, interval_s, n, err);
}

csf_status csf_store_get_frame_intervals(csf_store *s, int64_t session_id, double **out, size_t *n,
                                         csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return not_open(err);
    *out = NULL;
    *n = 0;
    return s->ops->get_frame_intervals(s, session_id, out, n, err);
}

csf_status csf_store_put_thresholds(csf_store *s, int64_t session_id, const csf_threshold_row *rows,
                                    size_t n, csf_error *err)
{
    csf_error_clear(err);
    if (!s || (n > 0 && !rows)) return not_open(err);
    if (s->readonly) return read_only(s, "thresholds", err);
    return s->ops->put_thresholds(s, session_id, rows, n, err);
}

csf_status csf_store_get_thresholds(csf_store *s, int64_t session_id, csf_threshold_row **out,
                                    size_t *n, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out || !n) return not_open(err);
    *out = NULL;
    *n = 0;
    return s->ops->get_thresholds(s, session_id, out, n, err);
}

/* ---- artifacts ----------------------------------------------------------------------------- */

csf_status csf_store_add_artifact(csf_store *s, int64_t session_id, const char *kind,
                                  const char *path, const void *blob, size_t len, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!kind || !*kind || strlen(kind) > 15)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: artifact kind must be 1 to 15 characters");
    if (len > 0 && !blob)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: artifact of %zu bytes without content", len);
    if (len > 512u * 1024 * 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: artifact of %zu bytes (limit 512 MiB)", len);
    if (s->readonly) return read_only(s, "an artifact", err);
    return s->ops->add_artifact(s, session_id, kind, path, blob, len, err);
}

csf_status csf_store_get_artifact(csf_store *s, int64_t session_id, const char *kind,
                                  void **blob, size_t *len, char *path_out, size_t path_len,
                                  csf_error *err)
{
    csf_error_clear(err);
    if (!s || !kind || !blob || !len) return not_open(err);
    *blob = NULL;
    *len = 0;
    return s->ops->get_artifact(s, session_id, kind, blob, len, path_out, path_len, err);
}

/* ---- displays, observers, studies, participants ------------------------------------------ */

csf_status csf_store_upsert_display(csf_store *s, const char *name, const char *profile_id,
                                    int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !name || !*name || strlen(name) > 255)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: display name must be 1 to 255 characters");
    if (profile_id && strlen(profile_id) > 127)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: profile id longer than 127 characters");
    if (s->readonly) return read_only(s, "a display", err);
    return s->ops->upsert_display(s, name, profile_id, id, err);
}

csf_status csf_store_display_profile_id(csf_store *s, const char *display, char *out, size_t cap,
                                        csf_error *err)
{
    csf_error_clear(err);
    if (!s || !display || !out || cap == 0) return not_open(err);
    out[0] = '\0';
    return s->ops->display_profile_id(s, display, out, cap, err);
}

csf_status csf_store_upsert_observer(csf_store *s, const char *name, int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !name || !*name || strlen(name) > 255)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: observer name must be 1 to 255 characters");
    if (s->readonly) return read_only(s, "an observer", err);
    return s->ops->upsert_observer(s, name, id, err);
}

csf_status csf_store_create_study(csf_store *s, const char *name, const char *design_json,
                                  int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    csf_status cs = check_name(name, "study name", 255, 1, err);
    if (cs != CSF_OK) return cs;
    if (s->readonly) return read_only(s, "a study", err);
    return s->ops->create_study(s, name, design_json, id, err);
}

csf_status csf_store_find_study(csf_store *s, const char *name, int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !name) return not_open(err);
    return s->ops->find_study(s, name, id, err);
}

csf_status csf_store_add_participant(csf_store *s, int64_t study_id, const char *code,
                                     int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    csf_status cs = check_name(code, "participant code", 63, 1, err);
    if (cs != CSF_OK) return cs;
    if (s->readonly) return read_only(s, "a participant", err);
    return s->ops->add_participant(s, study_id, code, id, err);
}

csf_status csf_store_count_participants(csf_store *s, int64_t study_id, int *n, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !n) return not_open(err);
    return s->ops->count_participants(s, study_id, n, err);
}

csf_status csf_store_link_session_participant(csf_store *s, int64_t session_id,
                                              int64_t participant_id, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (s->readonly) return read_only(s, "a participant link", err);
    return s->ops->link_session_participant(s, session_id, participant_id, err);
}
