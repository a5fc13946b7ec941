/* Exact flat-screen visual-angle geometry; see geometry.h for the frame of reference. Everything
 * is done with 3-D direction vectors from the eye, so no small-angle approximation enters. */
#include "stimuli/geometry.h"

#include <math.h>

#define DEG (M_PI / 180.0)

typedef struct {
    double x, y, z;
} vec3;

static vec3 v3(double x, double y, double z)
{
    vec3 r = {x, y, z};
    return r;
}
static double dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec3 cross3(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static vec3 norm3(vec3 a)
{
    double n = sqrt(dot3(a, a));
    return v3(a.x / n, a.y / n, a.z / n);
}
static vec3 scale_add(vec3 a, double s, vec3 b) { return v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z); }

/* Angle between unit vectors, accurate near 0 and pi (atan2 of |cross| and dot). */
static double angle3(vec3 a, vec3 b)
{
    vec3 c = cross3(a, b);
    return atan2(sqrt(dot3(c, c)), dot3(a, b));
}

/* Tangent basis at direction d: h horizontal-right, v up (d never parallel to the vertical for
 * a flat screen in front of the eye). */
static void tangent_basis(vec3 d, vec3 *h, vec3 *v)
{
    *h = norm3(cross3(d, v3(0, 1, 0)));
    *v = cross3(*h, d);
}

static vec3 eye_pos(const csf_geometry *g) { return v3(g->eye_x_mm, g->eye_y_mm, g->distance_mm); }

static vec3 dir_to_point(const csf_geometry *g, double x_mm, double y_mm)
{
    vec3 e = eye_pos(g);
    return norm3(v3(x_mm - e.x, y_mm - e.y, -e.z));
}

static vec3 fixation_dir(const csf_geometry *g) { return dir_to_point(g, 0.0, 0.0); }

static vec3 dir_of(const csf_geometry *g, double ecc_deg, double polar_deg)
{
    vec3 f = fixation_dir(g), h, v;
    tangent_basis(f, &h, &v);
    double e = ecc_deg * DEG, p = polar_deg * DEG;
    vec3 t = scale_add(scale_add(v3(0, 0, 0), cos(p), h), sin(p), v);
    return norm3(scale_add(scale_add(v3(0, 0, 0), cos(e), f), sin(e), t));
}

csf_status csf_geometry_init(csf_geometry *g, double width_mm, double height_mm, int width_px,
                             int height_px, double distance_mm, double eye_x_mm, double eye_y_mm,
                             csf_error *err)
{
    if (!g) return csf_error_set(err, CSF_E_INVALID_ARG, "geometry: NULL output");
    if (!(width_mm >= 10 && width_mm <= 10000) || !(height_mm >= 10 && height_mm <= 10000))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "screen size %g x %g mm is outside 10 to 10000 mm", width_mm, height_mm);
    if (width_px < 16 || width_px > 32768 || height_px < 16 || height_px > 32768)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "screen resolution %d x %d px is outside 16 to 32768 px", width_px,
                             height_px);
    if (!(distance_mm >= 50 && distance_mm <= 10000))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "viewing distance %g mm is outside 50 to 10000 mm", distance_mm);
    if (!(fabs(eye_x_mm) <= width_mm) || !(fabs(eye_y_mm) <= height_mm))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "eye offset (%g, %g) mm is outside +-(%g, %g) mm (the screen size)",
                             eye_x_mm, eye_y_mm, width_mm, height_mm);
    g->width_mm = width_mm;
    g->height_mm = height_mm;
    g->width_px = width_px;
    g->height_px = height_px;
    g->distance_mm = distance_mm;
    g->eye_x_mm = eye_x_mm;
    g->eye_y_mm = eye_y_mm;
    g->mm_per_px_x = width_mm / width_px;
    g->mm_per_px_y = height_mm / height_px;
    return CSF_OK;
}

void csf_geometry_px_to_mm(const csf_geometry *g, double px_x, double px_y, double *x_mm,
                           double *y_mm)
{
    *x_mm = px_x * g->mm_per_px_x - 0.5 * g->width_mm;
    *y_mm = 0.5 * g->height_mm - px_y * g->mm_per_px_y;
}

