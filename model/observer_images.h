/* The simulated observer judging image pairs (user studies with stimulus = image): how visible is
 * the difference between two images to an observer with a given CSF (model/observer_sim.h)?
 *
 * Model (docs/studies.md, "image pairs"): the images are relative luminance; their difference is
 * split into octave bands by differences of Gaussians, B_k = G(s_k) * d - G(2 s_k) * d with
 * s_k = 2^(k-1) px; band k peaks at f_k = 0.153 / s_k cycles per pixel (converted to cpd with the
 * image's pixel size, width = size_deg) with gain 0.4725, divided out so that a grating of
 * amplitude c at f_k gives |B_k| = c. Contrast is local (Peli 1990): |B_k| over the pair's mean
 * luminance blurred at 2 s_k (floored at a tenth of the image mean). Each pixel's eccentricity
 * follows from the image's place on screen. A band's detectability pools contrast/threshold over
 * space (Robson & Graham 1981) against the area a 1-deg Gabor pools at threshold:
 *     r_k = (sum_px (c/t)^slope * A_px / A_ref)^(1/slope),  A_ref = 2 pi sigma^2 / slope * mean|sin|^slope
 * and bands by probability summation (Quick pooling with the observer's Weibull slope):
 *     r = (sum_k r_k^slope)^(1/slope),   P(seen) = 1 - exp(-r^slope)
 * so r = 1 is a difference at threshold (P(seen) = 1 - 1/e, as a grating at t in the Weibull).
 * Bands finer than 0.5 cycle/px do not exist; bands coarser than the image are not used.
 * Decisions: a lapse (probability `lapse`) is a coin flip; otherwise a seen difference is reported
 * (same/different: "different"; 2AFC/2IFC: the altered image is picked) and an unseen one is
 * answered by guessing (same/different: "different" with probability `fa`; forced choice: 1/2).
 * Identical images have r = 0.
 * Moving images (csf_image_pair_evaluate_v): every band is judged as a grating drifting at the
 * image's speed, threshold csf_observer_sim_threshold_v(f_k, ecc, v) (Kelly 1979, Daly 1998, or
 * the person's 3-D table). The bands are isotropic, so this is the speed across the bars for
 * every orientation: components whose bars lie along the motion move less across them and are
 * judged a little too fast. The eccentricities are those at the image's starting place. */
#ifndef CSF_OBSERVER_IMAGES_H
#define CSF_OBSERVER_IMAGES_H

#include <stdint.h>

#include "model/observer_sim.h"

#define CSF_IMG_MAX_BANDS 10

typedef struct {
    int n_bands;
    double freq_cpd[CSF_IMG_MAX_BANDS];
    double contrast[CSF_IMG_MAX_BANDS];  /* largest band contrast anywhere in the image */
    double ratio[CSF_IMG_MAX_BANDS];     /* band detectability pooled over space (1 = a 1-deg Gabor at threshold) */
    double peak_ratio[CSF_IMG_MAX_BANDS]; /* largest local contrast / threshold */
    double r;                            /* pooled detectability */
} csf_image_pair_eval;

/* lum_a, lum_b: w*h relative luminance, top row first. size_deg: drawn width; (ecc_deg,
 * polar_deg): centre. Returns 0, or -1 on bad arguments or no memory. */
int csf_image_pair_evaluate(const csf_observer_sim *o, const float *lum_a, const float *lum_b, int w,
                            int h, double size_deg, double ecc_deg, double polar_deg,
                            csf_image_pair_eval *out);

/* The same for the pair moving at velocity_dps (retinal, deg/s; 0 = csf_image_pair_evaluate). */
int csf_image_pair_evaluate_v(const csf_observer_sim *o, const float *lum_a, const float *lum_b, int w, int h,
                              double size_deg, double ecc_deg, double polar_deg, double velocity_dps,
                              csf_image_pair_eval *out);

double csf_image_pair_p_seen(const csf_observer_sim *o, double r);

/* One same/different answer for a pair of detectability r (0 for a same pair): 1 "different",
 * 0 "same". seed/trial_index key the draws; *rt_s the response time. */
int csf_observer_sim_same_different(const csf_observer_sim *o, uint64_t seed, uint64_t trial_index,
                                    double r, double *rt_s);
/* One forced choice between two images of which `target` (0/1) is the altered one: the place or
 * interval chosen. */
int csf_observer_sim_image_afc(const csf_observer_sim *o, uint64_t seed, uint64_t trial_index,
                               double r, int target, double *rt_s);

#endif
