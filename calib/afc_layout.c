#include "calib/afc_layout.h"

#include <math.h>

/* Angle between two directions given as (ecc, polar) from the line of sight, deg. */
static double angle_between(double e1, double p1, double e2, double p2)
{
    const double r = M_PI / 180.0;
    double c = cos(e1 * r) * cos(e2 * r) + sin(e1 * r) * sin(e2 * r) * cos((p1 - p2) * r);
    return acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c) / r;
}

/* The whole patch (its rim sampled every 15 deg) lies on the visible screen. */
static int patch_on_screen(const csf_geometry *g, double ecc_deg, double polar_deg, double radius_deg)
{
    for (int k = 0; k < 24; k++) {
        double e, p, x, y;
        csf_geometry_move(g, ecc_deg, polar_deg, 15.0 * k, radius_deg, &e, &p);
        if (!csf_geometry_deg_to_mm(g, e, p, &x, &y) || !csf_geometry_on_screen(g, x, y)) return 0;
    }
    return 1;
}

void csf_afc_choose_layout(const csf_geometry *g, double ecc_deg, double sigma_deg,
                           int want_alternatives, csf_afc_layout *out)
{
    out->n_alternatives = 2;
    for (int k = 0; k < 4; k++) out->polar_deg[k] = 0.0;
    if (want_alternatives != 4 || !(ecc_deg > 0.0) || !(sigma_deg > 0.0)) return;
    double radius = CSF_AFC_PATCH_RADIUS_SIGMAS * sigma_deg;
    for (int a = 45; a >= 1; a--) {
        double pol[4] = {a, 180.0 - a, 180.0 + a, 360.0 - a};
        /* the closest neighbours are the pairs across the horizontal meridian (a <= 45) */
        if (angle_between(ecc_deg, pol[0], ecc_deg, pol[3]) < 2.0 * radius) return;
        int fits = 1;
        for (int k = 0; k < 4 && fits; k++) fits = patch_on_screen(g, ecc_deg, pol[k], radius);
        if (!fits) continue;
        out->n_alternatives = 4;
        for (int k = 0; k < 4; k++) out->polar_deg[k] = pol[k];
        return;
    }
}

int csf_afc_nearest_place(const csf_afc_layout *l, double ecc_deg, double polar_deg, double cell_ecc_deg)
{
    int best = 0;
    double best_d = INFINITY;
    for (int k = 0; k < 4; k++) {
        double d = angle_between(ecc_deg, polar_deg, cell_ecc_deg, l->polar_deg[k]);
        if (d < best_d) best_d = d, best = k;
    }
    return best;
}
