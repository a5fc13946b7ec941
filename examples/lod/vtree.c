#include "vtree.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef struct { float key; int vert; } sort_item;

static int cmp_item(const void *a, const void *b)
{
    float x = ((const sort_item *)a)->key, y = ((const sort_item *)b)->key;
    return (x > y) - (x < y);
}

/* Median split along the longest side of the cluster's bounding box. */
static int build_range(lod_vtree *t, sort_item *scratch, int lo, int hi)
{
    int idx = t->n_node++;
    lod_node *n = &t->node[idx];
    n->lo = lo;
    n->hi = hi;
    n->child[0] = n->child[1] = -1;
    if (hi - lo == 1) return idx;
    const float *pos = t->mesh->pos;
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = lo; i < hi; i++)
        for (int c = 0; c < 3; c++) {
            float p = pos[3 * t->perm[i] + c];
            mn[c] = p < mn[c] ? p : mn[c];
            mx[c] = p > mx[c] ? p : mx[c];
        }
    int axis = 0;
    for (int c = 1; c < 3; c++)
        if (mx[c] - mn[c] > mx[axis] - mn[axis]) axis = c;
    for (int i = lo; i < hi; i++) scratch[i] = (sort_item){pos[3 * t->perm[i] + axis], t->perm[i]};
    qsort(scratch + lo, (size_t)(hi - lo), sizeof *scratch, cmp_item);
    for (int i = lo; i < hi; i++) t->perm[i] = scratch[i].vert;
    int mid = lo + (hi - lo) / 2;
    int c0 = build_range(t, scratch, lo, mid);
    int c1 = build_range(t, scratch, mid, hi);
    t->node[idx].child[0] = c0;
    t->node[idx].child[1] = c1;
    return idx;
}

/* Per vertex, over its one-ring (the triangles around it, the leaf's region of support): the
 * largest distance to a neighbour and the luminance range. */
