/* Store round trips: every field of every entity comes back as written, after closing and
 * reopening; ordering by seq; refusals (duplicate seq, unknown session, bad kind/state/channel);
 * a session's person time added up over its runs and refused when bad or closed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "results/store/store.h"
#include "results/store/internal.h"
#include "store_test_util.h"
#include "tests/check.h"

/* The server's form of the portable schema: only BIGINT/INTEGER, DOUBLE PRECISION (never the
 * 4-byte REAL, which would round every value), TEXT and BYTEA; and the backend is the server's. */
static void check_pg_schema(csf_store *s, const char *path)
{
    CHECK(!strcmp(csf_store_backend(s), "postgresql"));
    long long cols = test_query_int(s, path, "SELECT COUNT(*) FROM information_schema.columns"
                                              " WHERE table_schema = current_schema()");
    long long odd = test_query_int(s, path, "SELECT COUNT(*) FROM information_schema.columns"
                                             " WHERE table_schema = current_schema() AND data_type"
                                             " NOT IN ('bigint', 'integer', 'double precision',"
                                             " 'text', 'bytea')");
    CHECK(cols > 60);
    CHECK_INT_EQ(odd, 0);
}

static void test_sessions_trials(const char *path)
{
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) {
        fprintf(stderr, "open failed: %s\n", err.msg);
        return;
    }
    CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);

    int64_t obs = 0, disp = 0;
    const char *settings = "{\"freqs_cpd\":[1,2,4,8],\"method\":\"fade\"}";
    const uint64_t big_seed = 0xfedcba9876543210ULL; /* above INT64_MAX: must round-trip */
    CHECK_INT_EQ(
        csf_store_begin_session(s, CSF_SESSION_OBSERVER, "alice", "lcd-1", settings, big_seed, &obs, &err),
        CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, "lcd-1", NULL, 7, &disp, &err),
                 CSF_OK);
    CHECK(obs > 0 && disp > 0 && obs != disp);

    /* Insert out of order: get_trials must come back ordered by seq (what resume replays). */
    const int n = 40;
    for (int k = 0; k < n; k++) {
        int seq = (k * 17) % n; /* a permutation of 0..n-1 since gcd(17, 40) = 1 */
        csf_trial t = make_trial(obs, seq, 99);
        CHECK_INT_EQ(csf_store_add_trial(s, &t, &err), CSF_OK);
    }
    /* Duplicate seq is refused with a message, not silently replaced. */
    csf_trial dup = make_trial(obs, 5, 123);
    CHECK_INT_EQ(csf_store_add_trial(s, &dup, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "trial 5");
    /* Unknown session is refused (foreign key). */
    csf_trial orphan = make_trial(obs + 1000, 0, 1);
    CHECK(csf_store_add_trial(s, &orphan, &err) != CSF_OK);
    /* Non-finite frequency refused. */
    csf_trial badf = make_trial(obs, 500, 1);
    badf.freq_cpd = NAN;
    CHECK_INT_EQ(csf_store_add_trial(s, &badf, &err), CSF_E_INVALID_ARG);

    double iv[5] = {1 / 60.0, 1 / 60.0, 2 / 60.0, 1 / 60.0, 0.0171};
    CHECK_INT_EQ(csf_store_add_frame_intervals(s, obs, 0, iv, 5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_frame_intervals(s, obs, 1, iv, 3, &err), CSF_OK);
    CHECK(csf_store_add_frame_intervals(s, obs, 1, iv, 3, &err) != CSF_OK); /* already stored */

    for (int k = 0; k < 6; k++) {
        csf_reading r;
        memset(&r, 0, sizeof r);
        r.session_id = disp;
        r.seq = k;
        snprintf(r.channel, sizeof r.channel, "%s", k == 0 ? "dark" : k < 3 ? "grey" : "r");
        r.drive01 = k / 5.0;
        r.lum_cdm2 = k == 5 ? NAN : 0.2 + 100.0 * pow(k / 5.0, 2.2);
        r.has_xyz = k % 2;
        r.X = 0.95 * r.lum_cdm2;
        r.Y = r.lum_cdm2;
        r.Z = 1.08 * r.lum_cdm2;
        r.t_s = 1.5 * k;
        r.status = k == 5 ? CSF_READING_TIMEOUT : CSF_READING_OK;
        CHECK_INT_EQ(csf_store_add_reading(s, &r, &err), CSF_OK);
    }
    csf_reading badr;
    memset(&badr, 0, sizeof badr);
    badr.session_id = disp;
    badr.seq = 10;
    snprintf(badr.channel, sizeof badr.channel, "uv");
    badr.status = CSF_READING_OK;
    CHECK_INT_EQ(csf_store_add_reading(s, &badr, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "channel");
    /* a good channel with a status no reading can be stored with */
    snprintf(badr.channel, sizeof badr.channel, "white");
    badr.status = CSF_READING_STATUS_UNKNOWN;
    CHECK_INT_EQ(csf_store_add_reading(s, &badr, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "ok, too_dark, saturated, timeout or error");
    badr.status = (csf_reading_status)42;
    CHECK_INT_EQ(csf_store_add_reading(s, &badr, &err), CSF_E_INVALID_ARG);

    csf_threshold_row rows[3] = {
        {4.0, 0.0, 0.0, 50.0, 0.004, 0.05, 30},
        {1.0, 0.0, 0.0, 50.0, 0.01, NAN, 25},
        {32.0, 10.0, 0.0, 50.0, INFINITY, 0.2, 12},
    };
    CHECK_INT_EQ(csf_store_put_thresholds(s, obs, rows, 3, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_put_thresholds(s, obs, rows, 3, &err), CSF_OK); /* replaces, not appends */
    CHECK_INT_EQ(csf_store_put_thresholds(s, 99999, rows, 1, &err), CSF_E_NOT_FOUND);

    const char blob[] = "csfcal-display-profile 1\nx = 1\n";
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "/tmp/p1.txt", "old", 3, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "/tmp/p2.txt", blob, sizeof blob - 1, &err), CSF_OK);
    /* A stored display profile becomes the display's current profile, with history. */
    const char prof[] = "csfcal-display-profile 1\n# comment\nid = lab-lcd-20261122-0badf00d\n"
                        "display = lab-lcd\ncreated_utc = 2026-11-22T06:00:00Z\n";
    char pid[128];
    CHECK_INT_EQ(csf_store_display_profile_id(s, "lab-lcd", pid, sizeof pid, &err), CSF_E_NOT_FOUND);
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "lab.profile", prof, sizeof prof - 1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_display_profile_id(s, "lab-lcd", pid, sizeof pid, &err), CSF_OK);
    CHECK(!strcmp(pid, "lab-lcd-20261122-0badf00d"));
    {
        char q[256];
        snprintf(q, sizeof q, "SELECT COUNT(*) FROM display_profiles p JOIN displays d"
                 " ON d.id = p.display_id WHERE d.name = 'lab-lcd' AND p.session_id = %lld",
                 (long long)disp);
        CHECK_INT_EQ(test_query_int(s, path, q), 1);
    }
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "/tmp/p2.txt", blob, sizeof blob - 1, &err), CSF_OK);
    /* A later path-only record (file written elsewhere) does not hide the stored bytes. */
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "/tmp/p3.txt", NULL, 0, &err), CSF_OK);
    CHECK(csf_store_add_artifact(s, 424242, "plot", "x.png", "a", 1, &err) != CSF_OK);

    CHECK_INT_EQ(csf_store_set_session_state(s, obs, CSF_SESSION_PAUSED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(s, disp, CSF_SESSION_FINISHED, &err), CSF_OK);
    /* A value outside the enum (a cast from bad data) and the unknown value are never stored. */
    CHECK_INT_EQ(csf_store_set_session_state(s, obs, (csf_session_state)99, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "running, paused, finished, aborted");
    CHECK_INT_EQ(csf_store_set_session_state(s, obs, CSF_SESSION_STATE_UNKNOWN, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_store_set_session_state(s, 99999, CSF_SESSION_FINISHED, &err), CSF_E_NOT_FOUND);
    int64_t bad = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, (csf_session_kind)-1, NULL, NULL, NULL, 1, &bad, &err),
                 CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_KIND_UNKNOWN, NULL, NULL, NULL, 1, &bad, &err),
                 CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "display, observer, study");

    int64_t study = 0, p1 = 0, p2 = 0, found = 0;
    CHECK_INT_EQ(csf_store_create_study(s, "lod-2afc", "{\"conditions\":4}", &study, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_create_study(s, "lod-2afc", NULL, NULL, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_store_find_study(s, "lod-2afc", &found, &err), CSF_OK);
    CHECK_INT_EQ(found, study);
    CHECK_INT_EQ(csf_store_find_study(s, "nope", &found, &err), CSF_E_NOT_FOUND);
    CHECK_INT_EQ(csf_store_add_participant(s, study, "P01", &p1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_participant(s, study, "P02", &p2, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_participant(s, study, "P01", NULL, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_store_add_participant(s, study + 50, "P09", NULL, &err), CSF_E_INVALID_ARG);
    int np = 0;
    CHECK_INT_EQ(csf_store_count_participants(s, study, &np, &err), CSF_OK);
    CHECK_INT_EQ(np, 2);
    int64_t st_sess = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_STUDY, "P01", "lcd-1", NULL, 3, &st_sess, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_link_session_participant(s, st_sess, p1, &err), CSF_OK);
    CHECK(csf_store_link_session_participant(s, st_sess, p2, &err) != CSF_OK);
    /* Long display names (profile ids) are kept in full, and read back whole. */
    char longname[200];
    memset(longname, 'x', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    int64_t long_sess = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, longname, NULL, 1, &long_sess, &err),
                 CSF_OK);
    csf_session_info li;
    CHECK_INT_EQ(csf_store_get_session(s, long_sess, &li, &err), CSF_OK);
    CHECK_INT_EQ(strlen(li.display), sizeof longname - 1);
    csf_session_info_free(&li);
    CHECK_INT_EQ(csf_store_set_session_state(s, long_sess, CSF_SESSION_ABORTED, &err), CSF_OK);
    int64_t d1 = 0, d2 = 0;
    CHECK_INT_EQ(csf_store_upsert_display(s, "lcd-1", "lcd-1-2026-11-22-abcd", &d1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_upsert_display(s, "lcd-1", NULL, &d2, &err), CSF_OK);
    CHECK_INT_EQ(d1, d2);
    csf_store_close(s);

    /* Everything survives a close and reopen. */
    s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return;
    csf_trial *trials = NULL;
    size_t nt = 0;
    CHECK_INT_EQ(csf_store_get_trials(s, obs, &trials, &nt, &err), CSF_OK);
    CHECK_INT_EQ(nt, n);
    int all_equal = 1;
    for (size_t i = 0; i < nt; i++) {
        csf_trial want = make_trial(obs, (int)i, 99);
        if (trials[i].seq != (int)i || !trials_equal(&trials[i], &want)) {
            all_equal = 0;
            fprintf(stderr, "trial %zu differs (seq %d)\n", i, trials[i].seq);
            break;
        }
    }
    CHECK(all_equal);
    free(trials);

    csf_reading *rd = NULL;
    size_t nr = 0;
    CHECK_INT_EQ(csf_store_get_readings(s, disp, &rd, &nr, &err), CSF_OK);
    CHECK_INT_EQ(nr, 6);
    if (nr == 6) {
        CHECK(!strcmp(rd[0].channel, "dark") && !strcmp(rd[3].channel, "r"));
        CHECK_NEAR(rd[4].lum_cdm2, 0.2 + 100.0 * pow(0.8, 2.2), 1e-12);
        CHECK(isnan(rd[5].lum_cdm2));
        CHECK(rd[5].status == CSF_READING_TIMEOUT);
        CHECK(rd[1].has_xyz && !rd[2].has_xyz);
        CHECK_NEAR(rd[1].Z, 1.08 * rd[1].lum_cdm2, 1e-12);
        CHECK_NEAR(rd[4].t_s, 6.0, 0);
    }
    free(rd);

    double *fi = NULL;
    size_t nf = 0;
    CHECK_INT_EQ(csf_store_get_frame_intervals(s, obs, &fi, &nf, &err), CSF_OK);
    CHECK_INT_EQ(nf, 8);
    if (nf == 8) {
        CHECK_NEAR(fi[2], 2 / 60.0, 0);
        CHECK_NEAR(fi[4], 0.0171, 0);
        CHECK_NEAR(fi[7], 2 / 60.0, 0);
    }
    free(fi);

    csf_threshold_row *th = NULL;
    size_t nth = 0;
    CHECK_INT_EQ(csf_store_get_thresholds(s, obs, &th, &nth, &err), CSF_OK);
    CHECK_INT_EQ(nth, 3);
    if (nth == 3) { /* ordered by ecc then freq */
        CHECK_NEAR(th[0].freq_cpd, 1.0, 0);
        CHECK(isnan(th[0].stderr_log10));
        CHECK_NEAR(th[1].threshold, 0.004, 0);
        CHECK_INT_EQ(th[1].n_trials, 30);
        CHECK(isinf(th[2].threshold) && th[2].threshold > 0);
    }
    free(th);

    void *b = NULL;
    size_t bl = 0;
    char apath[256];
    CHECK_INT_EQ(csf_store_get_artifact(s, disp, "profile", &b, &bl, apath, sizeof apath, &err), CSF_OK);
    CHECK_INT_EQ(bl, sizeof blob - 1);
    CHECK(b && memcmp(b, blob, bl) == 0 && ((char *)b)[bl] == '\0');
    CHECK(!strcmp(apath, "/tmp/p2.txt"));
    free(b);
    CHECK_INT_EQ(csf_store_get_artifact(s, obs, "csflut", &b, &bl, NULL, 0, &err), CSF_E_NOT_FOUND);

    csf_session_info info;
    CHECK_INT_EQ(csf_store_get_session(s, obs, &info, &err), CSF_OK);
    CHECK(info.kind == CSF_SESSION_OBSERVER && info.state == CSF_SESSION_PAUSED);
    CHECK(!strcmp(info.observer, "alice") && !strcmp(info.display, "lcd-1"));
    CHECK(!strcmp(info.settings_json, settings));
    CHECK(info.seed == big_seed);
    CHECK_INT_EQ(info.n_trials, n);
    CHECK_INT_EQ(info.n_readings, 0);
    CHECK(!strcmp(info.tool_version, CSF_VERSION));
    CHECK(strlen(info.created_utc) == 20 && info.created_utc[19] == 'Z');
    csf_session_info_free(&info);
    CHECK_INT_EQ(csf_store_get_session(s, 4242, &info, &err), CSF_E_NOT_FOUND);

    csf_session_info *list = NULL;
    size_t nl = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &nl, &err), CSF_OK);
    CHECK_INT_EQ(nl, 4);
    if (nl == 4) {
        CHECK(list[0].id == obs && list[1].id == disp && list[2].id == st_sess);
        CHECK_INT_EQ(list[1].n_readings, 6);
        CHECK(list[1].state == CSF_SESSION_FINISHED && !strcmp(list[1].settings_json, "{}"));
        CHECK(list[2].kind == CSF_SESSION_STUDY && list[2].state == CSF_SESSION_RUNNING);
    }
    csf_session_list_free(list, nl);

    char created[32], updated[32];
    CHECK_INT_EQ(csf_store_session_times(s, obs, created, updated, &err), CSF_OK);
    CHECK(strcmp(updated, created) >= 0);

    if (test_pg()) {
        check_pg_schema(s, path);
        csf_store_close(s);
        return;
    }
    /* Durability settings as promised in the contract. */
    sqlite3 *db = csf_store_db(s);
    sqlite3_stmt *st = NULL;
    sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &st, NULL);
    CHECK(sqlite3_step(st) == SQLITE_ROW && !strcmp((const char *)sqlite3_column_text(st, 0), "wal"));
    sqlite3_finalize(st);
    sqlite3_prepare_v2(db, "PRAGMA synchronous", -1, &st, NULL);
    CHECK(sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) == 2); /* FULL */
    sqlite3_finalize(st);
    sqlite3_prepare_v2(db, "PRAGMA foreign_keys", -1, &st, NULL);
    CHECK(sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) == 1);
    sqlite3_finalize(st);
    /* Portable schema: only INTEGER, REAL, TEXT, BLOB column types. */
    sqlite3_prepare_v2(db, "SELECT m.name, p.type FROM sqlite_master m, pragma_table_info(m.name) p "
                           "WHERE m.type = 'table'", -1, &st, NULL);
    int cols = 0, odd = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        const char *ty = (const char *)sqlite3_column_text(st, 1);
        cols++;
        if (strcmp(ty, "INTEGER") && strcmp(ty, "REAL") && strcmp(ty, "TEXT") && strcmp(ty, "BLOB")) {
            odd++;
            fprintf(stderr, "non-portable column type %s in %s\n", ty, sqlite3_column_text(st, 0));
        }
    }
    sqlite3_finalize(st);
    CHECK(cols > 60);
    CHECK_INT_EQ(odd, 0);
    csf_store_close(s);
}

