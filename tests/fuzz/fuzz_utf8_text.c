/* Text from a store another station wrote reaches the report's pages through csf_utf8_drawable
 * (core/utf8_text.h). The input is any bytes; the oracles are independent of its decoder:
 * - jansson, which refuses a string that is not UTF-8, must accept every output;
 * - no output byte is a C0 control or DEL, and no output holds a C1 control (C2 80..9F);
 * - the output never passes its cap;
 * - an input jansson accepts as UTF-8 and that holds no control character comes back unchanged
 *   when the cap allows it. */
#include <jansson.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/utf8_text.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int has_control(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c < 0x20 || c == 0x7F) return 1;
        if (c == 0xC2 && i + 1 < n && (unsigned char)s[i + 1] >= 0x80 && (unsigned char)s[i + 1] <= 0x9F)
            return 1;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    /* the first byte picks the cap, the rest is the text */
    size_t cap = size ? (size_t)data[0] * 4 : 0;
    const char *text = size ? (const char *)data + 1 : "";
    size_t n = size ? size - 1 : 0;
    char *out = csf_utf8_drawable(text, n, cap);
    if (!out) abort();
    size_t len = strlen(out);
    if (len > cap) abort();
    json_t *js = json_stringn(out, len);
    if (!js) abort(); /* not UTF-8 */
    json_decref(js);
    if (has_control(out, len)) abort();
    size_t in_len = strnlen(text, n);
    json_t *in = json_stringn(text, in_len);
    if (in && !has_control(text, in_len) && in_len <= cap && (len != in_len || memcmp(out, text, len) != 0))
        abort();
    json_decref(in);
    free(out);
    return 0;
}
