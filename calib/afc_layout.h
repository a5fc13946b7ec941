/* Forced-choice layout of a cell: two temporal intervals at one place, or four places shown at
 * once (spatial 4AFC). Four places give a guess rate of 1/4 instead of 1/2, so each answer says
 * more about the threshold (for a naive observer spatial 4AFC is also the more reliable task:
 * Jaekel & Wichmann 2006); the joint method reaches a given accuracy in markedly fewer trials
 * (docs/bayes-method.md). A foveal cell cannot have four places at its own eccentricity, so it
 * stays two-interval. */
#ifndef CSF_AFC_LAYOUT_H
#define CSF_AFC_LAYOUT_H

#include "stimuli/geometry.h"

/* Places are indexed 0 upper right, 1 upper left, 2 lower left, 3 lower right (as seen on screen);
 * their polar angles are a, 180 - a, 180 + a, 360 - a with 0 < a <= 45 deg. */
typedef struct {
    int n_alternatives;   /* 2: two intervals (polar_deg unused); 4: four places */
    double polar_deg[4];
} csf_afc_layout;

/* Radius of a Gabor patch that must lie on screen and apart from its neighbours, in sigmas. */
#define CSF_AFC_PATCH_RADIUS_SIGMAS 3.0

/* Chooses the layout for a Gabor of sigma_deg at ecc_deg: four places when want_alternatives is 4,
 * every patch (radius CSF_AFC_PATCH_RADIUS_SIGMAS sigma) lies on the screen, and neighbouring
 * centres are at least two patch radii apart; a is the largest angle <= 45 deg (in 1 deg steps)
 * for which that holds, so on a wide screen the places move towards the horizontal meridian at
 * large eccentricities. Otherwise two intervals. Deterministic in its inputs, so a resumed
 * session gets the layout it had. */
void csf_afc_choose_layout(const csf_geometry *g, double ecc_deg, double sigma_deg,
                           int want_alternatives, csf_afc_layout *out);

/* The place (0-3) whose centre is nearest to the direction (ecc_deg, polar_deg), e.g. a click. */
int csf_afc_nearest_place(const csf_afc_layout *l, double ecc_deg, double polar_deg, double cell_ecc_deg);

#endif
