/* The PostgreSQL store's local spool (see results/store/spool.h).
 *
 * When the server cannot be reached within spool_after_s, a trial, reading, frame timing, person
 * time or state change of a session this station runs goes into a local SQLite store (the spool) under
 * the session's uuid, durably, and the procedure goes on. Each later write first tries the
 * server again (at most every 5 s); once it answers, the spooled rows are sent with
 * csf_store_push_session (matched by uuid and seq: nothing doubled) before the new one. What is
 * still spooled at close is sent then if the server is back, else the close says how to send it
 * (csfcal sessions push). The spool keeps its copies after sending them: a local record. */
#include "results/store/spool.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "results/store/push.h"

static void spool_path(char *out, size_t cap)
{
    const char *e = getenv("CSF_STORE_SPOOL"), *xdg = getenv("XDG_DATA_HOME"), *home = getenv("HOME");
    if (e && *e) snprintf(out, cap, "%s", e);
    else if (xdg && *xdg) snprintf(out, cap, "%s/csfcal/spool.sqlite", xdg);
    else snprintf(out, cap, "%s/.local/share/csfcal/spool.sqlite", home && *home ? home : ".");
}

static void mkdir_parents(const char *path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *c = buf + 1; *c; c++)
        if (*c == '/') {
            *c = '\0';
            mkdir(buf, 0700);
            *c = '/';
        }
}

void csf_spool_init(csf_spool *sp, const char *location)
{
    snprintf(sp->location, sizeof sp->location, "%s", location);
    spool_path(sp->path, sizeof sp->path);
}

void csf_spool_close(csf_spool *sp)
{
    if (sp->store) sp->store->ops->close(sp->store);
    sp->store = NULL;
}

csf_status csf_spool_open_file(const char *path, csf_store **out, csf_error *err)
{
    return csf_store_sqlite_open(path, 0, out, err);
}

/* The spool itself, made with its folders at first use. */
static csf_status spool_open(csf_spool *sp, csf_error *err)
{
    if (sp->store) return CSF_OK;
    mkdir_parents(sp->path);
    return csf_spool_open_file(sp->path, &sp->store, err);
}

csf_status csf_spool_session(csf_spool *sp, const csf_session_info *k, int64_t *lsid, csf_error *err)
{
    csf_status cs = spool_open(sp, err);
    if (cs != CSF_OK) return cs;
    cs = sp->store->ops->find_session_uuid(sp->store, k->uuid, lsid, err);
    if (cs != CSF_E_NOT_FOUND) return cs;
    csf_error_clear(err);
    csf_store_session_new nw = {.kind = k->kind,
                                .observer = k->observer,
                                .display = k->display,
                                .profile_id = k->profile_id[0] ? k->profile_id : NULL,
                                .settings_json = k->settings_json,
                                .seed = k->seed,
                                .uuid = k->uuid,
                                .created_utc = k->created_utc,
                                .state = CSF_SESSION_RUNNING,
                                .tool_version = k->tool_version};
    return sp->store->ops->begin_session(sp->store, &nw, lsid, err);
}

csf_status csf_spool_put(csf_spool *sp, int64_t lsid, const csf_spool_write *w, csf_error *err)
{
    csf_status cs;
    csf_store *st = sp->store;
    if (w->kind == CSF_SPOOL_TRIAL) {
        csf_trial t = *w->t;
        t.session_id = lsid;
        cs = st->ops->add_trial_frames(st, &t, w->iv, w->n, err);
    } else if (w->kind == CSF_SPOOL_READING) {
        csf_reading r = *w->r;
        r.session_id = lsid;
        cs = st->ops->add_reading(st, &r, err);
    } else if (w->kind == CSF_SPOOL_FRAMES) {
        cs = st->ops->add_frame_intervals(st, lsid, w->seq, w->iv, w->n, err);
    } else if (w->kind == CSF_SPOOL_THRESHOLDS) {
        cs = st->ops->put_thresholds(st, lsid, w->rows, w->n_rows, err);
    } else if (w->kind == CSF_SPOOL_ARTIFACT) {
        cs = st->ops->add_artifact(st, lsid, w->art_kind, w->path, w->blob, w->len, err);
    } else if (w->kind == CSF_SPOOL_LINK) {
        cs = st->ops->link_named(st, lsid, w->study, NULL, w->code, err);
    } else if (w->kind == CSF_SPOOL_PERSON) {
        cs = st->ops->raise_person_time(st, lsid, w->person_s, err);
    } else {
        cs = st->ops->set_session_state(st, lsid, w->state, err);
    }
    if (cs != CSF_OK) return cs;
    if (!sp->spooling)
        fprintf(stderr,
                "csfcal: store %s: server unreachable; keeping what is measured in the "
                "local spool %s and sending it when the server is back\n",
                sp->location, sp->path);
    sp->spooling = 1;
    sp->n_spooled++;
    return CSF_OK;
}

