/* Buttons to responses, for response devices that report a set of buttons (gamepads, HID button
 * boxes): which button means what, and the events a change of the button set makes. A response
 * is the moment a button goes down (an edge); holding it does not repeat, releasing it says
 * nothing.
 *
 * Map text (the `map=` option of `gamepad` and `hid` responders): ACTION:BUTTON pairs separated by
 * '/', e.g. "press:0/first:4/second:5/pause:9". BUTTON is the button's number (0 to 63: a
 * gamepad's button index, or a HID report's bit number, see devices/responder_hid.h). ACTION:
 *   press             "I see something" (CSF_RESP_PRESS)
 *   first, second     two-interval choice 0 / 1 (CSF_RESP_CHOICE, places 2)
 *   ur, ul, ll, lr    four-place choice: upper right 0, upper left 1, lower left 2, lower right 3
 *                     (CSF_RESP_CHOICE, places 4; the order of calib/afc_layout.h)
 *   pause             CSF_RESP_ESCAPE
 *   none              the button reports CSF_RESP_KEY (key = CSF_BUTTON_KEY_BASE + BUTTON)
 * A map given on the command line changes only the buttons it names; the others keep the
 * device's default. A button may carry one action; several buttons may share one. */
#ifndef CSF_RESPONDER_MAP_H
#define CSF_RESPONDER_MAP_H

#include <stddef.h>
#include <stdint.h>

#include "devices/responder.h"

enum { CSF_MAP_BUTTONS = 64, CSF_BUTTON_KEY_BASE = 0x10000 };

typedef enum {
    CSF_ACT_NONE = 0, CSF_ACT_PRESS, CSF_ACT_FIRST, CSF_ACT_SECOND, CSF_ACT_UR, CSF_ACT_UL, CSF_ACT_LL,
    CSF_ACT_LR, CSF_ACT_PAUSE, CSF_ACT_COUNT
} csf_button_action;

typedef struct {
    unsigned char action[CSF_MAP_BUTTONS]; /* csf_button_action per button */
} csf_button_map;

/* Applies "ACTION:BUTTON/..." over *m (len bytes of text, not necessarily terminated). A bad pair
 * is refused with the pair, the known actions and the button range; *m is then unchanged. */
csf_status csf_button_map_parse(const char *text, size_t len, csf_button_map *m, csf_error *err);

/* "press:0/first:1/..." for the buttons that carry an action (for messages and docs). */
void csf_button_map_format(const csf_button_map *m, char *buf, size_t len);

const char *csf_button_action_name(csf_button_action a);

/* The responses for the buttons that went down from prev to now (bit i = button i), lowest button
 * first, each stamped t_s. Writes at most cap; returns how many. */
int csf_button_events(const csf_button_map *m, uint64_t prev, uint64_t now, double t_s, csf_response *out,
                      int cap);

#endif
