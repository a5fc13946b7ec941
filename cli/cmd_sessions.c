/* `csfcal sessions [list|show|export|abort]`: what the results store holds, session by session.
 * Listing shows each session's state so an unfinished one can be continued with --resume ID;
 * export writes tidy CSV/JSON (one row per trial, reading or threshold) for pandas and R. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "core/file_write.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "results/store/export.h"
#include "results/store/push.h"

static const char sessions_help[] =
    "usage: csfcal sessions [list] [--kind K] [--state S] [--store PATH] [--json]\n"
    "       csfcal sessions show ID [--store PATH] [--json]\n"
    "       csfcal sessions export ID --format csv|json\n"
    "                              [--table trials|readings|thresholds|frames]\n"
    "                              [-o FILE] [--store PATH]\n"
    "       csfcal sessions abort ID [--store PATH]\n"
    "       csfcal sessions push [ID...] --to LOCATION [--store PATH]\n"
    "       csfcal sessions init [--store PATH]\n\n"
    "list    every session in the store: id, kind, state, observer, display, trials, readings,\n"
    "        person time (the participant's minutes in the session, every run added up; - when\n"
    "        unknown; --json: person_s in seconds, null when unknown);\n"
    "        --kind display|observer|study and --state running|paused|finished|aborted filter.\n"
    "        Sessions in state running or paused can be continued with the --resume ID option\n"
    "        of the command that started them.\n"
    "show    one session in detail, with the settings it was started with.\n"
    "export  tidy table, one row per trial (observer/study sessions) or photometer reading\n"
    "        (display sessions) unless --table says otherwise (frames: one row per frame\n"
    "        interval). Column names carry units\n"
    "        (freq_cpd, ecc_deg, lum_cdm2, rt_s ...); empty CSV cell / JSON null = missing.\n"
    "        Writes to standard output unless -o FILE is given. See docs/store.md.\n"
    "abort   mark an unfinished session as aborted (it is then not offered for resuming).\n"
    "push    copy sessions (all, or the IDs given) of --store to the store at LOCATION (a\n"
    "        server: postgresql://..., service=NAME; or another file) without doubling\n"
    "        anything: a session already there gets only the trials, readings and artifacts\n"
    "        it lacks; thresholds, state and the study participant link go with it.\n"
    "        A station that ran on its own file while the server was away sends its sessions\n"
    "        this way. Prints what it sent per session.\n"
    "init    create the store (or migrate it to this csfcal's schema) and say so: what a lab's\n"
    "        database owner runs once on a new server database, before the roles of\n"
    "        docs/store_roles.sql are made.\n\n";

enum { OPT_FORMAT = CSF_OPT_FIRST_FREE, OPT_TABLE, OPT_KIND, OPT_STATE, OPT_TO };

static const struct option sessions_options[] = {
    {"format", required_argument, 0, OPT_FORMAT},
    {"table", required_argument, 0, OPT_TABLE},
    {"kind", required_argument, 0, OPT_KIND},
    {"state", required_argument, 0, OPT_STATE},
    {"to", required_argument, 0, OPT_TO},
    {"output", required_argument, 0, 'o'},
    {"help", no_argument, 0, 'h'},
    CSF_CLI_COMMON_OPTIONS,
    {0, 0, 0, 0},
};

/* A JSON string of text read from the store: jansson checks it is UTF-8; text that is not (a
 * row written around csfcal) is given in its escaped, printable form instead. */
static json_t *json_text(const char *s)
{
    json_t *j = json_string(s ? s : "");
    if (j) return j;
    char buf[4096];
    csf_store_printable(s, buf, sizeof buf);
    return json_string(buf);
}

static json_t *session_json(const csf_session_info *si, int with_settings)
{
    json_t *o = json_object();
    json_object_set_new(o, "id", json_integer(si->id));
    json_object_set_new(o, "kind", json_text(si->kind_text));
    json_object_set_new(o, "state", json_text(si->state_text));
    json_object_set_new(o, "observer", json_text(si->observer));
    json_object_set_new(o, "display", json_text(si->display));
    json_object_set_new(o, "profile_id", si->profile_id[0] ? json_text(si->profile_id) : json_null());
    /* csfcal's seeds are below 2^53 (--seed: 31 bits; study participants: 53). */
    json_object_set_new(o, "seed", json_integer((json_int_t)si->seed));
    json_object_set_new(o, "tool_version", json_text(si->tool_version));
    json_object_set_new(o, "created_utc", json_text(si->created_utc));
    json_object_set_new(o, "n_trials", json_integer(si->n_trials));
    json_object_set_new(o, "n_readings", json_integer(si->n_readings));
    /* seconds; null where unknown (sessions stored before person time was kept) */
    json_object_set_new(o, "person_s", isfinite(si->person_s) ? json_real(si->person_s) : json_null());
    /* Stored as text by the procedures; a string, so the output stays valid whatever it holds. */
    if (with_settings)
        json_object_set_new(o, "settings_json", json_text(si->settings_json ? si->settings_json : "{}"));
    return o;
}