void csf_spool_unsure_begin(csf_spool *sp, const csf_store_session_new *nw)
{
    csf_error e;
    csf_store_session_new ab = *nw;
    ab.state = CSF_SESSION_ABORTED;
    int64_t lsid = 0;
    csf_status cs = spool_open(sp, &e);
    if (cs == CSF_OK) cs = sp->store->ops->begin_session(sp->store, &ab, &lsid, &e);
    if (cs != CSF_OK)
        fprintf(stderr,
                "csfcal: store %s: the local spool %s cannot record the unfinished start "
                "of session %s (%s)\n",
                sp->location, sp->path, nw->uuid, e.msg);
    else
        fprintf(stderr,
                "csfcal: store %s: the server went away while session %s was starting; "
                "if the server recorded it, it is marked aborted when csfcal next reaches "
                "the server\n",
                sp->location, nw->uuid);
}

csf_status csf_spool_send(csf_spool *sp, csf_store *server, const csf_session_info *sessions, size_t n,
                          csf_error *err)
{
    sp->spooling = 0; /* the pushes below write to the server, never back into the spool */
    csf_status cs = CSF_OK;
    int sent = 0;
    for (size_t i = 0; i < n && cs == CSF_OK; i++) {
        int64_t lsid = 0;
        cs = sp->store->ops->find_session_uuid(sp->store, sessions[i].uuid, &lsid, err);
        if (cs == CSF_E_NOT_FOUND) {
            csf_error_clear(err);
            cs = CSF_OK;
            continue;
        }
        csf_push_counts c;
        if (cs == CSF_OK) cs = csf_store_push_session(sp->store, server, lsid, &c, err);
        if (cs == CSF_OK) sent += c.trials_sent + c.readings_sent;
    }
    if (cs != CSF_OK) {
        sp->spooling = 1;
        return cs;
    }
    fprintf(stderr, "csfcal: store %s: server back; %d spooled trials and readings sent\n", sp->location,
            sent);
    sp->n_spooled = 0;
    return CSF_OK;
}

/* A station that died while the server was away left rows in its spool that nobody sent. They
 * go to the server when the next csfcal opens it, before a procedure reads the trials it
 * resumes from (a resume without them would number new trials over them). */
void csf_spool_recover(csf_spool *sp, csf_store *server,
                       int (*abort_phantom)(csf_store *server, const csf_session_info *local, int64_t sid))
{
    if (access(sp->path, F_OK) != 0) return;
    csf_store *st = NULL;
    csf_error e;
    if (csf_spool_open_file(sp->path, &st, &e) != CSF_OK) {
        fprintf(stderr, "csfcal: store %s: the local spool cannot be read (%s)\n", sp->location, e.msg);
        return;
    }
    csf_session_info *list = NULL;
    size_t n = 0;
    csf_status cs = st->ops->list_sessions(st, &list, &n, &e);
    int sent = 0, aborted = 0;
    for (size_t i = 0; cs == CSF_OK && i < n; i++) {
        int64_t sid = 0;
        if (!list[i].uuid[0] || server->ops->find_session_uuid(server, list[i].uuid, &sid, NULL) != CSF_OK)
            continue;
        csf_push_counts c;
        cs = csf_store_push_rows(st, server, list[i].id, &c, &e);
        sent += c.trials_sent + c.readings_sent;
        if (cs == CSF_OK) aborted += abort_phantom(server, &list[i], sid);
    }
    if (cs != CSF_OK)
        fprintf(stderr, "csfcal: store %s: rows left in the local spool %s could not be sent (%s)\n",
                sp->location, sp->path, e.msg);
    else if (sent > 0)
        fprintf(stderr,
                "csfcal: store %s: %d trials and readings left in the local spool %s by an "
                "earlier run sent\n",
                sp->location, sent, sp->path);
    if (aborted > 0)
        fprintf(stderr,
                "csfcal: store %s: %d session(s) whose start was cut off by a lost "
                "connection marked aborted\n",
                sp->location, aborted);
    csf_session_list_free(list, n);
    st->ops->close(st);
}
