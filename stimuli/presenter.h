/* Stimulus presenter: draws fixation, Gabors, windowed gratings, drifting and
 * moving patches, PNG images and text screens, in exact visual degrees (stimuli/geometry.h), with
 * luminance computed in cd/m2 per fragment, mapped through the display profile's inverse and
 * dithered (spatially and temporally) to the framebuffer depth, so that the mean luminance of a
 * patch over frames matches the request far below one drive step.
 *
 * Two back ends share all drawing code:
 *   windowed  GLFW fullscreen on a chosen monitor, OpenGL through EGL (GLFW_EGL_CONTEXT_API),
 *             vsync, cursor hidden, OS gamma ramp set to identity and restored on every exit path
 *             (stimuli/gamma_guard.h); frames are timestamped after the swap on CLOCK_MONOTONIC.
 *   headless  EGL surfaceless (Mesa) with an offscreen framebuffer object; time runs on a VIRTUAL
 *             clock that advances by 1/refresh_hz per frame, and missed frames can be injected
 *             (csf_presenter_inject_missed / csf_presenter_set_miss_rate) to test the flagging.
 *
 * Luminance pipeline (fragment shader): L(x) in cd/m2 -> drive estimate from an inverse-profile
 * float texture -> bracketing framebuffer levels k, k+1 whose true luminances come from a second
 * texture built from the forward profile -> choose k+1 with probability (L - L_k)/(L_k+1 - L_k)
 * using an R2 low-discrepancy spatial mask plus a golden-ratio per-frame offset. The expectation
 * of the emitted luminance is therefore exactly L (to float precision), whatever the gamma.
 *
 * PERFORMANCE (for the observer area, simulated sessions): rasterising every frame at 1920x1080
 * on llvmpipe costs several ms; a 120-trial session must take < 10 s. Use
 *     cfg.headless = 1; cfg.render_width_px = 64; cfg.render_height_px = 36;  (cheap raster)
 *     cfg.render_every = -1;   (bookkeeping only: no rasterisation after validation)
 * With render_every = -1, csf_presenter_draw / csf_presenter_run_trial still validate the
 * stimulus, advance the virtual clock, apply injected misses and record the contrast per frame,
 * but skip GL work; render_every = N > 1 rasterises every N-th frame. Geometry checks (Nyquist,
 * off-screen) always use the full configured geometry, never the reduced render size.
 *
 * TESTS UNDER ASAN that open a presenter: set ASAN_OPTIONS=fast_unwind_on_malloc=1:... in the
 * test's env (see tests/stimuli/meson.build). The project default fast_unwind_on_malloc=0
 * deadlocks inside llvmpipe (LLVM's JIT registers EH frames while holding libgcc's lock, and the
 * slow unwinder takes it again). Mesa's own leaks stay suppressed by module (tests/lsan.supp). */
#ifndef CSF_STIMULI_PRESENTER_H
#define CSF_STIMULI_PRESENTER_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"
#include "results/display_profile.h"
#include "stimuli/geometry.h"
#include "stimuli/image.h"

enum {
    CSF_STIM_GABOR = 1,   /* sine carrier x Gaussian envelope (sigma_deg) */
    CSF_STIM_GRATING = 2, /* sine carrier in a circular window, raised-cosine edge */
    CSF_STIM_IMAGE = 3,   /* PNG image (stimuli/image.h) as luminance around the mean */
    CSF_STIM_DISC = 4     /* uniform disc of luminance mean*(1+contrast): luminance steps */
};

/* One stimulus. Unused fields may be 0. Conventions:
 *  orientation_deg  direction of the carrier's modulation in angle space, counter-clockwise from
 *                   horizontal: 0 = vertical bars, 90 = horizontal bars.
 *  phase_deg        carrier phase at the patch centre (0 = cosine peak, luminance maximum).
 *  ecc_deg/polar_deg  patch centre (geometry.h conventions).
 *  contrast         Michelson, fraction (0..1); the envelope multiplies it.
 *  mean_lum_cdm2    background and patch mean; <= 0 means the display's mid luminance
 *                   (black + max)/2.
 *  drift_hz         carrier drift (temporal frequency), phase advances 360*drift_hz*time_s; a
 *                   carrier drifting at v deg/s at freq_cpd has drift_hz = v * freq_cpd (Kelly
 *                   1979). Refused at or above half the refresh rate (it would alias).
 *                   csf_presenter_run_trial sets time_s from each frame's PREDICTED presentation
 *                   time, never a frame count, so a missed frame does not slow the grating: the
 *                   frame after it is drawn at the phase real time says (the phase step over the
 *                   held frame is 2*pi*drift_hz*interval). Headless, the prediction is exact
 *                   (injected misses included); in a window it is one refresh after the last swap.
 *  velocity_dps     patch moves along motion_dir_deg at this speed (deg/s of eccentricity space,
 *                   i.e. the centre direction rotates), from (ecc, polar) at time_s = 0.
 *  time_s           seconds since stimulus onset; csf_presenter_run_trial sets it per frame. */
