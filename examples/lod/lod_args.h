/* The lod example's command line (README.md in this folder): options, defaults and their parser,
 * apart from main() so that tests/fuzz/fuzz_lod_args can drive the parser. */
#ifndef LOD_ARGS_H
#define LOD_ARGS_H

#include <stdio.h>

#include "shade.h"

#define LOD_MAX_LEVELS 16

typedef struct {
    double distance_factor, threshold_factor;
    char name[32]; /* file name part: d1, d8, k4 */
} level;

typedef struct {
    const char *table, *out_dir;
    int width_px, height_px, views, subdiv;
    double ppd, object_deg, gaze_px[2];
    int gaze_set, diff_images;
    unsigned long long seed;
    level levels[LOD_MAX_LEVELS];
    int n_levels;
    lod_shade shade;
    /* the moving sequence (README.md, "Motion"); frames = 0: the still views instead */
    int frames, pursuit, judge_trials;
    double fps, object_velocity_dps, spin_dps, coarse_factor;
    const char *json_path; /* NULL: no JSON summary */
} options;

/* The defaults README.md documents. */
void lod_options_defaults(options *o);
/* 0: options valid and complete; 1: --help asked (nothing else checked); 2: bad options, the
 * problem and its limit already said on stderr. Values point into argv. */
int lod_parse_args(int argc, char **argv, options *o);
void lod_usage(FILE *f);

#endif
