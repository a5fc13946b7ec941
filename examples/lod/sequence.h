/* The moving sequence (README.md, "Motion"): per frame the retinal velocity of every node, three
 * simplifications (the table at velocity 0, the table at each node's real velocity, and a
 * deliberately coarser one at the real velocity with every threshold x coarse_factor), the full and
 * simplified renders as PNG frames, each compared with the full frame by the spatio-temporal rule
 * (imgdiff.h at each pixel's retinal velocity), the sequence judged by a simulated person
 * (judge.h), and a summary on stdout, in motion_summary.csv and optionally as JSON. */
#ifndef LOD_SEQUENCE_H
#define LOD_SEQUENCE_H

#include <csflut.h>

#include "lod_args.h"
#include "motion.h"
#include "render.h"
#include "vtree.h"

typedef struct {
    const options *o;
    const lod_vtree *tree;
    const csflut_table *tab;
    lod_renderer *r;
    lod_path path;
    lod_screen screen;
} lod_sequence;

/* 0, or 1 with the problem said on stderr. */
int lod_run_sequence(const lod_sequence *q);

#endif
