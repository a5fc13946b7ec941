/* Display profiles are outside input (copied between stations, edited by hand): the parser must
 * refuse garbage with a message and never read out of bounds; what it accepts must be usable
 * (monotone forward model, inverse inside [0, 1], serialisable and re-parsable). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "results/display_profile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_display_profile *p = NULL;
    csf_error err;
    if (csf_profile_parse((const char *)data, size, &p, &err) != CSF_OK) return 0;
    double prev = -INFINITY;
    for (int i = 0; i <= 64; i++) {
        double L = csf_profile_grey_lum(p, i / 64.0);
        if (!(L >= prev)) abort(); /* accepted profiles are monotone */
        prev = L;
        double v = csf_profile_grey_drive(p, L);
        if (!(v >= 0 && v <= 1)) abort();
        if (csf_profile_has_channels(p)) {
            double c = csf_profile_channel_lum(p, i % 3, i / 64.0);
            if (!(c >= 0) || !isfinite(c)) abort();
        }
    }
    char *text = NULL;
    if (csf_profile_to_text(p, &text, &err) == CSF_OK) {
        csf_display_profile *q = NULL;
        if (csf_profile_parse(text, strlen(text), &q, &err) != CSF_OK) abort(); /* own output re-parses */
        csf_profile_free(q);
        free(text);
    }
    csf_profile_free(p);
    return 0;
}