typedef struct {
    int kind;
    double freq_cpd, orientation_deg, phase_deg, sigma_deg, ecc_deg, polar_deg, contrast,
        mean_lum_cdm2, drift_hz, velocity_dps;
    /* additions beyond the contract's list */
    double motion_dir_deg; /* polar-angle convention direction of patch motion */
    double radius_deg;     /* GRATING window radius, DISC/IMAGE radius (0 = 2 deg); GABOR: ignored */
    double edge_deg;       /* GRATING/DISC raised-cosine edge width (0 = 0.25 deg) */
    double time_s;
    const csf_image *image; /* CSF_STIM_IMAGE */
} csf_stimulus;

typedef struct {
    long frame_index;      /* 0-based, counts frames presented since open */
    double t_s;            /* presentation time (virtual in headless mode) */
    double interval_s;     /* since the previous frame (0 for the first) */
    int missed;            /* interval > 1.5 refresh periods */
    int rendered;          /* 1 when rasterised (see render_every) */
    double contrast_shown; /* Michelson contrast drawn in this frame (0 for a blank field) */
} csf_frame_info;

/* NOISE: R2 spatial mask + per-frame offset between grey levels k and k+1 (default).
 * NONE: nearest level (for comparisons). BITSTEAL: pseudo-grey — the 8 mixes of k and k+1 across
 * r, g, b are sub-levels placed by the profile's channel curves, and the same noise dither runs
 * between the two sub-levels around the request, so the dither noise is a fraction of a grey
 * step; needs a profile with channel curves (the default profile has them). */
enum { CSF_DITHER_NOISE = 0, CSF_DITHER_NONE = 1, CSF_DITHER_BITSTEAL = 2 };

typedef struct {
    int headless;
    csf_geometry geometry;      /* from csf_geometry_init (CSF_GEOMETRY_FROM_CONFIG(cfg)) */
    double refresh_hz;          /* 0 = 60 */
    const csf_display_profile *profile; /* NULL = csf_profile_default(), reported as such */
    /* Optional forward luminance (cd/m2, R=G=B) overriding the profile, e.g. a simulated display
     * model in tests; must be increasing on [0,1]. */
    double (*grey_lum_fn)(void *ctx, double drive01);
    void *grey_lum_ctx;
    const char *grey_lum_name;  /* reported as the profile id when grey_lum_fn is used */
    int framebuffer_bits;       /* 8 or 10; 0 = 8. Windowed 10-bit falls back to 8 when refused */
    int render_width_px, render_height_px; /* headless only: 0 = geometry size */
    int render_every;           /* 0/1 every frame, N every N-th, -1 never (see PERFORMANCE) */
    int dither;                 /* CSF_DITHER_* */
    const char *monitor;        /* windowed: index ("0", "1") or name substring; NULL = primary */
    int windowed;               /* not headless: an ordinary window of the configured pixel size
                                   on the desktop instead of fullscreen on the monitor (a preview;
                                   the monitor's gamma ramp is guarded the same) */
    uint64_t seed;              /* per-run dither offset and miss-rate draws */
    /* Injected faults for tests of what reads the screen (a simulated person, a self-check): every
     * stimulus is drawn fault_polar_offset_deg of polar angle away from where it was asked for,
     * or (fault_blank) not drawn at all (a flat field), while validation and the contrast the
     * presenter reports stay the plan's. 0 = off. */
    double fault_polar_offset_deg;
    int fault_blank;
} csf_presenter_config;

typedef struct csf_presenter csf_presenter;

/* Fills defaults (headless, 60 Hz, 8 bit, default geometry 531x299 mm, 1920x1080, 570 mm). */
void csf_presenter_config_defaults(csf_presenter_config *cfg);

csf_status csf_presenter_open(const csf_presenter_config *cfg, csf_presenter **out, csf_error *err);
void csf_presenter_close(csf_presenter *p);

