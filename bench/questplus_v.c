#include "questplus_v.h"

#include "model/csf_model.h"
#include "model/csf_velocity.h"

enum { N_C2 = 3, N_STEEP = 3, N_VEL = N_C2 * N_STEEP };

static const double C2S[N_C2] = {0.85, 1.7, 3.4}, STEEPS[N_STEEP] = {0.35, 0.6, 1.0};

/* Surface number surf = static surface x N_VEL + velocity shape (c2 slower, steepness faster). */
static double velocity_surface(void *ctx, int surf, const csf_cell *cells, int n_cells, float *t_log10)
{
    (void)ctx;
    double prior;
    csf_model_params p = questplus_static_surface(surf / N_VEL, &prior);
    csf_velocity_params vp = csf_velocity_default();
    vp.c2 = C2S[surf % N_VEL / N_STEEP], vp.steepness = STEEPS[surf % N_VEL % N_STEEP];
    for (int c = 0; c < n_cells; c++)
        t_log10[c] = (float)(-csf_model_log10_sensitivity(&p, cells[c].freq_cpd, cells[c].ecc_deg) -
                             csf_velocity_log10_gain(&vp, cells[c].freq_cpd, cells[c].velocity_dps));
    return prior;
}

questplus *questplus_v_create(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                              double log10_cmin, double log10_cmax)
{
    return questplus_create_family(cells, n_cells, n_alt, lapse, log10_cmin, log10_cmax, QP_N_STATIC * N_VEL,
                                   velocity_surface, NULL);
}
