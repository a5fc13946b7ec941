/* A study's sessions in the store (see study_sessions.h). */
#include "studies/study_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

void csf_study_store_name(const char *study, int version, char *out, size_t cap)
{
    if (version <= 1) snprintf(out, cap, "%s", study);
    else snprintf(out, cap, "%s #%d", study, version);
}

void csf_study_sessions_free(csf_study_session *list, int n)
{
    for (int i = 0; list && i < n; i++) csf_study_identity_free(&list[i].identity);
    free(list);
}

/* A metadata text of a session's settings (outside input): kept when it fits and is printable
 * text, else left empty. */
static void read_meta(const json_t *j, const char *key, char out[CSF_STUDY_META_MAX])
{
    const char *v = json_string_value(json_object_get(j, key));
    csf_error e;
    out[0] = '\0';
    if (v && strlen(v) < CSF_STUDY_META_MAX && csf_store_check_text(v, key, &e) == CSF_OK)
        snprintf(out, CSF_STUDY_META_MAX, "%s", v);
}

/* One session's study fields from its settings JSON; 0 when it is not a session of study. */
static int read_session(const csf_session_info *info, const char *study, csf_study_session *o)
{
    json_error_t je;
    json_t *j = info->settings_json ? json_loads(info->settings_json, 0, &je) : NULL;
    const char *name = json_string_value(json_object_get(j, "study"));
    const char *part = json_string_value(json_object_get(j, "participant"));
    int ok = name && part && !strcmp(name, study) && strlen(part) < sizeof o->participant;
    if (ok) {
        memset(o, 0, sizeof *o);
        o->id = info->id;
        snprintf(o->participant, sizeof o->participant, "%s", part);
        o->state = info->state;
        snprintf(o->state_text, sizeof o->state_text, "%s", info->state_text);
        json_int_t v = json_integer_value(json_object_get(j, "version"));
        o->version = v >= 1 && v <= 1000000 ? (int)v : 1;
        o->n_trials = info->n_trials;
        json_int_t pi = json_integer_value(json_object_get(j, "participant_index"));
        o->participant_index = pi >= 0 && pi <= 1000000 ? (int)pi : 0;
        read_meta(j, "experimenter", o->experimenter);
        read_meta(j, "notes", o->notes);
        csf_error e;
        if (csf_study_identity_from_json(json_object_get(j, "identity"), &o->identity, &e) == CSF_OK) {
            memcpy(o->key, o->identity.sha256, sizeof o->key);
        } else {
            const char *h = json_string_value(json_object_get(j, "hash"));
            o->legacy = 1;
            snprintf(o->key, sizeof o->key, "%.16s", h ? h : "?");
            /* a session that names no files at all (the phantom an interrupted older csfcal could
             * leave before it stored any) belongs to no version and holds nothing to analyse */
            if (!h) ok = 0;
        }
    }
    json_decref(j);
    return ok;
}

csf_status csf_study_sessions_list(csf_store *store, const char *study, csf_study_session **out, int *n,
                                   csf_error *err)
{
    *out = NULL;
    *n = 0;
    csf_session_info *list = NULL;
    size_t nl = 0;
    csf_status st = csf_store_list_sessions(store, &list, &nl, err);
    if (st != CSF_OK) return st;
    csf_study_session *o = calloc(nl + 1, sizeof *o);
    if (!o) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (size_t i = 0; o && i < nl; i++) {
        if (list[i].kind != CSF_SESSION_STUDY) continue;
        /* the list carries no settings: read each study session */
        csf_session_info info;
        memset(&info, 0, sizeof info);
        csf_error e;
        if (csf_store_get_session(store, list[i].id, &info, &e) != CSF_OK) continue;
        info.n_trials = list[i].n_trials;
        if (read_session(&info, study, &o[*n])) (*n)++;
        csf_session_info_free(&info);
    }
    csf_session_list_free(list, nl);
    *out = o;
    return st;
}

int csf_study_versions_max(const csf_study_session *list, int n)
{
    int m = 0;
    for (int i = 0; i < n; i++)
        if (list[i].version > m) m = list[i].version;
    return m;
}

/* Visits each (version, identity) once, in the order first met, with its session counts. */
typedef void (*version_fn)(void *ctx, const csf_study_session *first, int n_sessions, int n_finished);

static int each_version(const csf_study_session *list, int n, const char *skip_key, version_fn fn, void *ctx)
{
    int count = 0;
    for (int i = 0; i < n; i++) {
        int seen = 0, ns = 0, nf = 0;
        for (int j = 0; j < i && !seen; j++)
            seen = list[j].version == list[i].version && !strcmp(list[j].key, list[i].key);
        if (seen || (skip_key && !strcmp(list[i].key, skip_key))) continue;
        for (int j = i; j < n; j++)
            if (list[j].version == list[i].version && !strcmp(list[j].key, list[i].key)) {
                ns++;
                nf += list[j].state == CSF_SESSION_FINISHED;
            }
        fn(ctx, &list[i], ns, nf);
        count++;
    }
    return count;
}

