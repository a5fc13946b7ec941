/* Luebke & Hallen's (2001) vertex tree and their perceptual fold criterion (§5.2).
 *
 * The tree is a hierarchical clustering of the mesh's vertices (here: median splits along the
 * longest axis, so each node holds a compact cluster; leaves hold one vertex). Folding a node
 * merges every vertex it supports into its proxy; triangles with two corners in one folded node
 * vanish. Per node, precomputed once: a bounding sphere of its region of support (the triangles
 * touching its vertices), the proxy, the luminance range of its vertices and the largest contrast
 * between a supported vertex and the proxy (Gouraud extremes are at vertices, so this bounds the
 * contrast the fold induces on the surface). Per view the cut is chosen top down: a node is
 * folded when the worst-case grating of its fold (lowest frequency 1/(2 x angular extent), at
 * its eccentricity from the gaze, at its contrast) is below the observer's threshold. */
#ifndef LOD_VTREE_H
#define LOD_VTREE_H

#include <csflut.h>
#include <stdint.h>

#include "mesh.h"
#include "shade.h"

typedef struct {
    int child[2];        /* -1 for a leaf */
    int lo, hi;          /* supported vertices: perm[lo..hi) */
    int proxy;           /* vertex whose position the folded node takes */
    float center[3], radius; /* sphere around the region of support */
    float normal[3];     /* proxy normal: mean of the supported vertices' normals */
    float lum_min, lum_max;  /* luminance range of the supported vertices, cd/m2 */
    float contrast;      /* max Michelson contrast between a supported vertex and the proxy */
    float lum_proxy;     /* luminance the folded node is drawn with (its normal's), cd/m2 */
} lod_node;

typedef struct {
    const lod_mesh *mesh;
    lod_node *node;      /* node[0] is the root; parents come before their children */
    int n_node;
    int *perm;           /* vertices in tree order */
    int *leaf_of;        /* vertex -> its leaf node */
    float scene_lum_min, scene_lum_max; /* darkest and brightest thing in the scene, background included */
} lod_vtree;

int lod_vtree_build(lod_vtree *t, const lod_mesh *m, const lod_shade *s);
void lod_vtree_free(lod_vtree *t);

/* A view as the simplifier sees it: the camera (world -> eye transform as a 4x4 column-major
 * matrix, eye at the origin looking down -z), the image, the viewer's geometry and the gaze. */
typedef struct {
    float view[16];
    int width_px, height_px;
    double dist_px;          /* eye to image plane, in pixels: ppd * 180 / pi */
    double gaze_px[2];       /* gaze point in image pixels (x right, y down) */
    double distance_factor;  /* delta: simplify as if the viewer were this many times farther */
    double threshold_factor; /* k: treat every threshold as k times higher */
    int cull_only;           /* fold only what cannot be seen (off screen, facing away): the
                                baseline the perceptual criterion is measured against */
    const float *vel_lo_dps; /* per node: the lowest and highest retinal velocity (deg/s) over */
    const float *vel_hi_dps; /* its vertices (lod_vtree_velocity_range); NULL = the still views'
                                  test (csflut_perceptible, no velocity) */
} lod_view;

typedef struct {
    int folded_nodes;
    int silhouette_nodes;  /* folds judged with silhouette contrast (and taken) */
    int culled_nodes;      /* folded because outside the frustum or entirely back-facing */
} lod_cut_stats;

/* Chooses the cut for one view and writes the triangles of the simplified mesh as node indices
 * into tri_out (3 per triangle; room for mesh->n_tri triangles). Returns the triangle count, or
 * -1 when out of memory. */
int lod_vtree_simplify(const lod_vtree *t, const csflut_table *tab, const lod_view *v,
                       uint32_t *tri_out, lod_cut_stats *stats);

/* Per node, the range of the retinal velocities of the vertices it supports, from velocity_dps
 * per node (a leaf's is its vertex's): a fold spans them all, so it is tested at both ends. */
void lod_vtree_velocity_range(const lod_vtree *t, const float *velocity_dps, float *lo_dps, float *hi_dps);

/* The full mesh as node indices (every vertex is its own leaf). */
int lod_vtree_full(const lod_vtree *t, uint32_t *tri_out);

#endif
