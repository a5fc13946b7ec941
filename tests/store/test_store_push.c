/* csfcal sessions push: a station ran on its own SQLite file and sends its
 * sessions to the lab store later (a server under CSF_TEST_BACKEND=postgresql, another SQLite
 * file otherwise). Everything arrives as stored (trials with their frame intervals, readings,
 * thresholds, artifacts, person time, state); pushing again sends nothing (the person time is
 * raised to the source's, never added twice); a session that grew sends only the
 * new trials; a session from before schema v6 (no uuid) gets one and is not doubled either. */
#include <stdlib.h>
#include <string.h>

#include "results/store/store.h"
#include "results/store/push.h"
#include "store_test_util.h"
#include "tests/check.h"

static void add_trials(csf_store *s, int64_t sid, int from, int to, uint64_t seed)
{
    csf_error err;
    for (int i = from; i < to; i++) {
        csf_trial t = make_trial(sid, i, seed);
        double iv[2] = {1 / 60.0, 0.0001 * i};
        CHECK_INT_EQ(csf_store_add_trial_frames(s, &t, iv, 2, &err), CSF_OK);
    }
}

static void check_copy(csf_store *dst, int64_t did, int n, uint64_t seed)
{
    csf_error err;
    csf_trial *t = NULL;
    size_t nt = 0;
    CHECK_INT_EQ(csf_store_get_trials(dst, did, &t, &nt, &err), CSF_OK);
    CHECK_INT_EQ(nt, n);
    int same = nt == (size_t)n;
    for (size_t k = 0; same && k < nt; k++) {
        csf_trial want = make_trial(did, (int)k, seed);
        same = trials_equal(&t[k], &want);
    }
    CHECK_MSG(same, "pushed trials differ");
    free(t);
    double *fi = NULL;
    size_t nf = 0;
    CHECK_INT_EQ(csf_store_get_frame_intervals(dst, did, &fi, &nf, &err), CSF_OK);
    CHECK_INT_EQ(nf, 2 * (size_t)n);
    if (nf == 2 * (size_t)n && n > 3) CHECK_NEAR(fi[7], 0.0001 * 3, 0);
    free(fi);
}

static int64_t push(csf_store *src, csf_store *dst, int64_t sid, int sent, int present)
{
    csf_error err;
    csf_push_counts c;
    CHECK_INT_EQ(csf_store_push_session(src, dst, sid, &c, &err), CSF_OK);
    CHECK_INT_EQ(c.trials_sent, sent);
    CHECK_INT_EQ(c.trials_present, present);
    return c.dest_id;
}

static double person_of(csf_store *s, int64_t id)
{
    csf_error err;
    csf_session_info si;
    if (csf_store_get_session(s, id, &si, &err) != CSF_OK) return -1.0;
    double v = si.person_s;
    csf_session_info_free(&si);
    return v;
}

