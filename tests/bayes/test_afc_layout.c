/* calib/afc_layout: which cells get four places on the default station and on a small screen,
 * that the places it returns are on screen and apart, and the click-to-place mapping. */
#include <math.h>

#include "calib/afc_layout.h"
#include "tests/check.h"

static double angle_deg(double e1, double p1, double e2, double p2)
{
    const double r = M_PI / 180.0;
    double c = cos(e1 * r) * cos(e2 * r) + sin(e1 * r) * sin(e2 * r) * cos((p1 - p2) * r);
    return acos(fmin(1.0, fmax(-1.0, c))) / r;
}

int main(void)
{
    csf_geometry g, small;
    csf_error err;
    CHECK(csf_geometry_init(&g, 531.0, 299.0, 1920, 1080, 570.0, 0.0, 0.0, &err) == CSF_OK);
    CHECK(csf_geometry_init(&small, 200.0, 150.0, 800, 600, 570.0, 0.0, 0.0, &err) == CSF_OK);

    csf_afc_layout l;
    /* the fovea and eccentricities too small to hold four separate patches: two intervals */
    csf_afc_choose_layout(&g, 0.0, 1.0, 4, &l);
    CHECK_INT_EQ(l.n_alternatives, 2);
    csf_afc_choose_layout(&g, 4.0, 1.0, 4, &l); /* neighbours 4*sqrt(2) = 5.7 deg < 6 sigma */
    CHECK_INT_EQ(l.n_alternatives, 2);
    /* asked for two intervals */
    csf_afc_choose_layout(&g, 10.0, 1.0, 2, &l);
    CHECK_INT_EQ(l.n_alternatives, 2);
    /* 5 and 10 deg: the diagonal places */
    for (int e = 5; e <= 10; e += 5) {
        csf_afc_choose_layout(&g, e, 1.0, 4, &l);
        CHECK_INT_EQ(l.n_alternatives, 4);
        CHECK_NEAR(l.polar_deg[0], 45.0, 1e-12);
        CHECK_NEAR(l.polar_deg[1], 135.0, 1e-12);
        CHECK_NEAR(l.polar_deg[2], 225.0, 1e-12);
        CHECK_NEAR(l.polar_deg[3], 315.0, 1e-12);
    }
    /* 20 deg on a 16:9 screen (half height 14.7 deg): the places move towards the horizontal
     * meridian, stay on screen with 3 sigma to spare and stay 6 sigma apart */
    csf_afc_choose_layout(&g, 20.0, 1.0, 4, &l);
    CHECK_INT_EQ(l.n_alternatives, 4);
    CHECK(l.polar_deg[0] < 45.0 && l.polar_deg[0] > 10.0);
    for (int k = 0; k < 4; k++) {
        double x, y;
        CHECK(csf_geometry_deg_to_mm(&g, 23.0, l.polar_deg[k], &x, &y) == 1);
        CHECK_MSG(fabs(y) <= 149.5 && fabs(x) <= 265.5, "place %d at %.1f deg reaches (%.0f, %.0f) mm", k,
                  l.polar_deg[k], x, y);
        for (int j = 0; j < k; j++) CHECK(angle_deg(20.0, l.polar_deg[k], 20.0, l.polar_deg[j]) >= 6.0);
    }
    /* beyond the screen's reach on the diagonal and the meridians: two intervals */
    csf_afc_choose_layout(&g, 25.0, 1.0, 4, &l);
    CHECK_INT_EQ(l.n_alternatives, 2);
    csf_afc_choose_layout(&small, 10.0, 1.0, 4, &l); /* half height 7.5 deg */
    CHECK_INT_EQ(l.n_alternatives, 2);
    csf_afc_choose_layout(&small, 5.0, 1.0, 4, &l);
    CHECK_INT_EQ(l.n_alternatives, 4);
    /* a larger patch needs more room: sigma 2 at 5 deg cannot hold four */
    csf_afc_choose_layout(&g, 5.0, 2.0, 4, &l);
    CHECK_INT_EQ(l.n_alternatives, 2);

    /* clicks: the nearest place, including a click near the centre or far outside the ring */
    csf_afc_choose_layout(&g, 10.0, 1.0, 4, &l);
    CHECK_INT_EQ(csf_afc_nearest_place(&l, 10.0, 40.0, 10.0), 0);
    CHECK_INT_EQ(csf_afc_nearest_place(&l, 9.0, 140.0, 10.0), 1);
    CHECK_INT_EQ(csf_afc_nearest_place(&l, 12.0, 200.0, 10.0), 2);
    CHECK_INT_EQ(csf_afc_nearest_place(&l, 3.0, 300.0, 10.0), 3);
    CHECK_INT_EQ(csf_afc_nearest_place(&l, 30.0, 100.0, 10.0), 1);
    return CHECK_RESULT();
}
