/* Names and labels a station stores are shown on other stations' terminals, and commands csfcal
 * prints are pasted into a shell. Each attack is tried and must fail:
 * - a control character (ESC, BEL, CR, DEL, C1, a byte that is not UTF-8, a direction override)
 *   in an observer, display, study or participant name, or an artifact kind, is refused at the
 *   store's door with the character as \xNN and its position, and leaves no row behind;
 * - settings that are not JSON (built by hand around such a name) are refused, not stored;
 * - a long name is refused with the limit or kept whole: a 255-character observer name reads
 *   back and pushes whole, and a longer one written past csfcal is flagged, never cut silently;
 * - a study file with such a character in a line is refused with its line and position, and
 *   a CSV field too long for its buffer is refused, not cut;
 * - text read from a store is shown escaped (csf_store_printable), printable UTF-8 as it is;
 * - a store location with '&', spaces and quotes in a printed command is one shell word
 *   (csf_shell_quote), checked by running it through sh.
 * Runs on SQLite, and on PostgreSQL under tests/store/pg_run.sh. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "studies/study_file.h"
#include "results/store/store.h"
#include "results/store/push.h"
#include "store_test_util.h"
#include "tests/check.h"

static int64_t count_sessions(csf_store *s)
{
    csf_session_info *list = NULL;
    size_t n = 0;
    csf_error err;
    if (csf_store_list_sessions(s, &list, &n, &err) != CSF_OK) return -1;
    csf_session_list_free(list, n);
    return (int64_t)n;
}

/* A refusal that names the character and its 1-based position. */
static void check_refusal(csf_status cs, const csf_error *err, const char *hex, const char *pos)
{
    CHECK_INT_EQ(cs, CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err->msg, hex);
    CHECK_STR_CONTAINS(err->msg, pos);
}

