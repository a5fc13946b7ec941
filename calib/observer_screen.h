/* The simulated person's eyes on the presenter (`--observer sim:view=frame`).
 *
 * While the person looks at one or more places, every frame_step-th frame the presenter draws
 * (csf_presenter_set_frame_hook) is rasterised again at the screen's full resolution in a small
 * region around each place (csf_presenter_readback_region: the frame's own pixels there, dither
 * included, whatever --render-every says), its pixels are turned into light through the
 * simulated display, and the Gabor's contrast is measured there by a matched filter
 * (model/observer_view.h). The person sees motion: each looked-at frame keeps its own response,
 * its presentation time and how long it stayed on screen (the time to the next frame the
 * presenter shows, so a held or missed frame counts for its whole duration), and what is seen
 * is the spatio-temporal matched filter's equivalent contrast at the reference velocity the
 * session asks about (csf_view_place_motion_contrast), weighed by the person's own sensitivity
 * to motion (csf_obs_screen_set_person). The region is a disc of CSF_OBS_SCREEN_RADIUS_SIGMAS Gabor sigmas
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
#include "model/observer_sim.h"
#include "model/observer_view.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"

#define CSF_OBS_SCREEN_RADIUS_SIGMAS 2.0 /* envelope^2 below 2 % beyond: the fit stays exact */
#define CSF_OBS_SCREEN_FIX_MASK_DEG 0.25 /* the fixation mark is 0.12 deg in radius */
#define CSF_OBS_SCREEN_MAX_PLACES 4
/* The fade task's window: the person judges the frames shown in the last 100 ms, about the
 * integration time of sustained vision at photopic levels (Barlow 1958; Watson 1986). */
#define CSF_OBS_SCREEN_WINDOW_S 0.1

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

/* Whose sensitivity to motion weighs the temporal components: the person's
 * (csf_observer_sim_velocity_log10_gain, which o must outlive the screen for); NULL = the
 * Kelly-Daly model with its published constants (the default until set). */
void csf_obs_screen_set_person(csf_obs_screen *s, const csf_observer_sim *o);
/* The same with any gain function (log10 sensitivity at a velocity over static). */
void csf_obs_screen_set_gain(csf_obs_screen *s, csf_view_gain_fn gain, void *ctx);

/* Looks at n places (eccentricity ecc_deg, polar angles polar_deg[n]) for a Gabor of freq_cpd
 * from the next frame on, to be judged as the equivalent contrast of a grating drifting at
 * ref_velocity_dps (the velocity the person is asked about; 0 = static; what is measured does not
 * assume the speed shown). max_frames > 0: an interval the person knows the length of; the
 * frames 0, frame_step, 2 frame_step ... below max_frames are analysed together. max_frames = 0:
 * the person watches frame by frame until csf_obs_screen_stop (the fade task); after each
 * looked-at frame, the frames of the last CSF_OBS_SCREEN_WINDOW_S are analysed
 * (csf_obs_screen_latest). A drift is seen up to the Nyquist frequency of the looking rate,
 * refresh / (2 frame_step): moving cells want frame_step=1. Refused: n outside 1..4, a place
 * off-screen, a reference velocity that is not finite. */
csf_status csf_obs_screen_look_v(csf_obs_screen *s, double freq_cpd, double ecc_deg, double ref_velocity_dps,
                                 const double *polar_deg, int n, int max_frames, csf_error *err);
/* csf_obs_screen_look_v at reference velocity 0 (a static grating). */
csf_status csf_obs_screen_look(csf_obs_screen *s, double freq_cpd, double ecc_deg,
                               const double *polar_deg, int n, int max_frames, csf_error *err);
/* Stops looking: contrast[k] = the contrast seen at place k over the frames looked at (for a
 * static grating at reference 0: the fit of their mean light). Reports an error the frame hook
 * met (a failed readback, no memory). */
csf_status csf_obs_screen_stop(csf_obs_screen *s, double *contrast, csf_error *err);
/* The same with what decided at each place (info[k]; NULL: not wanted). */
csf_status csf_obs_screen_stop_info(csf_obs_screen *s, double *contrast, csf_view_motion_info *info,
                                    csf_error *err);
/* The contrast seen at the first place over the window ending with the latest frame looked at
 * (0 before any): the fade task, where the person watches the contrast change. */
double csf_obs_screen_latest(const csf_obs_screen *s);
/* Frames looked at since csf_obs_screen_look. */
int csf_obs_screen_frames(const csf_obs_screen *s);

#endif
