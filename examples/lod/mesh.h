/* A procedural test mesh: an icosphere displaced by ridges at several scales, so that a
 * simplifier has detail to remove at every size and lighting turns geometry into contrast. */
#ifndef LOD_MESH_H
#define LOD_MESH_H

#include <stdint.h>

typedef struct {
    int n_vert, n_tri;
    float *pos;      /* 3 per vertex, object units (radius about 1) */
    float *nrm;      /* 3 per vertex, unit, area-weighted average of the face normals */
    uint32_t *tri;   /* 3 per triangle, counter-clockwise seen from outside */
} lod_mesh;

/* subdiv: 0..8 (20 * 4^subdiv triangles); seed picks the ridges. Returns 0, or -1 when out of
 * memory or subdiv is outside 0..8. */
int lod_mesh_bumpy_sphere(lod_mesh *m, int subdiv, uint64_t seed);
void lod_mesh_free(lod_mesh *m);

#endif