static void test_text_rules(void)
{
    csf_error err;
    static const struct {
        const char *text, *hex, *pos;
    } bad[] = {
        {"ab\x1b[2J", "\\x1b", "character 3"},
        {"bell\a", "\\x07", "character 5"},
        {"two\rrows", "\\x0d", "character 4"},
        {"del\x7f", "\\x7f", "character 4"},
        {"c1 \xc2\x9b" "31m", "\\xc2\\x9b", "character 4"},       /* CSI as a C1 control */
        {"M\xfcller", "\\xfc", "character 2"},                    /* Latin-1, not UTF-8 */
        {"\xc0\xafx", "\\xc0", "character 1"},                    /* overlong '/' */
        {"x\xe2\x80\xae" "evil", "\\xe2\\x80\\xae", "character 2"}, /* right-to-left override */
        {"\xed\xa0\x80", "\\xed", "character 1"},                 /* a surrogate */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        check_refusal(csf_store_check_text(bad[i].text, "name", &err), &err, bad[i].hex, bad[i].pos);
    /* Position counts characters, not bytes. */
    check_refusal(csf_store_check_text("M\xc3\xbcller\x1b", "name", &err), &err, "\\x1b", "character 7");
    CHECK_INT_EQ(csf_store_check_text("M\xc3\xbcller O'Brien \xe6\x9d\xb1", "name", &err), CSF_OK);
    CHECK_INT_EQ(csf_store_check_name("", "study name", 255, 1, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_store_check_name(NULL, "display name", 255, 0, &err), CSF_OK);
}

static void test_printable(void)
{
    char out[128];
    csf_store_printable("a\x1b[2Jb\a\rc\x7f", out, sizeof out);
    CHECK_MSG(!strcmp(out, "a\\x1b[2Jb\\x07\\rc\\x7f"), "escaped: %s", out);
    csf_store_printable("M\xc3\xbcller \xc2\x9b \xff \\", out, sizeof out);
    CHECK_MSG(!strcmp(out, "M\xc3\xbcller \\xc2\\x9b \\xff \\x5c"), "utf-8: %s", out);
    /* Clipped at a character: never half of a UTF-8 sequence or of an escape. */
    csf_store_printable("ab\xc3\xbc", out, 4);
    CHECK_MSG(!strcmp(out, "ab"), "clipped: %s", out);
    csf_store_printable("ab\x1b", out, 6);
    CHECK_MSG(!strcmp(out, "ab"), "clipped escape: %s", out);
}

static void test_store_refuses(const char *loc)
{
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(loc, &s, &err), CSF_OK);
    if (!s) return;
    int64_t id = 0;
    check_refusal(
        csf_store_begin_session(s, CSF_SESSION_OBSERVER, "eve\x1b]0;pwned\a", "lcd", NULL, 1, &id, &err),
        &err, "\\x1b", "character 4");
    CHECK_STR_CONTAINS(err.msg, "observer name");
    check_refusal(csf_store_begin_session(s, CSF_SESSION_DISPLAY, NULL, "booth\r-lcd", NULL, 1, &id, &err),
                  &err, "\\x0d", "character 6");
    check_refusal(
        csf_store_begin_session_profile(s, CSF_SESSION_OBSERVER, "eve", "lcd", "p\x07", NULL, 1, &id, &err),
        &err, "\\x07", "character 2");
    check_refusal(csf_store_upsert_display(s, "lcd\r", NULL, &id, &err), &err, "\\x0d", "character 4");
    check_refusal(csf_store_upsert_observer(s, "\x1b" "c", &id, &err), &err, "\\x1b", "character 1");
    check_refusal(csf_store_create_study(s, "contrast\x1b[31m", NULL, &id, &err), &err, "\\x1b",
                  "character 9");
    /* The settings a study session once stored when they were written by hand around such a
     * name: not JSON, so refused. */
    CHECK_INT_EQ(
        csf_store_begin_session(s, CSF_SESSION_STUDY, "P1", "lcd", "{\"study\":\"a\x1b\"}", 1, &id, &err),
        CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "not valid JSON");
    CHECK_INT_EQ(count_sessions(s), 0); /* nothing half-stored by any refusal */

    int64_t study = 0, sid = 0;
    CHECK_INT_EQ(csf_store_create_study(s, "contrast", "{\"design\":\"2afc\"}", &study, &err), CSF_OK);
    check_refusal(csf_store_add_participant(s, study, "P\a01", &id, &err), &err, "\\x07", "character 2");
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "O'Brien", "lcd", "{}", 1, &sid, &err),
                 CSF_OK);
    check_refusal(csf_store_add_artifact(s, sid, "plot\x1b", NULL, NULL, 0, &err), &err, "\\x1b",
                  "character 5");

    /* 332 characters: refused with the limit, not cut; 255 are kept whole. */
    char name[333];
    memset(name, 'n', sizeof name - 1);
    name[sizeof name - 1] = '\0';
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, name, "lcd", NULL, 1, &id, &err),
                 CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "255");
    CHECK_STR_CONTAINS(err.msg, "not shortened");
    name[255] = '\0';
    CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, name, name, NULL, 1, &id, &err), CSF_OK);
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(s, id, &si, &err), CSF_OK);
    CHECK_INT_EQ(strlen(si.observer), 255);
    CHECK_INT_EQ(strlen(si.display), 255);
    CHECK_INT_EQ(si.names_cut, 0);
    csf_session_info_free(&si);
    csf_store_close(s);
}

/* A session pushed keeps its 255-character name whole; a longer one written around csfcal (here
 * by SQLite directly) is flagged when read, so push can refuse it instead of cutting it. */
