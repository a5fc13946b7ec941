/* Replies of a Photo Research PR-655 / PR-670 (devices/photometer_pr655.h) are outside input:
 * each line of the input is parsed as one reply. A reply is refused with a message, or gives a
 * code and at most CSF_PR_MAX_FIELDS printable, terminated fields; a field read as a number is
 * finite; a non-zero code always has a sentence and an error status. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_pr655.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data, *end = p + size;
    while (p <= end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = nl ? (size_t)(nl - p) : (size_t)(end - p);
        csf_pr_reply r;
        csf_error err = {0};
        if (csf_pr_parse(p, len, &r, &err) != CSF_OK) {
            if (err.msg[0] == '\0' || err.code != CSF_E_PROTOCOL) abort();
        } else {
            if (r.n_fields < 0 || r.n_fields > CSF_PR_MAX_FIELDS) abort();
            for (int i = 0; i < r.n_fields; i++) {
                if (!memchr(r.field[i], '\0', sizeof r.field[i])) abort();
                double x;
                if (csf_pr_field_num(&r, i, &x) == 0 && !isfinite(x)) abort();
            }
            if (r.code != 0 && (!csf_pr_error_text(r.code)[0] || csf_pr_error_status(r.code) == CSF_OK)) abort();
        }
        if (!nl) break;
        p = nl + 1;
    }
    return 0;
}
