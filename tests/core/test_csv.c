/* core/csv: lines (byte-order mark, comments, trimming, line numbers, NUL and overlong lines,
 * the per-line check) and RFC 4180 fields (quotes, "" as a quote, refusals that never cut). */
#include <string.h>

#include "core/csv.h"
#include "tests/check.h"

static char fields[8][CSF_CSV_FIELD_MAX];

static int count_lines(const char *text, size_t len, int hash, int *last_line, const char **why)
{
    csf_lines r;
    CHECK(csf_lines_open(&r, text, len, 64) == 0);
    r.hash_comments = hash;
    char *l;
    int n = 0, got;
    while ((got = csf_lines_next(&r, &l)) > 0) n++;
    *last_line = r.line;
    *why = r.why;
    csf_lines_close(&r);
    return got < 0 ? -1 : n;
}

static int refuse_x(void *ctx, const char *raw, int line)
{
    (void)ctx;
    (void)line;
    return strchr(raw, 'x') != NULL;
}

static void test_lines(void)
{
    const char text[] = "\xEF\xBB\xBF"
                        "a,b\r\n\n  # comment\n  1 , 2 \t\n3,4 # tail\n";
    csf_lines r;
    CHECK(csf_lines_open(&r, text, sizeof text - 1, 64) == 0);
    char *l;
    CHECK(csf_lines_next(&r, &l) == 1 && strcmp(l, "a,b") == 0 && r.line == 1);
    CHECK(csf_lines_next(&r, &l) == 1 && strcmp(l, "1 , 2") == 0 && r.line == 4);
    CHECK(csf_lines_next(&r, &l) == 1 && strcmp(l, "3,4 # tail") == 0 && r.line == 5);
    CHECK(csf_lines_next(&r, &l) == 0);
    csf_lines_close(&r);
    int last;
    const char *why;
    CHECK(count_lines(text, sizeof text - 1, 1, &last, &why) == 3);
    /* '#' inside quotes is text, not a comment */
    const char quoted[] = "\"a#b\",c # d\n";
    CHECK(csf_lines_open(&r, quoted, sizeof quoted - 1, 64) == 0);
    r.hash_comments = 1;
    CHECK(csf_lines_next(&r, &l) == 1 && strcmp(l, "\"a#b\",c") == 0);
    csf_lines_close(&r);
    /* a NUL byte and an overlong line stop the walk, naming the line */
    const char nul[] = "a\nb\0c\n";
    CHECK(count_lines(nul, sizeof nul - 1, 0, &last, &why) == -1 && last == 2 && strstr(why, "NUL"));
    char longl[100];
    memset(longl, 'y', sizeof longl);
    CHECK(count_lines(longl, sizeof longl, 0, &last, &why) == -1 && strstr(why, "longer than 64"));
    /* the check sees every line as read, comments too */
    const char checked[] = "ok\n# x in a comment\n";
    CHECK(csf_lines_open(&r, checked, sizeof checked - 1, 64) == 0);
    r.check = refuse_x;
    CHECK(csf_lines_next(&r, &l) == 1);
    CHECK(csf_lines_next(&r, &l) == -1 && r.why == NULL && r.line == 2);
    csf_lines_close(&r);
}

static void test_split(void)
{
    const char *why = NULL;
    CHECK(csf_csv_split(" a , \"b, \"\"c\"\"\" ,,d", fields, 8, &why) == 4);
    CHECK(strcmp(fields[0], "a") == 0 && strcmp(fields[1], "b, \"c\"") == 0 && fields[2][0] == 0 &&
          strcmp(fields[3], "d") == 0);
    CHECK(csf_csv_split("a,b,c", fields, 2, &why) == -1 && strstr(why, "too many"));
    CHECK(csf_csv_split("\"open", fields, 8, &why) == -1 && strstr(why, "not closed"));
    CHECK(csf_csv_split("\"a\" b", fields, 8, &why) == -1 && strstr(why, "after a closing quote"));
    char big[CSF_CSV_FIELD_MAX + 8];
    memset(big, 'z', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    CHECK(csf_csv_split(big, fields, 8, &why) == -1 && strstr(why, "longer than 1023"));
    /* 1023 bytes fill the field with its NUL; 1024 are refused */
    char just[CSF_CSV_FIELD_MAX + 1];
    memset(just, 'z', sizeof just - 1);
    just[sizeof just - 1] = '\0';
    CHECK(csf_csv_split(just, fields, 8, &why) == -1);
    just[sizeof just - 2] = '\0';
    CHECK(csf_csv_split(just, fields, 8, &why) == 1 && strlen(fields[0]) == CSF_CSV_FIELD_MAX - 1);
    char t[] = " \t x y \r\n";
    CHECK(strcmp(csf_trim(t), "x y") == 0);
}

int main(void)
{
    test_lines();
    test_split();
    return CHECK_RESULT();
}
