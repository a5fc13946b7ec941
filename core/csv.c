/* Line-based text and CSV fields (see csv.h). */
#include "core/csv.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *csf_trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    return s;
}

int csf_lines_open(csf_lines *r, const char *text, size_t len, size_t max_line)
{
    memset(r, 0, sizeof *r);
    r->text = text;
    r->len = len;
    r->max_line = max_line > 65535 ? 65535 : max_line;
    r->buf = malloc(r->max_line + 1);
    return r->buf ? 0 : -1;
}

void csf_lines_close(csf_lines *r)
{
    free(r->buf);
    r->buf = NULL;
}

/* '#' outside double quotes ends the line. */
static void cut_comment(char *l)
{
    int quoted = 0;
    for (char *p = l; *p; p++) {
        if (*p == '"') quoted = !quoted;
        else if (*p == '#' && !quoted) {
            *p = '\0';
            return;
        }
    }
}

int csf_lines_next(csf_lines *r, char **line)
{
    while (r->pos < r->len) {
        const char *start = r->text + r->pos;
        const char *nl = memchr(start, '\n', r->len - r->pos);
        size_t n = nl ? (size_t)(nl - start) : r->len - r->pos;
        int first = r->pos == 0;
        r->pos += n + (nl ? 1 : 0);
        r->line++;
        if (memchr(start, '\0', n)) {
            r->why = "a NUL byte";
            return -1;
        }
        if (n > r->max_line) {
            snprintf(r->why_buf, sizeof r->why_buf, "a line longer than %zu characters", r->max_line);
            r->why = r->why_buf;
            return -1;
        }
        memcpy(r->buf, start, n);
        r->buf[n] = '\0';
        char *l = r->buf;
        if (first && n >= 3 && (unsigned char)l[0] == 0xEF && (unsigned char)l[1] == 0xBB &&
            (unsigned char)l[2] == 0xBF)
            l += 3;
        if (r->check && r->check(r->check_ctx, l, r->line)) {
            r->why = NULL;
            return -1;
        }
        if (r->hash_comments) cut_comment(l);
        l = csf_trim(l);
        if (!*l || l[0] == '#') continue;
        *line = l;
        return 1;
    }
    return 0;
}

/* One quoted field from just after its opening quote: *p ends after the closing quote and the
 * spaces behind it. */
static int quoted_field(const char **pp, char *f, const char **why)
{
    const char *p = *pp;
    size_t k = 0;
    for (;;) {
        if (!*p) {
            *why = "a quoted field is not closed on its line";
            return -1;
        }
        if (*p == '"' && p[1] != '"') {
            p++;
            break;
        }
        if (k + 1 >= CSF_CSV_FIELD_MAX) { /* refused, never cut */
            *why = "a field longer than 1023 characters";
            return -1;
        }
        f[k++] = *p;
        p += *p == '"' ? 2 : 1; /* "" is one quote */
    }
    f[k] = '\0';
    while (*p == ' ' || *p == '\t') p++;
    if (*p && *p != ',') {
        *why = "text after a closing quote";
        return -1;
    }
    *pp = p;
    return 0;
}

static int plain_field(const char **pp, char *f, const char **why)
{
    const char *p = *pp;
    size_t k = 0;
    while (*p && *p != ',') {
        if (k + 1 >= CSF_CSV_FIELD_MAX) {
            *why = "a field longer than 1023 characters";
            return -1;
        }
        f[k++] = *p++;
    }
    while (k > 0 && (f[k - 1] == ' ' || f[k - 1] == '\t')) k--;
    f[k] = '\0';
    *pp = p;
    return 0;
}

int csf_csv_split(const char *line, char fields[][CSF_CSV_FIELD_MAX], int max, const char **why)
{
    int n = 0;
    const char *p = line;
    for (;;) {
        if (n == max) {
            *why = "too many columns";
            return -1;
        }
        while (*p == ' ' || *p == '\t') p++;
        int bad = *p == '"' ? (p++, quoted_field(&p, fields[n], why)) : plain_field(&p, fields[n], why);
        if (bad) return -1;
        n++;
        if (*p != ',') break;
        p++;
    }
    return n;
}
