/* The SIMULATED display's truth (contract [C]): what light a monitor really emits for drive
 * values. Used by the simulated photometer and by the stimulus self-check to turn framebuffer
 * pixels into luminance. It is a model, not a table of answers the calibration could copy.
 *
 * Spec: KIND[,key=value...] with KIND one of
 *   crt       gain-offset-gamma per channel (docs/display-profile.md): L = black + Lmax*max(0, a v + b)^gamma
 *   lcd       S-shaped low end (the panel's dark toe), a few % channel interaction, black level
 *   oled      near-zero black, gamma ~2.2 with a hard clip near black, mild white-level droop
 *             when all channels are high (power limiting)
 *   file=PATH.csv   true curve as CSV `level,r_cdm2,g_cdm2,b_cdm2` for levels 0..255 (each
 *             row's luminance excludes black), linear interpolation, additive plus black
 * Keys (all optional): lmax=cd/m2 (white peak, 1..10000), black=cd/m2 (0..50), gamma=(1..4),
 * interaction=fraction (lcd, 0..0.2). Channels carry Rec.709-like weights unless from a file. */
#ifndef CSF_DISPLAY_MODEL_H
#define CSF_DISPLAY_MODEL_H

#include "core/csf_status.h"

typedef struct csf_display_model csf_display_model;

csf_status csf_display_model_create(const char *spec, csf_display_model **out, csf_error *err);
/* Parses the CSV truth from memory (the file= path uses this); name appears in errors. */
csf_status csf_display_model_from_csv(const char *text, size_t len, const char *name,
                                      csf_display_model **out, csf_error *err);
void csf_display_model_free(csf_display_model *m);

/* Luminance in cd/m2 (black included) for drive values in [0,1] (clamped). */
double csf_display_model_lum(const csf_display_model *m, double r01, double g01, double b01);
/* CIE XYZ (Y = luminance) for drive values in [0,1]. */
void csf_display_model_xyz(const csf_display_model *m, double r01, double g01, double b01,
                           double xyz[3]);
/* The display-model spec of a simulated photometer's spec ("sim[:display=...,lmax=...,...]", as a
 * display profile's "display" line records it): display=/file= and the model keys; the
 * instrument's own keys (noise, drift, ...) are left out. Returns -1 when phot is not a
 * simulated photometer's spec (a real monitor's name, "default"), else 0. */
int csf_display_model_spec_from_sim_photometer(const char *phot, char *out, size_t len);
/* Short name of the kind ("crt", "lcd", "oled", "csv"). */
const char *csf_display_model_kind(const csf_display_model *m);

#endif
