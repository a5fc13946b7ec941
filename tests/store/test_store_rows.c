/* What the rows mean: a store written by the schema-4 code
 * (fixtures/schema_v4.sql, made by csfcal itself) is repaired by the v5 migration; new sessions
 * record the display and the profile apart; one file is one artifact row; units in column names,
 * one threshold per cell, CHECKs on enumerations; someone else's database is refused without a
 * byte changed; /dev/null is named as what it is; a damaged stored_s is ignored, not cast; a
 * kind, state or status this build does not know reads as unknown, its text kept. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "results/store/store.h"
#include "results/store/internal.h"
#include "store_test_util.h"
#include "tests/check.h"

/* First column of the first row as text ("" when none), through the open store's connection. */
static void sql_text(csf_store *s, const char *sql, char *out, size_t cap)
{
    out[0] = '\0';
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(csf_store_db(s), sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW) {
        const unsigned char *t = sqlite3_column_text(st, 0);
        snprintf(out, cap, "%s", t ? (const char *)t : "");
    }
    sqlite3_finalize(st);
}

static int sql_int(csf_store *s, const char *sql)
{
    char buf[64];
    sql_text(s, sql, buf, sizeof buf);
    return atoi(buf);
}

static void check_sound(csf_store *s)
{
    char buf[256];
    sql_text(s, "PRAGMA integrity_check", buf, sizeof buf);
    CHECK_MSG(!strcmp(buf, "ok"), "integrity_check: %s", buf);
    sql_text(s, "SELECT COUNT(*) FROM pragma_foreign_key_check", buf, sizeof buf);
    CHECK_MSG(!strcmp(buf, "0"), "foreign_key_check rows: %s", buf);
}

static void test_v4_repair(const char *dir)
{
    const char *fx = getenv("CSF_STORE_FIXTURES");
    char fixture[600], path[700];
    snprintf(fixture, sizeof fixture, "%s/schema_v4.sql", fx ? fx : "tests/store/fixtures");
    char *sql = test_read_file(fixture, NULL);
    CHECK_MSG(sql != NULL, "cannot read %s", fixture);
    if (!sql) return;
    snprintf(path, sizeof path, "%s/v4.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), SQLITE_OK);
    free(sql);

    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
    check_sound(s);

    /* Observer sessions: the display the profile was measured on, and the profile apart. */
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(s, 2, &si, &err), CSF_OK);
    CHECK(!strcmp(si.display, "sim:display=lcd"));
    CHECK(!strcmp(si.profile_id, "sim-display-lcd-20261123-76c386bb"));
    csf_session_info_free(&si);
    CHECK_INT_EQ(csf_store_get_session(s, 3, &si, &err), CSF_OK);
    CHECK(!strcmp(si.display, "default"));
    CHECK(!strcmp(si.profile_id, "default-gamma2.2-100cdm2"));
    csf_session_info_free(&si);
    CHECK_INT_EQ(csf_store_get_session(s, 1, &si, &err), CSF_OK);
    CHECK(!strcmp(si.display, "sim:display=lcd") && si.profile_id[0] == '\0');
    csf_session_info_free(&si);

    /* No display row named after a profile, none without a profile, and every session's display
     * and profile join to a row. */
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM displays WHERE name IN (SELECT profile_id FROM display_profiles)"), 0);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM displays WHERE profile_id IS NULL"), 0);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM displays"), 2);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM sessions s JOIN displays d ON d.name = s.display"), 3);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM sessions s JOIN displays d ON d.name = s.display"
                            " JOIN display_profiles p ON p.display_id = d.id AND p.profile_id = s.profile_id"), 2);

    /* The profile file: one row with its path and its bytes. */
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM artifacts WHERE session_id = 1 AND kind = 'profile'"), 1);
    void *blob = NULL;
    size_t len = 0;
    char apath[256] = "";
    CHECK_INT_EQ(csf_store_get_artifact(s, 1, "profile", &blob, &len, apath, sizeof apath, &err), CSF_OK);
    CHECK(!strcmp(apath, "lcd.profile"));
    CHECK_INT_EQ(len, 9525);
    CHECK(blob && !strncmp(blob, "csfcal-display-profile", 22));
    free(blob);

    /* Units in the names; the values came across. */
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM pragma_table_info('readings') WHERE name IN"
                            " ('X_cdm2', 'Y_cdm2', 'Z_cdm2')"), 3);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM pragma_table_info('thresholds') WHERE name = 'threshold_michelson'"), 1);
    /* Trials came across whole: every column of the rebuilt table (v8 adds onset_s), and the rows. */
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM pragma_table_info('trials')"), 28);
    csf_trial *tr = NULL;
    size_t ntr = 0;
    CHECK_INT_EQ(csf_store_get_trials(s, 2, &tr, &ntr, &err), CSF_OK);
    CHECK_INT_EQ(ntr, 6);
    if (ntr == 6) {
        CHECK(tr[5].seq == 5 && !strcmp(tr[5].method, "bayes") && tr[5].n_alternatives == 4);
        CHECK_NEAR(tr[5].ecc_deg, 10.0, 0);
        CHECK_NEAR(tr[5].polar_deg, 45.0, 0);
        CHECK_NEAR(tr[5].contrast_requested, 0.05616293790000000119, 0);
        CHECK_NEAR(tr[5].rt_s, 0.8417427440000000427, 0);
        CHECK(tr[5].valid == 1 && tr[5].signal_interval == 1 && isnan(tr[5].click_x_deg));
    }
    free(tr);
    csf_reading *r = NULL;
    size_t nr = 0;
    CHECK_INT_EQ(csf_store_get_readings(s, 1, &r, &nr, &err), CSF_OK);
    CHECK(nr > 10);
    if (nr > 0) {
        CHECK(r[0].has_xyz);
        CHECK_NEAR(r[0].X, 169.76714800874373168, 0);
        CHECK_NEAR(r[0].Z, 194.51857434367065025, 0);
    }
    free(r);

    /* One threshold per cell: the duplicate row of the fixture is gone, the last one kept. */
    csf_threshold_row *th = NULL;
    size_t nth = 0;
    CHECK_INT_EQ(csf_store_get_thresholds(s, 3, &th, &nth, &err), CSF_OK);
    CHECK_INT_EQ(nth, 2);
    if (nth == 2) CHECK_NEAR(th[1].threshold, 0.0031, 0);
    free(th);
    csf_store_close(s);

    /* Reading commands migrate an old store on a writable file instead of refusing it. */
    snprintf(path, sizeof path, "%s/v4-ro.sqlite", dir);
    sql = test_read_file(fixture, NULL);
    CHECK_INT_EQ(test_sqlite_exec(path, sql), SQLITE_OK);
    free(sql);
    CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_OK);
    if (s) {
        CHECK_INT_EQ(csf_store_schema_version(s), CSF_STORE_SCHEMA_VERSION);
        csf_store_close(s);
    }
}

