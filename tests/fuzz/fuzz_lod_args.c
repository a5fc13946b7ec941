/* examples/lod's command line is outside input: the input, split at NUL bytes, is the argument
 * list. Whatever it holds, the parser either refuses (2), answers --help (1), or accepts options
 * inside the ranges README.md documents: finite numbers, a gaze inside the image, a model that
 * fits, 1-16 levels with factors 1-1000. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lod_args.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(const options *o)
{
    if (!o->table || !o->out_dir) abort();
    if (o->width_px < 16 || o->width_px > 4096 || o->height_px < 16 || o->height_px > 4096) abort();
    if (!(o->ppd >= 2 && o->ppd <= 200) || !(o->object_deg >= 1 && o->object_deg <= 120)) abort();
    if (o->views < 1 || o->views > 64 || o->subdiv < 3 || o->subdiv > 7) abort();
    if (o->n_levels < 0 || o->n_levels > LOD_MAX_LEVELS) abort();
    for (int i = 0; i < o->n_levels; i++) {
        const level *l = &o->levels[i];
        if (!(l->distance_factor >= 1 && l->distance_factor <= 1000)) abort();
        if (!(l->threshold_factor >= 1 && l->threshold_factor <= 1000)) abort();
        if (!memchr(l->name, '\0', sizeof l->name)) abort();
    }
    if (!(o->gaze_px[0] >= 0 && o->gaze_px[0] <= o->width_px && o->gaze_px[1] >= 0 && o->gaze_px[1] <= o->height_px))
        abort();
    if (!(o->shade.lum_black_cdm2 > 0 && o->shade.lum_black_cdm2 < o->shade.lum_peak_cdm2)) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 2048) return 0;
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    char *argv[66];
    int argc = 0;
    argv[argc++] = (char *)"lod";
    for (size_t i = 0; i <= size && argc < 65;) {
        argv[argc++] = buf + i;
        i += strlen(buf + i) + 1;
    }
    argv[argc] = NULL;
    options o;
    lod_options_defaults(&o);
    int rc = lod_parse_args(argc, argv, &o);
    if (rc != 0 && rc != 1 && rc != 2) abort();
    if (rc == 0) check(&o);
    free(buf);
    return 0;
}
