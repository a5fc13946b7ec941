/* Replies of a Konica Minolta LS-100 / LS-110 / CS-100A (devices/photometer_ls100.h) are outside
 * input: each line of the input is parsed as one reply. A reply is refused with a message, or
 * gives OK/ER, a code 0..99 and at most three finite values; an ER code always has a sentence. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_ls100.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data, *end = p + size;
    while (p <= end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = nl ? (size_t)(nl - p) : (size_t)(end - p);
        csf_minolta_reply r;
        csf_error err = {0};
        if (csf_minolta_parse(p, len, &r, &err) != CSF_OK) {
            if (err.msg[0] == '\0' || err.code != CSF_E_PROTOCOL) abort();
        } else {
            if (r.code < 0 || r.code > 99 || r.n_values < 0 || r.n_values > 3) abort();
            for (int i = 0; i < r.n_values; i++)
                if (!isfinite(r.v[i])) abort();
            if (!r.ok && (r.n_values || !csf_minolta_error_text(r.code)[0])) abort();
            if (!r.ok && csf_minolta_error_status(r.code) == CSF_OK) abort();
        }
        if (!nl) break;
        p = nl + 1;
    }
    return 0;
}
