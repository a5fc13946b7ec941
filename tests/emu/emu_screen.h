/* Emulator side of the screen mirror (devices/screen_mirror.h): an out-of-process instrument
 * emulator reads the file csfcal rewrites before each reading and turns the patch into the light
 * a simulated display (model/display_model.h) emits, seen through a simple instrument model
 * (gain error, relative and absolute noise drawn from core/rng.h by reading number).
 * Used by the serial emulators (emu_minolta, emu_pr), the spotread stand-in, and any other
 * emulator that measures light. */
#ifndef CSF_EMU_SCREEN_H
#define CSF_EMU_SCREEN_H

#include <stddef.h>
#include <stdint.h>

#include "model/display_model.h"

typedef struct {
    uint64_t seq;      /* csfcal's reading number */
    double drive[3];   /* drive values 0..1 */
    size_t n_px;
} emu_screen_patch;

/* Parses mirror text. 0 on success; -1 with a reason in why. */
int emu_screen_parse(const char *text, size_t len, emu_screen_patch *out, char *why, size_t why_len);
/* Reads the mirror file at path (NULL: $CSFCAL_SCREEN_MIRROR). 0, or -1 with a reason. */
int emu_screen_read(const char *path, emu_screen_patch *out, char *why, size_t why_len);

typedef struct {
    csf_display_model *display;
    double gain;       /* instrument calibration error as a factor (1: exact) */
    double noise_rel;  /* relative sd per reading */
    double noise_abs;  /* absolute sd, cd/m2 */
    uint64_t seed;
    uint64_t n;        /* readings taken (the noise index) */
} emu_light;

/* Opens the display model from spec ("lcd", "crt,gamma=2.4", ...). 0, or -1 with a reason. */
int emu_light_open(emu_light *l, const char *display_spec, char *why, size_t why_len);
void emu_light_close(emu_light *l);
/* XYZ (cd/m2) the instrument sees now: reads the mirror, runs the display model, applies gain
 * and noise. 0, or -1 with a reason (no mirror, unreadable mirror). */
int emu_light_measure(emu_light *l, double xyz[3], char *why, size_t why_len);

#endif