/* Writes doc (taken) and a newline; 0, or 1 after a message. */
static int print_json(json_t *doc)
{
    int bad = !doc || json_dumpf(doc, stdout, JSON_INDENT(1) | JSON_PRESERVE_ORDER) != 0;
    json_decref(doc);
    if (bad) fprintf(stderr, "csfcal: sessions: cannot write the JSON output\n");
    else putchar('\n');
    return bad;
}

/* The file a display profile was written to, from the display session that wrote it (its
 * "profile" artifact, whose bytes carry the id): an observer session keeps only the id, and a
 * resume without that profile is refused. 0 with the path in out, -1 when no session of this
 * store wrote it (a profile made elsewhere). */
static int profile_file_of(csf_store *s, const char *profile_id, char *out, size_t len)
{
    csf_session_info *list = NULL;
    size_t n = 0;
    csf_error err;
    if (!profile_id[0] || csf_store_list_sessions(s, &list, &n, &err) != CSF_OK) return -1;
    int found = -1;
    for (size_t i = n; i-- > 0 && found < 0;) {
        if (list[i].kind != CSF_SESSION_DISPLAY) continue;
        void *blob = NULL;
        size_t bl = 0;
        char path[1024] = "";
        if (csf_store_get_artifact(s, list[i].id, "profile", &blob, &bl, path, sizeof path, &err) != CSF_OK)
            continue;
        csf_display_profile *p = NULL;
        if (blob && path[0] && csf_store_check_text(path, "profile", &err) == CSF_OK &&
            csf_profile_parse(blob, bl, &p, &err) == CSF_OK && strcmp(csf_profile_id(p), profile_id) == 0) {
            snprintf(out, len, "%s", path);
            found = 0;
        }
        csf_profile_free(p);
        free(blob);
    }
    csf_session_list_free(list, n);
    return found;
}

/* The observer session's hint: its profile (found by id, or named when its file is unknown). */
static void print_observer_hint(FILE *out, csf_store *s, const csf_session_info *si, const char *q)
{
    long long id = (long long)si->id;
    char path[1024], pid[256];
    csf_store_printable(si->profile_id, pid, sizeof pid);
    if (!si->profile_id[0]) {
        fprintf(out,
                "  %lld (observer): csfcal observer calibrate --resume %lld --store %s --out FILE.csflut\n",
                id, id, q);
    } else if (profile_file_of(s, si->profile_id, path, sizeof path) == 0) {
        char *qp = csf_shell_quote(path);
        fprintf(out,
                "  %lld (observer): csfcal observer calibrate --resume %lld --store %s --profile %s --out "
                "FILE.csflut\n",
                id, id, q, qp ? qp : "?");
        free(qp);
    } else {
        fprintf(
            out,
            "  %lld (observer): csfcal observer calibrate --resume %lld --store %s --profile FILE.profile "
            "--out FILE.csflut\n      (FILE.profile: the display profile %s the session was measured with)\n",
            id, id, q, pid);
    }
}

/* The command that continues an unfinished session: each kind has its own (a display session
 * is continued by display calibrate, which needs the photometer and the profile file again).
 * location is the store as given (checked on open: printable, no secret), quoted for a shell
 * so the line pastes as it is. */
static void print_resume_hint(FILE *out, csf_store *s, const csf_session_info *si, const char *location)
{
    long long id = (long long)si->id;
    char *q = csf_shell_quote(location);
    char kind[64];
    csf_store_printable(si->kind_text, kind, sizeof kind);
    if (si->kind == CSF_SESSION_DISPLAY) {
        /* the photometer the session was started with, from its stored settings */
        json_error_t je;
        json_t *set = si->settings_json ? json_loads(si->settings_json, 0, &je) : NULL;
        const char *ph = json_string_value(json_object_get(set, "photometer"));
        csf_error te;
        /* shown only when it is text a terminal can show (the row may come from another station) */
        char *qp = ph && *ph && csf_store_check_text(ph, "photometer", &te) == CSF_OK ? csf_shell_quote(ph) : NULL;
        fprintf(out, "  %lld (display):  csfcal display calibrate --resume %lld --store %s --photometer %s "
                "--out FILE.profile\n", id, id, q ? q : "?", qp ? qp : "SPEC");
        free(qp);
        json_decref(set);
    } else if (si->kind == CSF_SESSION_OBSERVER) print_observer_hint(out, s, si, q ? q : "?");
    else
        fprintf(out, "  %lld (%s): cannot be resumed by this csfcal; csfcal sessions abort %lld --store %s "
                "closes it\n", id, kind, id, q ? q : "?");
    free(q);
}

