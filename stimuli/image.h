/* PNG image stimuli: decoded to relative luminance (0..1) per pixel, because the presenter's
 * pipeline is luminance (cd/m2) based.
 *
 * Colour handling (libpng's simplified reader, then exact sRGB decoding): sRGB chunk or no colour
 * chunk: the piecewise sRGB transfer function; gAMA chunk: libpng re-encodes to sRGB first;
 * colour is reduced to luminance in linear light with libpng's weights (cHRM-derived when the
 * file has one, else Rec.709). Precision is 8 bits per pixel (16-bit files are reduced). ICC
 * profiles (iCCP) are NOT interpreted and OpenColorIO is not used for PNG stills (colour_note
 * says so). Palette, grey and alpha images are accepted; alpha is kept as coverage and the
 * presenter composites over the mean grey. */
#ifndef CSF_STIMULI_IMAGE_H
#define CSF_STIMULI_IMAGE_H

#include <stddef.h>

#include "core/csf_status.h"

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
