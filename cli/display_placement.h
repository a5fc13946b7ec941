/* The placement screen a real photometer gets before its first reading (display calibrate and
 * verify, when they draw the patches): the patch with a target mark and instructions, the live
 * reading on screen and on the terminal, Space to go on once the reading is stable, Escape to
 * leave before anything is measured or stored. */
#ifndef CSF_DISPLAY_PLACEMENT_H
#define CSF_DISPLAY_PLACEMENT_H

#include "devices/photometer.h"
#include "stimuli/presenter.h"

/* Readings that count for "stable": the last CSF_PLACEMENT_N within CSF_PLACEMENT_SPREAD of their
 * mean (max - min over mean). */
#define CSF_PLACEMENT_N 4
#define CSF_PLACEMENT_SPREAD 0.01

/* Returns 0 when the user pressed Space on a stable reading, 1 when they pressed Escape (or closed
 * the window), 2 after an instrument or drawing error (printed, naming `what`). patch is the
 * session's patch (its size); the placement shows it at full drive on a mid-grey surround. */
int csf_display_placement(csf_presenter *pres, const csf_patch *patch, csf_photometer *ph, const char *what);

/* The stability rule on the last n readings (pure, for tests): 1 when there are at least
 * CSF_PLACEMENT_N and the last CSF_PLACEMENT_N spread by at most CSF_PLACEMENT_SPREAD of their
 * mean; *spread_rel gets that spread (NAN when too few). */
int csf_placement_stable(const double *lum_cdm2, int n, double *spread_rel);

#endif
