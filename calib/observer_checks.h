/* The observer session's checks before its first trial: output paths, the settings, the grid on
 * this screen, the display profile across --resume; and the default axes for a display. Internal
 * to the observer procedure. */
#ifndef CSF_OBSERVER_CHECKS_H
#define CSF_OBSERVER_CHECKS_H

#include <stddef.h>
#include <stdint.h>

#include "calib/observer_settings.h"
#include "core/station.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "stimuli/geometry.h"
#include "stimuli/presenter.h"

void obs_default_axes(const csf_geometry *g, csf_obs_settings *s, int quiet);
int obs_cmp_d(const void *a, const void *b);
/* Output paths, before anything is measured: a session that cannot write its table at the end
 * would have cost the person the whole session. Usage errors (exit status 2). */
csf_status obs_check_outputs(const csf_obs_options *opt, csf_error *err);
csf_status obs_check_settings(csf_obs_settings *set, int sort, csf_error *err);
/* Every cell of the grid, and the practice grating, can be drawn on this screen: checked before
 * the first trial, so a session never stops at a cell it cannot show. The messages name the
 * limit: how far the screen reaches, or the local Nyquist limit. */
csf_status obs_check_grid_on_screen(csf_presenter *pres, const csf_config *cfg, const csf_obs_settings *set,
                                    int practice_left, double mean_lum, csf_error *err);
/* On --resume: the profile this run has must be the one the session used last, unless the user
 * said --allow-profile-change; then the change is added to the history. */
csf_status obs_check_profile_on_resume(csf_store *store, int64_t sid, const char *began, int n_stored,
                                       const csf_display_profile *now, const csf_config *cfg, int allow,
                                       int quiet, csf_error *err);
/* The table's display_profile_id: the one profile, or every profile with the trial it began at. */
void obs_table_profile_id(csf_store *store, int64_t sid, const char *id, char *out, size_t len);

#endif
