/* PNG image stimuli: decoded to relative luminance (0..1) per pixel, because the presenter's
 * pipeline is luminance (cd/m2) based.
 *
 * Colour handling: the PNG's own colour description decides the decoding — sRGB chunk or no
 * colour chunk: sRGB transfer function; gAMA chunk: that power law; cHRM: its primaries for the
 * luminance weights (Y row of the RGB->XYZ matrix), else Rec.709/sRGB weights. ICC profiles
 * (iCCP) are NOT interpreted (the image is decoded as sRGB and csf_image_colour_note says so);
 * OpenColorIO is not used for PNG stills. 16-bit, palette, grey and alpha images are accepted;
 * alpha is composited over the mean grey (alpha kept as coverage). */
#ifndef CSF_STIMULI_IMAGE_H
#define CSF_STIMULI_IMAGE_H

#include <stddef.h>

#include "results/csf_status.h"

typedef struct csf_image {
    int width, height;
    float *lum;    /* width*height relative luminance 0..1, top row first */
    float *alpha;  /* width*height coverage 0..1 */
    double mean_lum;
    char colour_note[96]; /* how the colour was interpreted */
} csf_image;

/* Limits: width and height 1..8192, total pixels <= 16 M. */
csf_status csf_image_load_png(const char *path, csf_image **out, csf_error *err);
csf_status csf_image_load_png_memory(const void *buf, size_t len, csf_image **out, csf_error *err);
void csf_image_free(csf_image *img);

#endif