static int ring_summary(const lod_mesh *m, const lod_shade *s, float *radius, float *lum_lo, float *lum_hi)
{
    for (int v = 0; v < m->n_vert; v++) {
        radius[v] = 0;
        lum_lo[v] = lum_hi[v] = (float)lod_shade_lum(s, lod_shade_intensity(s, m->nrm + 3 * v));
    }
    for (int f = 0; f < m->n_tri; f++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = m->tri[3 * f + k], b = m->tri[3 * f + (k + 1) % 3];
            const float *pa = m->pos + 3 * a, *pb = m->pos + 3 * b;
            float d = sqrtf((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                            (pa[2] - pb[2]) * (pa[2] - pb[2]));
            float la = (float)lod_shade_lum(s, lod_shade_intensity(s, m->nrm + 3 * a));
            float lb = (float)lod_shade_lum(s, lod_shade_intensity(s, m->nrm + 3 * b));
            radius[a] = fmaxf(radius[a], d);
            radius[b] = fmaxf(radius[b], d);
            lum_lo[a] = fminf(lum_lo[a], lb);
            lum_hi[a] = fmaxf(lum_hi[a], lb);
            lum_lo[b] = fminf(lum_lo[b], la);
            lum_hi[b] = fmaxf(lum_hi[b], la);
        }
    return 0;
}

/* Bottom up (children have higher indices): spheres, luminance ranges, proxies, contrasts. */
static int summarise(lod_vtree *t, const lod_shade *s)
{
    const lod_mesh *m = t->mesh;
    float *rr = malloc((size_t)m->n_vert * 3 * sizeof *rr), *ring_lo = rr + m->n_vert, *ring_hi = rr + 2 * m->n_vert;
    double *sum = calloc((size_t)t->n_node * 6, sizeof *sum); /* position, normal */
    if (!rr || !sum) { free(rr); free(sum); return -1; }
    ring_summary(m, s, rr, ring_lo, ring_hi);
    for (int i = t->n_node - 1; i >= 0; i--) {
        lod_node *n = &t->node[i];
        double *si = sum + 6 * i;
        if (n->child[0] < 0) {
            int v = t->perm[n->lo];
            t->leaf_of[v] = i;
            memcpy(n->center, m->pos + 3 * v, sizeof n->center);
            n->radius = rr[v];
            for (int c = 0; c < 3; c++) {
                si[c] = m->pos[3 * v + c];
                si[3 + c] = m->nrm[3 * v + c];
            }
            n->lum_min = ring_lo[v];
            n->lum_max = ring_hi[v];
        } else {
            const lod_node *a = &t->node[n->child[0]], *b = &t->node[n->child[1]];
            for (int c = 0; c < 6; c++) si[c] = sum[6 * n->child[0] + c] + sum[6 * n->child[1] + c];
            n->lum_min = a->lum_min < b->lum_min ? a->lum_min : b->lum_min;
            n->lum_max = a->lum_max > b->lum_max ? a->lum_max : b->lum_max;
        }
        int count = n->hi - n->lo;
        double best = INFINITY;
        for (int j = n->lo; j < n->hi; j++) {
            const float *p = m->pos + 3 * t->perm[j];
            double d = 0;
            for (int c = 0; c < 3; c++) d += (p[c] - si[c] / count) * (p[c] - si[c] / count);
            if (d < best) { best = d; n->proxy = t->perm[j]; }
        }
        if (count > 1) { /* around the centroid: through every supported vertex's one-ring */
            double r = 0;
            for (int c = 0; c < 3; c++) n->center[c] = (float)(si[c] / count);
            for (int j = n->lo; j < n->hi; j++) {
                const float *p = m->pos + 3 * t->perm[j];
                double d = sqrt((p[0] - n->center[0]) * (p[0] - n->center[0]) + (p[1] - n->center[1]) * (p[1] - n->center[1]) +
                                (p[2] - n->center[2]) * (p[2] - n->center[2])) + rr[t->perm[j]];
                r = d > r ? d : r;
            }
            n->radius = (float)(r * 1.0001); /* float rounding must not leave a vertex outside */
        }
        double len = sqrt(si[3] * si[3] + si[4] * si[4] + si[5] * si[5]);
        for (int c = 0; c < 3; c++) n->normal[c] = len > 0 ? (float)(si[3 + c] / len) : 0.0f;
        /* Gouraud: a pixel of the region shows a blend of the region's vertices before the fold
         * and of the proxy and the region's border after it (L&H's footnote on Gouraud shading:
         * include the adjacent vertices), so the change is bounded by the whole range */
        double lp = lod_shade_lum(s, lod_shade_intensity(s, n->normal));
        double lo = fmin(n->lum_min, lp), hi = fmax(n->lum_max, lp);
        double cmax = count > 1 ? (hi - lo) / (hi + lo) : 0;
        n->lum_proxy = (float)lp;
        n->contrast = (float)cmax;
    }
    double bg = lod_shade_lum(s, s->background);
    t->scene_lum_min = (float)fmin(t->node[0].lum_min, bg);
    t->scene_lum_max = (float)fmax(t->node[0].lum_max, bg);
    free(rr);
    free(sum);
    return 0;
}

int lod_vtree_build(lod_vtree *t, const lod_mesh *m, const lod_shade *s)
{
    memset(t, 0, sizeof *t);
    if (m->n_vert < 1) return -1; /* build_range splits down to single vertices: it needs one */
    t->mesh = m;
    t->node = malloc((size_t)(2 * m->n_vert - 1) * sizeof *t->node);
    t->perm = malloc((size_t)m->n_vert * sizeof *t->perm);
    t->leaf_of = malloc((size_t)m->n_vert * sizeof *t->leaf_of);
    sort_item *scratch = malloc((size_t)m->n_vert * sizeof *scratch);
    if (!t->node || !t->perm || !t->leaf_of || !scratch) goto fail;
    for (int v = 0; v < m->n_vert; v++) t->perm[v] = v;
    build_range(t, scratch, 0, m->n_vert);
    free(scratch);
    scratch = NULL;
    if (summarise(t, s) != 0) goto fail;
    return 0;
fail:
    free(scratch);
    lod_vtree_free(t);
    return -1;
}

void lod_vtree_free(lod_vtree *t)
{
    free(t->node);
    free(t->perm);
    free(t->leaf_of);
    memset(t, 0, sizeof *t);
}

static void to_eye(const float m[16], const float p[3], float out[3])
{
    for (int r = 0; r < 3; r++) out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

enum { FACES_FRONT = 1, FACES_BACK = 2 };

/* Silhouette nodes (§5.2): nodes supporting both front- and back-facing triangles. The paper
 * approximates this with normal masks for speed; here each triangle's facing is computed exactly
 * for the view and OR-ed up the tree. */
static void facing_flags(const lod_vtree *t, const float *eye_pos, uint8_t *flag)
{
    const lod_mesh *m = t->mesh;
    memset(flag, 0, (size_t)t->n_node);
    for (int f = 0; f < m->n_tri; f++) {
        const float *a = eye_pos + 3 * m->tri[3 * f], *b = eye_pos + 3 * m->tri[3 * f + 1],
                    *c = eye_pos + 3 * m->tri[3 * f + 2];
        float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
        uint8_t bit = (n[0] * a[0] + n[1] * a[1] + n[2] * a[2]) < 0 ? FACES_FRONT : FACES_BACK;
        for (int k = 0; k < 3; k++) flag[t->leaf_of[m->tri[3 * f + k]]] |= bit;
    }
    /* One ring wider than the paper's definition: a node whose own triangles all face the viewer
     * can still be the crest of a ridge whose far side faces away, and folding it exposes the
     * surface behind the crest (measured: without this, "imperceptible" folds on the bumpy sphere
     * left blobs at 11x threshold; with it, none). */
    for (int f = 0; f < m->n_tri; f++) {
        int a = t->leaf_of[m->tri[3 * f]], b = t->leaf_of[m->tri[3 * f + 1]], c = t->leaf_of[m->tri[3 * f + 2]];
        uint8_t u = flag[a] | flag[b] | flag[c];
        flag[a] |= u; flag[b] |= u; flag[c] |= u;
    }
    for (int i = t->n_node - 1; i >= 0; i--)
        if (t->node[i].child[0] >= 0) flag[i] |= flag[t->node[i].child[0]] | flag[t->node[i].child[1]];
}

static int outside_frustum(const lod_view *v, const float c[3], float r)
{
    double tx = 0.5 * v->width_px / v->dist_px, ty = 0.5 * v->height_px / v->dist_px;
    double nx = 1 / sqrt(1 + tx * tx), ny = 1 / sqrt(1 + ty * ty);
    if (c[2] > r) return 1; /* behind the eye */
    if ((c[0] + c[2] * tx) * nx > r || (-c[0] + c[2] * tx) * nx > r) return 1;
    if ((c[1] + c[2] * ty) * ny > r || (-c[1] + c[2] * ty) * ny > r) return 1;
    return 0;
}

/* Luebke & Hallen §5.2: the contrast a fold may induce. Off the silhouette, the node's own bound;
 * on it, whatever the moved edge may expose: the node's luminance range against the darkest and
 * brightest things in the scene (background included). */
static double fold_contrast(const lod_vtree *t, const lod_node *n, int silhouette)
{
    double c = n->contrast;
    if (silhouette) {
        double hi = t->scene_lum_max, lo = t->scene_lum_min;
        c = fmax(c, (hi - n->lum_min) / (hi + n->lum_min));
        c = fmax(c, (n->lum_max - lo) / (n->lum_max + lo));
    }
    return c;
}

/* The fold test at a retinal velocity (Reddy 2001; Kelly 1979), in the LOD runtime's form: the fold
 * is visible when its frequency is at or below the finest frequency still visible at its contrast
 * (csflut_max_frequency4; seed 000 5.3 stores that as a wavelength). A table without a velocity
 * axis ignores the velocity.
 * Luebke & Hallen's bound puts all of a fold's change at its lowest frequency 1/(2 extent), which
 * is the worst case only while thresholds do not fall below it at coarser scales. Motion breaks
 * that: a moving low frequency is far more visible than a still one (Kelly 1979), so the table's
 * moving slices may put their most sensitive frequency well below a node's. The change of a fold is
 * a blob of the node's size; a band of coarser frequency f' sees it diluted by the area ratio,
 * at most (f' / f)^2 of its contrast, and the fold is visible if that reaches the threshold at f'. */
static int moving_fold_perceptible(const csflut_table *tab, double freq_cpd, double ecc_deg, double vel_dps,
                                   double contrast)
{
    double lum = csflut_default_luminance(tab);
    if (!(freq_cpd > csflut_max_frequency4(tab, ecc_deg, vel_dps, lum, contrast))) return 1;
    const double *grid_cpd = csflut_axis_points(tab, CSFLUT_AXIS_FREQ);
    for (int i = 0, n = csflut_axis_size(tab, CSFLUT_AXIS_FREQ); i < n && grid_cpd[i] < freq_cpd; i++) {
        double r = grid_cpd[i] / freq_cpd;
        if (contrast * r * r >= csflut_threshold4(tab, grid_cpd[i], ecc_deg, vel_dps, lum)) return 1;
    }
    return 0;
}

/* Where a node's change sits for the viewer: the lowest frequency of a change confined to its
 * sphere, 1 / (2 x angular extent), at most the display's Nyquist limit (a sub-pixel change
 * appears there), times the distance factor; and the eccentricity of its nearest point from the
 * gaze. 0 when the eye is inside the sphere (no angular bound: treat as visible). */
static int node_place(const lod_view *v, const lod_node *n, const float c_eye[3], double *freq_cpd,
                      double *ecc_deg)
{
    double dist = sqrt(c_eye[0] * c_eye[0] + c_eye[1] * c_eye[1] + c_eye[2] * c_eye[2]);
    if (dist <= n->radius) return 0;
    double extent_deg = 2 * asin(n->radius / dist) * 180 / LOD_PI;
    double ppd = v->dist_px * LOD_PI / 180, nyquist_cpd = 0.5 * ppd;
    *freq_cpd = v->distance_factor * fmin(1 / (2 * extent_deg), nyquist_cpd);
    double g[3] = {v->gaze_px[0] - 0.5 * v->width_px, -(v->gaze_px[1] - 0.5 * v->height_px), -v->dist_px};
    double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    double cosang = (g[0] * c_eye[0] + g[1] * c_eye[1] + g[2] * c_eye[2]) / (gl * dist);
    double ecc = acos(fmax(-1, fmin(1, cosang))) * 180 / LOD_PI - 0.5 * extent_deg;
    *ecc_deg = ecc > 0 ? ecc : 0;
    return 1;
}

/* Is a change of this contrast at node i's place visible (at both ends of its velocity range)? */
static int change_perceptible(const csflut_table *tab, const lod_view *v, int i, double freq_cpd,
                              double ecc_deg, double contrast)
{
    if (!v->vel_lo_dps) return csflut_perceptible(tab, freq_cpd, ecc_deg, contrast);
    return moving_fold_perceptible(tab, freq_cpd, ecc_deg, v->vel_lo_dps[i], contrast) ||
           (v->vel_hi_dps[i] != v->vel_lo_dps[i] &&
            moving_fold_perceptible(tab, freq_cpd, ecc_deg, v->vel_hi_dps[i], contrast));
}

/* Is folding node n (sphere centre c_eye in eye space) perceptible in this view? strict > 1 makes
 * the test stricter for a region whose folds add up to a visible change (aggregate_check). */
static int fold_perceptible(const lod_vtree *t, const csflut_table *tab, const lod_view *v, const lod_node *n,
                            const float c_eye[3], int silhouette, double strict)
{
    double freq_cpd, ecc_deg;
    if (!node_place(v, n, c_eye, &freq_cpd, &ecc_deg)) return 1;
    double contrast = strict * fold_contrast(t, n, silhouette) / v->threshold_factor;
    return change_perceptible(tab, v, (int)(n - t->node), freq_cpd, ecc_deg, contrast);
}

static int emit(const lod_vtree *t, const int *active_of, uint32_t *tri_out)
{
    const lod_mesh *m = t->mesh;
    int n = 0;
    for (int f = 0; f < m->n_tri; f++) {
        int a = active_of[m->tri[3 * f]], b = active_of[m->tri[3 * f + 1]], c = active_of[m->tri[3 * f + 2]];
        if (a == b || b == c || a == c) continue;
        tri_out[3 * n] = (uint32_t)a;
        tri_out[3 * n + 1] = (uint32_t)b;
        tri_out[3 * n + 2] = (uint32_t)c;
        n++;
    }
    return n;
}

typedef struct {
    float *eye_pos; /* per vertex, eye space */
    uint8_t *flag;  /* per node: facing */
    int *stack;
    float *stack_strict;
    int *active_of;    /* per vertex: the node it is drawn as */
    uint8_t *expanded; /* per node: above the cut (tested and kept) */
    float *strict;     /* per node: how much stricter its region's folds are judged */
    double *sum;       /* per node: luminance change and luminance summed over its vertices */
} cut_work;

/* One cut, top down (Luebke & Hallen 5.2), into w->active_of. */
static void choose_cut(const lod_vtree *t, const csflut_table *tab, const lod_view *v, cut_work *w,
                       lod_cut_stats *stats)
{
    int top = 0;
    memset(stats, 0, sizeof *stats);
    memset(w->expanded, 0, (size_t)t->n_node);
    w->stack[top] = 0;
    w->stack_strict[top++] = 1;
    while (top > 0) {
        top--;
        int i = w->stack[top];
        double strict = w->stack_strict[top] * w->strict[i];
        const lod_node *n = &t->node[i];
        int fold = n->child[0] < 0;
        if (!fold) {
            float c_eye[3];
            to_eye(v->view, n->center, c_eye);
            int silhouette = w->flag[i] == (FACES_FRONT | FACES_BACK);
            if (outside_frustum(v, c_eye, n->radius) || w->flag[i] == FACES_BACK) {
                fold = 1;
                stats->culled_nodes++;
            } else if (!v->cull_only && !fold_perceptible(t, tab, v, n, c_eye, silhouette, strict)) {
                fold = 1;
                stats->folded_nodes++;
                stats->silhouette_nodes += silhouette;
            }
        }
        if (fold) {
            for (int j = n->lo; j < n->hi; j++) w->active_of[t->perm[j]] = i;
        } else {
            w->expanded[i] = 1;
            for (int c = 0; c < 2; c++) {
                w->stack[top] = n->child[c];
                w->stack_strict[top++] = (float)strict;
            }
        }
    }
}

/* Luebke & Hallen bound each fold alone. Many folds side by side can add up to a change at a
 * coarser scale (the shading of a whole region shifts when all its fine ridges go), and where a
 * table makes coarse scales far more visible than the folds' own (a moving slice: Kelly 1979) that
 * sum is what shows. For every node kept above the cut, the mean luminance change of its vertices
 * (each drawn with its fold's proxy normal) over their mean luminance is a change at the node's
 * own place; where it is visible the node's region is judged 4x stricter. Returns the number of
 * regions made stricter. */
static int aggregate_check(const lod_vtree *t, const csflut_table *tab, const lod_view *v, cut_work *w)
{
    int n_strict = 0;
    for (int i = t->n_node - 1; i >= 0; i--) {
        const lod_node *n = &t->node[i];
        double *si = w->sum + 2 * i;
        if (n->child[0] < 0) {
            int vert = t->perm[n->lo];
            si[0] = t->node[w->active_of[vert]].lum_proxy - n->lum_proxy;
            si[1] = n->lum_proxy;
            continue;
        }
        for (int c = 0; c < 2; c++) {
            si[c] = w->sum[2 * n->child[0] + c] + w->sum[2 * n->child[1] + c];
        }
        if (!w->expanded[i] || si[0] == 0 || !(si[1] > 0)) continue;
        float c_eye[3];
        double freq_cpd, ecc_deg;
        to_eye(v->view, n->center, c_eye);
        if (!node_place(v, n, c_eye, &freq_cpd, &ecc_deg)) continue;
        if (change_perceptible(tab, v, i, freq_cpd, ecc_deg, fabs(si[0]) / si[1] / v->threshold_factor)) {
            w->strict[i] *= 4;
            n_strict++;
        }
    }
    return n_strict;
}

#define LOD_AGGREGATE_ROUNDS 6

int lod_vtree_simplify(const lod_vtree *t, const csflut_table *tab, const lod_view *v, uint32_t *tri_out,
                       lod_cut_stats *stats)
{
    const lod_mesh *m = t->mesh;
    size_t nn = (size_t)t->n_node;
    cut_work w = {.eye_pos = malloc((size_t)m->n_vert * 3 * sizeof *w.eye_pos),
                  .flag = malloc(nn),
                  .stack = malloc(nn * sizeof *w.stack),
                  .stack_strict = calloc(nn, sizeof *w.stack_strict),
                  .active_of = malloc((size_t)m->n_vert * sizeof *w.active_of),
                  .expanded = malloc(nn),
                  .strict = calloc(nn, sizeof *w.strict),
                  .sum = malloc(nn * 2 * sizeof *w.sum)};
    int result = -1;
    if (!w.eye_pos || !w.flag || !w.stack || !w.stack_strict || !w.active_of || !w.expanded || !w.strict ||
        !w.sum)
        goto done;
    for (int i = 0; i < m->n_vert; i++) to_eye(v->view, m->pos + 3 * i, w.eye_pos + 3 * i);
    facing_flags(t, w.eye_pos, w.flag);
    for (size_t i = 0; i < nn; i++) w.strict[i] = 1;
    choose_cut(t, tab, v, &w, stats);
    /* the still views keep Luebke & Hallen's test alone; the moving sequence adds the check */
    for (int round = 0; v->vel_lo_dps && !v->cull_only && round < LOD_AGGREGATE_ROUNDS; round++) {
        if (aggregate_check(t, tab, v, &w) == 0) break;
        choose_cut(t, tab, v, &w, stats);
    }
    result = emit(t, w.active_of, tri_out);
done:
    free(w.eye_pos);
    free(w.flag);
    free(w.stack);
    free(w.stack_strict);
    free(w.active_of);
    free(w.expanded);
    free(w.strict);
    free(w.sum);
    return result;
}

void lod_vtree_velocity_range(const lod_vtree *t, const float *velocity_dps, float *lo_dps, float *hi_dps)
{
    for (int i = t->n_node - 1; i >= 0; i--) { /* children come after their parents */
        const lod_node *n = &t->node[i];
        if (n->child[0] < 0) {
            lo_dps[i] = hi_dps[i] = velocity_dps[i];
        } else {
            lo_dps[i] = fminf(lo_dps[n->child[0]], lo_dps[n->child[1]]);
            hi_dps[i] = fmaxf(hi_dps[n->child[0]], hi_dps[n->child[1]]);
        }
    }
}

int lod_vtree_full(const lod_vtree *t, uint32_t *tri_out)
{
    const lod_mesh *m = t->mesh;
    for (int f = 0; f < 3 * m->n_tri; f++) tri_out[f] = (uint32_t)t->leaf_of[m->tri[f]];
    return m->n_tri;
}
