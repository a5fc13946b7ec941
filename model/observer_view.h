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
 * luminance (csf_view_place_contrast).
 *
 * Motion (csf_view_place_motion_contrast): a mean over frames would average a drifting grating
 * away, so each looked-at frame also keeps its own quadrature response z_k = a_k + i b_k, its
 * presentation time t_k and the time d_k it stayed on screen (a held or missed frame counts for
 * its whole duration). The person's temporal analysis is a spatio-temporal matched filter (motion
 * energy, Adelson & Bergen 1985) over a bank of temporal frequencies tf of both signs (both drift
 * directions), from the frames' light as it was on screen (each frame held for d_k):
 *     L0   = sum_k d_k L0_k / D,           D = sum_k d_k (the mean luminance),
 *     Z0   = sum_k d_k z_k / D              (the sustained, static component),
 *     R(tf) = sum_k (z_k - Z0) d_k sinc(tf d_k) exp(-i 2 pi tf (t_k + d_k / 2)) / D,
 * for tf = j / (4 T), j = +-1 .. +-J, T the span of the frames looked at, up to the Nyquist
 * frequency of the looking rate (1 / (2 mean spacing); at most CSF_VIEW_BANK_MAX per sign). The
 * moving components are taken about the sustained one, so a grating that does not change puts
 * nothing into them (the edges of the looking window are not motion). A component at tf is a
 * grating drifting at |tf| / f; the person weighs it by their sensitivity there relative to the
 * velocity they are asked about (the reference), G(tf) = 10^(gain(f, |tf|/f) - gain(f, v_ref)),
 * gain = log10 sensitivity over static (model/csf_velocity.h or the person's table). Components
 * combine by probability summation in its high-exponent limit (Quick 1974; Watson 1979 found
 * temporal-channel summation exponents of 3.5-4, where the largest term all but decides): the
 * most detectable component decides,
 *     contrast = max(|Z0| G(0), max_tf |R(tf)| G(tf)) / L0,
 * the equivalent contrast of a grating drifting at the reference velocity. Nothing assumes the
 * speed shown: a grating drawn frozen, juddering or at the wrong speed puts its energy elsewhere
 * and is weighed there. A static grating measured at reference 0 gives |Z0| / L0, the fit of the
 * mean light (frames of equal duration: csf_view_place_contrast to rounding), unless a noise
 * component weighed up by motion sensitivity outgrows it (only near the noise floor).
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

/* ---- motion (see the top of this file) ---- */

#define CSF_VIEW_BANK_MAX 512 /* temporal frequencies per sign: bounds the work per look */

/* log10 of the person's sensitivity to a grating of freq_cpd at ecc_deg drifting at
 * velocity_dps over the same grating static (e.g. csf_observer_sim_velocity_log10_gain). */
typedef double (*csf_view_gain_fn)(void *ctx, double freq_cpd, double ecc_deg, double velocity_dps);

/* Adds a frame presented at t_s (the presenter's clock): as csf_view_place_add_frame, and keeps
 * its quadrature response and time for the motion analysis. Its time on screen is unknown until
 * the next frame: csf_view_place_set_duration. Refused (CSF_E_NOMEM) only when out of memory. */
csf_status csf_view_place_add_frame_at(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb,
                                       double t_s, csf_error *err);
/* How long the latest frame added with csf_view_place_add_frame_at stayed on screen (s, > 0). */
void csf_view_place_set_duration(csf_view_place *pl, double duration_s);

typedef struct {
    double static_contrast; /* |Z0| / L0: what the fit of the mean light sees */
    double tf_hz;           /* the deciding component (0: the sustained one; sign = direction) */
    double velocity_dps;    /* tf_hz / f: the speed it was seen at */
    int n_frames;           /* frames in the window */
} csf_view_motion_info;

/* The equivalent contrast, at reference velocity ref_velocity_dps, of what was shown over the
 * frames added with csf_view_place_add_frame_at whose time is >= since_s (-INFINITY: all);
 * frames whose duration was never set count for default_duration_s (e.g. one refresh period).
 * gain NULL: the Kelly-Daly model with its published constants (csf_velocity_default). ecc_deg is
 * passed to gain. 0 without frames or over a black field. info may be NULL. */
double csf_view_place_motion_contrast(const csf_view_place *pl, double ecc_deg, double ref_velocity_dps,
                                      double since_s, double default_duration_s, csf_view_gain_fn gain,
                                      void *gain_ctx, csf_view_motion_info *info);

#endif
