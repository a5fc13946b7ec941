#include "pngout.h"

#include <png.h>
#include <setjmp.h>
#include <stdio.h>

#include "outfile.h"

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
    lod_outfile o;
    if (lod_outfile_open(&o, path, err, err_len) != 0) return -1;
    int ok = encode(o.f, rgb, width, height) == 0;
    if (lod_outfile_close(&o, ok, err, err_len) != 0) {
        if (!ok) snprintf(err, err_len, "cannot write %s: the PNG encoder failed", path);
        return -1;
    }
    return 0;
}
