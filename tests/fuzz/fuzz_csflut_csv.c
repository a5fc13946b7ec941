/* CSV importer on hostile text: refuse with a line number or accept a grid that the writer and the
 * reader accept too (the importer must never hand the writer something it refuses). */
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
    if (csflut_write_memory(csflut_grid_build(g), &buf, &len) != CSFLUT_OK) abort();
    csflut_table *t;
    if (csflut_open_memory(buf, len, &t) != CSFLUT_OK) abort();
    volatile double s = csflut_threshold(t, 2, 3) + csflut_max_frequency(t, 1, 0.1);
    (void)s;
    csflut_close(t);
    free(buf);
    csflut_grid_free(g);
    return 0;
}
