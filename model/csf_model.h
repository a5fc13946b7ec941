/* Parametric contrast sensitivity: truncated log-parabola over frequency (Lesmes et al. 2010)
 * times the stelaCSF eccentricity factor (Mantiuk et al. 2022). Used by the simulated observer's
 * default truth, by the Bayesian surface fit, and by benchmarks as the analytic comparison. */
#ifndef CSF_MODEL_H
#define CSF_MODEL_H

typedef struct {
    double smax;       /* peak sensitivity (1/Michelson) */
    double fmax_cpd;   /* frequency of the peak */
    double beta_oct;   /* full bandwidth at half height, octaves */
    double delta_log10;/* low-frequency truncation depth below log10 smax */
    double ecc_a;      /* stelaCSF eccentricity slope, constant term (per degree) */
    double ecc_b;      /* stelaCSF eccentricity slope, per cpd per degree */
    double ecc_scale_per_deg; /* frequency scaling (cortical magnification): at eccentricity e the
                                 band is the foveal one at f * (1 + ecc_scale_per_deg * e); 0 = none */
    double fovea_dip_log10; /* sensitivity lost at the fovea alone (a central depression, as in early
                               macular degeneration), fading as exp(-(e / 2 deg)^2); 0 = none */
} csf_model_params;

/* Typical young adult, fovea, temporal field: Smax 250, fmax 3 cpd, 3 octaves, delta 0.5,
 * a = 0.0297, b = 0.0190, no frequency scaling. */
csf_model_params csf_model_default(void);

/* Nasal-field eccentricity constants (a = 0.0114, b = 0.0194). */
void csf_model_use_nasal_field(csf_model_params *p);

double csf_model_log10_sensitivity(const csf_model_params *p, double freq_cpd, double ecc_deg);
double csf_model_sensitivity(const csf_model_params *p, double freq_cpd, double ecc_deg);
/* 1/S; may exceed 1, which means no contrast makes it visible. */
double csf_model_threshold(const csf_model_params *p, double freq_cpd, double ecc_deg);

#endif