/* Refuses a stimulus above the local Nyquist limit (anywhere inside its envelope), off-screen,
 * with bad parameters, or with a luminance outside the display's range; the message states the
 * limit that was broken. */
csf_status csf_presenter_validate(csf_presenter *p, const csf_stimulus *s, csf_error *err);

/* Draws one frame (NULL stimulus = blank field at the display's mid luminance), fixation mark if
 * fixation != 0, presents it (swap, or glFinish offscreen) and timestamps it. */
csf_status csf_presenter_draw(csf_presenter *p, const csf_stimulus *s, int fixation,
                              csf_frame_info *out, csf_error *err);

/* ---- place marks (placeholders / pre-cues) ----
 * Marks the places where a grating may appear, so that an observer has no spatial uncertainty:
 * each mark is a thin dark ring of radius radius_deg around the direction (ecc_deg[i],
 * polar_deg[i]) (geometry.h conventions), computed per fragment as the exact angular distance
 * from that direction, like the stimulus (so the ring is a circle in visual angle, not on the
 * screen). Look: line CSF_MARK_WIDTH_DEG wide, but never thinner than 2 render pixels,
 * antialiased over one pixel; luminance CSF_MARK_LUM_FRACTION x the frame's mean luminance (the
 * stimulus' mean_lum_cdm2, or the display's mid luminance on a blank frame), i.e. 30 % darker,
 * drawn through the same profile inverse and dithering as every stimulus, so it respects the
 * display profile. Inside the ring nothing changes: the place's centre and the field between
 * rings stay at the mean. The fixation mark is drawn over a ring.
 *
 * While set, the marks are drawn on every frame of csf_presenter_draw and
 * csf_presenter_run_trial (blank and stimulus frames alike), never on text screens or measurement
 * patches. Setting them costs no GL work (bookkeeping-only presenters, render_every = -1, accept
 * them and just keep the state); they take effect from the next frame drawn. A ring that reaches
 * past the screen edge is clipped there.
 *
 * n = 0 clears (ecc_deg, polar_deg and radius_deg are then ignored). Refused, with the limit in
 * the message, and leaving the current marks as they were: n < 0 or n > CSF_PRESENTER_MAX_MARKS,
 * NULL lists, a radius that is not in (0, CSF_MARK_MAX_RADIUS_DEG], a non-finite eccentricity or
 * polar angle, an eccentricity outside [0, 90) deg, a centre that is off-screen. Psychophysical
 * use: show them before the stimulus and clear them before it begins, so that they cannot mask
 * it (calib/observer_calib.c), with a radius outside the visible patch (3 sigma of a Gabor). */
#define CSF_PRESENTER_MAX_MARKS 8
#define CSF_MARK_WIDTH_DEG 0.12     /* line width (deg), at least 2 render pixels */
#define CSF_MARK_LUM_FRACTION 0.7   /* ring luminance / the frame's mean luminance */
#define CSF_MARK_MAX_RADIUS_DEG 30.0
csf_status csf_presenter_set_marks(csf_presenter *p, int n, const double *ecc_deg,
                                   const double *polar_deg, double radius_deg, csf_error *err);
/* Number of marks now set (0 when cleared). */
int csf_presenter_mark_count(const csf_presenter *p);

/* Baseline for benchmarks: a frame that only clears to the mean grey (no stimulus shader). */
csf_status csf_presenter_draw_clear(csf_presenter *p, csf_frame_info *out, csf_error *err);

/* ---- measurement patches (display calibration) ---- */
/* A uniform patch given by DRIVE values, not luminance: the photometric calibration measures what
 * a drive value produces, so the profile's luminance -> drive mapping is bypassed. Each channel's
 * fractional drive v (0..1) is shown as framebuffer levels k = floor(v * maxlevel) and k + 1,
 * k + 1 with probability frac(v * maxlevel), chosen by the stimulus pipeline's dither (the same R2
 * spatial mask and golden-ratio per-frame offset; CSF_DITHER_NONE rounds, BITSTEAL dithers like
 * NOISE since each channel is given on its own). A drive of 0.50037 on 8 bits (127.594 levels) is
 * therefore 59.4 % level 128 and 40.6 % level 127 over the patch and over frames, and its mean
 * light is the display's light at those levels, mixed in that proportion.
 * The patch is a square centred on the screen: side size_deg visual degrees (2 D tan(size/2) mm,
 * D the viewing distance) when size_deg > 0, else screen_fraction of the screen height when > 0,
 * else the full field. The surround shows bg_drive01 (dithered the same way). Choose the size to
 * cover the photometer's aperture with a margin (a 1 cm aperture at 570 mm is ~1 deg). */
