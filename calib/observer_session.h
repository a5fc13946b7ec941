/* One observer session in the steps its command takes, the way display calibration is given its
 * store and photometer: the session's settings first (from the options, or from the store on
 * --resume), then the resources the command opens for those settings (observer_resources.h), the
 * checks of this screen, and only then the store for a new session, so that a refused session
 * writes nothing; then the trials and the table.
 *
 *   csf_obs_session_begin   options and settings checked; the method and who answers chosen
 *   csf_obs_session_check   the lent resources taken; the grid checked on this screen
 *   csf_obs_session_run     the session row, the trials, the table (or _demo: nothing stored)
 *   csf_obs_session_free    what the session made; the lent resources stay open
 *
 * csf_observer_calibrate (observer_calib.h) takes these steps with resources it opens itself. */
#ifndef CSF_OBSERVER_SESSION_H
#define CSF_OBSERVER_SESSION_H

#include <stdint.h>

#include "calib/observer_calib.h"
#include "calib/observer_screen.h"
#include "calib/observer_settings.h"
#include "devices/responder.h"
#include "model/observer_sim.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "stimuli/geometry.h"
#include "stimuli/presenter.h"

typedef struct csf_obs_session csf_obs_session;

/* What a session is lent. The session closes none of them. */
typedef struct {
    csf_store *store;             /* results store (a new session: may come at csf_obs_session_run) */
    csf_display_profile *profile; /* the display's luminance, which the presenter maps through */
    csf_presenter *pres;          /* the screen the trials are drawn on */
    csf_observer_sim *sim;        /* the simulated person (NULL with a human) */
    csf_obs_screen *eyes;         /* view=frame: the simulated person's eyes on pres (or NULL) */
    csf_responder *resp;          /* a human's buttons (NULL with a simulated person) */
} csf_obs_resources;

/* Checks the options and the output paths, and settles the settings: a new session's from the
 * options and the display's geometry, a resumed one's from store (which must then be open; a
 * session that cannot be resumed is refused, and one whose stored settings are unreadable is
 * marked aborted). res is cleared here and filled as the session goes. */
csf_status csf_obs_session_begin(const csf_obs_options *opt, csf_store *store, csf_obs_result *res,
                                 csf_obs_session **out, csf_error *err);
/* The settings the resources are opened for, the session's seed, and whether a simulated person
 * answers (else a human). */
const csf_obs_settings *csf_obs_session_settings(const csf_obs_session *s, uint64_t *seed, int *is_sim);
const csf_geometry *csf_obs_session_geometry(const csf_obs_session *s);
/* Takes the resources and checks that this screen can show the session's grid and practice
 * grating, that a resumed session has its display profile (or --allow-profile-change), and that
 * drifting cells are shown on enough of the grid. Nothing is stored by a refusal. */
csf_status csf_obs_session_check(csf_obs_session *s, const csf_obs_resources *r, csf_error *err);
/* Runs the checked session (store: the results store, when it was not lent before). */
csf_status csf_obs_session_run(csf_obs_session *s, csf_store *store, csf_error *err);
/* --demo: the practice trials with feedback; nothing is stored. */
csf_status csf_obs_session_demo(csf_obs_session *s, csf_error *err);
void csf_obs_session_free(csf_obs_session *s);

#endif
