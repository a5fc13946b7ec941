/* The results store's front: checks every argument at the API boundary, picks the backend from
 * the location and calls through its table (results/store/backend.h). The SQLite backend is in
 * results/store/sqlite.c, the PostgreSQL one in results/store/pg.c. */
#include "results/store/store.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include <jansson.h>
#include <libpq-fe.h>

#include "results/store/backend.h"

/* ---- names and printable text -------------------------------------------------------------- */

/* Length (1-4) of the well-formed UTF-8 sequence at p, 0 when it is not one (overlong forms,
 * surrogates and code points past U+10FFFF are not); *cp gets its code point. */
static size_t utf8_char(const unsigned char *p, uint32_t *cp)
{
    static const uint32_t min[5] = {0, 0, 0x80, 0x800, 0x10000};
    size_t n = p[0] < 0x80 ? 1 : p[0] >= 0xc2 && p[0] < 0xe0 ? 2 : p[0] >= 0xe0 && p[0] < 0xf0 ? 3
             : p[0] >= 0xf0 && p[0] < 0xf5 ? 4 : 0;
    if (n == 0) return 0;
    uint32_t c = n == 1 ? p[0] : p[0] & (0x7fu >> n);
    for (size_t i = 1; i < n; i++) {
        if ((p[i] & 0xc0) != 0x80) return 0;
        c = (c << 6) | (p[i] & 0x3fu);
    }
    if (c < min[n] || c > 0x10ffff || (c >= 0xd800 && c <= 0xdfff)) return 0;
    *cp = c;
    return n;
}

/* Characters a terminal acts on instead of showing: C0 controls, DEL, C1 controls (which some
 * terminals take as escape sequences), and the line separators and direction overrides that
 * make one row look like another. */
static int is_control(uint32_t c)
{
    return c < 0x20 || (c >= 0x7f && c <= 0x9f) || c == 0x2028 || c == 0x2029 ||
           (c >= 0x202a && c <= 0x202e) || (c >= 0x2066 && c <= 0x2069);
}

/* Byte offset of the first character of s that is not printable text, or -1; *pos its 1-based
 * position in characters and *len its length in bytes (1 for a byte that is not UTF-8). */
static long first_unprintable(const char *s, size_t *pos, size_t *len)
{
    const unsigned char *p = (const unsigned char *)s;
    for (size_t i = 0, k = 1; p[i]; k++) {
        uint32_t c = 0;
        size_t n = utf8_char(p + i, &c);
        if (n == 0 || is_control(c)) {
            *pos = k;
            *len = n ? n : 1;
            return (long)i;
        }
        i += n;
    }
    return -1;
}

csf_status csf_store_check_text(const char *s, const char *what, csf_error *err)
{
    if (!s) return CSF_OK;
    size_t pos = 0, len = 0;
    long at = first_unprintable(s, &pos, &len);
    if (at < 0) return CSF_OK;
    char hex[20] = "";
    for (size_t i = 0; i < len; i++)
        snprintf(hex + 4 * i, sizeof hex - 4 * i, "\\x%02x", (unsigned char)s[at + (long)i]);
    return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s %s at character %zu refused (only "
                         "printable text is accepted)", what,
                         len == 1 && (unsigned char)s[at] >= 0x80 ? "byte" : "control character",
                         hex, pos);
}

csf_status csf_store_check_name(const char *v, const char *what, size_t max, int required,
                                csf_error *err)
{
    if ((required && (!v || !*v)) || (v && strlen(v) > max))
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: %s must be %s%zu characters%s", what,
                             required ? "1 to " : "at most ", max,
                             v && strlen(v) > max ? " (it is not shortened)" : "");
    if (!v) return CSF_OK;
    char w[96];
    snprintf(w, sizeof w, "store: %s", what);
    return csf_store_check_text(v, w, err);
}

