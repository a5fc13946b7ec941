/* core/spec.c reads every simulated device's spec and the command line's numbers: outside
 * input. The first byte picks the parser, the rest is the text. A split that succeeds must
 * give back the text item by item, with no empty item and no key twice; a refusal must say why
 * without raw control bytes; a number accepted must be finite and inside its range. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/spec.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_split(const char *text, size_t len)
{
    static csf_spec s;
    csf_error err;
    csf_error_clear(&err);
    if (csf_spec_split(text, "fuzz", &s, &err) != CSF_OK) {
        if (err.code != CSF_E_INVALID_ARG || strncmp(err.msg, "fuzz: ", 6) != 0) abort();
        for (const char *p = err.msg; *p; p++)
            if ((unsigned char)*p < 0x20 || (unsigned char)*p >= 0x7f) abort();
        return;
    }
    if (len > CSF_SPEC_MAX_CHARS || s.n < 0 || s.n > CSF_SPEC_MAX_ITEMS || (len == 0) != (s.n == 0)) abort();
    /* the items, joined again, are the text */
    char *joined = malloc(len + 1);
    size_t o = 0;
    for (int i = 0; i < s.n; i++) {
        const csf_spec_item *it = &s.item[i];
        if (!it->key[0] && !it->value) abort(); /* an empty item was let through */
        size_t kl = strlen(it->key), vl = it->value ? strlen(it->value) : 0;
        if (o + (i ? 1 : 0) + kl + (it->value ? 1 + vl : 0) > len) abort();
        if (i) joined[o++] = ',';
        memcpy(joined + o, it->key, kl);
        o += kl;
        if (it->value) {
            joined[o++] = '=';
            memcpy(joined + o, it->value, vl);
            o += vl;
        }
        for (int j = 0; j < i; j++)
            if (it->value && s.item[j].value && strcmp(s.item[j].key, it->key) == 0) abort();
    }
    if (o != len || memcmp(joined, text, len) != 0) abort();
    free(joined);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 4096) return 0;
    char *text = malloc(size);
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';
    size_t len = strlen(text);
    switch (data[0] % 3) {
    case 0: check_split(text, len); break;
    case 1: {
        double v = NAN;
        csf_num_result r = csf_number_parse(text, -2.5, 1e4, &v);
        if (r == CSF_NUM_OK && !(v >= -2.5 && v <= 1e4)) abort();
        if (r == CSF_NUM_OUT_OF_RANGE && (!isfinite(v) || (v >= -2.5 && v <= 1e4))) abort();
        break;
    }
    default: {
        long v = 0;
        csf_num_result r = csf_whole_parse(text, -7, 5000, &v);
        if (r == CSF_NUM_OK && (v < -7 || v > 5000)) abort();
        if (r == CSF_NUM_OUT_OF_RANGE && v >= -7 && v <= 5000) abort();
        break;
    }
    }
    free(text);
    return 0;
}
