#include "mesh.h"
#include "shade.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

/* Edge midpoints are shared between the two triangles of an edge: an open-addressing table keyed
 * by the (smaller, larger) vertex pair keeps the subdivided mesh closed. */
typedef struct { uint64_t *key; uint32_t *val; size_t cap; } edge_map;

static uint32_t midpoint(edge_map *em, float *pos, int *n_vert, uint32_t a, uint32_t b)
{
    uint64_t k = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
    size_t i = (size_t)((k * 0x9e3779b97f4a7c15ULL) >> 17) & (em->cap - 1);
    while (em->key[i] != UINT64_MAX) {
        if (em->key[i] == k) return em->val[i];
        i = (i + 1) & (em->cap - 1);
    }
    uint32_t v = (uint32_t)(*n_vert)++;
    double p[3], len = 0;
    for (int c = 0; c < 3; c++) {
        p[c] = 0.5 * (pos[3 * a + c] + pos[3 * b + c]);
        len += p[c] * p[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; c++) pos[3 * v + c] = (float)(p[c] / len);
    em->key[i] = k;
    em->val[i] = v;
    return v;
}

static int icosphere(lod_mesh *m, int subdiv)
{
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    const double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const uint32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                   {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                   {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                   {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    size_t n_tri_final = (size_t)20 << (2 * subdiv);
    size_t n_vert_final = 10 * ((size_t)1 << (2 * subdiv)) + 2;
    m->pos = malloc(n_vert_final * 3 * sizeof *m->pos);
    m->tri = malloc(n_tri_final * 3 * sizeof *m->tri);
    uint32_t *tmp = malloc(n_tri_final * 3 * sizeof *tmp);
    if (!m->pos || !m->tri || !tmp) { free(tmp); return -1; }
    for (int v = 0; v < 12; v++) {
        double len = sqrt(base[v][0] * base[v][0] + base[v][1] * base[v][1] + base[v][2] * base[v][2]);
        for (int c = 0; c < 3; c++) m->pos[3 * v + c] = (float)(base[v][c] / len);
    }
    memcpy(m->tri, faces, sizeof faces);
    m->n_vert = 12;
    m->n_tri = 20;
    for (int level = 0; level < subdiv; level++) {
        edge_map em;
        em.cap = 1;
        while (em.cap < (size_t)m->n_tri * 4) em.cap <<= 1;
        em.key = malloc(em.cap * sizeof *em.key);
        em.val = malloc(em.cap * sizeof *em.val);
        if (!em.key || !em.val) { free(em.key); free(em.val); free(tmp); return -1; }
        memset(em.key, 0xff, em.cap * sizeof *em.key);
        int n = 0;
        for (int f = 0; f < m->n_tri; f++) {
            uint32_t a = m->tri[3 * f], b = m->tri[3 * f + 1], c = m->tri[3 * f + 2];
            uint32_t ab = midpoint(&em, m->pos, &m->n_vert, a, b);
            uint32_t bc = midpoint(&em, m->pos, &m->n_vert, b, c);
            uint32_t ca = midpoint(&em, m->pos, &m->n_vert, c, a);
            const uint32_t out[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
            memcpy(tmp + 3 * n, out, sizeof out);
            n += 4;
        }
        free(em.key);
        free(em.val);
        memcpy(m->tri, tmp, (size_t)n * 3 * sizeof *tmp);
        m->n_tri = n;
    }
    free(tmp);
    return 0;
}

/* Ridges sin(2 pi f (u . d) + phase) along random directions d, at octave-spaced frequencies f
 * with amplitude 1/f: every scale has about the same slope, so every scale shades visibly. */
static void displace(lod_mesh *m, uint64_t seed)
{
    enum { SCALES = 5, PER_SCALE = 5 };
    double dir[SCALES * PER_SCALE][3], freq[SCALES * PER_SCALE], amp[SCALES * PER_SCALE],
        phase[SCALES * PER_SCALE];
    uint64_t s = seed;
    for (int k = 0; k < SCALES * PER_SCALE; k++) {
        double z = 2 * uniform01(&s) - 1, a = 2 * LOD_PI * uniform01(&s), r = sqrt(1 - z * z);
        dir[k][0] = r * cos(a);
        dir[k][1] = r * sin(a);
        dir[k][2] = z;
        freq[k] = 0.75 * pow(2.0, k / PER_SCALE);
        amp[k] = 0.045 / freq[k];
        phase[k] = 2 * LOD_PI * uniform01(&s);
    }
    for (int v = 0; v < m->n_vert; v++) {
        float *p = m->pos + 3 * v;
        /* fine detail on one side only: real models mix smooth and detailed regions, and the
         * smooth ones are where a perceptual criterion should find most to remove */
        double side = p[0] * 0.6 + p[1] * 0.64 + p[2] * 0.48, mask = fmin(1, fmax(0, 0.5 + 2 * side));
        double r = 1;
        for (int k = 0; k < SCALES * PER_SCALE; k++)
            r += (k < 2 * PER_SCALE ? 1 : mask) * amp[k] * sin(2 * LOD_PI * freq[k] * (p[0] * dir[k][0] + p[1] * dir[k][1] + p[2] * dir[k][2]) + phase[k]);
        for (int c = 0; c < 3; c++) p[c] = (float)(p[c] * r);
    }
}

static void normals(lod_mesh *m)
{
    memset(m->nrm, 0, (size_t)m->n_vert * 3 * sizeof *m->nrm);
    for (int f = 0; f < m->n_tri; f++) {
        const float *a = m->pos + 3 * m->tri[3 * f], *b = m->pos + 3 * m->tri[3 * f + 1],
                    *c = m->pos + 3 * m->tri[3 * f + 2];
        float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; k++)
            for (int c2 = 0; c2 < 3; c2++) m->nrm[3 * m->tri[3 * f + k] + c2] += n[c2];
    }
    for (int v = 0; v < m->n_vert; v++) {
        float *n = m->nrm + 3 * v;
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0)
            for (int c = 0; c < 3; c++) n[c] /= len;
    }
}

int lod_mesh_bumpy_sphere(lod_mesh *m, int subdiv, uint64_t seed)
{
    memset(m, 0, sizeof *m);
    if (subdiv < 0 || subdiv > 8 || icosphere(m, subdiv) != 0) { lod_mesh_free(m); return -1; }
    displace(m, seed);
    m->nrm = malloc((size_t)m->n_vert * 3 * sizeof *m->nrm);
    if (!m->nrm) { lod_mesh_free(m); return -1; }
    normals(m);
    return 0;
}

void lod_mesh_free(lod_mesh *m)
{
    free(m->pos);
    free(m->nrm);
    free(m->tri);
    memset(m, 0, sizeof *m);
}