void csf_store_printable(const char *in, char *out, size_t cap)
{
    if (!out || cap == 0) return;
    size_t o = 0;
    const unsigned char *p = (const unsigned char *)(in ? in : "");
    out[0] = '\0';
    while (*p) {
        uint32_t c = 0;
        size_t n = utf8_char(p, &c);
        if (n && !is_control(c) && *p != '\\') {
            if (o + n >= cap) break;
            memcpy(out + o, p, n);
            o += n;
        } else {
            n = 1;
            char q[8];
            csf_quote_bytes((const char *)p, 1, q, sizeof q);
            size_t ql = strlen(q);
            if (o + ql >= cap) break;
            memcpy(out + o, q, ql);
            o += ql;
        }
        p += n;
        out[o] = '\0';
    }
}

/* ---- locations ------------------------------------------------------------------------------ */

int csf_store_is_server(const char *location)
{
    if (!location) return 0;
    return !strncmp(location, "postgresql://", 13) || !strncmp(location, "postgres://", 11) ||
           !strncmp(location, "service=", 8);
}

/* libpq marks the options whose values it hides (password, sslpassword) with '*'. */
static int is_secret(const PQconninfoOption *o) { return o->dispchar && strchr(o->dispchar, '*'); }

/* The options libpq reads from a location, after its own percent-decoding of a URI; NULL when
 * libpq cannot read it. Free with PQconninfoFree. */
static PQconninfoOption *parse_location(const char *location)
{
    char *msg = NULL;
    PQconninfoOption *opts = PQconninfoParse(location, &msg);
    PQfreemem(msg); /* may quote the string, secret included: never shown */
    return opts;
}

static const PQconninfoOption *secret_option(const PQconninfoOption *opts)
{
    for (const PQconninfoOption *o = opts; o && o->keyword; o++)
        if (o->val && is_secret(o)) return o;
    return NULL;
}

/* Appends n bytes of src to out at *o, clipped to cap (out stays terminated). */
static void put(char *out, size_t cap, size_t *o, const char *src, size_t n)
{
    while (n-- > 0 && *o + 1 < cap) out[(*o)++] = *src++;
    out[*o] = '\0';
}

/* key=value form of the options libpq read, secrets left out, each value quoted as libpq reads
 * it back. */
static void rebuild_conninfo(const PQconninfoOption *opts, char *out, size_t cap)
{
    size_t o = 0;
    out[0] = '\0';
    for (const PQconninfoOption *op = opts; op->keyword; op++) {
        if (!op->val || is_secret(op)) continue;
        int quote = !*op->val || strpbrk(op->val, " \t\n\r\f\v'\\") != NULL;
        if (o) put(out, cap, &o, " ", 1);
        put(out, cap, &o, op->keyword, strlen(op->keyword));
        put(out, cap, &o, quote ? "='" : "=", quote ? 2 : 1);
        for (const char *v = op->val; *v; v++) {
            if (quote && (*v == '\'' || *v == '\\')) put(out, cap, &o, "\\", 1);
            put(out, cap, &o, v, 1);
        }
        if (quote) put(out, cap, &o, "'", 1);
    }
}

#define UNREADABLE_LOCATION "(a connection string libpq cannot read; not shown)"

static int shown_has_secret(const char *shown);

void csf_store_redact(const char *location, char *out, size_t cap)
{
    if (!out || cap == 0) return;
    out[0] = '\0';
    if (!location) return;
    if (!csf_store_is_server(location)) {
        csf_store_printable(location, out, cap);
        return;
    }
    PQconninfoOption *opts = parse_location(location);
    if (!opts) {
        snprintf(out, cap, "%s", UNREADABLE_LOCATION);
        return;
    }
    if (secret_option(opts)) {
        char *plain = malloc(cap);
        if (plain) rebuild_conninfo(opts, plain, cap);
        csf_store_printable(plain ? plain : "", out, cap);
        free(plain);
    } else {
        csf_store_printable(location, out, cap);
    }
    PQconninfoFree(opts);
    /* Escaping can change how libpq would read the shown text ("a\ password=x", a backslash
     * escaping the blank, is shown with the backslash as \x5c, which no longer escapes it): a
     * shown form that would read as holding a secret is not shown at all. */
    if (shown_has_secret(out)) snprintf(out, cap, "%s", UNREADABLE_LOCATION);
}

/* 1 when libpq reads a secret from text (whatever csfcal takes it for). */
static int libpq_secret(const char *text)
{
    PQconninfoOption *opts = parse_location(text);
    int has = secret_option(opts) != NULL;
    PQconninfoFree(opts);
    return has;
}

