/* The presenter's headless context: EGL on Mesa's surfaceless platform (see stimuli/context.h). */
#include "stimuli/context.h"

#include <EGL/eglext.h>
#include <dlfcn.h>
#include <link.h>
#include <string.h>

/* Marks the loaded Mesa/LLVM driver modules as never-unloaded. eglTerminate would otherwise
 * dlclose them, and the driver's own leftover allocations would then appear in leak reports with
 * no module name, so they could not be told apart from ours (tests/lsan.supp matches by module).
 * Keeping a driver resident for the life of the process costs nothing. */
static int pin_module(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    (void)data;
    const char *n = info->dlpi_name;
    if (n && *n &&
        (strstr(n, "_dri.so") || strstr(n, "libLLVM") || strstr(n, "libgallium") ||
         strstr(n, "libEGL_mesa") || strstr(n, "libglapi"))) {
        void *h = dlopen(n, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        if (h) dlclose(h);
    }
    return 0;
}

void csf_context_pin_driver(void)
{
    dl_iterate_phdr(pin_module, NULL);
}

csf_status csf_context_egl_open(EGLDisplay *dpy, EGLContext *ctx, csf_error *err)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (get_platform_display)
        *dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (*dpy == EGL_NO_DISPLAY)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "no EGL surfaceless display (Mesa EGL_MESA_platform_surfaceless needed "
                             "for --headless)");
    EGLint major, minor;
    if (!eglInitialize(*dpy, &major, &minor)) {
        *dpy = EGL_NO_DISPLAY;
        return csf_error_set(err, CSF_E_UNSUPPORTED, "eglInitialize failed on the surfaceless platform");
    }
    if (!eglBindAPI(EGL_OPENGL_API))
        return csf_error_set(err, CSF_E_UNSUPPORTED, "EGL cannot bind the desktop OpenGL API");
    static const EGLint versions[][2] = {{4, 5}, {3, 3}};
    for (int i = 0; i < 2 && *ctx == EGL_NO_CONTEXT; i++) {
        EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION,
                         versions[i][0],
                         EGL_CONTEXT_MINOR_VERSION,
                         versions[i][1],
                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                         EGL_NONE};
        *ctx = eglCreateContext(*dpy, (EGLConfig)0 /* EGL_NO_CONFIG_KHR */, EGL_NO_CONTEXT, attr);
    }
    if (*ctx == EGL_NO_CONTEXT)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "cannot create an OpenGL 4.5 or 3.3 core context through EGL (0x%x)",
                             (unsigned)eglGetError());
    if (!eglMakeCurrent(*dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, *ctx))
        return csf_error_set(err, CSF_E_UNSUPPORTED, "eglMakeCurrent without a surface failed");
    csf_context_pin_driver();
    return CSF_OK;
}

void csf_context_egl_close(EGLDisplay dpy, EGLContext ctx)
{
    if (ctx != EGL_NO_CONTEXT) {
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(dpy, ctx);
    }
    if (dpy != EGL_NO_DISPLAY) eglTerminate(dpy);
}
