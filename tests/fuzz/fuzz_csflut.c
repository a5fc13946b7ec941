/* csflut reader on hostile bytes: open from memory must refuse or accept cleanly, and every query
 * (velocity and batch ones included), view change, metadata pair and export on an accepted table
 * must stay in bounds; what it accepts, the writer writes again. The CRC check would reject
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
                sink += csflut_threshold3(t, f[i], e[j], -f[i]);
                sink += csflut_perceptible3(t, f[i], e[j], e[j], 0.02);
                sink += csflut_max_frequency4(t, e[j], f[i], 50, 0.05);
                sink += csflut_max_frequency(t, e[j], fabs(f[i]) * 0.01);
                sink += csflut_max_frequency4(t, e[j], 1, 50, 0.05);
                sink += csflut_perceptible(t, f[i], e[j], 0.02);
            }
        sink += csflut_peak_frequency(t, 3);
        double out[sizeof f / sizeof f[0]];
        csflut_threshold3_batch(t, f, f, f, out, sizeof f / sizeof f[0]);
        sink += out[3];
    }
    sink += csflut_velocity_warp_v0(t);
    for (int k = 0; k <= csflut_meta_count(t); k++) {
        const char *key = csflut_meta_key(t, k), *val = csflut_meta_value(t, k);
        if (key && val) sink += (double)strlen(key) + (double)strlen(val) + (csflut_meta_find(t, key) == val);
    }
    csflut_set_stderr_shift(t, 1.5);
    for (int fmt = 0; fmt < 4; fmt++) {
        char *out;
        if (csflut_export(t, (csflut_format)fmt, "fz", &out, NULL) == CSFLUT_OK) free(out);
    }
    /* an accepted table (metadata pairs included) is written again and read back */
    csflut_build b;
    csflut_table_to_build(t, &b);
    csflut_meta meta[256];
    size_t nm = csflut_table_meta(t, meta, 256);
    unsigned char *w;
    size_t wl;
    if (csflut_write_memory_meta(&b, meta, nm, &w, &wl, NULL) == CSFLUT_OK) {
        csflut_table *t2 = NULL;
        if (csflut_open_memory(w, wl, &t2) != CSFLUT_OK) abort();
        if (csflut_meta_count(t2) != (int)nm) abort();
        csflut_close(t2);
        free(w);
    }
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
