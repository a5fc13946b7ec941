/* The display=FILE.csv truth of the simulated photometer is outside input: refuse garbage with a
 * message, never read out of bounds; an accepted curve is monotone and finite. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "model/display_model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_display_model *m = NULL;
    csf_error err;
    if (csf_display_model_from_csv((const char *)data, size, "fuzz.csv", &m, &err) != CSF_OK) return 0;
    double prev = -INFINITY;
    for (int i = 0; i <= 300; i++) {
        double v = i / 300.0;
        double L = csf_display_model_lum(m, v, v, v);
        if (!isfinite(L) || L < prev) abort();
        prev = L;
    }
    csf_display_model_free(m);
    return 0;
}
