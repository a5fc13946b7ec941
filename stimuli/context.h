/* Where the presenter's OpenGL context comes from, one source per file (as GLFW keeps
 * egl_context.c apart from glx_context.c): an EGL surfaceless context for --headless
 * (stimuli/context_egl.c) or a fullscreen GLFW window (stimuli/context_glfw.c). Each leaves its
 * context current when it succeeds. Internal to stimuli/: the presenter is its only user. */
#ifndef CSF_STIMULI_CONTEXT_H
#define CSF_STIMULI_CONTEXT_H

#include <EGL/egl.h>

#include "core/csf_status.h"

typedef struct GLFWwindow GLFWwindow;

/* Marks the loaded Mesa/LLVM driver modules as never-unloaded (see stimuli/context_egl.c). */
void csf_context_pin_driver(void);

/* Creates an OpenGL 4.5 (else 3.3) core context on the surfaceless platform, without a surface.
 * *dpy and *ctx start as EGL_NO_DISPLAY / EGL_NO_CONTEXT and keep what was made even on
 * failure, for csf_context_egl_close. */
csf_status csf_context_egl_open(EGLDisplay *dpy, EGLContext *ctx, csf_error *err);
void csf_context_egl_close(EGLDisplay dpy, EGLContext ctx);

/* A fullscreen (or, windowed, a desktop) window with an OpenGL 3.3 core context through EGL. The fields after the inputs
 * are set even on failure as far as the open got, for csf_context_glfw_close. */
typedef struct {
    const char *monitor;     /* --monitor: an index or part of a name; NULL or "": the primary */
    int width_px, height_px; /* the configured size: the window's when the monitor has no mode */
    int bits;                /* 8 or 10 asked; 8 when a 10-bit window was refused */
    int windowed;            /* a desktop window of width_px x height_px, not fullscreen */
    GLFWwindow *win;
    int glfw_inited;
    int fb_w, fb_h;        /* the framebuffer's size */
    int has_mode, mode_hz; /* the monitor's video mode and its refresh rate */
} csf_glfw_context;

csf_status csf_context_glfw_open(csf_glfw_context *c, csf_error *err);
void csf_context_glfw_close(GLFWwindow *win, int glfw_inited);

#endif
