/* What spotread prints (devices/photometer_spotread.h) is outside input: the bridge scans it for
 * prompts, result lines and failures. Every event found uses up some of the input and no more than
 * all of it; a result carries three finite numbers; a failure has an error status and its line;
 * scanning what is left goes on until nothing complete remains. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_spotread.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data;
    size_t left = size;
    for (int guard = 0; guard < 100000; guard++) {
        csf_spotread_event ev;
        csf_spotread_scan(p, left, &ev);
        if (ev.consumed > left) abort();
        if (ev.kind == CSF_SPOT_NONE) {
            if (ev.consumed) abort();
            break;
        }
        if (ev.consumed == 0) abort();
        if (!memchr(ev.reason, '\0', sizeof ev.reason)) abort();
        if (ev.kind == CSF_SPOT_RESULT)
            for (int k = 0; k < 3; k++)
                if (!isfinite(ev.xyz[k])) abort();
        if (ev.kind == CSF_SPOT_FAIL && (ev.status == CSF_OK || !ev.reason[0])) abort();
        p += ev.consumed;
        left -= ev.consumed;
    }
    return 0;
}