static int shown_has_secret(const char *shown)
{
    return csf_store_is_server(shown) && libpq_secret(shown);
}

int csf_store_has_password(const char *location)
{
    return csf_store_is_server(location) && libpq_secret(location);
}

/* A server location libpq reads, with no secret in it and no control character in any value
 * it decodes. */
static csf_status check_server_location(const char *location, const char *where, csf_error *err)
{
    PQconninfoOption *opts = parse_location(location);
    if (!opts)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: libpq cannot read this PostgreSQL "
                             "connection string (not repeated here: it may hold a secret); the "
                             "forms are postgresql://[user@]host[:port]/dbname[?key=value&...] "
                             "and service=NAME [key=value ...] (docs/store.md)", where);
    csf_status cs = CSF_OK;
    const PQconninfoOption *sec = secret_option(opts);
    if (sec) {
        char red[1024];
        csf_store_redact(location, red, sizeof red);
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "%s: a password in the store location is "
                           "refused (libpq reads it as %s; the rest is %s); put it in ~/.pgpass "
                           "(or the file PGPASSFILE names) or a service file (PGSERVICEFILE), "
                           "see docs/store.md", where, sec->keyword, red);
    }
    for (const PQconninfoOption *o = opts; cs == CSF_OK && o->keyword; o++) {
        char what[160];
        snprintf(what, sizeof what, "%s: option %s of the store location", where, o->keyword);
        if (o->val) cs = csf_store_check_text(o->val, what, err);
    }
    PQconninfoFree(opts);
    return cs;
}

csf_status csf_store_check_location(const char *location, const char *where, csf_error *err)
{
    if (!location || !*location)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: empty store location", where);
    if (strlen(location) >= 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: store location longer than 1023 "
                             "characters", where);
    char what[160];
    snprintf(what, sizeof what, "%s: store location", where);
    csf_status cs = csf_store_check_text(location, what, err);
    if (cs == CSF_OK && csf_store_is_server(location))
        cs = check_server_location(location, where, err);
    else if (cs == CSF_OK && strchr(location, '=') && libpq_secret(location))
        /* "host=db password=x" is a file name to csfcal, but meant as a connection string: its
         * password would be shown in every message naming the file. */
        cs = csf_error_set(err, CSF_E_INVALID_ARG, "%s: a password in the store location is "
                           "refused (a server is named postgresql://... or service=NAME; the "
                           "password goes in ~/.pgpass), see docs/store.md", where);
    return cs;
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
    /* A password in the location would end up in shell history, process lists and any
     * message that names the store: libpq reads it from its own files instead. */
    csf_status cs = csf_store_check_location(path, "store", err);
    if (cs != CSF_OK) return cs;
    if (csf_store_is_server(path)) cs = csf_store_pg_open(path, readonly, out, err);
    else cs = csf_store_sqlite_open(path, readonly, out, err);
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
    if (t->has_onset && !(isfinite(t->onset_s) && t->onset_s >= 0))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: trial %d has onset %g s (a time on the "
                             "session's clock: finite, 0 or later)",
                             t->seq, t->onset_s);
    if (s->readonly) return read_only(s, "a trial", err);
    return CSF_OK;
}

/* Settings and designs are read back as JSON by reports and by the analyst's SQL: text that is
 * not a JSON object or array (one built by hand around a name with a quote or a control
 * character in it) is refused rather than stored. NULL stands for "{}". */
