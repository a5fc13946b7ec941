#include "motion.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEG_PER_RAD (180 / LOD_PI)
#define MAP_TILE_PX 8

void lod_mat_mul(const float a[16], const float b[16], float out[16])
{
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            float s = 0;
            for (int k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
            out[c * 4 + r] = s;
        }
}

void lod_path_model(const lod_path *p, double t_s, float model[16])
{
    double turn = p->spin_dps * t_s / DEG_PER_RAD, c = cos(turn), s = sin(turn);
    /* equal angle per unit time: the centre at angle theta sits x = d tan(theta) along the
     * camera's right axis, which is the first row of the view's rotation */
    double shift = p->object_dist * tan(p->velocity_dps * (t_s - p->t_mid_s) / DEG_PER_RAD);
    memset(model, 0, 16 * sizeof *model);
    model[0] = (float)c;
    model[2] = (float)-s;
    model[5] = 1;
    model[8] = (float)s;
    model[10] = (float)c;
    for (int k = 0; k < 3; k++) model[12 + k] = (float)(shift * p->view[k * 4 + 0]);
    model[15] = 1;
}

void lod_path_frame(const lod_path *p, double t_s, float view[16], float mvp[16])
{
    float model[16];
    lod_path_model(p, t_s, model);
    lod_mat_mul(p->view, model, view);
    lod_mat_mul(p->mvp, model, mvp);
}

static void eye_dir(const float m[16], const float q[3], double u[3])
{
    for (int r = 0; r < 3; r++) u[r] = m[r] * q[0] + m[4 + r] * q[1] + m[8 + r] * q[2] + m[12 + r];
    double l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int r = 0; r < 3; r++) u[r] = l > 0 ? u[r] / l : 0;
}

/* angular velocity of a model-space point as a vector in the eye's frame, rad/s (the change of its
 * unit direction: exact in magnitude to first order in the angle moved per frame) */
static void angular_velocity(const float v0[16], const float v1[16], const float q[3], double dt_s,
                             double w[3])
{
    double a[3], b[3];
    eye_dir(v0, q, a);
    eye_dir(v1, q, b);
    for (int r = 0; r < 3; r++) w[r] = (b[r] - a[r]) / dt_s;
}

static void project_px(const lod_screen *sc, const double e[3], double px[2])
{
    double z = e[2] < -1e-12 ? -e[2] : 1e-12;
    px[0] = 0.5 * sc->width_px + sc->dist_px * e[0] / z;
    px[1] = 0.5 * sc->height_px - sc->dist_px * e[1] / z;
}

int lod_motion_velocities(const lod_vtree *t, const lod_path *p, const lod_screen *sc, double t_s,
                          double dt_s, float *velocity_dps, double gaze_px[2], double *eye_dps)
{
    float v0[16], v1[16], mvp[16];
    const float origin[3] = {0, 0, 0};
    lod_path_frame(p, t_s, v0, mvp);
    lod_path_frame(p, t_s + dt_s, v1, mvp);
    double w_obj[3], w_eye[3] = {0, 0, 0}, u[3];
    angular_velocity(v0, v1, origin, dt_s, w_obj);
    gaze_px[0] = sc->fixation_px[0];
    gaze_px[1] = sc->fixation_px[1];
    *eye_dps = 0;
    if (p->pursuit) {
        /* Daly (1998): the eye follows at 82 % of the target's speed plus its drift, up to the
         * pursuit limit; a still target leaves the drift, taken along the screen's x axis */
        double v_obj = sqrt(w_obj[0] * w_obj[0] + w_obj[1] * w_obj[1] + w_obj[2] * w_obj[2]) * DEG_PER_RAD;
        double v_eye = fmin(0.82 * v_obj + 0.15, 80);
        for (int r = 0; r < 3; r++) w_eye[r] = v_obj > 0 ? w_obj[r] / (v_obj / DEG_PER_RAD) : (r == 0);
        for (int r = 0; r < 3; r++) w_eye[r] *= v_eye / DEG_PER_RAD;
        *eye_dps = v_eye;
        for (int r = 0; r < 3; r++) u[r] = v0[12 + r];
        project_px(sc, u, gaze_px);
    }
    for (int i = 0; i < t->n_node; i++) {
        double w[3];
        angular_velocity(v0, v1, t->node[i].center, dt_s, w);
        for (int r = 0; r < 3; r++) w[r] -= w_eye[r];
        velocity_dps[i] = (float)(sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * DEG_PER_RAD);
    }
    (void)mvp;
    return 0;
}