static void version_line(const csf_study_session *f, int ns, int nf, char *out, size_t cap)
{
    snprintf(out, cap, "version %d (%s %.12s...): %d session%s, %d finished", f->version,
             f->legacy ? "files hash" : "sha256", f->key, ns, ns == 1 ? "" : "s", nf);
}

typedef struct {
    FILE *fp;
    const char *indent;
    char *out;
    size_t cap;
} version_sink;

static void print_one(void *ctx, const csf_study_session *f, int ns, int nf)
{
    version_sink *k = ctx;
    char line[200];
    version_line(f, ns, nf, line, sizeof line);
    fprintf(k->fp, "%s%s\n", k->indent, line);
}

static void text_one(void *ctx, const csf_study_session *f, int ns, int nf)
{
    version_sink *k = ctx;
    char line[200];
    version_line(f, ns, nf, line, sizeof line);
    size_t used = strlen(k->out);
    if (used + 1 < k->cap) snprintf(k->out + used, k->cap - used, "%s%s", used ? "; " : "", line);
}

int csf_study_versions_print(const csf_study_session *list, int n, const char *skip_key, const char *indent,
                             FILE *fp)
{
    version_sink k = {fp, indent, NULL, 0};
    return each_version(list, n, skip_key, print_one, &k);
}

void csf_study_versions_text(const csf_study_session *list, int n, const char *skip_key, char *out,
                             size_t cap)
{
    out[0] = '\0';
    version_sink k = {NULL, NULL, out, cap};
    each_version(list, n, skip_key, text_one, &k);
}

void csf_study_selection_free(csf_study_selection *s)
{
    if (!s) return;
    csf_study_sessions_free(s->all, s->n_all);
    free(s->sel);
    memset(s, 0, sizeof *s);
}

/* study names a readable settings file: its name and its files' identity (and the 64-bit hash
 * that sessions stored before identities carry). 0 when study is a name. */
static int from_file(const char *study, char *name, size_t cap, char key[CSF_SHA256_HEX], char fnv[32],
                     csf_status *st, csf_error *err)
{
    if (access(study, F_OK) != 0 && !strchr(study, '/') && !strstr(study, ".conf")) return 0;
    csf_study *s = NULL;
    *st = csf_study_load(study, &s, err);
    csf_study_identity id;
    if (*st == CSF_OK && (*st = csf_study_identity_compute(s, 0, &id, err)) == CSF_OK) {
        snprintf(name, cap, "%s", s->name);
        memcpy(key, id.sha256, CSF_SHA256_HEX);
        snprintf(fnv, 32, "%016llx", (unsigned long long)s->hash);
        csf_study_identity_free(&id);
    }
    csf_study_free(s);
    return 1;
}

/* A name without a version: the one (version, identity) the store holds. */
static csf_status only_version(csf_study_selection *o, csf_error *err)
{
    char held[2000];
    csf_study_versions_text(o->all, o->n_all, NULL, held, sizeof held);
    for (int i = 1; i < o->n_all; i++)
        if (o->all[i].version != o->all[0].version || strcmp(o->all[i].key, o->all[0].key))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "study %s: the store holds several versions (%s): "
                                 "give the settings file of the one to analyse, or --version N",
                                 o->name, held);
    o->version = o->all[0].version;
    memcpy(o->key, o->all[0].key, sizeof o->key);
    o->legacy = o->all[0].legacy;
    return CSF_OK;
}

static int selected(const csf_study_selection *o, const csf_study_session *x, int by_file, const char *fnv)
{
    if (o->version > 0 && x->version != o->version) return 0;
    if (by_file) return x->legacy ? !strcmp(x->key, fnv) : !strcmp(x->key, o->key);
    return !strcmp(x->key, o->key);
}