/* A column of the listing: the text in printable form, cut to width characters for the table
 * only (never in the store), padded. */
static void print_cell(const char *text, int width)
{
    char buf[1024];
    csf_store_printable(text && *text ? text : "-", buf, sizeof buf);
    int shown = 0;
    const char *p = buf;
    while (*p) {
        /* One column per character; an escape (\xNN, \r, \n) is kept whole or left out. */
        size_t n = *p == '\\' ? (p[1] == 'x' ? 4 : 2) : 1;
        while (n == 1 && (p[n] & 0xc0) == 0x80) n++; /* the rest of a UTF-8 character */
        int cols = *p == '\\' ? (int)n : 1;
        if (shown + cols > width) break;
        fwrite(p, 1, n, stdout);
        p += n;
        shown += cols;
    }
    printf("%*s ", width - shown, "");
}

/* The person time in minutes with one decimal, "-" when unknown. */
static void person_minutes(const csf_session_info *si, char *out, size_t cap)
{
    if (isfinite(si->person_s)) snprintf(out, cap, "%.1f", si->person_s / 60.0);
    else snprintf(out, cap, "-");
}

static int unfinished(const csf_session_info *si)
{
    return csf_session_state_open(si->state);
}

static int parse_id(const char *text, int64_t *id)
{
    long v;
    if (csf_parse_int(text, "session ID", 1, 0x7fffffffL, &v) < 0) return -1;
    *id = v;
    return 0;
}

/* Reading commands open the store read-only: they work on archived stores on read-only media
 * and never create an empty store as a side effect of a typo in --store. */
static int open_store(csf_cli *cli, csf_store **s, int writable)
{
    csf_error err;
    const char *path = csf_cli_store_path(cli);
    csf_status st = writable ? csf_store_open(path, s, &err) : csf_store_open_readonly(path, s, &err);
    if (st != CSF_OK) return csf_cli_report("sessions", &err);
    return 0;
}

/* kind, state: CSF_SESSION_KIND_UNKNOWN / CSF_SESSION_STATE_UNKNOWN for no filter. */
static int cmd_list(csf_cli *cli, csf_session_kind kind, csf_session_state state)
{
    csf_store *s = NULL;
    csf_error err;
    const char *path = csf_cli_store_path(cli);
    csf_status ost = csf_store_open_readonly(path, &s, &err);
    if (ost == CSF_E_NOT_FOUND) {
        /* Nothing recorded yet is not an error for a listing. */
        char shown[1024];
        csf_store_redact(path, shown, sizeof shown);
        if (cli->json) printf("[]\n");
        else printf("No sessions yet: the store %s does not exist.\n", shown);
        return 0;
    }
    if (ost != CSF_OK) return csf_cli_report("sessions", &err);
    csf_session_info *list = NULL;
    size_t n = 0;
    if (csf_store_list_sessions(s, &list, &n, &err) != CSF_OK) {
        csf_store_close(s);
        return csf_cli_report("sessions", &err);
    }
    /* Filters: keep the matching sessions at the front of the list. */
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        if ((kind && list[i].kind != kind) || (state && list[i].state != state)) {
            csf_session_info_free(&list[i]);
            continue;
        }
        list[kept++] = list[i];
    }
    n = kept;
    int rc = 0;
    if (cli->json) {
        json_t *arr = json_array();
        for (size_t i = 0; i < n; i++) json_array_append_new(arr, session_json(&list[i], 0));
        rc = print_json(arr);
    } else if (n == 0) {
        printf("No %ssessions in %s\n", kind || state ? "matching " : "", csf_store_path(s));
    } else {
        printf("%-5s %-8s %-9s %-14s %-18s %7s %8s %10s  %s\n", "ID", "KIND", "STATE", "OBSERVER", "DISPLAY",
               "TRIALS", "READINGS", "PERSON MIN", "CREATED (UTC)");
        int n_open = 0;
        for (size_t i = 0; i < n; i++) {
            const csf_session_info *si = &list[i];
            printf("%-5lld ", (long long)si->id);
            print_cell(si->kind_text, 8);
            print_cell(si->state_text, 9);
            print_cell(si->observer, 14);
            print_cell(si->display, 18);
            char created[64];
            csf_store_printable(si->created_utc, created, sizeof created);
            char person[32];
            person_minutes(si, person, sizeof person);
            printf("%7d %8d %10s  %s\n", si->n_trials, si->n_readings, person, created);
            n_open += unfinished(si);
        }
        if (n_open) {
            printf("\n%d unfinished session%s; continue with:\n", n_open, n_open == 1 ? "" : "s");
            for (size_t i = 0; i < n; i++)
                if (unfinished(&list[i])) print_resume_hint(stdout, s, &list[i], path);
        }
    }
    csf_session_list_free(list, n);
    csf_store_close(s);
    return rc;
}