typedef struct {
    double drive01[3];      /* patch drive per channel, [0,1], fractional */
    double bg_drive01[3];   /* surround drive per channel, [0,1] */
    double size_deg;        /* side of the square patch in degrees (> 0 wins) */
    double screen_fraction; /* else side as a fraction of the screen height; both 0: full field */
} csf_patch;

/* Draws and presents one frame of the patch. Always rasterises (render_every does not apply: a
 * measurement reads the frame), advances the frame clock like csf_presenter_draw, and refuses
 * drives outside [0,1] or a patch larger than the screen. Call once per refresh while the
 * instrument integrates so the temporal dither averages out. */
csf_status csf_presenter_draw_patch(csf_presenter *p, const csf_patch *patch, csf_frame_info *out,
                                    csf_error *err);
/* The placement screen before a real meter's first reading: the patch (as csf_presenter_draw_patch)
 * with a target mark at its centre and text lines ('\n'-separated, at most 8, top left), both in
 * the caption's dark ink; give the surround a mid-grey drive so the text can be read. Presented
 * as one frame. */
csf_status csf_presenter_draw_placement(csf_presenter *p, const csf_patch *patch, const char *text,
                                        csf_frame_info *out, csf_error *err);
/* Sets the number of the next frame (what the temporal dither's per-frame offset and injected
 * misses key on). A measurement that starts each reading at a frame number of its own (reading k
 * at k x frames per reading) draws the same dithered frames whenever it is repeated: a resumed
 * display calibration shows exactly what the uninterrupted one showed. */
void csf_presenter_set_frame_index(csf_presenter *p, long frame_index);
/* The patch's pixels in the readback's coordinates (top row first): x, y, w, h render pixels. */
csf_status csf_presenter_patch_rect(const csf_presenter *p, const csf_patch *patch, int *x, int *y,
                                    int *w, int *h, csf_error *err);

/* ---- temporal envelopes and trials ---- */
enum { CSF_ENV_FIXED = 0, CSF_ENV_RAISED_COSINE = 1, CSF_ENV_FADE_LOG = 2 };
typedef struct {
    int kind;
    double duration_s;     /* total presentation time */
    double ramp_s;         /* RAISED_COSINE: on and off ramp duration each */
    double start_contrast; /* FADE_LOG: contrast at t = 0; rises linearly in log10 contrast to the
                              stimulus contrast at duration_s */
} csf_envelope;

/* Contrast planned at time t_s after onset (0 outside [0, duration]). */
double csf_envelope_contrast(const csf_envelope *e, double peak_contrast, double t_s);

/* Called after every frame of a trial; return non-zero to end the trial (a response). */
typedef int (*csf_trial_stop_fn)(void *ctx, const csf_frame_info *frame);

typedef struct {
    int frames_planned;        /* duration * refresh */
    int frames_shown;          /* refresh periods the stimulus was on screen (missed = repeats) */
    int frames_drawn;          /* frames actually produced */
    int frames_missed;
    double contrast_shown_mean, contrast_shown_max, contrast_shown_last;
    double max_abs_deviation;  /* max |shown - planned| contrast per refresh period */
    double t_onset_s, t_end_s;
    int stopped_by_callback;
    double *contrast_per_period; /* malloc'd, frames_shown entries */
    double *interval_s;          /* malloc'd, frames_drawn entries */
    int deviated;              /* presentation differed from the plan (missed frames during the
                                  stimulus, or |shown - planned| > 1 % relative) */
    char flags[64];            /* e.g. "missed_frames,contrast_dev" ("" when fine) */
} csf_trial_record;

/* Runs one trial: frames from onset until the envelope's duration or until stop returns
 * non-zero. Contrast per frame = envelope at the frame's (virtual or real) time. */
csf_status csf_presenter_run_trial(csf_presenter *p, const csf_stimulus *s, const csf_envelope *env,
                                   int fixation, csf_trial_stop_fn stop, void *stop_ctx,
                                   csf_trial_record *out, csf_error *err);
void csf_trial_record_free(csf_trial_record *r);

