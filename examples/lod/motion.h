/* Motion for the moving sequence: the object's path across the screen, and the retinal velocity
 * of every vertex-tree node from the screen-space motion between two instants and the viewing
 * geometry, under one of two assumptions about the eye (README.md, "Motion"):
 *   - fixate: the eye holds a fixed point, so the retinal velocity is the screen velocity;
 *   - pursuit: the eye follows the object with Daly's (1998) smooth-pursuit model, eye velocity
 *     min(0.82 v + 0.15, 80) deg/s along the object's motion (v its centre's angular speed), and the
 *     retinal velocity is |node - eye| (as vectors). A still object still leaves the eye's
 *     0.15 deg/s drift. */
#ifndef LOD_MOTION_H
#define LOD_MOTION_H

#include "vtree.h"

typedef struct {
    float view[16];      /* camera: world -> eye */
    float mvp[16];       /* camera: world -> clip */
    double object_dist;  /* eye to the model's centre (world units) */
    double velocity_dps; /* angular speed of the model's centre across the screen */
    double spin_dps;     /* turn about the model's vertical axis */
    double t_mid_s;      /* the centre passes the line of sight at this time */
    int pursuit;         /* 0: fixate, 1: smooth pursuit */
} lod_path;

/* Column-major 4x4: the model's world transform at time t_s (turned, then moved along the
 * camera's right axis so that its centre is at angle velocity * (t - t_mid) from the line of
 * sight). */
void lod_path_model(const lod_path *p, double t_s, float model[16]);

/* c = a * b, column-major 4x4 */
void lod_mat_mul(const float a[16], const float b[16], float out[16]);

/* The view of the object at t_s: world -> eye with the model transform folded in, and -> clip. */
void lod_path_frame(const lod_path *p, double t_s, float view[16], float mvp[16]);

typedef struct {
    int width_px, height_px;
    double dist_px;        /* eye to image plane, pixels */
    double fixation_px[2]; /* the fixed gaze point (fixate) */
} lod_screen;

/* Retinal velocity (deg/s) of every node's sphere centre at t_s, from its position at t_s and
 * t_s + dt_s (one frame later). gaze_px receives where the eye looks at t_s (the fixation point, or
 * the model's centre in pursuit); eye_dps the eye's own speed (0 when fixating). 0, or -1 when out
 * of memory. */
int lod_motion_velocities(const lod_vtree *t, const lod_path *p, const lod_screen *sc, double t_s,
                          double dt_s, float *velocity_dps, double gaze_px[2], double *eye_dps);

/* A per-pixel velocity range for the image check: tiles of 8 px hold the lowest and highest
 * retinal velocity of the vertices facing the eye that project into them (a difference between two renders of the
 * object, silhouettes included, moves with the object); an empty tile takes its neighbours' range,
 * and one with none near it the background's (the eye's own speed: a fixating eye sees the
 * background still). vel_lo and vel_hi: width*height each. 0, or -1 when out of memory. */
int lod_motion_velocity_map(const lod_vtree *t, const float view[16], const lod_screen *sc,
                            const float *velocity_dps, double eye_dps, float *vel_lo, float *vel_hi);

#endif