/* A difference between two renders of the object moves with the object, silhouettes included
 * (the background is uniform, so nothing of it shows in a difference): a tile with vertices keeps
 * their range; an empty one (an edge the vertices miss) takes the range of its eight neighbours',
 * and only tiles with no vertex near them take the background's. Empty tiles hold lo > hi. */
static void spread_tiles(const float *lo, const float *hi, int tw, int th, float background_dps, float *lo2,
                         float *hi2)
{
    for (int ty = 0; ty < th; ty++)
        for (int tx = 0; tx < tw; tx++) {
            float a = lo[ty * tw + tx], b = hi[ty * tw + tx];
            for (int dy = -1; dy <= 1 && a > b; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int x = tx + dx, y = ty + dy;
                    if (x < 0 || y < 0 || x >= tw || y >= th || lo[y * tw + x] > hi[y * tw + x]) continue;
                    a = a > b ? lo[y * tw + x] : fminf(a, lo[y * tw + x]);
                    b = fmaxf(b, hi[y * tw + x]);
                }
            lo2[ty * tw + tx] = a <= b ? a : background_dps;
            hi2[ty * tw + tx] = a <= b ? b : background_dps;
        }
}

int lod_motion_velocity_map(const lod_vtree *t, const float view[16], const lod_screen *sc,
                            const float *velocity_dps, double eye_dps, float *vel_lo, float *vel_hi)
{
    int tw = (sc->width_px + MAP_TILE_PX - 1) / MAP_TILE_PX,
        th = (sc->height_px + MAP_TILE_PX - 1) / MAP_TILE_PX;
    size_t nt = (size_t)tw * th;
    float *buf = malloc(4 * nt * sizeof *buf);
    if (!buf) return -1;
    float *lo = buf, *hi = buf + nt, *lo2 = buf + 2 * nt, *hi2 = buf + 3 * nt;
    for (size_t i = 0; i < nt; i++) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
    }
    const lod_mesh *m = t->mesh;
    for (int v = 0; v < m->n_vert; v++) {
        const float *q = m->pos + 3 * v;
        double e[3], px[2];
        for (int r = 0; r < 3; r++)
            e[r] = view[r] * q[0] + view[4 + r] * q[1] + view[8 + r] * q[2] + view[12 + r];
        const float *nv = m->nrm + 3 * v;
        double facing = 0;
        for (int r = 0; r < 3; r++)
            facing += (view[r] * nv[0] + view[4 + r] * nv[1] + view[8 + r] * nv[2]) * e[r];
        if (e[2] >= 0 || facing > 0) continue; /* behind the eye, or on the far side: not what is seen */
        project_px(sc, e, px);
        if (!(px[0] >= 0 && px[1] >= 0 && px[0] < sc->width_px && px[1] < sc->height_px)) continue;
        size_t k = (size_t)((int)px[1] / MAP_TILE_PX) * tw + (size_t)((int)px[0] / MAP_TILE_PX);
        float s = velocity_dps[t->leaf_of[v]];
        lo[k] = fminf(lo[k], s);
        hi[k] = fmaxf(hi[k], s);
    }
    /* the background moves on the retina as the eye does */
    spread_tiles(lo, hi, tw, th, (float)eye_dps, lo2, hi2);
    for (int y = 0; y < sc->height_px; y++)
        for (int x = 0; x < sc->width_px; x++) {
            size_t k = (size_t)(y / MAP_TILE_PX) * tw + (size_t)(x / MAP_TILE_PX);
            vel_lo[(size_t)y * sc->width_px + x] = lo2[k];
            vel_hi[(size_t)y * sc->width_px + x] = hi2[k];
        }
    free(buf);
    return 0;
}