/* One session in detail; every text from the store in printable form. */
static void print_show(const csf_session_info *si, const char *created, const char *updated)
{
    const char *label[] = {"kind", "state", "observer", "display", "profile"};
    const char *val[] = {si->kind_text, si->state_text, si->observer, si->display, si->profile_id};
    char buf[1024];
    printf("session      %lld\n", (long long)si->id);
    for (size_t i = 0; i < sizeof label / sizeof label[0]; i++) {
        csf_store_printable(val[i][0] ? val[i] : "-", buf, sizeof buf);
        printf("%-12s %s\n", label[i], buf);
    }
    csf_store_printable(si->tool_version, buf, sizeof buf);
    printf("seed         %llu\ntool version %s\n", (unsigned long long)si->seed, buf);
    csf_store_printable(created, buf, sizeof buf);
    printf("created      %s\n", buf);
    csf_store_printable(updated, buf, sizeof buf);
    printf("last write   %s\ntrials       %d\nreadings     %d\n", buf, si->n_trials, si->n_readings);
    if (isfinite(si->person_s)) printf("person time  %.1f min (%.0f s)\n", si->person_s / 60.0, si->person_s);
    else printf("person time  -\n");
    size_t n = si->settings_json ? strlen(si->settings_json) : 0;
    char *settings = malloc(4 * n + 1);
    if (settings) csf_store_printable(si->settings_json ? si->settings_json : "", settings, 4 * n + 1);
    printf("settings     %s\n", settings ? settings : "?");
    free(settings);
}

static int cmd_show(csf_cli *cli, int64_t id)
{
    csf_store *s = NULL;
    int rc = open_store(cli, &s, 0);
    if (rc) return rc;
    csf_error err;
    csf_session_info si;
    char created[32], updated[32];
    if (csf_store_get_session(s, id, &si, &err) != CSF_OK ||
        csf_store_session_times(s, id, created, updated, &err) != CSF_OK) {
        csf_store_close(s);
        return csf_cli_report("sessions", &err);
    }
    if (cli->json) {
        rc = print_json(session_json(&si, 1));
    } else {
        print_show(&si, created, updated);
        if (unfinished(&si)) {
            printf("unfinished; continue with:\n");
            print_resume_hint(stdout, s, &si, csf_cli_store_path(cli));
        }
    }
    csf_session_info_free(&si);
    csf_store_close(s);
    return rc;
}

static int cmd_abort(csf_cli *cli, int64_t id)
{
    csf_store *s = NULL;
    int rc = open_store(cli, &s, 1);
    if (rc) return rc;
    csf_error err;
    csf_session_info si;
    if (csf_store_get_session(s, id, &si, &err) != CSF_OK) {
        csf_store_close(s);
        return csf_cli_report("sessions", &err);
    }
    csf_session_state state = si.state;
    char state_text[64];
    csf_store_printable(si.state_text, state_text, sizeof state_text);
    csf_session_info_free(&si);
    /* A state this build does not know may be a closed one: left as it is. */
    if (state == CSF_SESSION_FINISHED || state == CSF_SESSION_STATE_UNKNOWN) {
        csf_store_close(s);
        fprintf(stderr,
                "csfcal: sessions: session %lld is %s%s; only running or paused "
                "sessions can be aborted\n",
                (long long)id, state_text, state ? "" : " (a state this csfcal does not know)");
        return 1;
    }
    if (csf_store_set_session_state(s, id, CSF_SESSION_ABORTED, &err) != CSF_OK) {
        csf_store_close(s);
        return csf_cli_report("sessions", &err);
    }
    printf("session %lld marked aborted\n", (long long)id);
    csf_store_close(s);
    return 0;
}

