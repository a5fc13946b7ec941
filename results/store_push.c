/* Copying sessions from one store to another (csfcal sessions push; a station's spool going to
 * the server): sessions are matched by uuid, trials and readings by seq, so a second push, or a
 * push of sessions the server already partly has, adds only what is missing. Written against
 * results/store.h plus two backend calls (uuid lookup and assignment, one trial's frames), so it
 * works between any two backends. */
#include "results/store_push.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "results/store_backend.h"

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
    csf_store_session_new nw = {.kind = si->kind, .observer = si->observer,
                                .display = si->display, .profile_id = si->profile_id[0] ? si->profile_id : NULL,
                                .settings_json = si->settings_json, .seed = si->seed,
                                .uuid = si->uuid, .created_utc = si->created_utc,
                                .state = si->state, .tool_version = si->tool_version};
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

/* Thresholds are replaced whole (the source's are the session's result); artifacts of the
 * usual kinds are copied when the destination has none of that kind. */
static csf_status push_results(csf_store *src, csf_store *dst, int64_t sid, int64_t did,
                               csf_error *err)
{
    csf_threshold_row *th = NULL;
    size_t nth = 0;
    csf_status cs = csf_store_get_thresholds(src, sid, &th, &nth, err);
    if (cs == CSF_OK && nth > 0) cs = csf_store_put_thresholds(dst, did, th, nth, err);
    free(th);
    static const char *const kinds[] = {"csflut", "profile", "plot"};
    for (size_t k = 0; cs == CSF_OK && k < sizeof kinds / sizeof kinds[0]; k++) {
        void *b = NULL;
        size_t len = 0;
        char path[1024] = "";
        if (csf_store_get_artifact(dst, did, kinds[k], &b, &len, NULL, 0, err) == CSF_OK) {
            free(b);
            continue;
        }
        csf_error_clear(err);
        cs = csf_store_get_artifact(src, sid, kinds[k], &b, &len, path, sizeof path, err);
        if (cs == CSF_E_NOT_FOUND) {
            csf_error_clear(err);
            cs = CSF_OK;
            continue;
        }
        if (cs == CSF_OK) cs = csf_store_add_artifact(dst, did, kinds[k], path, b, len, err);
        free(b);
    }
    return cs;
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
    if (cs == CSF_OK) cs = dest_session(dst, &si, &did, &created, err);
    if (cs == CSF_OK) cs = push_trials(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_readings(src, dst, session_id, did, c, err);
    if (cs == CSF_OK) cs = push_results(src, dst, session_id, did, err);
    /* The copy takes the source's state once it has everything (and lets go of the claim a
     * new server session was made with), unless the destination's copy is already over. */
    csf_session_info di;
    if (cs == CSF_OK && !keep_state) cs = csf_store_get_session(dst, did, &di, err);
    if (cs == CSF_OK && !keep_state) {
        int over = !strcmp(di.state, "finished") || !strcmp(di.state, "aborted");
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