static csf_status check_json(const char *text, const char *what, csf_error *err)
{
    if (!text) return CSF_OK;
    json_error_t je;
    /* Numbers as reals: a 64-bit seed past INT64_MAX is valid JSON that jansson's integers
     * cannot hold. */
    json_t *doc = json_loads(text, JSON_DECODE_INT_AS_REAL, &je);
    if (doc) {
        json_decref(doc);
        return CSF_OK;
    }
    return csf_error_set(err, CSF_E_INVALID_ARG, "store: %s are not valid JSON (%s at character "
                         "%d)", what, je.text, je.position);
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

csf_status csf_store_begin_session(csf_store *s, csf_session_kind kind, const char *observer,
                                   const char *display, const char *settings_json, uint64_t seed, int64_t *id,
                                   csf_error *err)
{
    return csf_store_begin_session_profile(s, kind, observer, display, NULL, settings_json, seed,
                                           id, err);
}

csf_status csf_store_begin_session_profile(csf_store *s, csf_session_kind kind, const char *observer,
                                           const char *display, const char *profile_id,
                                           const char *settings_json, uint64_t seed, int64_t *id,
                                           csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!csf_session_kind_name(kind))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: session kind %d unknown (allowed display, observer, study)", (int)kind);
    csf_status cs = csf_store_check_name(observer, "observer name", 255, 0, err);
    if (cs == CSF_OK) cs = csf_store_check_name(display, "display name", 255, 0, err);
    if (cs == CSF_OK) cs = csf_store_check_name(profile_id, "profile id", 127, 0, err);
    if (cs == CSF_OK) cs = check_json(settings_json, "session settings", err);
    if (cs != CSF_OK) return cs;
    if (s->readonly) return read_only(s, "a session", err);
    if (profile_id && !*profile_id) profile_id = NULL;
    char uuid[40];
    if (csf_store_new_uuid(uuid) < 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: no random bytes for the session's uuid",
                             s->path);
    csf_store_session_new nw = {.kind = kind,
                                .observer = observer,
                                .display = display,
                                .profile_id = profile_id,
                                .settings_json = settings_json,
                                .seed = seed,
                                .uuid = uuid,
                                .state = CSF_SESSION_RUNNING};
    return s->ops->begin_session(s, &nw, id, err);
}

csf_status csf_store_get_session(csf_store *s, int64_t id, csf_session_info *out, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out) return not_open(err);
    memset(out, 0, sizeof *out);
    return s->ops->get_session(s, id, out, err);
}

csf_status csf_store_set_session_state(csf_store *s, int64_t id, csf_session_state state, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!csf_session_state_name(state))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: session state %d unknown (allowed "
                             "running, paused, finished, aborted)",
                             (int)state);
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

csf_status csf_store_add_person_time(csf_store *s, int64_t session_id, double seconds, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    if (!isfinite(seconds))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: person time of session %lld is %g, "
                             "not a number of seconds (a run adds 0 to %g s)",
                             (long long)session_id, seconds, CSF_STORE_PERSON_S_MAX);
    if (seconds < 0.0 || seconds > CSF_STORE_PERSON_S_MAX)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "store: person time %g s for session %lld "
                             "is %s (a run adds 0 to %g s, 11.6 days)",
                             seconds, (long long)session_id, seconds < 0.0 ? "negative" : "past the limit",
                             CSF_STORE_PERSON_S_MAX);
    if (s->readonly) return read_only(s, "person time", err);
    return s->ops->add_person_time(s, session_id, seconds, err);
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

void csf_store_artifacts_free(csf_store_artifact *list, size_t n)
{
    for (size_t i = 0; list && i < n; i++) free(list[i].blob);
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
    if (!csf_reading_status_name(r->status))
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
    csf_status cs = csf_store_check_name(kind, "artifact kind", 15, 1, err);
    if (cs != CSF_OK) return cs;
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
    if (!s) return not_open(err);
    csf_status cs = csf_store_check_name(name, "display name", 255, 1, err);
    if (cs == CSF_OK) cs = csf_store_check_name(profile_id, "profile id", 127, 0, err);
    if (cs != CSF_OK) return cs;
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
    if (!s) return not_open(err);
    csf_status cs = csf_store_check_name(name, "observer name", 255, 1, err);
    if (cs != CSF_OK) return cs;
    if (s->readonly) return read_only(s, "an observer", err);
    return s->ops->upsert_observer(s, name, id, err);
}

csf_status csf_store_create_study(csf_store *s, const char *name, const char *design_json,
                                  int64_t *id, csf_error *err)
{
    csf_error_clear(err);
    if (!s) return not_open(err);
    csf_status cs = csf_store_check_name(name, "study name", 255, 1, err);
    if (cs == CSF_OK) cs = check_json(design_json, "study design", err);
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
    csf_status cs = csf_store_check_name(code, "participant code", 63, 1, err);
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