static void test_push_whole(const char *dir, const char *dest)
{
    char src_path[1100];
    snprintf(src_path, sizeof src_path, "%s/station.sqlite", dir);
    csf_error err;
    csf_store *src = NULL, *dst = NULL;
    CHECK_INT_EQ(csf_store_open(src_path, &src, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_open(dest, &dst, &err), CSF_OK);
    if (!src || !dst) {
        csf_store_close(src);
        csf_store_close(dst);
        return;
    }
    char name[256];
    memset(name, 'q', sizeof name - 1);
    name[sizeof name - 1] = '\0';
    int64_t sid = 0, raw = 0;
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_OBSERVER, name, "lcd", NULL, 5, &sid, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(src, CSF_SESSION_OBSERVER, "short", "lcd", NULL, 6, &raw, &err),
                 CSF_OK);
    csf_push_counts c;
    CHECK_INT_EQ(csf_store_push_session(src, dst, sid, &c, &err), CSF_OK);
    csf_session_info si;
    CHECK_INT_EQ(csf_store_get_session(dst, c.dest_id, &si, &err), CSF_OK);
    CHECK_MSG(!strcmp(si.observer, name), "pushed name has %zu characters", strlen(si.observer));
    csf_session_info_free(&si);
    csf_store_close(src);

    char sql[600];
    snprintf(sql, sizeof sql, "UPDATE sessions SET observer = printf('%%.332c', 'r') WHERE id = %lld",
             (long long)raw);
    CHECK_INT_EQ(test_sqlite_exec(src_path, sql), 0);
    CHECK_INT_EQ(csf_store_open(src_path, &src, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_get_session(src, raw, &si, &err), CSF_OK);
    CHECK_INT_EQ(si.names_cut, 1);
    csf_session_info_free(&si);
    csf_store_close(src);
    csf_store_close(dst);
}

/* A study file's names and labels are read once, where a control character is refused with
 * the file, line and position; a field too long for its buffer is refused, never cut. */
static csf_status study(const char *settings, const char *conditions, csf_error *err)
{
    csf_study *s = NULL;
    csf_status cs = csf_study_from_texts(settings, conditions, "s.conf", "s.csv", 0, &s, err);
    csf_study_free(s);
    return cs;
}

static void test_study_files(void)
{
    const char *ok_set = "name = fine\ndesign = 2afc\nconditions = s.csv\n";
    const char *ok_csv = "label,freq_cpd,ecc_deg,contrast\na,2,5,0.01\n";
    csf_error err;
    CHECK_INT_EQ(study(ok_set, ok_csv, &err), CSF_OK);
    check_refusal(study("name = a\x1b[2J\ndesign = 2afc\nconditions = s.csv\n", ok_csv, &err), &err,
                  "s.conf:1: control character \\x1b", "character 9");
    check_refusal(study(ok_set, "label,freq_cpd,ecc_deg,contrast\nA\rB,2,5,0.01\n", &err), &err,
                  "s.csv:2: control character \\x0d", "character 2");
    CHECK_INT_EQ(study(ok_set, "label,freq_cpd,ecc_deg,contrast\r\na,2,5,0.01\r\n", &err), CSF_OK);
    CHECK_INT_EQ(study("name = O'Brien\ndesign = 2afc\nconditions = s.csv\n", ok_csv, &err), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "no quotes");
    /* A quoted field of 1023 characters (all its buffer holds) and an escaped quote: the quote
     * was dropped, and the field read as 1023 characters. */
    char csv[1200];
    int n = snprintf(csv, sizeof csv, "label,freq_cpd,ecc_deg,contrast,\"");
    memset(csv + n, 'c', 1023);
    snprintf(csv + n + 1023, sizeof csv - (size_t)n - 1023, "\"\"\"\na,2,5,0.01,x\n");
    CHECK_INT_EQ(study(ok_set, csv, &err), CSF_E_FORMAT);
    CHECK_STR_CONTAINS(err.msg, "longer than 1023");
}

/* A command line as sh reads it back: the words of `printf '%s\n' WORDS`. */
static void test_shell_quote(void)
{
    static const char *const words[] = {
        "postgresql://db.lab/csf?host=/run/pg&user=booth1&sslmode=require",
        "/data/O'Brien's store & co/csfcal.sqlite",
        "service=lab user='b o' host=h",
        "$(touch /tmp/csfcal-pwned)`id`;|<>*?~#!",
        "",
        "/plain/path-1.sqlite",
    };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        char *q = csf_shell_quote(words[i]);
        CHECK(q != NULL);
        if (!q) continue;
        char cmd[1200];
        snprintf(cmd, sizeof cmd, "printf '[%%s]\\n' %s", q);
        FILE *p = popen(cmd, "r");
        char got[1100] = "";
        size_t n = p ? fread(got, 1, sizeof got - 1, p) : 0;
        got[n] = '\0';
        if (p) pclose(p);
        char want[1100];
        snprintf(want, sizeof want, "[%s]\n", words[i]);
        CHECK_MSG(!strcmp(got, want), "sh read %s back as %s", q, got);
        free(q);
    }
    char *q = csf_shell_quote("/plain/path-1.sqlite");
    CHECK_MSG(q && !strcmp(q, "/plain/path-1.sqlite"), "plain word quoted: %s", q ? q : "(null)");
    free(q);
}

int main(void)
{
    test_text_rules();
    test_printable();
    test_shell_quote();
    test_study_files();
    char dir[512], loc[1024], dest[1024];
    if (tmp_dir(dir, sizeof dir, "names") < 0) return 1;
    if (test_store_location(dir, "names.sqlite", loc, sizeof loc) == 0) test_store_refuses(loc);
    else CHECK(0);
    if (test_store_location(dir, "dest.sqlite", dest, sizeof dest) == 0) test_push_whole(dir, dest);
    else CHECK(0);
    rm_rf(dir);
    return CHECK_RESULT();
}
