/* The presenter's windowed context: a fullscreen GLFW window on the chosen monitor, its OpenGL
 * context made through EGL, with the monitor's gamma ramp guarded (see stimuli/context.h). */
#include "stimuli/context.h"

#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stimuli/gamma_guard.h"

static GLFWmonitor *pick_monitor(const char *spec, csf_error *err)
{
    int n = 0;
    GLFWmonitor **mons = glfwGetMonitors(&n);
    if (n <= 0) {
        csf_error_set(err, CSF_E_UNSUPPORTED, "no monitor found for a fullscreen window");
        return NULL;
    }
    if (!spec || !*spec) return glfwGetPrimaryMonitor();
    char *end;
    long idx = strtol(spec, &end, 10);
    if (*end == '\0') {
        if (idx < 0 || idx >= n) {
            csf_error_set(err, CSF_E_INVALID_ARG, "--monitor %ld: there are %d monitors (0 to %d)", idx, n,
                          n - 1);
            return NULL;
        }
        return mons[idx];
    }
    for (int i = 0; i < n; i++) {
        const char *name = glfwGetMonitorName(mons[i]);
        if (name && strstr(name, spec)) return mons[i];
    }
    csf_error_set(err, CSF_E_NOT_FOUND, "--monitor '%s': no monitor with that name among %d", spec, n);
    return NULL;
}

csf_status csf_context_glfw_open(csf_glfw_context *c, csf_error *err)
{
    if (!glfwInit()) {
        const char *d = NULL;
        glfwGetError(&d);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "GLFW could not start (%s); use --headless",
                             d ? d : "no display");
    }
    c->glfw_inited = 1;
    GLFWmonitor *mon = pick_monitor(c->monitor, err);
    if (!mon) return err ? err->code : CSF_E_UNSUPPORTED;
    const GLFWvidmode *mode = glfwGetVideoMode(mon);
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_RED_BITS, c->bits);
    glfwWindowHint(GLFW_GREEN_BITS, c->bits);
    glfwWindowHint(GLFW_BLUE_BITS, c->bits);
    glfwWindowHint(GLFW_REFRESH_RATE, mode ? mode->refreshRate : GLFW_DONT_CARE);
    glfwWindowHint(GLFW_AUTO_ICONIFY, GLFW_FALSE);
    int w = mode ? mode->width : c->width_px, h = mode ? mode->height : c->height_px;
    GLFWmonitor *full = mon;
    if (c->windowed) { /* a preview on the desktop: the configured size, no monitor takeover */
        w = c->width_px;
        h = c->height_px;
        full = NULL;
    }
    c->win = glfwCreateWindow(w, h, "csfcal", full, NULL);
    if (!c->win && c->bits == 10) { /* 10-bit refused: fall back to 8 and say so via bits */
        c->bits = 8;
        glfwWindowHint(GLFW_RED_BITS, 8);
        glfwWindowHint(GLFW_GREEN_BITS, 8);
        glfwWindowHint(GLFW_BLUE_BITS, 8);
        c->win = glfwCreateWindow(w, h, "csfcal", full, NULL);
    }
    if (!c->win) {
        const char *d = NULL;
        glfwGetError(&d);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "cannot open a %s OpenGL 3.3 window through EGL (%s)",
                             c->windowed ? "desktop" : "fullscreen", d ? d : "unknown");
    }
    glfwMakeContextCurrent(c->win);
    csf_context_pin_driver();
    glfwSwapInterval(1);
    glfwSetInputMode(c->win, GLFW_CURSOR, GLFW_CURSOR_HIDDEN);
    int fw, fh;
    glfwGetFramebufferSize(c->win, &fw, &fh);
    if (fw != c->width_px || fh != c->height_px)
        fprintf(stderr,
                "csfcal: warning: the window is %dx%d px but the configuration says %dx%d px; "
                "drawing at the window size with the configured size in mm\n",
                fw, fh, c->width_px, c->height_px);
    c->fb_w = fw;
    c->fb_h = fh;
    c->has_mode = mode != NULL;
    c->mode_hz = mode ? mode->refreshRate : 0;
    csf_error gerr;
    if (csf_gamma_guard_install(mon, &gerr) != CSF_OK) fprintf(stderr, "csfcal: warning: %s\n", gerr.msg);
    return CSF_OK;
}

void csf_context_glfw_close(GLFWwindow *win, int glfw_inited)
{
    if (win) glfwDestroyWindow(win);
    if (glfw_inited) {
        csf_gamma_guard_restore();
        glfwTerminate();
    }
}
