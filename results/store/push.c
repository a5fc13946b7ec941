/* Copying sessions from one store to another (csfcal sessions push; a station's spool going to
 * the server): sessions are matched by uuid, trials and readings by seq, so a second push, or a
 * push of sessions the server already partly has, adds only what is missing. Written against
 * results/store/store.h plus two backend calls (uuid lookup and assignment, one trial's frames), so it
 * works between any two backends. */
#include "results/store/push.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "results/store/backend.h"

/* The source session's uuid; one is given (and stored) to a session from before schema v6. */
static csf_status source_uuid(csf_store *src, csf_session_info *si, csf_error *err)
{
    if (si->uuid[0]) return CSF_OK;
    char uuid[40];
    if (csf_store_new_uuid(uuid) < 0)
        return csf_error_set(err, CSF_E_STORE, "store %s: no random bytes for a uuid", src->path);
    csf_status cs = src->ops->set_session_uuid(src, si->id, uuid, err);
    if (cs == CSF_OK) snprintf(si->uuid, sizeof si->uuid, "%s", uuid);
    return cs;
}

/* The destination's copy of the session, made when it has none. */
static csf_status dest_session(csf_store *dst, const csf_session_info *si, int64_t *id,
                               int *created, csf_error *err)
{
    *created = 0;
    csf_status cs = dst->ops->find_session_uuid(dst, si->uuid, id, err);
    if (cs != CSF_E_NOT_FOUND) return cs;
    csf_error_clear(err);
    csf_store_session_new nw = {.kind = si->kind,
                                .observer = si->observer,
                                .display = si->display,
                                .profile_id = si->profile_id[0] ? si->profile_id : NULL,
                                .settings_json = si->settings_json,
                                .seed = si->seed,
                                .uuid = si->uuid,
                                .created_utc = si->created_utc,
                                .state = CSF_SESSION_PAUSED,
                                .tool_version = si->tool_version};
    /* Made paused, never finished: a lab's server refuses rows added to a finished session,
     * and the copy takes the source's state once it has everything (push, below). */
    *created = 1;
    return dst->ops->begin_session(dst, &nw, id, err);
}

static int has_seq(const int *seqs, size_t n, int seq)
{
    for (size_t i = 0; i < n; i++)
        if (seqs[i] == seq) return 1;
    return 0;
}

