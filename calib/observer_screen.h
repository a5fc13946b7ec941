/* The simulated person's eyes on the presenter (`--observer sim:view=frame`).
 *
 * While the person looks at one or more places, every frame_step-th frame the presenter draws
 * (csf_presenter_set_frame_hook) is rasterised again at the screen's full resolution in a small
 * region around each place (csf_presenter_readback_region: the frame's own pixels there, dither
 * included, whatever --render-every says), its pixels are turned into light through the
 * simulated display, and the Gabor's contrast is measured there by a matched filter
 * (model/observer_view.h). The region is a disc of CSF_OBS_SCREEN_RADIUS_SIGMAS Gabor sigmas
 * around the place, less the fixation mark (a person does not take the mark they fixate for the
 * grating). Nothing here sees the plan: not where the grating was drawn, nor its contrast.
 *
 * The display is chosen by name: "crt", "lcd", "oled" (with display_gamma > 0 replacing the
 * model's gamma), "file=PATH.csv" (model/display_model.h), "profile" (the profile in use is
 * the truth: a perfect profile), or "" = the display the profile was measured on: a profile made
 * with the simulated photometer names it in its display line ("sim:display=crt,..."); any other
 * profile (a real monitor, the documented default) describes its display, so it is the truth. */
#ifndef CSF_OBSERVER_SCREEN_H
#define CSF_OBSERVER_SCREEN_H

#include "core/csf_status.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"

#define CSF_OBS_SCREEN_RADIUS_SIGMAS 2.0 /* envelope^2 below 2 % beyond: the fit stays exact */
#define CSF_OBS_SCREEN_FIX_MASK_DEG 0.25 /* the fixation mark is 0.12 deg in radius */
#define CSF_OBS_SCREEN_MAX_PLACES 4

typedef struct csf_obs_screen csf_obs_screen;

/* Installs the frame hook on pres (which must outlive the screen). sigma_deg and orientation_deg
 * are the session's Gabor's (the person knows what to look for, not where it is drawn);
 * frame_step 1..30. */
csf_status csf_obs_screen_open(csf_presenter *pres, const csf_display_profile *profile,
                               const char *display, double display_gamma, double sigma_deg,
                               double orientation_deg, int frame_step, csf_obs_screen **out,
                               csf_error *err);
/* Removes the hook and frees. */
void csf_obs_screen_close(csf_obs_screen *s);
/* The display in words, e.g. "lcd (the profile's display)", for messages and metadata. */
const char *csf_obs_screen_display(const csf_obs_screen *s);

/* Looks at n places (eccentricity ecc_deg, polar angles polar_deg[n]) for a Gabor of freq_cpd
 * from the next frame on. max_frames > 0: an interval the person knows the length of; the frames
 * 0, frame_step, 2 frame_step ... below max_frames are integrated. max_frames = 0: the person
 * watches frame by frame until csf_obs_screen_stop (the fade task); each looked-at frame is
 * measured on its own (csf_obs_screen_latest). Refused: n outside 1..4, a place off-screen. */
csf_status csf_obs_screen_look(csf_obs_screen *s, double freq_cpd, double ecc_deg,
                               const double *polar_deg, int n, int max_frames, csf_error *err);
/* Stops looking: contrast[k] = the contrast seen at place k over the frames looked at (the fit of
 * their mean light). Reports an error the frame hook met (a failed readback). */
csf_status csf_obs_screen_stop(csf_obs_screen *s, double *contrast, csf_error *err);
/* The contrast seen at the first place in the latest frame looked at (0 before any): the fade
 * task, where the person watches the contrast change frame by frame. */
double csf_obs_screen_latest(const csf_obs_screen *s);
/* Frames looked at since csf_obs_screen_look. */
int csf_obs_screen_frames(const csf_obs_screen *s);

#endif
