/* Outside text made drawable (see core/utf8_text.h). */
#include "core/utf8_text.h"

#include <stdlib.h>
#include <string.h>

/* The length of the well-formed UTF-8 sequence at p (at most left bytes) and its code point, or 0
 * when none starts there (the table of well-formed byte sequences, RFC 3629 section 4). */
static size_t sequence_at(const unsigned char *p, size_t left, unsigned long *cp)
{
    unsigned char b = p[0];
    if (b < 0x80) {
        *cp = b;
        return 1;
    }
    size_t len = b >= 0xC2 && b <= 0xDF ? 2 : b >= 0xE0 && b <= 0xEF ? 3 : b >= 0xF0 && b <= 0xF4 ? 4 : 0;
    if (!len || len > left) return 0;
    /* the second byte's range is narrower after E0 (overlong), ED (surrogates), F0 (overlong) and F4
     * (above U+10FFFF) */
    unsigned char lo = b == 0xE0   ? 0xA0
                       : b == 0xF0 ? 0x90
                                   : 0x80,
                  hi = b == 0xED   ? 0x9F
                       : b == 0xF4 ? 0x8F
                                   : 0xBF;
    if (p[1] < lo || p[1] > hi) return 0;
    unsigned long v = b & (len == 2 ? 0x1F : len == 3 ? 0x0F : 0x07);
    for (size_t i = 1; i < len; i++) {
        if (i > 1 && (p[i] < 0x80 || p[i] > 0xBF)) return 0;
        v = (v << 6) | (p[i] & 0x3F);
    }
    *cp = v;
    return len;
}

char *csf_utf8_drawable(const char *s, size_t n, size_t max_out)
{
    static const char replacement[] = "\xEF\xBF\xBD";
    size_t len = s ? strnlen(s, n) : 0;
    size_t cap = len * 3 < max_out ? len * 3 : max_out; /* a byte grows to at most three */
    char *out = malloc(cap + 1);
    if (!out) return NULL;
    const unsigned char *p = (const unsigned char *)s;
    size_t i = 0, o = 0;
    while (i < len) {
        unsigned long cp = 0;
        size_t k = sequence_at(p + i, len - i, &cp);
        int bad = !k || cp < 0x20 || (cp >= 0x7F && cp <= 0x9F);
        size_t w = bad ? 3 : k;
        if (o + w > cap) break;
        memcpy(out + o, bad ? replacement : (const char *)p + i, w);
        o += w;
        i += k ? k : 1;
    }
    out[o] = '\0';
    return out;
}