static void test_new_rows(const char *dir)
{
    char path[700];
    snprintf(path, sizeof path, "%s/new.sqlite", dir);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (!s) return;
    int64_t disp = 0, obs = 0, obs2 = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, "lab-oled", NULL, 1, &disp, &err),
                 CSF_OK);
    /* display calibrate stores the bytes, then the command that saved the file its path. */
    const char text[] = "csfcal-display-profile 1\nid = lab-oled-20261123-0badf00d\ndisplay = lab-oled\n";
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", NULL, text, sizeof text - 1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "profile", "oled.profile", NULL, 0, &err), CSF_OK);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM artifacts"), 1);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM artifacts WHERE path = 'oled.profile' AND"
                            " size_bytes = length(content)"), 1);
    /* The other order completes the row too. */
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "plot", "p.png", NULL, 0, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_add_artifact(s, disp, "plot", NULL, "PNG", 3, &err), CSF_OK);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM artifacts WHERE kind = 'plot' AND path = 'p.png'"
                            " AND size_bytes = 3"), 1);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM artifacts"), 2);

    /* An observer session on that display with its profile: no display row for the profile. */
    CHECK_INT_EQ(csf_store_begin_session_profile(s, CSF_SESSION_OBSERVER, "ann", "lab-oled",
                                                 "lab-oled-20261123-0badf00d", NULL, 2, &obs, &err),
                 CSF_OK);
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(s, obs, &si, &err), CSF_OK);
    CHECK(!strcmp(si.display, "lab-oled") && !strcmp(si.profile_id, "lab-oled-20261123-0badf00d"));
    csf_session_info_free(&si);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM displays"), 1);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM display_profiles"), 1);
    /* An older profile file for that display goes into its history but does not become current. */
    CHECK_INT_EQ(csf_store_begin_session_profile(s, CSF_SESSION_OBSERVER, "ann", "lab-oled",
                                                 "lab-oled-20260101-00000001", NULL, 3, &obs2, &err),
                 CSF_OK);
    CHECK_INT_EQ(sql_int(s, "SELECT COUNT(*) FROM display_profiles"), 2);
    char cur[128];
    CHECK_INT_EQ(csf_store_display_profile_id(s, "lab-oled", cur, sizeof cur, &err), CSF_OK);
    CHECK(!strcmp(cur, "lab-oled-20261123-0badf00d"));

    /* One threshold per cell. */
    csf_threshold_row rows[2] = {{2, 0, 0, 50, 0.01, 0.1, 8}, {2, 0, 0, 50, 0.02, 0.1, 8}};
    CHECK_INT_EQ(csf_store_put_thresholds(s, obs, rows, 2, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "UNIQUE");
    rows[1].freq_cpd = 4;
    CHECK_INT_EQ(csf_store_put_thresholds(s, obs, rows, 2, &err), CSF_OK);

    /* CHECK constraints hold against writers that bypass this API. */
    sqlite3 *db = csf_store_db(s);
    CHECK(sqlite3_exec(db, "UPDATE sessions SET state = 'done' WHERE id = 1", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "UPDATE sessions SET kind = 'movie' WHERE id = 1", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "INSERT INTO readings (session_id, seq, channel, drive01, t_s, status)"
                           " VALUES (1, 0, 'purple', 0.5, 0, 'ok')", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "INSERT INTO readings (session_id, seq, channel, drive01, t_s, status)"
                           " VALUES (1, 0, 'grey', 0.5, 0, 'fine')", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "INSERT INTO readings (session_id, seq, channel, drive01, t_s, status)"
                           " VALUES (1, 0, 'grey', 0.5, 0, 'ok')", NULL, NULL, NULL) == SQLITE_OK);
    csf_trial t = make_trial(obs, 0, 9);
    CHECK_INT_EQ(csf_store_add_trial(s, &t, &err), CSF_OK);
    CHECK(sqlite3_exec(db, "UPDATE trials SET valid = 2", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "UPDATE trials SET is_catch = -1", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "UPDATE trials SET n_alternatives = 1", NULL, NULL, NULL) != SQLITE_OK);
    CHECK(sqlite3_exec(db, "UPDATE trials SET n_alternatives = 4", NULL, NULL, NULL) == SQLITE_OK);
    check_sound(s);

    /* A damaged stored_s (here 1e300 s) does not become the session's last write time: it is
     * no time at all, and converting it to time_t would be undefined. */
    CHECK(sqlite3_exec(db, "UPDATE readings SET stored_s = 1e300", NULL, NULL, NULL) == SQLITE_OK);
    char created[32], updated[32];
    CHECK_INT_EQ(csf_store_session_times(s, 1, created, updated, &err), CSF_OK);
    CHECK_MSG(!strcmp(created, updated), "created %s, updated %s", created, updated);
    /* 1e13 s is the year 318857: a time_t, but no time a row was stored at; it used to become
     * "318857-..." as the last write. */
    CHECK(sqlite3_exec(db, "UPDATE readings SET stored_s = 1e13", NULL, NULL, NULL) == SQLITE_OK);
    CHECK_INT_EQ(csf_store_session_times(s, 1, created, updated, &err), CSF_OK);
    CHECK_MSG(!strcmp(created, updated), "created %s, updated %s", created, updated);
    CHECK(sqlite3_exec(db, "UPDATE readings SET stored_s = -1e19", NULL, NULL, NULL) == SQLITE_OK);
    CHECK_INT_EQ(csf_store_session_times(s, 1, created, updated, &err), CSF_OK);
    CHECK_MSG(!strcmp(created, updated), "created %s, updated %s", created, updated);
    csf_store_close(s);
}

