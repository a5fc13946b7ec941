#include "model/csf_model.h"

#include <math.h>

/* The foveal depression's radius: gone by the 5 deg ring (0.2 % left there). */
static const double FOVEA_DIP_RADIUS_DEG = 2.0;

csf_model_params csf_model_default(void)
{
    csf_model_params p = {.smax = 250.0, .fmax_cpd = 3.0, .beta_oct = 3.0, .delta_log10 = 0.5,
                          .ecc_a = 0.0297, .ecc_b = 0.0190};
    return p;
}

void csf_model_use_nasal_field(csf_model_params *p)
{
    p->ecc_a = 0.0114;
    p->ecc_b = 0.0194;
}

double csf_model_log10_sensitivity(const csf_model_params *p, double freq_cpd, double ecc_deg)
{
    const double log2v = log10(2.0);
    double lsmax = log10(p->smax);
    double half_width = p->beta_oct * log2v / 2.0;
    /* Below the peak a magnified periphery gains at low frequencies what it loses at high ones,
     * which no loss linear in f * e can express (Rovamo & Virsu 1979) */
    double band_cpd = freq_cpd * (1.0 + p->ecc_scale_per_deg * ecc_deg);
    double u = (log10(band_cpd) - log10(p->fmax_cpd)) / half_width;
    double ls = lsmax - log2v * u * u;
    if (band_cpd < p->fmax_cpd && ls < lsmax - p->delta_log10) ls = lsmax - p->delta_log10;
    ls -= (p->ecc_a + p->ecc_b * freq_cpd) * ecc_deg;
    /* The loss above only grows outwards, so a poor fovea would drag every ring down with it. */
    if (p->fovea_dip_log10 != 0.0) {
        double r = ecc_deg / FOVEA_DIP_RADIUS_DEG;
        ls -= p->fovea_dip_log10 * exp(-r * r);
    }
    return ls;
}

double csf_model_sensitivity(const csf_model_params *p, double freq_cpd, double ecc_deg)
{
    return pow(10.0, csf_model_log10_sensitivity(p, freq_cpd, ecc_deg));
}

double csf_model_threshold(const csf_model_params *p, double freq_cpd, double ecc_deg)
{
    return pow(10.0, -csf_model_log10_sensitivity(p, freq_cpd, ecc_deg));
}
