/* PNG stimuli through libpng's simplified API: it decodes to linear luminance (Y) with alpha,
 * honouring the file's sRGB/gAMA chunks and cHRM-derived luminance weights, so the presenter can
 * treat the pixel values as relative luminance (8-bit precision per pixel). Limits are checked before anything is allocated. */
#include "stimuli/image.h"

#include <math.h>
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SIDE 8192
#define MAX_PIXELS (16u * 1024u * 1024u)
#define MAX_FILE_BYTES (256u * 1024u * 1024u)

void csf_image_free(csf_image *img)
{
    if (!img) return;
    free(img->lum);
    free(img->alpha);
    free(img);
}

csf_status csf_image_load_png_memory(const void *buf, size_t len, csf_image **out, csf_error *err)
{
    if (!out) return csf_error_set(err, CSF_E_INVALID_ARG, "image: NULL output");
    *out = NULL;
    if (!buf || len < 8) return csf_error_set(err, CSF_E_FORMAT, "not a PNG file (%zu bytes)", len);
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&pi, buf, len)) {
        csf_status st = csf_error_set(err, CSF_E_FORMAT, "not a readable PNG: %s", pi.message);
        png_image_free(&pi);
        return st;
    }
    if (pi.width < 1 || pi.height < 1 || pi.width > MAX_SIDE || pi.height > MAX_SIDE ||
        (size_t)pi.width * pi.height > MAX_PIXELS) {
        csf_status st = csf_error_set(err, CSF_E_FORMAT,
                                      "PNG is %ux%u px; images are limited to %d px a side and %u "
                                      "pixels", pi.width, pi.height, MAX_SIDE, MAX_PIXELS);
        png_image_free(&pi);
        return st;
    }
    int had_colour = (pi.format & PNG_FORMAT_FLAG_COLOR) != 0;
    /* 8-bit sRGB-encoded grey + alpha: libpng converts colour to grey in linear light and any
     * file gAMA to sRGB encoding; we then apply the exact piecewise sRGB decoding ourselves,
     * because libpng's own linear output models sRGB as a pure 2.2 power (up to 1 % off). */
    pi.format = PNG_FORMAT_GA;
    size_t n = (size_t)pi.width * pi.height;
    uint8_t *px = malloc(PNG_IMAGE_SIZE(pi));
    csf_image *img = calloc(1, sizeof *img);
    if (img) {
        img->lum = malloc(sizeof(float) * n);
        img->alpha = malloc(sizeof(float) * n);
    }
    if (!px || !img || !img->lum || !img->alpha) {
        free(px);
        csf_image_free(img);
        png_image_free(&pi);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory for a %ux%u image", pi.width, pi.height);
    }
    if (!png_image_finish_read(&pi, NULL, px, 0, NULL)) {
        csf_status st = csf_error_set(err, CSF_E_FORMAT, "PNG decoding failed: %s", pi.message);
        free(px);
        csf_image_free(img);
        png_image_free(&pi);
        return st;
    }
    double srgb_table[256];
    for (int k = 0; k < 256; k++) {
        double v = k / 255.0;
        srgb_table[k] = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
    }
    img->width = (int)pi.width;
    img->height = (int)pi.height;
    double sum = 0, wsum = 0;
    for (size_t i = 0; i < n; i++) {
        double a = px[2 * i + 1] / 255.0;
        double y = srgb_table[px[2 * i]];
        img->lum[i] = (float)y;
        img->alpha[i] = (float)a;
        sum += y * a;
        wsum += a;
    }
    img->mean_lum = wsum > 0 ? sum / wsum : 0.5;
    if (img->mean_lum < 1e-3) img->mean_lum = 1e-3;
    snprintf(img->colour_note, sizeof img->colour_note, "%s; 8-bit sRGB decoding, gAMA honoured, iCCP ignored",
             had_colour ? "colour reduced to luminance" : "grey");
    free(px);
    png_image_free(&pi);
    *out = img;
    return CSF_OK;
}

csf_status csf_image_load_png(const char *path, csf_image **out, csf_error *err)
{
    if (!path || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "image: NULL argument");
    FILE *f = fopen(path, "rb");
    if (!f) return csf_error_set(err, CSF_E_IO, "cannot open image '%s'", path);
    if (fseek(f, 0, SEEK_END) != 0) {
        fclose(f);
        return csf_error_set(err, CSF_E_IO, "cannot read image '%s'", path);
    }
    long sz = ftell(f);
    rewind(f);
    if (sz < 0 || (unsigned long)sz > MAX_FILE_BYTES) {
        fclose(f);
        return csf_error_set(err, CSF_E_FORMAT, "image '%s' is larger than %u bytes", path,
                             MAX_FILE_BYTES);
    }
    unsigned char *buf = malloc((size_t)sz + 1);
    if (!buf) {
        fclose(f);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory reading '%s'", path);
    }
    size_t got = fread(buf, 1, (size_t)sz, f);
    fclose(f);
    csf_status st = csf_image_load_png_memory(buf, got, out, err);
    free(buf);
    if (st && err) {
        char tmp[sizeof err->msg];
        memcpy(tmp, err->msg, sizeof tmp);
        tmp[300] = '\0';
        csf_error_set(err, st, "%.200s: %s", path, tmp);
    }
    return st;
}