/* The words each enum is stored as, both ways; nothing else, however close, is a known value. */
static void test_words(void)
{
    static const char *kinds[] = {"display", "observer", "study"};
    static const char *states[] = {"running", "paused", "finished", "aborted"};
    static const char *statuses[] = {"ok", "too_dark", "saturated", "timeout", "error"};
    for (int i = 0; i < 3; i++) {
        CHECK_INT_EQ((int)csf_session_kind_from_name(kinds[i]), i + 1);
        CHECK(!strcmp(csf_session_kind_name((csf_session_kind)(i + 1)), kinds[i]));
    }
    for (int i = 0; i < 4; i++) {
        CHECK_INT_EQ((int)csf_session_state_from_name(states[i]), i + 1);
        CHECK(!strcmp(csf_session_state_name((csf_session_state)(i + 1)), states[i]));
    }
    for (int i = 0; i < 5; i++) {
        CHECK_INT_EQ((int)csf_reading_status_from_name(statuses[i]), i + 1);
        CHECK(!strcmp(csf_reading_status_name((csf_reading_status)(i + 1)), statuses[i]));
    }
    const char *near[] = {NULL, "", "Display", "display ", "runnin", "okay", "unknown"};
    for (size_t i = 0; i < sizeof near / sizeof near[0]; i++) {
        CHECK_INT_EQ((int)csf_session_kind_from_name(near[i]), CSF_SESSION_KIND_UNKNOWN);
        CHECK_INT_EQ((int)csf_session_state_from_name(near[i]), CSF_SESSION_STATE_UNKNOWN);
        CHECK_INT_EQ((int)csf_reading_status_from_name(near[i]), CSF_READING_STATUS_UNKNOWN);
    }
    CHECK(!csf_session_kind_name(CSF_SESSION_KIND_UNKNOWN) && !csf_session_kind_name((csf_session_kind)4) &&
          !csf_session_kind_name((csf_session_kind)-1));
    CHECK(!csf_session_state_name(CSF_SESSION_STATE_UNKNOWN) &&
          !csf_session_state_name((csf_session_state)5));
    CHECK(!csf_reading_status_name(CSF_READING_STATUS_UNKNOWN) &&
          !csf_reading_status_name((csf_reading_status)6));
    CHECK(!csf_session_state_open(CSF_SESSION_STATE_UNKNOWN) &&
          !csf_session_state_closed(CSF_SESSION_STATE_UNKNOWN));
}

