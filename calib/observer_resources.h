/* Opens what an observer session is lent (observer_session.h) for its settings: the display
 * profile, the presenter (headless for a simulated person, a window for a human), the simulated
 * person and its eyes on the frames, or a human's responder. The command opens them and the
 * session runs on them, as display calibration runs on the store and photometer its command
 * opened. */
#ifndef CSF_OBSERVER_RESOURCES_H
#define CSF_OBSERVER_RESOURCES_H

#include "calib/observer_session.h"

/* Opens r's profile, presenter, person side for session s (r->store is left as it is). On an
 * error what was opened stays in r for csf_obs_resources_close. */
csf_status csf_obs_resources_open(const csf_obs_options *opt, const csf_obs_session *s, csf_obs_resources *r,
                                  csf_error *err);
/* Closes everything in r, the store included, and clears it. */
void csf_obs_resources_close(csf_obs_resources *r);

#endif
