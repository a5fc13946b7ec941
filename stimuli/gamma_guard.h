/* OS gamma-ramp guard for the fullscreen window. csfcal corrects luminance in its own shader from
 * the display profile, so the operating system's ramp must be identity while it draws — and the
 * user's own ramp must come back on every way out: normal close, exit(), SIGINT, SIGTERM, SIGHUP,
 * SIGQUIT, and crashes (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT). The handlers restore the saved
 * ramp, then pass the signal on to the handler installed before the guard (a session's graceful
 * stop, a sanitizer's crash report) or re-raise it with the default action.
 * (Calling GLFW/Xlib from a signal handler is not async-signal-safe; it is done once, as the last
 * act of a dying process, because leaving the user's monitor with a wrong ramp is worse.) */
#ifndef CSF_STIMULI_GAMMA_GUARD_H
#define CSF_STIMULI_GAMMA_GUARD_H

#include "core/csf_status.h"

typedef struct GLFWmonitor GLFWmonitor;

/* Saves mon's current ramp, installs the exit/signal hooks (once per process) and sets the
 * identity ramp. CSF_E_UNSUPPORTED when the system offers no gamma ramp (then nothing changes;
 * the caller may go on and should say so). */
csf_status csf_gamma_guard_install(GLFWmonitor *mon, csf_error *err);
/* Puts the saved ramp back; idempotent; safe to call when nothing was installed. */
void csf_gamma_guard_restore(void);
/* 1 while an identity ramp installed by the guard is active. */
int csf_gamma_guard_active(void);
/* 1 when the ramp of mon is identity (within one 16-bit step per entry). */
int csf_gamma_ramp_is_identity(GLFWmonitor *mon);

#endif
