/* Screen mirror: how an out-of-process instrument emulator learns what csfcal shows.
 *
 * A real instrument measures the light of the screen; an emulator (tests/emu/) has no light to
 * measure, so csfcal tells it what is on screen through a small file. When the environment
 * variable CSFCAL_SCREEN_MIRROR names a file, every real (non-simulated) photometer opened by
 * csf_photometer_open rewrites that file atomically (temporary file in the same folder, fsync,
 * rename: a reader never sees half of it) just before each reading is asked for, with the patch
 * under the sensor. The emulator reads it when the measure command arrives and runs the drive
 * values through its simulated display (model/display_model.h). Without the variable nothing
 * is written; the simulated photometer never writes it (it is told the patch directly).
 *
 * File format (text, version 1, lines in this order, '\n' endings):
 *   csfcal-screen-mirror 1
 *   seq N                     readings asked for since the photometer was opened (0-based)
 *   drive R G B               drive values 0..1 of the uniform patch under the sensor (for a
 *                             rendered source: the mean framebuffer level of its pixels, per
 *                             channel, over the framebuffer's full scale)
 *   pixels N                  how many pixels that mean is over (1 for a uniform patch)
 * Readers must ignore lines they do not know (later versions may add some). The reader the
 * emulators use is tests/emu/emu_screen.h. */
#ifndef CSF_SCREEN_MIRROR_H
#define CSF_SCREEN_MIRROR_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

#define CSF_SCREEN_MIRROR_ENV "CSFCAL_SCREEN_MIRROR"

typedef struct csf_screen_mirror csf_screen_mirror;

/* *out = NULL when CSFCAL_SCREEN_MIRROR is unset or empty (nothing to do). Otherwise checks that
 * the file can be written (CSF_E_IO naming the path and the OS error) and returns a mirror. */
csf_status csf_screen_mirror_from_env(csf_screen_mirror **out, csf_error *err);
/* Writes the patch (drive values 0..1, clamped) for reading number seq, averaged over n_px pixels. */
csf_status csf_screen_mirror_write(csf_screen_mirror *m, uint64_t seq, const double rgb01[3], size_t n_px,
                                   csf_error *err);
const char *csf_screen_mirror_path(const csf_screen_mirror *m);
void csf_screen_mirror_free(csf_screen_mirror *m);

#endif
