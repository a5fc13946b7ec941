/* 8-bit RGB PNG files through libpng, written to a temporary beside the destination and renamed,
 * so a study never reads half an image. */
#ifndef LOD_PNGOUT_H
#define LOD_PNGOUT_H

#include <stddef.h>
#include <stdint.h>

/* rgb: width*height*3 bytes, top row first. 0, or -1 with the file and the OS error in err. */
int lod_png_write(const char *path, const uint8_t *rgb, int width, int height, char *err, size_t err_len);

#endif
