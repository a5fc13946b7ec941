/* Joint Bayesian CSF procedure ("bayes"): extra read-outs beyond calib/procedure.h.
 * The procedure itself is csf_procedure_bayes (see procedure.h); these functions take the state
 * pointer its create() returned, for sessions and reports that want to show the model check. */
#ifndef CSF_METHOD_BAYES_H
#define CSF_METHOD_BAYES_H

#include "calib/procedure.h"

/* Per-cell model check. The surface (log-parabola x stelaCSF with a per-cell offset) predicts the
 * cell's threshold; the cell's own trials either agree with that prediction or not. */
typedef struct {
    double surface_log10;       /* surface-only prediction of log10 threshold (posterior mean) */
    double log10_bayes_factor;  /* log10 evidence(weak per-cell prior: surface blurred by 0.4 log10)
                                   / evidence(surface prior with the learned offset sd);
                                   > 0.5 (3:1) with >= 5 trials: the surface does not explain it */
    int misfit;                 /* 1: estimate() fell back to the per-cell estimate */
    int n_trials;
} csf_bayes_cell_check;

/* Fills out[n_cells] (n_cells of the setup). state = the pointer create() returned. */
csf_status csf_bayes_check(void *state, csf_bayes_cell_check *out, csf_error *err);

/* The person's psychometric slope (geometric posterior mean over the grid 1.5-6) and lapse rate
 * (posterior mean over 0-0.08) as the method currently weighs them; the setup's values when it
 * asked for fixed_psychometric. */
void csf_bayes_psychometric(void *state, double *slope, double *lapse);

/* Effective number of particles behind the surface posterior right now (diagnostic). */
double csf_bayes_effective_particles(void *state);

/* Posterior mean of the surface parameters (log10 Smax, log10 fmax, beta octaves, delta,
 * ecc_a, ecc_b, ecc_scale_per_deg, fovea_dip_log10, log10 of the motion gain's velocity scale over
 * Daly's, the motion gain's steepness), for reports. */
#define CSF_BAYES_NPAR 10
void csf_bayes_surface_mean(void *state, double out[CSF_BAYES_NPAR]);

#endif
