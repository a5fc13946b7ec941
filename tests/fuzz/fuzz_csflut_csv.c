/* CSV importer on hostile text: refuse with a line number or accept a grid (velocity axis and
 * "# meta.KEY: value" pairs included) that the writer and the reader accept too (the importer
 * must never hand the writer something it refuses). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "results/csflut/csflut.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csflut_grid *g = NULL;
    csflut_diag d;
    if (csflut_import_csv((const char *)data, size, &g, &d) != CSFLUT_OK) return 0;
    unsigned char *buf;
    size_t len;
    size_t nm = 0;
    const csflut_meta *meta = csflut_grid_meta(g, &nm);
    if (csflut_write_memory_meta(csflut_grid_build(g), meta, nm, &buf, &len, NULL) != CSFLUT_OK) abort();
    csflut_table *t;
    if (csflut_open_memory(buf, len, &t) != CSFLUT_OK) abort();
    if (csflut_meta_count(t) != (int)nm) abort();
    volatile double s = csflut_threshold(t, 2, 3) + csflut_max_frequency(t, 1, 0.1) +
                        csflut_threshold3(t, 2, 3, 0) + csflut_max_frequency4(t, 1, 5, 50, 0.1);
    (void)s;
    csflut_close(t);
    free(buf);
    csflut_grid_free(g);
    return 0;
}