static int cmd_export(csf_cli *cli, int64_t id, const char *format, const char *table, const char *out_path)
{
    csf_export_format fmt;
    if (!format) {
        fprintf(stderr, "csfcal: sessions export: --format is required (csv or json)\n");
        return 2;
    }
    if (!strcmp(format, "csv")) fmt = CSF_EXPORT_CSV;
    else if (!strcmp(format, "json")) fmt = CSF_EXPORT_JSON;
    else {
        fprintf(stderr, "csfcal: sessions export: --format '%s' unknown (allowed csv, json)\n", format);
        return 2;
    }
    csf_export_table tab = CSF_TABLE_AUTO;
    if (table) {
        if (!strcmp(table, "trials")) tab = CSF_TABLE_TRIALS;
        else if (!strcmp(table, "readings")) tab = CSF_TABLE_READINGS;
        else if (!strcmp(table, "thresholds")) tab = CSF_TABLE_THRESHOLDS;
        else if (!strcmp(table, "frames")) tab = CSF_TABLE_FRAMES;
        else {
            fprintf(stderr, "csfcal: sessions export: --table '%s' unknown (allowed trials, readings, "
                    "thresholds, frames)\n", table);
            return 2;
        }
    }
    csf_store *s = NULL;
    int rc = open_store(cli, &s, 0);
    if (rc) return rc;
    csf_error err;
    csf_session_info si;
    /* Check the session before creating the output file, so a typo leaves no empty file. */
    if (csf_store_get_session(s, id, &si, &err) != CSF_OK) {
        csf_store_close(s);
        return csf_cli_report("sessions export", &err);
    }
    csf_session_info_free(&si);
    /* A file is written beside its destination and renamed over it when complete: a full disk
     * leaves the old file (or none), never half an export. */
    FILE *out = stdout;
    csf_atomic_file af = {0};
    int to_file = out_path && strcmp(out_path, "-") != 0;
    if (to_file) {
        if (csf_atomic_open(&af, out_path, "session export", &err) != CSF_OK) {
            csf_store_close(s);
            return csf_cli_report("sessions export", &err);
        }
        out = af.fp;
    }
    csf_status st = csf_store_export(s, id, tab, fmt, out, &err);
    csf_store_close(s);
    if (to_file) {
        if (st == CSF_OK) st = csf_atomic_commit(&af, &err);
        else csf_atomic_abort(&af);
    } else if (st == CSF_OK && fflush(stdout) != 0) {
        st = csf_error_set(&err, CSF_E_IO, "writing to standard output failed (%s)", strerror(errno));
    }
    if (st != CSF_OK) return csf_cli_report("sessions export", &err);
    return 0;
}

static int cmd_init(csf_cli *cli)
{
    csf_store *s = NULL;
    int rc = open_store(cli, &s, 1);
    if (rc) return rc;
    printf("store %s: %s, schema version %d\n", csf_store_path(s), csf_store_backend(s),
           csf_store_schema_version(s));
    csf_store_close(s);
    return 0;
}

/* One session's push, reported on one line; 0 or 1. */
static int push_one(csf_store *src, csf_store *dst, int64_t id)
{
    csf_error err;
    csf_push_counts c;
    csf_session_info si;
    if (csf_store_get_session(src, id, &si, &err) == CSF_OK) {
        int cut = si.names_cut;
        csf_session_info_free(&si);
        if (cut) {
            fprintf(stderr, "csfcal: sessions push: session %lld: its observer or display name is "
                    "longer than %zu characters; not copied, as the copy would hold it cut\n",
                    (long long)id, sizeof si.observer - 1);
            return 1;
        }
    }
    if (csf_store_push_session(src, dst, id, &c, &err) != CSF_OK) {
        fprintf(stderr, "csfcal: sessions push: session %lld: %s\n", (long long)id, err.msg);
        return 1;
    }
    if (c.skipped_empty) {
        printf("session %lld: aborted before anything was measured; not copied\n", (long long)id);
        return 0;
    }
    printf("session %lld -> %lld%s: %d trials sent, %d already there; %d readings sent, %d "
           "already there; %d artifacts sent%s\n", (long long)id, (long long)c.dest_id,
           c.created ? " (new)" : "", c.trials_sent, c.trials_present, c.readings_sent,
           c.readings_present, c.artifacts_sent,
           c.participant_linked ? "; study participant linked" : "");
    return 0;
}

