/* What a simulated person sees at one place on the screen (`--observer
 * sim:view=frame`): the contrast of a Gabor of known frequency, orientation and size, measured
 * from framebuffer pixels turned into light by the simulated display, never from the plan.
 *
 * A place is a set of pixels around the direction the person attends to, each with its
 * stimulus-local angle-space coordinates (u, v) in degrees (stimuli/geometry.h's local_uv, which
 * the caller computes: devices/ does not know the screen's geometry). The measurement is a
 * matched filter: the least-squares fit of the luminance over those pixels to
 *     L(u, v) = L0 + a E(u, v) cos(2 pi f w) + b E(u, v) sin(2 pi f w),
 *     w = u cos(theta) + v sin(theta),  E = exp(-(u^2 + v^2) / (2 sigma^2)),
 * i.e. the projection on the quadrature pair of the expected Gabor plus the mean (phase-blind
 * Gabor energy). The contrast seen is hypot(a, b) / L0: for a Gabor of Michelson contrast C drawn
 * at the place with this frequency, orientation and size it is C (envelope-peak contrast, the
 * convention of stimuli/presenter.h); a grating drawn elsewhere, at another frequency or
 * orientation, or a flat field gives a small value (the projection of what is there, plus the
 * dither's noise). Frames add linearly: the fit over several frames is the fit of their mean
 * luminance, as a person integrates over an interval.
 *
 * Pixels become luminance through the caller's display truth (a simulated display model or a
 * profile); grey pixels (R = G = B) go through a table of the maxlevel + 1 grey levels, mixed
 * pixels (bit-stealing) through the function itself. */
#ifndef CSF_OBSERVER_VIEW_H
#define CSF_OBSERVER_VIEW_H

#include <stdint.h>

#include "core/csf_status.h"

/* Light of one pixel with drive values r, g, b in [0,1], cd/m2. */
typedef double (*csf_view_lum_fn)(void *ctx, double r01, double g01, double b01);

/* The display the person looks at: its luminance function and a table of its grey levels. */
typedef struct {
    csf_view_lum_fn lum;
    void *ctx;
    int maxlevel;        /* 255 (8 bit) or 1023 (10 bit) */
    double *grey_cdm2;   /* maxlevel + 1 entries */
} csf_view_display;

/* maxlevel 1 .. 65535. */
csf_status csf_view_display_init(csf_view_display *d, csf_view_lum_fn lum, void *ctx, int maxlevel,
                                 csf_error *err);
void csf_view_display_free(csf_view_display *d);
/* Luminance of a pixel given as framebuffer levels (clamped to 0 .. maxlevel). */
double csf_view_display_pixel(const csf_view_display *d, const uint16_t rgb[3]);

typedef struct csf_view_place csf_view_place;

/* A place of n_px pixels (0 < n_px <= 2^24); u_deg/v_deg their angle-space coordinates around the
 * place centre; use[i] = 0 leaves pixel i out of the fit (e.g. the fixation mark, which a
 * person does not take for the stimulus). Refused: bad sizes (freq (0, 1000] cpd, sigma
 * [0.02, 30] deg), non-finite coordinates, or pixels that cannot tell the three components apart
 * (fewer than 16 used pixels, or a singular fit). */
csf_status csf_view_place_create(const float *u_deg, const float *v_deg, const unsigned char *use,
                                 int n_px, double freq_cpd, double orientation_deg, double sigma_deg,
                                 csf_view_place **out, csf_error *err);
void csf_view_place_free(csf_view_place *pl);
/* Forgets the frames added so far. */
void csf_view_place_reset(csf_view_place *pl);
/* Adds one frame: rgb holds the place's n_px pixels as levels (3 per pixel, same order). */
void csf_view_place_add_frame(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb);
/* Frames added since the last reset. */
int csf_view_place_frames(const csf_view_place *pl);
/* The Michelson contrast of the Gabor component over the frames added (0 without frames), and
 * the fitted mean luminance L0 in *mean_cdm2 if not NULL. */
double csf_view_place_contrast(const csf_view_place *pl, double *mean_cdm2);

#endif