/* Headless only: the frame with index frame_index is presented `periods` refresh periods late. */
csf_status csf_presenter_inject_missed(csf_presenter *p, long frame_index, int periods,
                                       csf_error *err);
/* Headless only: each frame is late by one period with this probability (counter RNG on seed). */
void csf_presenter_set_miss_rate(csf_presenter *p, double probability);

/* ---- readback and properties ---- */
void csf_presenter_render_size(const csf_presenter *p, int *w, int *h);
int csf_presenter_bits(const csf_presenter *p);
/* Last frame, top row first: w*h*3 bytes (8-bit values; 10-bit framebuffers are scaled). */
csf_status csf_presenter_readback_rgb8(csf_presenter *p, unsigned char *rgb, csf_error *err);
/* Last frame as framebuffer levels 0..2^bits-1, w*h*3 uint16, top row first. */
csf_status csf_presenter_readback_levels(csf_presenter *p, uint16_t *rgb, csf_error *err);
/* The last frame drawn by csf_presenter_draw or csf_presenter_run_trial (a stimulus or blank
 * frame, with its fixation mark, place marks and dither), rasterised again at the CONFIGURED
 * resolution (geometry width_px x height_px, not the reduced headless render size) but only the
 * w x h pixels whose top-left pixel is (x, y) (top row first, as the readback), and read back as
 * framebuffer levels (w*h*3 uint16, top row first). The same shader, uniforms and dither frame
 * number as the frame: the pixels are those a full-resolution frame has there. Works whatever
 * render_every says (the region is always rasterised), so a simulated person can look at the few
 * places it needs at full resolution while the session's own frames stay small or are skipped.
 * Refused: a region not inside the screen or over CSF_REGION_MAX_PX a side, or a last frame
 * that was a text screen or a measurement patch. */
#define CSF_REGION_MAX_PX 4096
csf_status csf_presenter_readback_region(csf_presenter *p, int x, int y, int w, int h, uint16_t *rgb,
                                         csf_error *err);
/* Called after every frame of csf_presenter_draw and csf_presenter_run_trial (stimulus and blank
 * frames alike, after it is presented, before run_trial's stop callback), e.g. to read back a
 * region of it. NULL removes the hook. The hook must not draw. */
typedef void (*csf_frame_hook)(void *ctx, csf_presenter *p, const csf_frame_info *frame);
void csf_presenter_set_frame_hook(csf_presenter *p, csf_frame_hook fn, void *ctx);
/* Luminance the presenter believes level k (R=G=B) produces. */
double csf_presenter_level_lum(const csf_presenter *p, int level);
void csf_presenter_lum_range(const csf_presenter *p, double *black_cdm2, double *max_cdm2);
const char *csf_presenter_profile_id(const csf_presenter *p); /* "default-..." when no profile */
const csf_geometry *csf_presenter_geometry(const csf_presenter *p);
double csf_presenter_refresh_hz(const csf_presenter *p);
double csf_presenter_time(const csf_presenter *p); /* now, on the presenter's clock */

/* Windowed only: GLFWwindow* for responders (NULL headless); cursor shown while a response
 * needs it. */
void *csf_presenter_window(csf_presenter *p);
void csf_presenter_show_cursor(csf_presenter *p, int show);

/* Text screen (instructions, breaks, progress) drawn with cairo, centred, on the mean-grey field;
 * presented as one frame. Lines separated by '\n'. */
csf_status csf_presenter_text_screen(csf_presenter *p, const char *text, csf_error *err);

/* A one-line caption (cairo, dark, top-left corner) drawn over every later stimulus and blank
 * frame of csf_presenter_draw / run_trial until cleared (NULL or ""), through the same luminance
 * mapping and dither; only the text's own pixels change. Never on text screens or patches, and
 * not in csf_presenter_readback_region (which shows the stimulus without it). Refused: longer
 * than CSF_CAPTION_MAX_CHARS or holding a newline. */
#define CSF_CAPTION_MAX_CHARS 400
csf_status csf_presenter_set_caption(csf_presenter *p, const char *text, csf_error *err);

/* When the next frame will be on screen, on the presenter's clock: what run_trial draws a
 * frame's drift phase for (exact on the headless virtual clock, injected misses included; one
 * refresh after the last frame in a window). 0 before the first frame. */
double csf_presenter_next_frame_time(csf_presenter *p);
/* Number the next frame will have (what csf_presenter_inject_missed keys on). */
long csf_presenter_frame_index(const csf_presenter *p);

#endif