void csf_geometry_mm_to_px(const csf_geometry *g, double x_mm, double y_mm, double *px_x,
                           double *px_y)
{
    *px_x = (x_mm + 0.5 * g->width_mm) / g->mm_per_px_x;
    *px_y = (0.5 * g->height_mm - y_mm) / g->mm_per_px_y;
}

void csf_geometry_mm_to_deg(const csf_geometry *g, double x_mm, double y_mm, double *ecc_deg,
                            double *polar_deg)
{
    vec3 f = fixation_dir(g), h, v;
    tangent_basis(f, &h, &v);
    vec3 d = dir_to_point(g, x_mm, y_mm);
    if (ecc_deg) *ecc_deg = angle3(d, f) / DEG;
    if (polar_deg) {
        double p = atan2(dot3(d, v), dot3(d, h)) / DEG;
        *polar_deg = p < 0 ? p + 360.0 : p;
    }
}

int csf_geometry_deg_to_mm(const csf_geometry *g, double ecc_deg, double polar_deg, double *x_mm,
                           double *y_mm)
{
    vec3 c = dir_of(g, ecc_deg, polar_deg);
    if (!(c.z < -1e-9)) return 0;
    vec3 e = eye_pos(g);
    double t = -e.z / c.z;
    *x_mm = e.x + t * c.x;
    *y_mm = e.y + t * c.y;
    return 1;
}

int csf_geometry_deg_to_px(const csf_geometry *g, double ecc_deg, double polar_deg, double *px_x,
                           double *px_y)
{
    double x, y;
    if (!csf_geometry_deg_to_mm(g, ecc_deg, polar_deg, &x, &y)) return 0;
    csf_geometry_mm_to_px(g, x, y, px_x, px_y);
    return 1;
}

void csf_geometry_local_uv(const csf_geometry *g, double ecc_deg, double polar_deg, double x_mm,
                           double y_mm, double *u_deg, double *v_deg)
{
    vec3 c = dir_of(g, ecc_deg, polar_deg), h, v;
    tangent_basis(c, &h, &v);
    vec3 d = dir_to_point(g, x_mm, y_mm);
    double a = angle3(d, c);
    double x = dot3(d, h), y = dot3(d, v), s = hypot(x, y);
    /* Azimuthal equidistant: angular distance a along the direction (x, y)/s. */
    double k = s > 1e-15 ? a / s : 1.0;
    *u_deg = k * x / DEG;
    *v_deg = k * y / DEG;
}

int csf_geometry_on_screen(const csf_geometry *g, double x_mm, double y_mm)
{
    return fabs(x_mm) <= 0.5 * g->width_mm && fabs(y_mm) <= 0.5 * g->height_mm;
}