static csf_status push_trials(csf_store *src, csf_store *dst, int64_t sid, int64_t did,
                              csf_push_counts *c, csf_error *err)
{
    csf_trial *st = NULL, *dt = NULL;
    size_t ns = 0, nd = 0;
    csf_status cs = csf_store_get_trials(src, sid, &st, &ns, err);
    if (cs == CSF_OK) cs = csf_store_get_trials(dst, did, &dt, &nd, err);
    int *have = nd ? malloc(nd * sizeof *have) : NULL;
    if (cs == CSF_OK && nd && !have) {
        free(st);
        free(dt);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    for (size_t i = 0; have && i < nd; i++) have[i] = dt[i].seq;
    for (size_t i = 0; cs == CSF_OK && i < ns; i++) {
        if (has_seq(have, nd, st[i].seq)) {
            c->trials_present++;
            continue;
        }
        double *iv = NULL;
        size_t niv = 0;
        cs = src->ops->get_trial_frames(src, sid, st[i].seq, &iv, &niv, err);
        csf_trial t = st[i];
        t.session_id = did;
        if (cs == CSF_OK) cs = csf_store_add_trial_frames(dst, &t, iv, (int)niv, err);
        free(iv);
        if (cs == CSF_OK) c->trials_sent++;
    }
    free(have);
    free(st);
    free(dt);
    return cs;
}

static csf_status push_readings(csf_store *src, csf_store *dst, int64_t sid, int64_t did,
                                csf_push_counts *c, csf_error *err)
{
    csf_reading *sr = NULL, *dr = NULL;
    size_t ns = 0, nd = 0;
    csf_status cs = csf_store_get_readings(src, sid, &sr, &ns, err);
    if (cs == CSF_OK) cs = csf_store_get_readings(dst, did, &dr, &nd, err);
    int *have = nd ? malloc(nd * sizeof *have) : NULL;
    if (cs == CSF_OK && nd && !have) {
        free(sr);
        free(dr);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    for (size_t i = 0; have && i < nd; i++) have[i] = dr[i].seq;
    for (size_t i = 0; cs == CSF_OK && i < ns; i++) {
        if (has_seq(have, nd, sr[i].seq)) {
            c->readings_present++;
            continue;
        }
        csf_reading r = sr[i];
        r.session_id = did;
        cs = csf_store_add_reading(dst, &r, err);
        if (cs == CSF_OK) c->readings_sent++;
    }
    free(have);
    free(sr);
    free(dr);
    return cs;
}

/* The destination has this artifact: same kind, and the same path and bytes as far as the
 * source row has them (a path-only or bytes-only source row matches the row it completed). */
static int has_artifact(const csf_store_artifact *have, size_t n, const csf_store_artifact *a)
{
    for (size_t i = 0; i < n; i++) {
        if (strcmp(have[i].kind, a->kind) != 0) continue;
        if (a->path[0] && strcmp(have[i].path, a->path) != 0) continue;
        if (a->blob && (!have[i].blob || have[i].len != a->len ||
                        (a->len && memcmp(have[i].blob, a->blob, a->len) != 0)))
            continue;
        return 1;
    }
    return 0;
}

/* Thresholds are replaced whole (the source's are the session's result); every artifact the
 * destination lacks is copied, in the order it was stored. */
static csf_status push_results(csf_store *src, csf_store *dst, int64_t sid, int64_t did,
                               csf_push_counts *c, csf_error *err)
{
    csf_threshold_row *th = NULL;
    size_t nth = 0;
    csf_status cs = csf_store_get_thresholds(src, sid, &th, &nth, err);
    if (cs == CSF_OK && nth > 0) cs = csf_store_put_thresholds(dst, did, th, nth, err);
    free(th);
    csf_store_artifact *sa = NULL, *da = NULL;
    size_t ns = 0, nd = 0;
    if (cs == CSF_OK) cs = src->ops->list_artifacts(src, sid, &sa, &ns, err);
    if (cs == CSF_OK) cs = dst->ops->list_artifacts(dst, did, &da, &nd, err);
    for (size_t i = 0; cs == CSF_OK && i < ns; i++) {
        if (has_artifact(da, nd, &sa[i])) continue;
        cs = csf_store_add_artifact(dst, did, sa[i].kind, sa[i].path[0] ? sa[i].path : NULL,
                                    sa[i].blob, sa[i].len, err);
        if (cs == CSF_OK) c->artifacts_sent++;
    }
    csf_store_artifacts_free(sa, ns);
    csf_store_artifacts_free(da, nd);
    return cs;
}

/* The study participant the session belongs to, made on the destination when missing (by
 * study name and participant code: ids differ between stores). */
static csf_status push_participant(csf_store *src, csf_store *dst, int64_t sid, int64_t did,
                                   csf_push_counts *c, csf_error *err)
{
    char study[256], code[64];
    char *design = NULL;
    csf_status cs = src->ops->session_participant(src, sid, study, &design, code, err);
    if (cs == CSF_E_NOT_FOUND) {
        csf_error_clear(err);
        return CSF_OK;
    }
    if (cs == CSF_OK) cs = dst->ops->link_named(dst, did, study, design, code, err);
    if (cs == CSF_OK) c->participant_linked = 1;
    free(design);
    return cs;
}

/* The source's person time, which only grows, raises the copy's to it (a second push changes
 * nothing); a copy already finished or aborted keeps its own, as it keeps its state. */
static csf_status push_person_time(const csf_session_info *si, csf_store *dst, int64_t did, csf_error *err)
{
    if (isnan(si->person_s)) return CSF_OK;
    csf_session_info di;
    csf_status cs = csf_store_get_session(dst, did, &di, err);
    if (cs != CSF_OK) return cs;
    int over = csf_session_state_closed(di.state);
    int has = di.person_s >= si->person_s;
    csf_session_info_free(&di);
    if (over || has) return CSF_OK;
    return dst->ops->raise_person_time(dst, did, si->person_s, err);
}

/* A session whose kind or state this build does not know (a store written by a newer csfcal,
 * or by hand) is not copied: its copy could only be stored as some known kind or state, which
 * it is not. */
static csf_status known_session(const csf_store *src, const csf_session_info *si, csf_error *err)
{
    if (si->kind != CSF_SESSION_KIND_UNKNOWN && si->state != CSF_SESSION_STATE_UNKNOWN) return CSF_OK;
    char kind[64], state[64];
    csf_store_printable(si->kind_text, kind, sizeof kind);
    csf_store_printable(si->state_text, state, sizeof state);
    return csf_error_set(err, CSF_E_STORE,
                         "store %s: session %lld has kind '%s' and state '%s', which this csfcal "
                         "does not know (allowed kinds display, observer, study; states running, "
                         "paused, finished, aborted): not copied",
                         src->path, (long long)si->id, kind, state);
}

static csf_status push(csf_store *src, csf_store *dst, int64_t session_id, int keep_state,
                       csf_push_counts *c, csf_error *err)
{
    csf_error_clear(err);
    if (!src || !dst || !c) return csf_error_set(err, CSF_E_INVALID_ARG, "store: not open");
    if (dst->readonly || src->readonly)
        return csf_error_set(err, CSF_E_INVALID_ARG, "store: push needs both stores writable");
    memset(c, 0, sizeof *c);
    csf_session_info si;
    csf_status cs = csf_store_get_session(src, session_id, &si, err);
    if (cs != CSF_OK) return cs;
    int64_t did = 0;
    int created = 0;
    cs = source_uuid(src, &si, err);
    /* A session aborted before anything was measured (among them the start a spool records
     * when the server may or may not have got it) is not made on a destination that lacks it:
     * it would be a phantom there. One the destination has still takes the state. */
    if (cs == CSF_OK) cs = known_session(src, &si, err);
    if (cs == CSF_OK && si.state == CSF_SESSION_ABORTED && !si.n_trials && !si.n_readings) {
        cs = dst->ops->find_session_uuid(dst, si.uuid, &did, err);
        if (cs == CSF_E_NOT_FOUND) {
            csf_error_clear(err);
            c->skipped_empty = 1;
            csf_session_info_free(&si);
            return CSF_OK;
        }
    }
    if (cs == CSF_OK) cs = dest_session(dst, &si, &did, &created, err);
    if (cs == CSF_OK) cs = push_trials(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_readings(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_participant(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_results(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_person_time(&si, dst, did, err);
    /* The copy takes the source's state once it has everything (and lets go of the claim a
     * new server session was made with), unless the destination's copy is already over. */
    csf_session_info di;
    if (cs == CSF_OK && !keep_state) cs = csf_store_get_session(dst, did, &di, err);
    if (cs == CSF_OK && !keep_state) {
        int over = csf_session_state_closed(di.state);
        csf_session_info_free(&di);
        if (!over) cs = csf_store_set_session_state(dst, did, si.state, err);
    }
    if (cs == CSF_OK) {
        c->dest_id = did;
        c->created = created;
    }
    csf_session_info_free(&si);
    return cs;
}

csf_status csf_store_push_session(csf_store *src, csf_store *dst, int64_t session_id,
                                  csf_push_counts *c, csf_error *err)
{
    return push(src, dst, session_id, 0, c, err);
}

csf_status csf_store_push_rows(csf_store *src, csf_store *dst, int64_t session_id,
                               csf_push_counts *c, csf_error *err)
{
    return push(src, dst, session_id, 1, c, err);
}