csf_status csf_study_select(csf_store *store, const char *study, int version, csf_study_selection *o,
                            csf_error *err)
{
    memset(o, 0, sizeof *o);
    char fnv[32] = "";
    csf_status st = CSF_OK;
    int by_file = from_file(study, o->name, sizeof o->name, o->key, fnv, &st, err);
    if (st != CSF_OK) return st;
    if (!by_file) snprintf(o->name, sizeof o->name, "%s", study);
    o->version = version;
    st = csf_study_sessions_list(store, o->name, &o->all, &o->n_all, err);
    if (st == CSF_OK && !o->n_all)
        st = csf_error_set(err, CSF_E_NOT_FOUND, "the store %s holds no session of study '%s'",
                           csf_store_path(store), o->name);
    if (st == CSF_OK && !by_file && version > 0) {
        for (int i = 0; i < o->n_all && !o->key[0]; i++)
            if (o->all[i].version == version) {
                memcpy(o->key, o->all[i].key, sizeof o->key);
                o->legacy = o->all[i].legacy;
            }
    } else if (st == CSF_OK && !by_file) {
        st = only_version(o, err);
    }
    if (st == CSF_OK && !(o->sel = calloc(o->n_all > 0 ? (size_t)o->n_all : 1, sizeof *o->sel)))
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int i = 0; st == CSF_OK && i < o->n_all; i++)
        if (selected(o, &o->all[i], by_file, fnv)) {
            if (!o->n_sel && by_file) {
                o->version = o->all[i].version;
                o->legacy = o->all[i].legacy;
            }
            o->sel[o->n_sel++] = i;
        }
    if (st == CSF_OK && !o->n_sel) {
        char held[2000];
        csf_study_versions_text(o->all, o->n_all, NULL, held, sizeof held);
        st = csf_error_set(
            err, CSF_E_NOT_FOUND, "study %s: no session ran %s; the store holds %s", o->name,
            by_file ? "these files (their SHA-256 differs from every version's)" : "that version", held);
    }
    if (st == CSF_OK && by_file && o->legacy) memcpy(o->key, fnv, sizeof fnv);
    if (st != CSF_OK) csf_study_selection_free(o);
    return st;
}

static void session_data_clear(csf_study_session_data *d)
{
    csf_study_free(d->study);
    free(d->plan);
    free(d->trials);
    csf_study_table_free(&d->table);
    memset(d, 0, sizeof *d);
}

void csf_study_session_data_free(csf_study_session_data *d, int n)
{
    for (int i = 0; d && i < n; i++) session_data_clear(&d[i]);
    free(d);
}

/* CSF_E_NOT_FOUND when the session has no stored study files. */
static csf_status session_load(csf_store *store, const csf_study_session *x, int want_table,
                               csf_study_session_data *d, csf_error *err)
{
    memset(d, 0, sizeof *d);
    d->x = x;
    void *sb = NULL, *cb = NULL;
    size_t sl = 0, cl = 0;
    char sp[1024] = "", cp[1024] = "";
    csf_session_info info;
    memset(&info, 0, sizeof info);
    csf_status st = csf_store_get_session(store, x->id, &info, err);
    if (st == CSF_OK) st = csf_store_get_artifact(store, x->id, "study", &sb, &sl, sp, sizeof sp, err);
    if (st == CSF_OK) st = csf_store_get_artifact(store, x->id, "conditions", &cb, &cl, cp, sizeof cp, err);
    if (st == CSF_OK) st = csf_study_from_texts(sb, cb, sp, cp, 0, &d->study, err);
    /* the seed as stored with the session row (exact; the JSON number is a double) */
    if (st == CSF_OK)
        st = csf_study_make_plan(d->study, info.seed, x->participant_index, &d->plan, &d->n_plan, err);
    if (st == CSF_OK) st = csf_store_get_trials(store, x->id, &d->trials, &d->n_trials, err);
    if (st == CSF_OK && want_table) st = csf_study_conditions_table(d->study, &d->table, err);
    csf_session_info_free(&info);
    free(sb);
    free(cb);
    return st;
}

csf_status csf_study_sessions_load(csf_store *store, const csf_study_selection *sel, int want_table,
                                   const char *note, csf_study_session_data **out, int *n, csf_error *err)
{
    *n = 0;
    *out = calloc(sel->n_sel > 0 ? (size_t)sel->n_sel : 1, sizeof **out);
    if (!*out) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = CSF_OK;
    for (int i = 0; st == CSF_OK && i < sel->n_sel; i++) {
        const csf_study_session *x = &sel->all[sel->sel[i]];
        csf_error e;
        csf_status ls = session_load(store, x, want_table, &(*out)[*n], &e);
        if (ls == CSF_OK) {
            (*n)++;
            continue;
        }
        session_data_clear(&(*out)[*n]);
        if (ls == CSF_E_NOT_FOUND) { /* a start cut short: no study files stored, nothing to pool */
            if (note)
                fprintf(stderr, "csfcal: %s: session %lld left out: %s\n", note, (long long)x->id, e.msg);
            continue;
        }
        st = csf_error_set(err, ls, "session %lld: %s", (long long)x->id, e.msg);
    }
    if (st != CSF_OK) {
        csf_study_session_data_free(*out, *n);
        *out = NULL;
        *n = 0;
    }
    return st;
}
