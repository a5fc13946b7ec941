/* csflut reader on hostile bytes: open from memory must refuse or accept cleanly, and every query,
 * view change and export on an accepted table must stay in bounds. The CRC check would reject
 * almost every mutation before the parser proper, so when the input is long enough the target
 * also parses a copy with the checksum recomputed, to reach the section parsing and validation. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "results/csflut/csflut.h"
#include "results/csflut/csflut_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void exercise(const unsigned char *buf, size_t len)
{
    csflut_table *t = NULL;
    csflut_diag d;
    if (csflut_open_memory_diag(buf, len, &t, &d) != CSFLUT_OK) return;
    static const double f[] = {-1, 0, 1e-300, 0.25, 1, 3.3, 17, 1e6, INFINITY, NAN};
    static const double e[] = {-5, 0, 2.5, 13, 90, INFINITY, NAN};
    volatile double sink = 0;
    for (int view = 0; view < 2; view++) {
        csflut_set_conservative(t, view);
        for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
            for (size_t j = 0; j < sizeof e / sizeof e[0]; j++) {
                sink += csflut_threshold(t, f[i], e[j]);
                sink += csflut_threshold4(t, f[i], e[j], f[i], f[i]);
                sink += csflut_max_frequency(t, e[j], fabs(f[i]) * 0.01);
                sink += csflut_max_frequency4(t, e[j], 1, 50, 0.05);
                sink += csflut_perceptible(t, f[i], e[j], 0.02);
            }
        sink += csflut_peak_frequency(t, 3);
    }
    csflut_set_stderr_shift(t, 1.5);
    for (int fmt = 0; fmt < 4; fmt++) {
        char *out;
        if (csflut_export(t, (csflut_format)fmt, "fz", &out, NULL) == CSFLUT_OK) free(out);
    }
    csflut_build b;
    csflut_table_to_build(t, &b);
    unsigned char *w;
    size_t wl;
    if (csflut_write_memory(&b, &w, &wl) == CSFLUT_OK) free(w);
    (void)sink;
    csflut_close(t);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    exercise(data, size);
    if (size >= CSFLUT_HEADER_SIZE + 4 && size < (1u << 20)) {
        unsigned char *copy = malloc(size);
        memcpy(copy, data, size);
        /* make the size field and the checksum agree with the bytes */
        for (int i = 0; i < 8; i++) copy[16 + i] = (unsigned char)((uint64_t)size >> (8 * i));
        uint32_t crc = csflut_crc32(copy, size - 4);
        for (int i = 0; i < 4; i++) copy[size - 4 + i] = (unsigned char)(crc >> (8 * i));
        exercise(copy, size);
        free(copy);
    }
    return 0;
}
