/* Schema migration: a store written by schema version 1 (fixture SQL script) is opened by this
 * build, migrated forward, keeps every old row, and takes the new fields; so does one of the
 * previous version (6), whose sessions read an unknown person time. A newer schema and a
 * foreign SQLite database are refused; a failing migration step leaves the old version intact. */
#include <stdlib.h>
#include <string.h>

#include "results/store/store.h"
#include "results/store/internal.h"
#include "results/store/migrations.h"
#include "store_test_util.h"
#include "tests/check.h"

static int raw_version(const char *path)
{
    sqlite3 *db = NULL;
    int v = -1;
    if (sqlite3_open(path, &db) == SQLITE_OK) {
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(db, "SELECT MAX(version) FROM schema_version", -1, &st, NULL) == SQLITE_OK &&
            sqlite3_step(st) == SQLITE_ROW)
            v = sqlite3_column_int(st, 0);
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return v;
}

/* Schema v7 (the v1 fixture through the real steps 1 to 6): opening it adds trials.onset_s,
 * NULL (no onset recorded) for every trial stored before; a new trial's onset reads back, and
 * one that is no time on the session's clock is refused. */
static void test_from_v7(const char *dir, const char *v1_sql)
{
    char path[600];
    snprintf(path, sizeof path, "%s/v7.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, v1_sql), 0);
    for (int v = 1; v < 7; v++) {
        char upd[64];
        snprintf(upd, sizeof upd, "UPDATE schema_version SET version = %d", v + 1);
        CHECK_INT_EQ(test_sqlite_exec(path, csf_store_migrations[v]), 0);
        CHECK_INT_EQ(test_sqlite_exec(path, upd), 0);
    }
    CHECK_INT_EQ(raw_version(path), 7);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return;
    CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
    int old = test_query_int(s, path, "SELECT COUNT(*) FROM trials");
    CHECK(old > 0);
    CHECK_INT_EQ(test_query_int(s, path, "SELECT COUNT(*) FROM trials WHERE onset_s IS NULL"), old);
    csf_trial *t = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_get_trials(s, 2, &t, &n, &err), CSF_OK);
    for (size_t k = 0; k < n; k++) CHECK(!t[k].has_onset && t[k].onset_s == 0);
    free(t);
    csf_trial a = make_trial(2, 90, 3);
    a.has_onset = 1;
    a.onset_s = 12.5;
    CHECK_INT_EQ(csf_store_add_trial(s, &a, &err), CSF_OK);
    a.seq = 91;
    a.onset_s = -1;
    CHECK_INT_EQ(csf_store_add_trial(s, &a, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "trial 91 has onset -1 s");
    CHECK_INT_EQ(csf_store_get_trials(s, 2, &t, &n, &err), CSF_OK);
    int found = 0;
    for (size_t k = 0; k < n; k++)
        if (t[k].seq == 90) found = t[k].has_onset && t[k].onset_s == 12.5;
    CHECK(found);
    free(t);
    csf_store_close(s);
}

/* The previous schema (v6), made as a v6 csfcal made it: the v1 fixture taken through the real
 * migration steps 1 to 5, plus a session a v6 build stored (with a uuid). Opening it adds
 * person_s, NULL for every session stored before; the new column takes what the runs add and
 * refuses a negative value written past csfcal. */
static void test_from_v6(const char *dir, const char *v1_sql)
{
    char path[600];
    snprintf(path, sizeof path, "%s/v6.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, v1_sql), 0);
    for (int v = 1; v < 6; v++) {
        char upd[64];
        snprintf(upd, sizeof upd, "UPDATE schema_version SET version = %d", v + 1);
        CHECK_INT_EQ(test_sqlite_exec(path, csf_store_migrations[v]), 0);
        CHECK_INT_EQ(test_sqlite_exec(path, upd), 0);
    }
    CHECK_INT_EQ(test_sqlite_exec(path, "INSERT INTO sessions (id, kind, state, observer, display,"
                                        " settings_json, seed, tool_version, created_utc, updated_utc, uuid)"
                                        " VALUES (3, 'study', 'running', 'P1', 'lab-crt', '{}', 5, '0.6.0',"
                                        " '2026-11-01T10:00:00Z', '2026-11-01T10:20:00Z',"
                                        " '0b7f5e52-3c1e-4a51-9d2f-6f0e8c1d2a3b')"),
                 0);
    CHECK_INT_EQ(raw_version(path), 6);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return;
    CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
    CHECK_INT_EQ(test_query_int(s, path, "SELECT COUNT(*) FROM sessions WHERE person_s IS NULL"), 3);
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, 3);
    for (size_t i = 0; i < n; i++) CHECK(isnan(list[i].person_s));
    if (n == 3) CHECK(!strcmp(list[2].uuid, "0b7f5e52-3c1e-4a51-9d2f-6f0e8c1d2a3b"));
    csf_session_list_free(list, n);
    /* the paused v1 session and the running v6 one take person time; the finished one does not */
    CHECK_INT_EQ(csf_store_add_person_time(s, 2, 30.5, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, 3, 600.0, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, 3, 45.0, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_person_time(s, 1, 1.0, &err), CSF_E_STORE);
    CHECK_INT_EQ(test_query_int(s, path, "SELECT CAST(person_s * 100 AS INTEGER) FROM sessions WHERE id = 3"),
                 64500);
    CHECK_INT_EQ(test_query_int(s, path, "SELECT COUNT(*) FROM sessions WHERE person_s IS NULL"), 1);
    csf_store_close(s);
    CHECK_INT_EQ(raw_version(path), CSF_STORE_SCHEMA_VERSION);
    CHECK(test_sqlite_exec(path, "UPDATE sessions SET person_s = -1 WHERE id = 2") != SQLITE_OK);
}

int main(void)
{
    const char *fx = getenv("CSF_STORE_FIXTURES");
    char fixture[600];
    snprintf(fixture, sizeof fixture, "%s/schema_v1.sql", fx ? fx : "tests/store/fixtures");
    char *sql = test_read_file(fixture, NULL);
    CHECK_MSG(sql != NULL, "cannot read %s", fixture);
    if (!sql) return CHECK_RESULT();

    char dir[512], path[600];
    if (tmp_dir(dir, sizeof dir, "migrate") < 0) return 1;
    snprintf(path, sizeof path, "%s/v1.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), 0);
    CHECK_INT_EQ(raw_version(path), 1);

    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) {
        fprintf(stderr, "%s\n", err.msg);
        return CHECK_RESULT();
    }
    CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);

    /* Old rows intact, new columns at their documented defaults. */
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, 2);
    if (n == 2) {
        CHECK(list[0].kind == CSF_SESSION_DISPLAY && list[0].state == CSF_SESSION_FINISHED);
        CHECK(!strcmp(list[1].observer, "bob") && list[1].seed == 42);
        CHECK(!strcmp(list[1].tool_version, "0.0.9"));
        CHECK_INT_EQ(list[0].n_readings, 3);
        CHECK_INT_EQ(list[1].n_trials, 3);
        CHECK(!strcmp(list[1].settings_json, "{\"method\":\"fade\"}"));
        CHECK(isnan(list[0].person_s) && isnan(list[1].person_s)); /* added in v7: unknown */
    }
    csf_session_list_free(list, n);

    csf_trial *t = NULL;
    size_t nt = 0;
    CHECK_INT_EQ(csf_store_get_trials(s, 2, &t, &nt, &err), CSF_OK);
    CHECK_INT_EQ(nt, 3);
    if (nt == 3) {
        CHECK_NEAR(t[1].freq_cpd, 4.0, 0);
        CHECK_NEAR(t[1].contrast_shown_max, 0.0083, 0);
        CHECK_INT_EQ(t[1].frames_missed, 2);
        CHECK_INT_EQ(t[1].valid, 0);
        CHECK_NEAR(t[1].velocity_dps, 0.0, 0); /* added in v2, default 0 */
        CHECK(isnan(t[1].click_x_deg) && isnan(t[1].click_y_deg));
        CHECK(!strcmp(t[1].flags, ""));
        CHECK(isnan(t[2].rt_s) && isnan(t[2].contrast_shown_mean));
        CHECK_INT_EQ(t[2].is_catch, 1);
    }
    free(t);
    csf_reading *r = NULL;
    size_t nr = 0;
    CHECK_INT_EQ(csf_store_get_readings(s, 1, &r, &nr, &err), CSF_OK);
    CHECK_INT_EQ(nr, 3);
    if (nr == 3) {
        CHECK(!r[0].has_xyz && r[1].has_xyz);
        CHECK_NEAR(r[2].Z, 106.1, 0);
    }
    free(r);
    csf_threshold_row *th = NULL;
    size_t nth = 0;
    CHECK_INT_EQ(csf_store_get_thresholds(s, 2, &th, &nth, &err), CSF_OK);
    CHECK_INT_EQ(nth, 1);
    if (nth == 1) {
        CHECK_NEAR(th[0].threshold, 0.0062, 0);
        CHECK_NEAR(th[0].velocity_dps, 0.0, 0);
    }
    free(th);

    /* The migrated store takes what v1 could not hold: resume session 2 at seq 3. */
    csf_trial nt3 = make_trial(2, 3, 5);
    nt3.velocity_dps = 2.5;
    CHECK_INT_EQ(csf_store_add_trial(s, &nt3, &err), CSF_OK);
    double iv[2] = {0.0167, 0.0333};
    CHECK_INT_EQ(csf_store_add_frame_intervals(s, 2, 3, iv, 2, &err), CSF_OK);
    int64_t study = 0;
    CHECK_INT_EQ(csf_store_create_study(s, "after-migration", NULL, &study, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, 2, "csflut", "bob.csflut", "CSFLUT", 6, &err), CSF_OK);
    csf_store_close(s);

    /* Reopening does not migrate again and keeps everything. */
    s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (s) {
        CHECK_INT_EQ(csf_store_get_trials(s, 2, &t, &nt, &err), CSF_OK);
        CHECK_INT_EQ(nt, 4);
        if (nt == 4) CHECK_NEAR(t[3].velocity_dps, 2.5, 0);
        free(t);
        csf_store_close(s);
    }
    CHECK_INT_EQ(raw_version(path), CSF_STORE_SCHEMA_VERSION);

    /* A newer schema than this build knows is refused, not misread. */
    snprintf(path, sizeof path, "%s/future.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), 0);
    sqlite3 *db = NULL;
    sqlite3_open(path, &db);
    sqlite3_exec(db, "UPDATE schema_version SET version = 99", NULL, NULL, NULL);
    sqlite3_close(db);
    s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_E_STORE);
    CHECK(s == NULL);
    CHECK_STR_CONTAINS(err.msg, "newer");
    CHECK_STR_CONTAINS(err.msg, path);
    CHECK_INT_EQ(raw_version(path), 99);

    /* Someone else's SQLite database is left alone. */
    snprintf(path, sizeof path, "%s/foreign.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, "CREATE TABLE photos (id INTEGER, name TEXT);"), 0);
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "not a csfcal store");

    /* A migration step that fails (here: v1 store already has a column v2 adds) rolls back whole:
     * the store stays at version 1 with its data, and the error names the step. */
    snprintf(path, sizeof path, "%s/broken-v1.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), 0);
    sqlite3_open(path, &db);
    sqlite3_exec(db, "ALTER TABLE trials ADD COLUMN flags TEXT", NULL, NULL, NULL);
    sqlite3_close(db);
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "version 1 to 2");
    CHECK_INT_EQ(raw_version(path), 1);
    sqlite3_open(path, &db);
    sqlite3_stmt *st = NULL;
    int has_frames = 1;
    if (sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM sqlite_master WHERE name = 'frame_intervals'", -1,
                           &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        has_frames = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    CHECK_INT_EQ(has_frames, 0);

    /* Forced-choice trials stored before v4 were all two-interval: they migrate to
     * n_alternatives 2, fade trials (signal_interval 0) to 0, and new four-place rows keep 4. */
    snprintf(path, sizeof path, "%s/v1-2afc.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), 0);
    sqlite3_open(path, &db);
    CHECK_INT_EQ(sqlite3_exec(db,
                              "INSERT INTO sessions VALUES (3, 'observer', 'paused', 'bob', 'lab-crt',"
                              " '{\"method\":\"2afc\"}', 7, '0.0.9', '2026-10-02T09:00:00Z', '2026-10-02T09:03:00Z');"
                              "INSERT INTO trials VALUES (3, 0, '2afc', 2.0, 5.0, 30.0, 0.0, 1.0, 50.0, 0, 0, 0.01,"
                              " 0.01, 0.01, 30, 30, 0, 1, 1, 0.7, 1);"
                              "INSERT INTO trials VALUES (3, 1, '2afc', 4.0, 5.0, 60.0, 0.0, 1.0, 50.0, 0, 0, 0.02,"
                              " 0.02, 0.02, 30, 30, 0, 2, 1, 0.6, 1);",
                              NULL, NULL, NULL),
                 SQLITE_OK);
    sqlite3_close(db);
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (s) {
        csf_trial *ft = NULL;
        size_t nft = 0;
        CHECK_INT_EQ(csf_store_get_trials(s, 3, &ft, &nft, &err), CSF_OK);
        CHECK_INT_EQ(nft, 2);
        for (size_t k = 0; k < nft; k++) CHECK_INT_EQ(ft[k].n_alternatives, 2);
        free(ft);
        CHECK_INT_EQ(csf_store_get_trials(s, 2, &ft, &nft, &err), CSF_OK);
        for (size_t k = 0; k < nft; k++) CHECK_INT_EQ(ft[k].n_alternatives, 0);
        free(ft);
        csf_trial four = make_trial(3, 2, 5);
        four.n_alternatives = 4;
        four.signal_interval = 3;
        four.response = 3;
        CHECK_INT_EQ(csf_store_add_trial(s, &four, &err), CSF_OK);
        four.seq = 3;
        four.n_alternatives = 1; /* not a layout: refused with the allowed values */
        CHECK_INT_EQ(csf_store_add_trial(s, &four, &err), CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(err.msg, "2-16");
        CHECK_INT_EQ(csf_store_get_trials(s, 3, &ft, &nft, &err), CSF_OK);
        CHECK_INT_EQ(nft, 3);
        if (nft == 3) CHECK_INT_EQ(ft[2].n_alternatives, 4);
        free(ft);
        csf_store_close(s);
    }

    /* An empty file becomes a new store. */
    snprintf(path, sizeof path, "%s/empty.sqlite", dir);
    FILE *f = fopen(path, "wb");
    if (f) fclose(f);
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (s) {
        CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
        csf_store_close(s);
    }
    test_from_v6(dir, sql);
    test_from_v7(dir, sql);
    free(sql);
    rm_rf(dir);
    return CHECK_RESULT();
}
