/* The responder backend interface (devices/responder.h is what callers see): one struct of
 * function pointers per backend file, the libusb backend shape, and every backend's instance.
 * devices/responder.c opens and checks a spec through the table of these; only backends include
 * this. */
#ifndef CSF_RESPONDER_BACKEND_H
#define CSF_RESPONDER_BACKEND_H

#include "devices/responder.h"

typedef struct {
    const char *name;
    /* options: the text after "name:" ("" when none); window: the GLFWwindow* of the presenter
     * (NULL for backends that need none). */
    csf_status (*open)(const char *options, void *window, void **state, csf_error *err);
    /* Pumps the device and returns 1 with the oldest pending event, 0 when none is pending. */
    int (*poll)(void *state, csf_response *out);
    void (*close)(void *state);
    /* Checks options without opening anything (csf_responder_check_spec). NULL: the backend
     * takes no options. */
    csf_status (*check_options)(const char *options, csf_error *err);
} csf_responder_backend;

/* Wraps an opened backend state (for backends opened through a test seam, e.g. an emulated HID
 * device: devices/responder_hid.h). Closes the state through b->close on failure. */
csf_status csf_responder_wrap(const csf_responder_backend *b, void *state, csf_responder **out,
                              csf_error *err);

/* The window's keyboard and mouse (devices/responder_glfw.c), a gamepad
 * (devices/responder_gamepad.c) and a USB HID button box (devices/responder_hid.c). */
extern const csf_responder_backend csf_responder_glfw_keyboard, csf_responder_glfw_mouse,
    csf_responder_gamepad, csf_responder_hid;

#endif
