/* The one reader of line-based text files csfcal takes from outside: CSV tables (a study's
 * conditions, a simulated display's curves, a simulated person's thresholds) and key = value
 * settings. csf_lines walks the lines of a text held in memory: a UTF-8 byte-order mark before
 * the first line is dropped, each line is trimmed of spaces, tabs and a CR, blank lines and lines
 * that start with '#' are skipped, and a NUL byte or a line longer than the caller's limit stops
 * the walk with the reason; line numbers count every line, skipped ones included, so messages
 * name the line an editor shows. csf_csv_split cuts one line into fields by RFC 4180: a field in
 * double quotes may hold commas, "" is one quote; fields outside quotes are trimmed. Hand-written
 * rather than taken from a library: it must refuse (never cut) an overlong field and report the
 * reason in words, and it is 100 lines. */
#ifndef CSF_CORE_CSV_H
#define CSF_CORE_CSV_H

#include <stddef.h>

#define CSF_CSV_FIELD_MAX 1024 /* a field's bytes, its NUL included */

typedef struct {
    const char *text;
    size_t len, pos;
    int line;          /* the number of the line last returned (from 1) */
    int hash_comments; /* 1: '#' also ends a line where it stands (outside quotes) */
    size_t max_line;   /* longest line accepted, in bytes */
    char *buf;
    const char *why; /* why csf_lines_next returned -1 */
    char why_buf[64];
    /* Optional: sees each line as read (the byte-order mark dropped), before anything is cut or
     * skipped, comments included; non-zero stops the walk (csf_lines_next returns -1 with why
     * NULL: the check said why). */
    int (*check)(void *ctx, const char *raw_line, int line);
    void *check_ctx;
} csf_lines;

/* Walks text[0, len); lines longer than max_line bytes are refused (at most 65535). Returns 0, or
 * -1 when out of memory. */
int csf_lines_open(csf_lines *r, const char *text, size_t len, size_t max_line);
/* The next line that holds something, trimmed, in *line (valid until the next call). Returns 1,
 * 0 at the end, or -1 with r->why ("a NUL byte", "a line longer than N characters") and r->line. */
int csf_lines_next(csf_lines *r, char **line);
void csf_lines_close(csf_lines *r);

/* Fields of one line into fields[0 .. max-1]. Returns their number, or -1 with *why: too many
 * columns, an unclosed quote, text after a closing quote, a field of CSF_CSV_FIELD_MAX bytes or
 * more. */
int csf_csv_split(const char *line, char fields[][CSF_CSV_FIELD_MAX], int max, const char **why);

/* s without its leading and trailing spaces, tabs, CRs and LFs (cut in place). */
char *csf_trim(char *s);

#endif
