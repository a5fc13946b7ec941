/* Geometry against its closed forms (docs/stimuli.md): atan(r/D), D/cos^2 radial pixel density,
 * 0.5 cycle/pixel Nyquist limit, screen reach, eye offset, and argument checks. */
#include <math.h>

#include "core/rng.h"
#include "stimuli/geometry.h"
#include "tests/check.h"

#define DEG (M_PI / 180.0)

int main(void)
{
    csf_geometry g;
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 1920, 1080, 570, 0, 0, &e), CSF_OK);

    /* eccentricity of random screen points is atan(r / D); round trip through deg_to_mm */
    for (int i = 0; i < 200; i++) {
        double x = (csf_rng_uniform(7, 1, i) - 0.5) * 531, y = (csf_rng_uniform(7, 2, i) - 0.5) * 299;
        double ecc, pol, x2, y2;
        csf_geometry_mm_to_deg(&g, x, y, &ecc, &pol);
        CHECK_NEAR(ecc, atan(hypot(x, y) / 570) / DEG, 1e-9);
        double want_pol = atan2(y, x) / DEG;
        if (want_pol < 0) want_pol += 360;
        if (hypot(x, y) > 1) CHECK_NEAR(pol, want_pol, 1e-7);
        CHECK(csf_geometry_deg_to_mm(&g, ecc, pol, &x2, &y2));
        CHECK_NEAR(x2, x, 1e-7);
        CHECK_NEAR(y2, y, 1e-7);
        double px, py, x3, y3;
        csf_geometry_mm_to_px(&g, x, y, &px, &py);
        csf_geometry_px_to_mm(&g, px, py, &x3, &y3);
        CHECK_NEAR(x3, x, 1e-9);
        CHECK_NEAR(y3, y, 1e-9);
    }
    /* pixel convention: top-left pixel centre is up-left of the screen centre */
    double x, y;
    csf_geometry_px_to_mm(&g, 0.5, 0.5, &x, &y);
    CHECK(x < 0 && y > 0);

    /* along the horizontal meridian the local coordinate u is the exact angle difference */
    csf_geometry_local_uv(&g, 20, 0, 570 * tan(23 * DEG), 0, &x, &y);
    CHECK_NEAR(x, 3.0, 1e-9);
    CHECK_NEAR(y, 0.0, 1e-9);
    csf_geometry_local_uv(&g, 10, 90, 0, 570 * tan(8 * DEG), &x, &y);
    CHECK_NEAR(y, -2.0, 1e-9);

    /* local pixel density: radial D/cos^2, tangential D/cos (relative to the centre) */
    double r0, t0, r, t;
    csf_geometry_px_per_deg(&g, 0, 0, &r0, &t0);
    CHECK_NEAR(r0, 570 * DEG / (531.0 / 1920), 1e-3 * r0);
    /* at the centre every direction has the same density (square pixels), also tangentially */
    CHECK_NEAR(t0, r0, 2e-3 * r0);
    csf_geometry_px_per_deg(&g, 0, 90, &r, &t);
    CHECK_NEAR(t, r0, 2e-3 * r0);
    CHECK_NEAR(r, r0, 2e-3 * r0);
    for (int ecc = 5; ecc <= 20; ecc += 5) {
        double c = cos(ecc * DEG);
        csf_geometry_px_per_deg(&g, ecc, 0, &r, &t);
        CHECK_NEAR(r / r0, 1 / (c * c), 2e-3);
        CHECK_NEAR(t / r0, 1 / c, 2e-3);
    }
    /* Nyquist: 0.5 cycle/pixel; at the centre the same for every orientation (square pixels) */
    double ny0 = csf_geometry_nyquist_cpd(&g, 0, 0, 0);
    CHECK_NEAR(ny0, 0.5 * 570 * DEG / (531.0 / 1920), 2e-3 * ny0);
    CHECK_NEAR(csf_geometry_nyquist_cpd(&g, 0, 0, 90), ny0, 2e-3 * ny0);
    /* oblique carriers sample diagonally: limit grows to 0.5*sqrt(2)/... at 45 deg */
    CHECK_NEAR(csf_geometry_nyquist_cpd(&g, 0, 0, 45), ny0 * sqrt(2.0), 5e-3 * ny0);
    CHECK_NEAR(csf_geometry_nyquist_cpd_any(&g, 0, 0), ny0, 2e-3 * ny0);
    /* radial carrier at 20 deg: pixels are denser in angle by 1/cos^2 */
    double c20 = cos(20 * DEG);
    CHECK_NEAR(csf_geometry_nyquist_cpd(&g, 20, 0, 0), ny0 / (c20 * c20), 5e-3 * ny0);
    CHECK_NEAR(csf_geometry_nyquist_cpd(&g, 20, 0, 90), ny0 / c20, 5e-3 * ny0);

    /* screen reach */
    CHECK_NEAR(csf_geometry_max_ecc(&g, 0), atan(265.5 / 570) / DEG, 1e-6);
    CHECK_NEAR(csf_geometry_max_ecc(&g, 90), atan(149.5 / 570) / DEG, 1e-6);
    CHECK_NEAR(csf_geometry_max_ecc(&g, 45), atan(hypot(149.5, 149.5) / 570) / DEG, 1e-6);
    CHECK(csf_geometry_on_screen(&g, 265, 149));
    CHECK(!csf_geometry_on_screen(&g, 266, 0));

    /* moving a centre along the meridian */
    double e2, p2;
    csf_geometry_move(&g, 10, 0, 0, 5, &e2, &p2);
    CHECK_NEAR(e2, 15, 1e-9);
    csf_geometry_move(&g, 10, 0, 180, 15, &e2, &p2);
    CHECK_NEAR(e2, 5, 1e-9);
    CHECK_NEAR(p2, 180, 1e-9);

    /* eye offset: eccentricity is the angle between the rays to fixation (centre) and point */
    csf_geometry go;
    CHECK_INT_EQ(csf_geometry_init(&go, 531, 299, 1920, 1080, 570, 100, -50, &e), CSF_OK);
    {
        double ax = 0 - 100, ay = 0 + 50, az = -570, bx = 200 - 100, by = 100 + 50, bz = -570;
        double want = acos((ax * bx + ay * by + az * bz) /
                           (sqrt(ax * ax + ay * ay + az * az) * sqrt(bx * bx + by * by + bz * bz))) / DEG;
        double ecc;
        csf_geometry_mm_to_deg(&go, 200, 100, &ecc, NULL);
        CHECK_NEAR(ecc, want, 1e-9);
        double pol;
        csf_geometry_mm_to_deg(&go, 200, 100, &ecc, &pol);
        CHECK(csf_geometry_deg_to_mm(&go, ecc, pol, &x, &y));
        CHECK_NEAR(x, 200, 1e-7);
        CHECK_NEAR(y, 100, 1e-7);
    }

    /* argument checks name the limit */
    CHECK_INT_EQ(csf_geometry_init(&g, 5, 299, 1920, 1080, 570, 0, 0, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "10 to 10000 mm");
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 1920, 1080, 20, 0, 0, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "50 to 10000 mm");
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 8, 1080, 570, 0, 0, &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 1920, 1080, NAN, 0, 0, &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_geometry_init(&g, 531, 299, 1920, 1080, 570, 600, 0, &e), CSF_E_INVALID_ARG);
    return CHECK_RESULT();
}
