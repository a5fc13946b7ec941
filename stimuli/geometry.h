/* Visual-angle geometry of a flat screen (docs/stimuli.md, "Geometry").
 *
 * Frame of reference: millimetres, origin at the screen centre, x to the right, y up, the screen
 * in the plane z = 0 and the eye at (eye_x_mm, eye_y_mm, viewing_distance_mm). The fixation mark
 * is at the screen centre; with the default eye offset (0, 0) the eye is on the normal through
 * fixation and a point at distance r mm from the centre is seen at eccentricity atan(r / D).
 * With an offset, eccentricity is the exact angle between the ray to the point and the ray to
 * fixation (no small-angle or constant pixels-per-degree approximation anywhere).
 *
 * Angles: eccentricity ecc_deg from fixation; polar angle polar_deg counter-clockwise from the
 * rightward horizontal (0 = right, 90 = up). Stimulus-local "angle space" (u, v) in degrees is the
 * azimuthal-equidistant map around the stimulus centre direction: the angular distance from the
 * centre is exact, u points right and v up (tangent to the sphere). The presenter evaluates
 * carriers and envelopes in this space for every fragment.
 *
 * Pixels: (px_x, px_y) with px_x to the right from the left edge and px_y DOWN from the top edge;
 * pixel (i, j) covers [i, i+1) x [j, j+1), its centre is at (i + 0.5, j + 0.5).
 *
 * This header depends on results/ only. To build a geometry from a station configuration
 * (cli/config.h): csf_geometry_init(&g, CSF_GEOMETRY_FROM_CONFIG(cfg), &err). */
#ifndef CSF_STIMULI_GEOMETRY_H
#define CSF_STIMULI_GEOMETRY_H

#include "core/csf_status.h"

typedef struct {
    double width_mm, height_mm;   /* visible image area */
    int width_px, height_px;
    double distance_mm;           /* eye to the screen plane, along the normal */
    double eye_x_mm, eye_y_mm;    /* foot of the normal from the eye, relative to the centre */
    double mm_per_px_x, mm_per_px_y;
} csf_geometry;

/* Expands a csf_config (by value or lvalue) into the arguments of csf_geometry_init. */
#define CSF_GEOMETRY_FROM_CONFIG(c)                                                   \
    (c).screen_width_mm, (c).screen_height_mm, (c).screen_width_px, (c).screen_height_px, \
    (c).viewing_distance_mm, (c).eye_offset_x_mm, (c).eye_offset_y_mm

/* Checks ranges (sizes 10..10000 mm, 16..32768 px, distance 50..10000 mm, eye offset inside
 * +-screen size) and fills g. */
csf_status csf_geometry_init(csf_geometry *g, double width_mm, double height_mm, int width_px,
                             int height_px, double distance_mm, double eye_x_mm, double eye_y_mm,
                             csf_error *err);

/* Screen mm <-> pixel coordinates (continuous; pixel centres at +0.5). */
void csf_geometry_px_to_mm(const csf_geometry *g, double px_x, double px_y, double *x_mm,
                           double *y_mm);
void csf_geometry_mm_to_px(const csf_geometry *g, double x_mm, double y_mm, double *px_x,
                           double *px_y);

/* Eccentricity and polar angle (deg) of the screen point (x_mm, y_mm), seen from the eye. */
void csf_geometry_mm_to_deg(const csf_geometry *g, double x_mm, double y_mm, double *ecc_deg,
                            double *polar_deg);
/* Screen point of the direction (ecc_deg, polar_deg). Returns 0 when the ray misses the screen
 * plane (>= 90 deg from the normal) — the point is then not written. The point may still lie
 * outside the visible area: see csf_geometry_on_screen. */
int csf_geometry_deg_to_mm(const csf_geometry *g, double ecc_deg, double polar_deg, double *x_mm,
                           double *y_mm);
int csf_geometry_deg_to_px(const csf_geometry *g, double ecc_deg, double polar_deg, double *px_x,
                           double *px_y);
/* Stimulus-local angle-space coordinates (u, v) deg of screen point (x_mm, y_mm) for a stimulus
 * centred at (ecc_deg, polar_deg). Same mapping as the fragment shader. */
void csf_geometry_local_uv(const csf_geometry *g, double ecc_deg, double polar_deg, double x_mm,
                           double y_mm, double *u_deg, double *v_deg);

/* 1 when the screen point lies inside the visible area. */
int csf_geometry_on_screen(const csf_geometry *g, double x_mm, double y_mm);
/* Largest eccentricity reachable along polar_deg before the screen edge (deg). */
double csf_geometry_max_ecc(const csf_geometry *g, double polar_deg);

/* Local Nyquist limit (cpd) at (ecc_deg, polar_deg) for a carrier whose modulation direction is
 * orientation_deg in angle space: 0.5 cycle per pixel along both pixel axes, converted to cpd
 * through the exact local Jacobian. csf_geometry_nyquist_cpd_any is the minimum over
 * orientations (the limit that holds for every orientation). */
double csf_geometry_nyquist_cpd(const csf_geometry *g, double ecc_deg, double polar_deg,
                                double orientation_deg);
double csf_geometry_nyquist_cpd_any(const csf_geometry *g, double ecc_deg, double polar_deg);

/* Nyquist limit (cpd) at the screen point (x_mm, y_mm) of a patch centred at (ecc, polar);
 * orientation_deg < 0 means the minimum over orientations. Used to check a whole patch. */
double csf_geometry_nyquist_at(const csf_geometry *g, double ecc_deg, double polar_deg,
                               double x_mm, double y_mm, double orientation_deg);

/* Direction vectors (unit, from the eye) of the patch centre c and its tangent basis h (right),
 * v (up) — the uniforms of the presenter's shader. */
void csf_geometry_centre_basis(const csf_geometry *g, double ecc_deg, double polar_deg,
                               double c[3], double h[3], double v[3]);

/* Moves a centre direction by dist_deg along the great circle leaving it in direction dir_deg
 * (polar convention in its tangent plane); writes the new (ecc, polar). */
void csf_geometry_move(const csf_geometry *g, double ecc_deg, double polar_deg, double dir_deg,
                       double dist_deg, double *ecc_out, double *polar_out);

/* Local pixels per degree along the radial and tangential directions at (ecc, polar). */
void csf_geometry_px_per_deg(const csf_geometry *g, double ecc_deg, double polar_deg,
                             double *radial, double *tangential);

#endif
