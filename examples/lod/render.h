/* Offscreen rendering of the mesh (full or simplified) with OpenGL 3.3 core on an EGL surfaceless
 * context (EGL_PLATFORM_SURFACELESS_MESA: no window system, llvmpipe in CI), 4x multisampled,
 * read back as 8-bit RGB. */
#ifndef LOD_RENDER_H
#define LOD_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "shade.h"

typedef struct lod_renderer lod_renderer;

/* NULL on failure with a sentence in err. */
lod_renderer *lod_render_open(int width_px, int height_px, char *err, size_t err_len);
void lod_render_close(lod_renderer *r);

/* Vertex data: one entry per tree node (position and unit normal, world space). */
int lod_render_set_vertices(lod_renderer *r, const float *pos, const float *nrm, int n);

/* Draws n_tri triangles (indices into the vertices) with the camera (column-major 4x4 world ->
 * clip) and the shading model, and reads the image into rgb (width*height*3 bytes, top row
 * first). 0 on success, -1 with a sentence in err. */
int lod_render_draw(lod_renderer *r, const uint32_t *tri, int n_tri, const float mvp[16],
                    const lod_shade *s, uint8_t *rgb, char *err, size_t err_len);

#endif
