/* How different two renders are, for the viewer the simplifier assumed.
 *
 * Both images are turned into luminance through the display model (shade.h). Plain measures:
 * RMS and largest luminance difference over the mean luminance of the first image. The
 * CSF-weighted measure is band-limited contrast (Peli 1990): a difference-of-Gaussians pyramid
 * (sigma 0.5, 1, 2, ... px, each band divided by the next coarser low-pass, i.e. local contrast
 * per octave band, normalised so a sine at the band's centre frequency reads its own Michelson
 * contrast). The difference of the two images' band contrasts at each pixel, divided by the
 * observer's threshold at the band's centre frequency and the pixel's eccentricity from the gaze
 * (csflut_threshold), is a visibility in threshold units; peak_visibility is its largest value
 * over pixels and bands (>= 1: a single-band detector would see a difference there), pooled
 * the Minkowski sum (beta 4) over all of them. */
#ifndef LOD_IMGDIFF_H
#define LOD_IMGDIFF_H

#include <csflut.h>
#include <stdint.h>

#include "shade.h"

typedef struct {
    double rms_contrast;     /* RMS(L_a - L_b) / mean(L_a) */
    double max_contrast;     /* max |L_a - L_b| / mean(L_a) */
    double peak_visibility;  /* max band-contrast difference / threshold */
    double pooled_visibility;/* Minkowski beta = 4 over pixels and bands */
    double peak_freq_cpd, peak_ecc_deg; /* where the peak is */
    int changed_pixels;      /* pixels whose 8-bit values differ */
} lod_diff;

/* a, b: width*height*3 bytes (R = G = B). ppd: pixels per degree at the centre; gaze in pixels.
 * 0, or -1 when out of memory. */
int lod_image_diff(const uint8_t *a, const uint8_t *b, int width, int height, const lod_shade *s,
                   double ppd, const double gaze_px[2], const csflut_table *t, lod_diff *out);

/* The same for a frame of a moving sequence: each pixel's threshold is the table's at its retinal
 * velocity (csflut_threshold4 at the table's default luminance), the lower of those at the
 * pixel's velocity range [vel_lo, vel_hi] (width*height each, deg/s), since a band's difference
 * near an edge may belong to either side. A table without a velocity axis ignores it. */
int lod_image_diff_moving(const uint8_t *a, const uint8_t *b, int width, int height, const lod_shade *s,
                          double ppd, const double gaze_px[2], const csflut_table *t, const float *vel_lo,
                          const float *vel_hi, lod_diff *out);

#endif
