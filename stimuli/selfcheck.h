/* Self-check of the presenter: render frames offscreen, read them back, turn pixels into
 * luminance with the caller's idea of the display's truth (a simulated display model, or a
 * profile), and measure what was drawn: spatial frequency, orientation, position, Michelson
 * contrast averaged over frames, mean luminance, and the effective luminance resolution.
 * Used by `csfcal stimulus check`, the stimulus tests and bench_frame. */
#ifndef CSF_STIMULI_SELFCHECK_H
#define CSF_STIMULI_SELFCHECK_H

#include <stdint.h>

#include "stimuli/presenter.h"

/* Luminance in cd/m2 of one pixel with drive values r, g, b in [0,1]. */
typedef double (*csf_pixel_lum_fn)(void *ctx, double r01, double g01, double b01);

typedef struct {
    int frames;
    double freq_cpd;          /* frequency maximising the carrier projection (angle space) */
    double orientation_deg;   /* orientation maximising it */
    double ecc_deg, polar_deg;/* centroid of the contrast energy */
    double contrast;          /* Michelson, least squares on the frame-averaged luminance */
    double mean_lum_cdm2;     /* background/patch mean from the same fit */
} csf_selfcheck_result;

/* Renders `frames` frames of s (Gabor or grating, static), measures them. The presenter must be
 * headless or windowed with rendering on every frame. */
csf_status csf_selfcheck_stimulus(csf_presenter *p, const csf_stimulus *s, int frames,
                                  csf_pixel_lum_fn lum, void *lum_ctx, csf_selfcheck_result *out,
                                  csf_error *err);

typedef struct {
    int levels, frames, patch_px;
    double max_err_frac;     /* max |measured - requested| patch-mean luminance / display range */
    double rms_err_frac;
    double effective_bits;   /* -log2(max_err_frac) */
} csf_selfcheck_resolution;

/* Effective luminance resolution: `levels` random uniform fields between 20 % and 80 % of peak
 * luminance (counter RNG on seed), each shown for `frames` frames; the mean luminance of the
 * central patch_px x patch_px patch over the frames is compared with the request. */
csf_status csf_selfcheck_resolution_run(csf_presenter *p, int levels, int frames, int patch_px,
                                        uint64_t seed, csf_pixel_lum_fn lum, void *lum_ctx,
                                        csf_selfcheck_resolution *out, csf_error *err);

#endif
