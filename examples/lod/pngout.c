#define _POSIX_C_SOURCE 200809L
#include "pngout.h"

#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int encode(FILE *f, const uint8_t *rgb, int width, int height)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) { png_destroy_write_struct(&png, NULL); return -1; }
    if (setjmp(png_jmpbuf(png))) { png_destroy_write_struct(&png, &info); return -1; }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    /* the pixel values are for a gamma-2.2 display (shade.h); say so */
    png_set_gAMA(png, info, 1 / 2.2);
    png_write_info(png, info);
    for (int y = 0; y < height; y++) png_write_row(png, rgb + (size_t)y * width * 3);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return 0;
}

int lod_png_write(const char *path, const uint8_t *rgb, int width, int height, char *err, size_t err_len)
{
    size_t n = strlen(path) + 16;
    char *tmp = malloc(n);
    if (!tmp) { snprintf(err, err_len, "%s: out of memory", path); return -1; }
    snprintf(tmp, n, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        snprintf(err, err_len, "cannot write %s: %s", path, strerror(errno));
        free(tmp);
        return -1;
    }
    FILE *f = fdopen(fd, "wb");
    int rc = f ? encode(f, rgb, width, height) : -1;
    int saved = errno;
    if (f && fflush(f) != 0) { rc = -1; saved = errno; }
    if (rc == 0 && fsync(fd) != 0) { rc = -1; saved = errno; }
    if (f ? fclose(f) != 0 : close(fd) != 0) { if (rc == 0) saved = errno; rc = -1; }
    if (rc == 0 && rename(tmp, path) != 0) { rc = -1; saved = errno; }
    if (rc != 0) {
        snprintf(err, err_len, "cannot write %s: %s", path, saved ? strerror(saved) : "PNG encoder failed");
        unlink(tmp);
    }
    free(tmp);
    return rc;
}