/* Person time: the runs of a session add up, on either backend and after reopening; bad values
 * are refused naming the value and the limit, and leave the stored time as it was; a finished
 * or aborted session is closed to it; a session nobody gave any reads NaN. */
static double person_of(csf_store *s, int64_t id)
{
    csf_error err;
    csf_session_info si;
    if (csf_store_get_session(s, id, &si, &err) != CSF_OK) return -1.0;
    double v = si.person_s;
    csf_session_info_free(&si);
    return v;
}

static void test_person_time(const char *path)
{
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return;
    int64_t a = 0, b = 0, c = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "pt", "lcd", NULL, 11, &a, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_STUDY, "P3", "lcd", NULL, 12, &b, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "pt2", "lcd", NULL, 13, &c, &err), CSF_OK);
    CHECK(isnan(person_of(s, a)));
    CHECK_INT_EQ(csf_store_add_person_time(s, a, 90.25, &err), CSF_OK);
    CHECK_NEAR(person_of(s, a), 90.25, 0);
    /* a second run of the session (paused, then resumed) adds its own */
    CHECK_INT_EQ(csf_store_set_session_state(s, a, CSF_SESSION_PAUSED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, a, 167.5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(s, a, CSF_SESSION_RUNNING, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, a, 0.0, &err), CSF_OK);
    CHECK_NEAR(person_of(s, a), 257.75, 0);
    CHECK(isnan(person_of(s, b)));

    /* bad values: refused with the value and the limit, nothing stored */
    const double bad[] = {NAN, INFINITY, -INFINITY, -0.5, CSF_STORE_PERSON_S_MAX * 1.0001};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK_INT_EQ(csf_store_add_person_time(s, a, bad[i], &err), CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(err.msg, "1e+06 s");
    }
    CHECK_INT_EQ(csf_store_add_person_time(s, a, -0.5, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "negative");
    CHECK_INT_EQ(csf_store_add_person_time(s, a, 2e6, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "past the limit");
    CHECK_NEAR(person_of(s, a), 257.75, 0);
    CHECK_INT_EQ(csf_store_add_person_time(s, b, CSF_STORE_PERSON_S_MAX, &err),
                 CSF_OK); /* the limit itself */
    CHECK_NEAR(person_of(s, b), CSF_STORE_PERSON_S_MAX, 0);
    CHECK_INT_EQ(csf_store_add_person_time(s, 999999, 5.0, &err), CSF_E_NOT_FOUND);
    CHECK_INT_EQ(csf_store_add_person_time(NULL, a, 5.0, &err), CSF_E_INVALID_ARG);

    /* closed sessions keep what they have */
    CHECK_INT_EQ(csf_store_set_session_state(s, a, CSF_SESSION_FINISHED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, a, 10.0, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "finished and closed");
    CHECK_NEAR(person_of(s, a), 257.75, 0);
    CHECK_INT_EQ(csf_store_set_session_state(s, c, CSF_SESSION_ABORTED, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, c, 10.0, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "aborted and closed");
    CHECK(isnan(person_of(s, c)));
    csf_store_close(s);

    /* kept, and listed, after reopening; a read-only store refuses to add */
    s = NULL;
    CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_OK);
    if (!s) return;
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    int seen = 0;
    for (size_t i = 0; i < n; i++) {
        if (list[i].id == a) seen += list[i].person_s == 257.75;
        if (list[i].id == b) seen += list[i].person_s == CSF_STORE_PERSON_S_MAX;
        if (list[i].id == c) seen += isnan(list[i].person_s);
    }
    CHECK_INT_EQ(seen, 3);
    csf_session_list_free(list, n);
    CHECK_INT_EQ(csf_store_add_person_time(s, b, 1.0, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "read-only");
    csf_store_close(s);
}

/* The server's refusals: a database without a store is not one to read, and a read-only store
 * refuses writes with the same words as a read-only file. */
static void test_pg_open(const char *path)
{
    csf_error err;
    csf_store *s = NULL;
    char empty[1024];
    CHECK_INT_EQ(test_store_location("", "", empty, sizeof empty), 0);
    CHECK_INT_EQ(csf_store_open_readonly(empty, &s, &err), CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(err.msg, "no csfcal store");
    CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_OK);
    if (s) {
        csf_session_info *list = NULL;
        size_t nl = 0;
        CHECK_INT_EQ(csf_store_list_sessions(s, &list, &nl, &err), CSF_OK);
        CHECK_INT_EQ(nl, 4);
        csf_session_list_free(list, nl);
        int64_t id = 0;
        CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "x", "y", NULL, 1, &id, &err),
                     CSF_E_STORE);
        CHECK_STR_CONTAINS(err.msg, "read-only");
        csf_store_close(s);
    }
    /* A server that is not there: refused at open, with what to do instead. */
    CHECK_INT_EQ(csf_store_open("postgresql:///csfcal?host=/nonexistent-socket-dir", &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "cannot connect");
    CHECK_STR_CONTAINS(err.msg, "sessions push");
}

int main(void)
{
    char dir[512], path[1024];
    test_pg_require();
    if (tmp_dir(dir, sizeof dir, "basic") < 0) return 1;
    if (test_store_location(dir, "store.sqlite", path, sizeof path) < 0) return 1;
    test_sessions_trials(path);
    char person[1024];
    if (test_store_location(dir, "person.sqlite", person, sizeof person) < 0) return 1;
    test_person_time(person);
    if (test_pg()) {
        test_pg_open(path);
        rm_rf(dir);
        return CHECK_RESULT();
    }

    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open("", &s, &err), CSF_E_INVALID_ARG);
    CHECK(s == NULL);
    CHECK_INT_EQ(csf_store_open(dir, &s, &err), CSF_E_STORE); /* a folder */
    CHECK_STR_CONTAINS(err.msg, "folder");
    snprintf(path, sizeof path, "%s/no/such/dir/store.sqlite", dir);
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "does not exist");
    /* Read-only opening: a missing file is not created; an existing store reads, refuses writes. */
    snprintf(path, sizeof path, "%s/never-created.sqlite", dir);
    CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(err.msg, "does not exist");
    CHECK(access(path, F_OK) != 0);
    snprintf(path, sizeof path, "%s/store.sqlite", dir);
    CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_OK);
    if (s) {
        csf_session_info *list = NULL;
        size_t nl = 0;
        CHECK_INT_EQ(csf_store_list_sessions(s, &list, &nl, &err), CSF_OK);
        CHECK_INT_EQ(nl, 4);
        csf_session_list_free(list, nl);
        int64_t id = 0;
        CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "x", "y", NULL, 1, &id, &err),
                     CSF_E_STORE);
        CHECK_STR_CONTAINS(err.msg, "read-only");
        csf_trial t = make_trial(1, 1000, 1);
        CHECK_INT_EQ(csf_store_add_trial(s, &t, &err), CSF_E_STORE);
        csf_store_close(s);
    }
    rm_rf(dir);
    return CHECK_RESULT();
}