/* Rows holding words this build does not know (written with the CHECKs off: by hand, or a newer
 * csfcal): read as the unknown values, whole text kept for display, never a known value. */
static void test_unknown_words(const char *dir)
{
    char path[700];
    snprintf(path, sizeof path, "%s/later.sqlite", dir);
    csf_error err;
    csf_store *s = test_open_or_exit(path, "test_store_rows");
    int64_t a = 0, b = 0;
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, "lcd", NULL, 1, &a, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "ann", "lcd", NULL, 2, &b, &err), CSF_OK);
    csf_reading r = {.session_id = a, .seq = 0, .drive01 = 1, .lum_cdm2 = 100, .status = CSF_READING_OK};
    snprintf(r.channel, sizeof r.channel, "white");
    CHECK_INT_EQ(csf_store_add_reading(s, &r, &err), CSF_OK);
    sqlite3 *db = csf_store_db(s);
    CHECK(sqlite3_exec(db,
                       "PRAGMA ignore_check_constraints = ON;"
                       "UPDATE sessions SET kind = 'survey', state = 'archived' WHERE id = 1;"
                       /* a known word with more after it, past the 15 bytes shown */
                       "UPDATE sessions SET kind = 'observer-with-eye-tracker' WHERE id = 2;"
                       "UPDATE readings SET status = 'dim';",
                       NULL, NULL, NULL) == SQLITE_OK);
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(s, a, &si, &err), CSF_OK);
    CHECK_INT_EQ((int)si.kind, CSF_SESSION_KIND_UNKNOWN);
    CHECK_INT_EQ((int)si.state, CSF_SESSION_STATE_UNKNOWN);
    CHECK(!strcmp(si.kind_text, "survey") && !strcmp(si.state_text, "archived"));
    csf_session_info_free(&si);
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ((int)n, 2);
    if (n == 2) {
        CHECK_INT_EQ((int)list[1].kind, CSF_SESSION_KIND_UNKNOWN);
        CHECK_INT_EQ((int)list[1].state, CSF_SESSION_RUNNING);
        CHECK(!strcmp(list[1].kind_text, "observer-with-e")); /* cut to 15 bytes */
    }
    csf_session_list_free(list, n);
    csf_reading *rd = NULL;
    CHECK_INT_EQ(csf_store_get_readings(s, a, &rd, &n, &err), CSF_OK);
    CHECK(n == 1 && rd[0].status == CSF_READING_STATUS_UNKNOWN && !strcmp(rd[0].status_text, "dim"));
    free(rd);
    csf_store_close(s);
}

static void test_refusals(const char *dir)
{
    /* Someone else's database: refused, and not one byte of it changed (it stays in rollback
     * journal mode; before, the WAL switch rewrote its header). */
    char path[700];
    snprintf(path, sizeof path, "%s/photos.sqlite", dir);
    CHECK_INT_EQ(test_sqlite_exec(path, "CREATE TABLE photos (id INTEGER, name TEXT); INSERT INTO photos VALUES (1, 'a');"),
                 SQLITE_OK);
    size_t n0 = 0, n1 = 0;
    char *before = test_read_file(path, &n0);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "not a csfcal store");
    char *after = test_read_file(path, &n1);
    CHECK(before && after && n0 == n1 && memcmp(before, after, n0) == 0);
    free(before);
    free(after);
    char wal[720];
    snprintf(wal, sizeof wal, "%s-wal", path);
    struct stat st;
    CHECK(stat(wal, &st) != 0);

    /* /dev/null is named as a device, for writing and for reading. */
    CHECK_INT_EQ(csf_store_open("/dev/null", &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "character device");
    CHECK_STR_CONTAINS(err.msg, "--store");
    CHECK_INT_EQ(csf_store_open_readonly("/dev/null", &s, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "character device");
}

int main(void)
{
    char dir[512];
    if (tmp_dir(dir, sizeof dir, "rows") < 0) return 1;
    test_v4_repair(dir);
    test_new_rows(dir);
    test_refusals(dir);
    test_words();
    test_unknown_words(dir);
    rm_rf(dir);
    return CHECK_RESULT();
}
