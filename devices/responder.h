/* Response devices for a real person: one backend per file behind one struct of function
 * pointers (devices/responder_backend.h, the libusb backend shape), chosen by spec
 * "name[:options]". Events carry a timestamp in seconds on raw CLOCK_MONOTONIC
 * (csf_responder_now). The windowed presenter's frame times are the same clock minus its first
 * frame's time: to compare an event with a frame, subtract csf_responder_now() -
 * csf_presenter_time(p) from the event's t_s first.
 *
 * Backends (docs/instruments.md, "Response devices", has each one's timestamp and latency):
 *  - "keyboard" and "mouse" (devices/responder_glfw.c: both read the presenter's GLFW window; any
 *    mouse button or Space = press, Left/1 and Right/2 = two-interval choice, keypad 9/7/1/3 and
 *    I/U/J/K = four-place choice (upper right/upper left/lower left/lower right), a click carries
 *    its position in framebuffer pixels, Escape = pause; the "mouse" backend reports keys only as
 *    CSF_RESP_KEY/ESCAPE);
 *  - "gamepad[:N][,map=...]" (devices/responder_gamepad.c: GLFW's joystick/gamepad API, joystick
 *    N or the first gamepad found; the window's keyboard keeps working beside it);
 *  - "hid:VID:PID[,serial=S][,report=ID][,offset=BYTE][,bytes=N][,active=low][,map=...]"
 *    (devices/responder_hid.c: a USB HID button box through hidapi, a reader thread stamping each
 *    input report as it arrives; the window's keyboard and mouse keep working beside it, as
 *    beside a gamepad);
 *  - "queue" (devices/responder.c): events pushed by the program itself with
 *    csf_responder_push, for scripted sessions and tests.
 * A device that disappears during a session (unplugged) reports one CSF_RESP_ESCAPE with key
 * CSF_RESP_KEY_GONE: the session pauses rather than waiting for answers that cannot come. */
#ifndef CSF_RESPONDER_H
#define CSF_RESPONDER_H

#include "core/csf_status.h"

typedef enum {
    CSF_RESP_NONE = 0,
    CSF_RESP_PRESS = 1,   /* "I see something" (button or Space) */
    CSF_RESP_CHOICE = 2,  /* forced choice. places = 2 (or 0): an interval key, choice = 0 (first /
                             left) or 1 (second / right); places = 4: a place key, choice = 0
                             upper right, 1 upper left, 2 lower left, 3 lower right (the order
                             of csf_afc_layout in calib/afc_layout.h) */
    CSF_RESP_CLICK = 3,   /* pointer click at (x_px, y_px), framebuffer pixels, y down;
                             choice = the button (0 left, 1 right, 2 middle) */
    CSF_RESP_ESCAPE = 4,  /* pause request */
    CSF_RESP_KEY = 5,     /* any other key; key = its character or code */
} csf_response_kind;

typedef struct {
    csf_response_kind kind;
    int choice;
    int key;
    double x_px, y_px;
    double t_s;           /* CLOCK_MONOTONIC seconds */
    int places;           /* CSF_RESP_CHOICE: 4 = choice is a place (0-3), else an interval (0/1) */
} csf_response;

/* key of the CSF_RESP_ESCAPE a backend reports when its device has gone */
enum { CSF_RESP_KEY_GONE = -1 };

typedef struct csf_responder csf_responder;

/* spec: "name[:options]" (above). Unknown names are refused with the list of known ones. */
csf_status csf_responder_open(const char *spec, void *window, csf_responder **out, csf_error *err);
/* Checks a spec without opening anything (name known, options well formed): for the command
 * line, before the first trial. CSF_E_INVALID_ARG with the problem. */
csf_status csf_responder_check_spec(const char *spec, csf_error *err);
int csf_responder_poll(csf_responder *r, csf_response *out);
/* Queue backend only: appends an event (returns -1 when full or not a queue responder). */
int csf_responder_push(csf_responder *r, const csf_response *ev);
const char *csf_responder_name(const csf_responder *r);
void csf_responder_close(csf_responder *r);

/* Monotonic clock, seconds. */
double csf_responder_now(void);

#endif
