/* Text from outside (a store another station wrote, a damaged file) made safe to draw: a renderer
 * such as cairo refuses a string that is not valid UTF-8 and stops drawing the whole page, and a
 * control character has no glyph and no business on a report. */
#ifndef CSF_UTF8_TEXT_H
#define CSF_UTF8_TEXT_H

#include <stddef.h>

/* A copy of the first n bytes of s (up to its NUL) as valid UTF-8: each byte that does not begin a
 * well-formed sequence (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF) and
 * each control character (U+0000-U+001F, U+007F-U+009F) becomes U+FFFD. The copy stops before a
 * character that would take it past max_out bytes (NUL not counted). NULL when out of memory; the
 * caller frees it. */
char *csf_utf8_drawable(const char *s, size_t n, size_t max_out);

#endif
