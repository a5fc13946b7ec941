/* Gamepads through GLFW's joystick and gamepad API: spec, default map and the seam tests use.
 *
 * Spec: "gamepad[:N][,map=...]". N: GLFW joystick 0 to 15 (default: the first connected joystick
 * that GLFW knows as a gamepad, else the first connected one). Buttons are numbered as GLFW's
 * gamepad layout (the SDL_GameControllerDB mapping GLFW ships): 0 A/cross, 1 B/circle, 2 X/square,
 * 3 Y/triangle, 4 left bumper, 5 right bumper, 6 back, 7 start, 8 guide, 9 left thumb, 10 right
 * thumb, 11 d-pad up, 12 right, 13 down, 14 left, and the triggers as buttons 15 (left) and 16
 * (right) when pressed past half way. A joystick without a gamepad mapping reports its raw
 * buttons 0.. (up to 64) under the same numbers.
 * Default map: press:0 (A), first:2/first:14 (X, d-pad left), second:1/second:12 (B, d-pad right),
 * ul:4/ur:5/ll:15/lr:16 (the bumpers and triggers sit where the four places are), pause:7
 * (start). */
#ifndef CSF_RESPONDER_GAMEPAD_H
#define CSF_RESPONDER_GAMEPAD_H

#include <stdint.h>

#include "devices/responder.h"
#include "devices/responder_map.h"

typedef struct {
    int joystick;        /* -1: the first gamepad found */
    csf_button_map map;
} csf_gamepad_spec;

csf_status csf_gamepad_spec_parse(const char *options, csf_gamepad_spec *out, csf_error *err);

/* Where the button state comes from: GLFW on a real pad, an emulator in tests. */
typedef struct csf_pad_io {
    /* 1 and the buttons held by joystick jid (bit i = button i), 0 when it is not connected */
    int (*buttons)(struct csf_pad_io *io, int jid, uint64_t *bits);
    /* 1 when jid is connected and has a gamepad mapping */
    int (*is_gamepad)(struct csf_pad_io *io, int jid);
    void *user;
} csf_pad_io;

/* Opens a gamepad responder on io instead of GLFW (no window, no keyboard beside it). */
csf_status csf_responder_open_gamepad_io(const char *options, const csf_pad_io *io, csf_responder **out,
                                         csf_error *err);

#endif
