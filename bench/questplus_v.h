/* Joint QUEST+ (Watson 2017) over a parametric SPATIO-VELOCITY surface, the velocity benchmark's
 * anchor (bench/bench_velocity.c): the static anchor's surface (bench/questplus.h: qCSF's
 * truncated log-parabola, Lesmes et al. 2010, times the stelaCSF eccentricity factor, on the same
 * grids and prior) times the Kelly (1979) / Daly (1998) gain of model/csf_velocity.h with two free
 * knobs: the velocity scale c2 (0.85, 1.7, 3.4; Daly's value in the middle) and the steepness
 * (0.35, 0.6, 1), c1 fixed at Daly's 0.67. That is the parametric model a vision scientist would
 * fit to a velocity grid with QUEST+, and the same family the bayes method's prior is drawn from,
 * so the anchor knows as much about the shape of motion as the method does. 5376 static surfaces
 * x 9 velocity shapes x slope 2, 3.2, 5 = 145152 hypotheses; flat prior on the velocity knobs.
 * Stimuli, placement (QP_CELLS_PER_TRIAL random cells x 23 contrasts, least expected entropy),
 * the pruning of hypotheses below 1e-7 of the largest and the estimate (posterior mean of
 * min(t, log10 cmax); never visible when more than half the mass says t >= log10 cmax) are the
 * static anchor's. */
#ifndef BENCH_QUESTPLUS_V_H
#define BENCH_QUESTPLUS_V_H

#include "questplus.h"

/* cells carry velocity_dps; n_alt[c] = 2 or 4 (guess 1/2 or 1/4). The questplus_* functions run it
 * (questplus_best_fit_rms: the anchor's floor, whatever the budget). NULL when out of memory. */
questplus *questplus_v_create(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                              double log10_cmin, double log10_cmax);

#endif
