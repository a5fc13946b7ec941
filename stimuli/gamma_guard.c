/* See gamma_guard.h. */
#define GLFW_INCLUDE_NONE
#include "stimuli/gamma_guard.h"

#include <GLFW/glfw3.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#define MAX_RAMP 4096

static GLFWmonitor *g_mon;
static unsigned short g_orig[3][MAX_RAMP];
static unsigned int g_size;
static volatile sig_atomic_t g_active;
static int g_hooks_installed;

static const int guarded_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGSEGV,
                                      SIGBUS, SIGFPE,  SIGILL, SIGABRT};

static void set_ramp(unsigned short *r, unsigned short *g, unsigned short *b)
{
    GLFWgammaramp ramp = {r, g, b, g_size};
    glfwSetGammaRamp(g_mon, &ramp);
    /* Xlib buffers requests: a reply-bearing request forces the set out before we may die. */
    (void)glfwGetGammaRamp(g_mon);
}

void csf_gamma_guard_restore(void)
{
    if (!g_active) return;
    g_active = 0;
    set_ramp(g_orig[0], g_orig[1], g_orig[2]);
}

int csf_gamma_guard_active(void) { return g_active != 0; }

static struct sigaction g_prev[NSIG];

/* Restores the ramp, then hands the signal on: to the handler that was installed before ours
 * (a session's graceful stop, a sanitizer's crash report), or to the default action, so the
 * process ends exactly as it would have without the guard. */
static void on_signal(int sig, siginfo_t *info, void *uctx)
{
    csf_gamma_guard_restore();
    struct sigaction prev = g_prev[sig];
    sigaction(sig, &prev, NULL);
    if ((prev.sa_flags & SA_SIGINFO) && prev.sa_sigaction) {
        prev.sa_sigaction(sig, info, uctx);
        return;
    }
    if (!(prev.sa_flags & SA_SIGINFO) && prev.sa_handler != SIG_DFL && prev.sa_handler != SIG_IGN) {
        prev.sa_handler(sig);
        return;
    }
    signal(sig, SIG_DFL);
    raise(sig); /* delivered with the default action when this handler returns */
}

static void on_exit_hook(void) { csf_gamma_guard_restore(); }

static void install_hooks(void)
{
    if (g_hooks_installed) return;
    g_hooks_installed = 1;
    atexit(on_exit_hook);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_SIGINFO;
    for (size_t i = 0; i < sizeof guarded_signals / sizeof guarded_signals[0]; i++)
        sigaction(guarded_signals[i], &sa, &g_prev[guarded_signals[i]]);
}

int csf_gamma_ramp_is_identity(GLFWmonitor *mon)
{
    const GLFWgammaramp *r = glfwGetGammaRamp(mon);
    if (!r || r->size < 2) return 0;
    for (unsigned int i = 0; i < r->size; i++) {
        long want = (long)((double)i * 65535.0 / (r->size - 1) + 0.5);
        if (labs((long)r->red[i] - want) > 1 || labs((long)r->green[i] - want) > 1 ||
            labs((long)r->blue[i] - want) > 1)
            return 0;
    }
    return 1;
}

csf_status csf_gamma_guard_install(GLFWmonitor *mon, csf_error *err)
{
    if (!mon) return csf_error_set(err, CSF_E_INVALID_ARG, "gamma guard: no monitor");
    if (g_active) csf_gamma_guard_restore();
    const GLFWgammaramp *r = glfwGetGammaRamp(mon);
    if (!r || r->size < 2 || r->size > MAX_RAMP)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "this display system offers no gamma ramp (size %u); the OS ramp "
                             "cannot be set to identity, so make sure no colour correction is "
                             "active", r ? r->size : 0u);
    g_mon = mon;
    g_size = r->size;
    memcpy(g_orig[0], r->red, sizeof(unsigned short) * g_size);
    memcpy(g_orig[1], r->green, sizeof(unsigned short) * g_size);
    memcpy(g_orig[2], r->blue, sizeof(unsigned short) * g_size);
    install_hooks();
    static unsigned short id[MAX_RAMP];
    for (unsigned int i = 0; i < g_size; i++)
        id[i] = (unsigned short)((double)i * 65535.0 / (g_size - 1) + 0.5);
    g_active = 1;
    set_ramp(id, id, id);
    return CSF_OK;
}