double csf_geometry_max_ecc(const csf_geometry *g, double polar_deg)
{
    double lo = 0.0, hi = 89.9, x, y;
    if (csf_geometry_deg_to_mm(g, hi, polar_deg, &x, &y) && csf_geometry_on_screen(g, x, y))
        return hi;
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        if (csf_geometry_deg_to_mm(g, mid, polar_deg, &x, &y) && csf_geometry_on_screen(g, x, y))
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Gradients of (u, v) in deg per pixel at screen point (x_mm, y_mm) for a stimulus centred at
 * (ecc, polar): du/dpx_x, dv/dpx_x, du/dpx_y, dv/dpx_y by central differences of +-0.5 px. */
static void uv_gradients(const csf_geometry *g, double ecc_deg, double polar_deg, double x_mm,
                         double y_mm, double grad[4])
{
    double hx = 0.5 * g->mm_per_px_x, hy = 0.5 * g->mm_per_px_y;
    double u1, v1, u2, v2;
    csf_geometry_local_uv(g, ecc_deg, polar_deg, x_mm + hx, y_mm, &u1, &v1);
    csf_geometry_local_uv(g, ecc_deg, polar_deg, x_mm - hx, y_mm, &u2, &v2);
    grad[0] = u1 - u2;
    grad[1] = v1 - v2;
    /* pixel y grows downwards: +1 px is -mm_per_px_y */
    csf_geometry_local_uv(g, ecc_deg, polar_deg, x_mm, y_mm - hy, &u1, &v1);
    csf_geometry_local_uv(g, ecc_deg, polar_deg, x_mm, y_mm + hy, &u2, &v2);
    grad[2] = u1 - u2;
    grad[3] = v1 - v2;
}

double csf_geometry_nyquist_at(const csf_geometry *g, double ecc_deg, double polar_deg,
                               double x_mm, double y_mm, double orientation_deg)
{
    double gr[4];
    uv_gradients(g, ecc_deg, polar_deg, x_mm, y_mm, gr);
    double gx, gy;
    if (orientation_deg < 0) {
        gx = hypot(gr[0], gr[1]);
        gy = hypot(gr[2], gr[3]);
    } else {
        double c = cos(orientation_deg * DEG), s = sin(orientation_deg * DEG);
        gx = fabs(c * gr[0] + s * gr[1]);
        gy = fabs(c * gr[2] + s * gr[3]);
    }
    double m = gx > gy ? gx : gy;
    return m > 0 ? 0.5 / m : INFINITY;
}

double csf_geometry_nyquist_cpd(const csf_geometry *g, double ecc_deg, double polar_deg,
                                double orientation_deg)
{
    double x, y;
    if (!csf_geometry_deg_to_mm(g, ecc_deg, polar_deg, &x, &y)) return 0.0;
    double o = fmod(orientation_deg, 360.0);
    if (o < 0) o += 360.0;
    return csf_geometry_nyquist_at(g, ecc_deg, polar_deg, x, y, o);
}

double csf_geometry_nyquist_cpd_any(const csf_geometry *g, double ecc_deg, double polar_deg)
{
    double x, y;
    if (!csf_geometry_deg_to_mm(g, ecc_deg, polar_deg, &x, &y)) return 0.0;
    return csf_geometry_nyquist_at(g, ecc_deg, polar_deg, x, y, -1.0);
}

void csf_geometry_px_per_deg(const csf_geometry *g, double ecc_deg, double polar_deg,
                             double *radial, double *tangential)
{
    const double h = 1e-3; /* deg */
    double x1, y1, x2, y2;
    double e0 = ecc_deg < h ? h : ecc_deg;
    if (radial) {
        *radial = 0;
        if (csf_geometry_deg_to_px(g, e0 + h, polar_deg, &x1, &y1) &&
            csf_geometry_deg_to_px(g, e0 - h, polar_deg, &x2, &y2))
            *radial = hypot(x1 - x2, y1 - y2) / (2 * h);
    }
    if (tangential) {
        /* angular distance on the sphere for a polar step dp is sin(ecc) dp; near the centre the
         * ring is so small that dp stops being a small step (the chord falls short of the arc), so
         * step around a ring of at least 0.1 deg, where dp stays under 0.6 deg of polar angle. */
        double et = ecc_deg < 0.1 ? 0.1 : ecc_deg;
        double dp = h / sin(et * DEG);
        *tangential = 0;
        if (csf_geometry_deg_to_px(g, et, polar_deg + dp, &x1, &y1) &&
            csf_geometry_deg_to_px(g, et, polar_deg - dp, &x2, &y2))
            *tangential = hypot(x1 - x2, y1 - y2) / (2 * h);
    }
}

void csf_geometry_centre_basis(const csf_geometry *g, double ecc_deg, double polar_deg,
                               double c[3], double h[3], double v[3])
{
    vec3 cc = dir_of(g, ecc_deg, polar_deg), hh, vv;
    tangent_basis(cc, &hh, &vv);
    c[0] = cc.x, c[1] = cc.y, c[2] = cc.z;
    h[0] = hh.x, h[1] = hh.y, h[2] = hh.z;
    v[0] = vv.x, v[1] = vv.y, v[2] = vv.z;
}

void csf_geometry_move(const csf_geometry *g, double ecc_deg, double polar_deg, double dir_deg,
                       double dist_deg, double *ecc_out, double *polar_out)
{
    vec3 c = dir_of(g, ecc_deg, polar_deg), h, v;
    tangent_basis(c, &h, &v);
    vec3 m = scale_add(scale_add(v3(0, 0, 0), cos(dir_deg * DEG), h), sin(dir_deg * DEG), v);
    double a = dist_deg * DEG;
    vec3 n = norm3(scale_add(scale_add(v3(0, 0, 0), cos(a), c), sin(a), m));
    vec3 f = fixation_dir(g), fh, fv;
    tangent_basis(f, &fh, &fv);
    *ecc_out = angle3(n, f) / DEG;
    double p = atan2(dot3(n, fv), dot3(n, fh)) / DEG;
    *polar_out = p < 0 ? p + 360.0 : p;
}