static int cmd_push(csf_cli *cli, const char *to, char **ids, int n_ids)
{
    if (!to || !*to) {
        fprintf(stderr, "csfcal: sessions push: --to LOCATION is required (the store to copy to)\n");
        return 2;
    }
    csf_error err;
    if (csf_store_check_location(to, "--to", &err) != CSF_OK)
        return csf_cli_report("sessions push", &err);
    int64_t *want = n_ids ? calloc((size_t)n_ids, sizeof *want) : NULL;
    for (int i = 0; i < n_ids; i++)
        if (!want || parse_id(ids[i], &want[i]) < 0) {
            free(want);
            return 2;
        }
    csf_store *src = NULL, *dst = NULL;
    int rc = open_store(cli, &src, 1);
    if (rc) {
        free(want);
        return rc;
    }
    if (csf_store_open(to, &dst, &err) != CSF_OK) {
        csf_store_close(src);
        free(want);
        return csf_cli_report("sessions push", &err);
    }
    int failed = 0;
    if (n_ids) {
        for (int i = 0; i < n_ids; i++) failed |= push_one(src, dst, want[i]);
    } else {
        csf_session_info *list = NULL;
        size_t n = 0;
        if (csf_store_list_sessions(src, &list, &n, &err) != CSF_OK) failed = csf_cli_report("sessions push", &err);
        for (size_t i = 0; i < n; i++) failed |= push_one(src, dst, list[i].id);
        if (!failed && n == 0) printf("No sessions in %s\n", csf_store_path(src));
        csf_session_list_free(list, n);
    }
    csf_store_close(dst);
    csf_store_close(src);
    free(want);
    return failed ? 1 : 0;
}

int csf_cmd_sessions(int argc, char **argv)
{
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    const char *format = NULL, *table = NULL, *out_path = NULL;
    csf_session_kind kind = CSF_SESSION_KIND_UNKNOWN; /* no filter */
    csf_session_state state = CSF_SESSION_STATE_UNKNOWN;
    const char *to = NULL;
    optind = 0;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":o:h", sessions_options, NULL)) != -1) {
        switch (c) {
        case OPT_FORMAT: format = optarg; break;
        case OPT_TABLE: table = optarg; break;
        case OPT_KIND:
            kind = csf_session_kind_from_name(optarg);
            if (!kind) {
                fprintf(stderr, "csfcal: sessions: --kind '%s' unknown (allowed display, observer, study)\n", optarg);
                return 2;
            }
            break;
        case OPT_STATE:
            state = csf_session_state_from_name(optarg);
            if (!state) {
                fprintf(stderr, "csfcal: sessions: --state '%s' unknown (allowed running, paused, "
                        "finished, aborted)\n", optarg);
                return 2;
            }
            break;
        case 'o': out_path = optarg; break;
        case OPT_TO: to = optarg; break;
        default:
            rc = csf_cli_option_default(&cli, "sessions", sessions_help, c, argv);
            if (rc >= 0) return rc;
        }
    }
    int npos = argc - optind;
    char **pos = argv + optind;
    const char *sub = npos > 0 ? pos[0] : "list";
    int64_t id = 0;
    if (!strcmp(sub, "list")) {
        if (npos > 1) {
            fprintf(stderr, "csfcal: sessions list: unexpected argument '%s'\n", pos[1]);
            return 2;
        }
        return cmd_list(&cli, kind, state);
    }
    if (!strcmp(sub, "show") || !strcmp(sub, "export") || !strcmp(sub, "abort")) {
        if (npos != 2) {
            fprintf(stderr, "csfcal: sessions %s: expected one session ID (see csfcal sessions list)\n", sub);
            return 2;
        }
        if (parse_id(pos[1], &id) < 0) return 2;
        if (!strcmp(sub, "show")) return cmd_show(&cli, id);
        if (!strcmp(sub, "abort")) return cmd_abort(&cli, id);
        return cmd_export(&cli, id, format, table, out_path);
    }
    if (!strcmp(sub, "push")) return cmd_push(&cli, to, pos + 1, npos - 1);
    if (!strcmp(sub, "init")) {
        if (npos > 1) {
            fprintf(stderr, "csfcal: sessions init: unexpected argument '%s'\n", pos[1]);
            return 2;
        }
        return cmd_init(&cli);
    }
    fprintf(stderr, "csfcal: sessions: unknown subcommand '%s' (allowed list, show, export, abort, "
                    "push, init)\n", sub);
    return 2;
}