int main(void)
{
    test_pg_require();
    char dir[512], local[600], lab[1024];
    if (tmp_dir(dir, sizeof dir, "push") < 0) return 1;
    snprintf(local, sizeof local, "%s/station.sqlite", dir);
    if (test_store_location(dir, "lab.sqlite", lab, sizeof lab) < 0) return 1;
    csf_error err;
    csf_store *src = NULL, *dst = NULL;
    CHECK_INT_EQ(csf_store_open(local, &src, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_open(lab, &dst, &err), CSF_OK);
    if (!src || !dst) return CHECK_RESULT();

    /* The lab store already has a session of its own: ids differ between the stores. */
    int64_t other = 0, sid = 0, disp = 0;
    CHECK_INT_EQ(csf_store_begin_session(dst, CSF_SESSION_OBSERVER, "someone", "lcd", NULL, 1, &other, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(dst, other, CSF_SESSION_FINISHED, &err), CSF_OK);
    CHECK_INT_EQ(
        csf_store_begin_session(src, CSF_SESSION_OBSERVER, "p7", "booth-lcd", "{\"a\":1}", 42, &sid, &err),
        CSF_OK);
    add_trials(src, sid, 0, 30, 42);
    csf_threshold_row rows[2] = {{4.0, 0.0, 0.0, 50.0, 0.004, 0.05, 30},
                                 {32.0, 0.0, 0.0, 50.0, INFINITY, NAN, 12}};
    CHECK_INT_EQ(csf_store_put_thresholds(src, sid, rows, 2, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(src, sid, "csflut", "/tmp/p7.csflut", "LUTBYTES", 8, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(src, sid, 600.5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(src, sid, CSF_SESSION_PAUSED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_DISPLAY, NULL, "booth-lcd", NULL, 5, &disp, &err),
                 CSF_OK);
    for (int k = 0; k < 4; k++) {
        csf_reading r;
        memset(&r, 0, sizeof r);
        r.session_id = disp;
        r.seq = k;
        snprintf(r.channel, sizeof r.channel, "grey");
        r.drive01 = k / 3.0;
        r.lum_cdm2 = 0.5 + 30.0 * k;
        r.status = CSF_READING_OK;
        CHECK_INT_EQ(csf_store_add_reading(src, &r, &err), CSF_OK);
    }

    /* Two artifacts of one kind and one of another kind: every one arrives, once. */
    CHECK_INT_EQ(csf_store_add_artifact(src, sid, "plot", "/tmp/p7-a.png", "PNGA", 4, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(src, sid, "plot", "/tmp/p7-b.png", "PNGBB", 5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(src, sid, "notes", "/tmp/p7.txt", NULL, 0, &err), CSF_OK);
    /* The session belongs to a study participant; the lab store already knows the study (made
     * by another station) but not the participant. */
    int64_t study = 0, part = 0, lab_study = 0;
    CHECK_INT_EQ(csf_store_create_study(src, "pushed-study", "{\"design\":2}", &study, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_participant(src, study, "P7", &part, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_link_session_participant(src, sid, part, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_create_study(dst, "pushed-study", "{\"design\":2}", &lab_study, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_participant(dst, lab_study, "P1", NULL, &err), CSF_OK);

    int64_t did = push(src, dst, sid, 30, 0);
    CHECK(did != 0 && did != other);
    check_copy(dst, did, 30, 42);
    csf_session_info a, b;
    CHECK_INT_EQ(csf_store_get_session(src, sid, &a, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_get_session(dst, did, &b, &err), CSF_OK);
    CHECK(!strcmp(a.uuid, b.uuid) && strlen(a.uuid) == 36);
    CHECK(b.state == CSF_SESSION_PAUSED && !strcmp(b.observer, "p7") && b.seed == 42);
    CHECK(!strcmp(a.created_utc, b.created_utc) && !strcmp(b.settings_json, "{\"a\":1}"));
    CHECK_NEAR(b.person_s, 600.5, 0);
    csf_session_info_free(&a);
    csf_session_info_free(&b);
    csf_threshold_row *th = NULL;
    size_t nth = 0;
    CHECK_INT_EQ(csf_store_get_thresholds(dst, did, &th, &nth, &err), CSF_OK);
    CHECK_INT_EQ(nth, 2);
    if (nth == 2) CHECK(isinf(th[1].threshold) && isnan(th[1].stderr_log10));
    free(th);
    void *blob = NULL;
    size_t len = 0;
    char path[256];
    CHECK_INT_EQ(csf_store_get_artifact(dst, did, "csflut", &blob, &len, path, sizeof path, &err), CSF_OK);
    CHECK(len == 8 && blob && !memcmp(blob, "LUTBYTES", 8) && !strcmp(path, "/tmp/p7.csflut"));
    free(blob);

    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM artifacts"), 4);
    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM artifacts WHERE kind = 'plot'"), 2);
    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM artifacts WHERE kind = 'notes'"
                                          " AND path = '/tmp/p7.txt' AND content IS NULL"), 1);
    char lq[256];
    snprintf(lq, sizeof lq, "SELECT p.study_id FROM session_participants sp JOIN participants p ON"
             " p.id = sp.participant_id WHERE sp.session_id = %lld AND p.code = 'P7'", (long long)did);
    CHECK_INT_EQ(test_query_int(dst, lab, lq), lab_study);
    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM studies"), 1);
    int np = 0;
    CHECK_INT_EQ(csf_store_count_participants(dst, lab_study, &np, &err), CSF_OK);
    CHECK_INT_EQ(np, 2);

    /* Again: nothing new. Grown: only the new trials. */
    CHECK_INT_EQ(push(src, dst, sid, 0, 30), did);
    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM artifacts"), 4);
    CHECK_INT_EQ(test_query_int(dst, lab, "SELECT COUNT(*) FROM session_participants"), 1);
    CHECK_INT_EQ(csf_store_count_participants(dst, lab_study, &np, &err), CSF_OK);
    CHECK_INT_EQ(np, 2);
    CHECK_NEAR(person_of(dst, did), 600.5, 0); /* raised to the source's, not added again */
    CHECK_INT_EQ(csf_store_set_session_state(src, sid, CSF_SESSION_RUNNING, &err), CSF_OK);
    add_trials(src, sid, 30, 45, 42);
    CHECK_INT_EQ(csf_store_add_person_time(src, sid, 120.25, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(src, sid, CSF_SESSION_FINISHED, &err), CSF_OK);
    CHECK_INT_EQ(push(src, dst, sid, 15, 30), did);
    check_copy(dst, did, 45, 42);
    CHECK_NEAR(person_of(dst, did), 720.75, 0);    /* the second run's time arrives before the finish */
    CHECK_INT_EQ(push(src, dst, sid, 0, 45), did); /* a finished copy that has it: nothing to do */
    CHECK_NEAR(person_of(dst, did), 720.75, 0);
    csf_push_counts c;
    CHECK_INT_EQ(csf_store_push_session(src, dst, disp, &c, &err), CSF_OK);
    CHECK_INT_EQ(c.readings_sent, 4);
    CHECK_INT_EQ(csf_store_push_session(src, dst, disp, &c, &err), CSF_OK);
    CHECK_INT_EQ(c.readings_sent, 0);
    CHECK_INT_EQ(c.readings_present, 4);
    CHECK(isnan(person_of(dst, c.dest_id))); /* none given: none made up */

    /* A session stored before v6 has no uuid: it gets one on the first push, kept after. */
    int64_t old = 0;
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_OBSERVER, "old", "lcd", NULL, 9, &old, &err),
                 CSF_OK);
    add_trials(src, old, 0, 5, 9);
    char q[128];
    snprintf(q, sizeof q, "UPDATE sessions SET uuid = NULL WHERE id = %lld", (long long)old);
    CHECK_INT_EQ(sqlite3_exec(csf_store_db(src), q, NULL, NULL, NULL), SQLITE_OK);
    int64_t dold = push(src, dst, old, 5, 0);
    CHECK_INT_EQ(push(src, dst, old, 0, 5), dold);

    /* Aborted before anything was measured: not made on the destination (it would list a
     * phantom); once the destination has it (pushed while running), the abort reaches it. */
    int64_t empty = 0, empty2 = 0;
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_OBSERVER, "gone", "lcd", NULL, 3, &empty, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(src, empty, CSF_SESSION_ABORTED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_push_session(src, dst, empty, &c, &err), CSF_OK);
    CHECK(c.skipped_empty && c.dest_id == 0);
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_OBSERVER, "left", "lcd", NULL, 4, &empty2, &err),
                 CSF_OK);
    CHECK_INT_EQ(push(src, dst, empty2, 0, 0) > 0, 1);
    CHECK_INT_EQ(csf_store_set_session_state(src, empty2, CSF_SESSION_ABORTED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_push_session(src, dst, empty2, &c, &err), CSF_OK);
    CHECK(!c.skipped_empty && c.dest_id > 0);
    csf_session_info es;
    CHECK_INT_EQ(csf_store_get_session(dst, c.dest_id, &es, &err), CSF_OK);
    CHECK(es.state == CSF_SESSION_ABORTED);
    csf_session_info_free(&es);

    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(dst, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, 5); /* its own, and four pushed once each (not the empty aborted one) */
    csf_session_list_free(list, n);
    csf_store_close(src);
    csf_store_close(dst);
    rm_rf(dir);
    return CHECK_RESULT();
}
