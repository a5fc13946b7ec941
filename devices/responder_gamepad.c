/* Gamepads through GLFW's joystick/gamepad API (see devices/responder_gamepad.h). GLFW keeps no
 * event queue for joysticks and passes no times: the pad's state is read at each poll, a button
 * that went down since the last poll is a response stamped with the poll's time. The session polls
 * every frame, so the time is late by up to one frame (docs/instruments.md). GLFW's joystick
 * functions run on the main thread only, so there is no reader thread as for HID boxes. */
#include "devices/responder_gamepad.h"

#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/responder_backend.h"

#define PAD_QUEUE_CAP 128
enum { PAD_LT = 15, PAD_RT = 16 };

static void default_map(csf_button_map *m)
{
    memset(m, 0, sizeof *m);
    m->action[GLFW_GAMEPAD_BUTTON_A] = CSF_ACT_PRESS;
    m->action[GLFW_GAMEPAD_BUTTON_X] = CSF_ACT_FIRST;
    m->action[GLFW_GAMEPAD_BUTTON_DPAD_LEFT] = CSF_ACT_FIRST;
    m->action[GLFW_GAMEPAD_BUTTON_B] = CSF_ACT_SECOND;
    m->action[GLFW_GAMEPAD_BUTTON_DPAD_RIGHT] = CSF_ACT_SECOND;
    m->action[GLFW_GAMEPAD_BUTTON_LEFT_BUMPER] = CSF_ACT_UL;
    m->action[GLFW_GAMEPAD_BUTTON_RIGHT_BUMPER] = CSF_ACT_UR;
    m->action[PAD_LT] = CSF_ACT_LL;
    m->action[PAD_RT] = CSF_ACT_LR;
    m->action[GLFW_GAMEPAD_BUTTON_START] = CSF_ACT_PAUSE;
}

csf_status csf_gamepad_spec_parse(const char *options, csf_gamepad_spec *out, csf_error *err)
{
    csf_gamepad_spec s;
    s.joystick = -1;
    default_map(&s.map);
    const char *p = options ? options : "";
    size_t len = strlen(p), first = strcspn(p, ",");
    if (first > 0) {
        int v = 0, ok = first <= 2;
        for (size_t i = 0; ok && i < first; i++) {
            if (p[i] < '0' || p[i] > '9') ok = 0;
            else v = v * 10 + (p[i] - '0');
        }
        if (!ok || v > GLFW_JOYSTICK_LAST)
            return csf_error_set(err, CSF_E_INVALID_ARG, "responder gamepad: joystick '%.*s' is not a number from "
                                 "0 to %d", (int)(first > 20 ? 20 : first), p, GLFW_JOYSTICK_LAST);
        s.joystick = v;
    }
    size_t i = first;
    while (i < len) {
        i++;
        const char *o = p + i;
        size_t n = strcspn(o, ",");
        if (n > 4 && !memcmp(o, "map=", 4)) {
            csf_status st = csf_button_map_parse(o + 4, n - 4, &s.map, err);
            if (st) return st;
        } else {
            return csf_error_set(err, CSF_E_INVALID_ARG, "responder gamepad: option '%.*s' is unknown (known: "
                                 "map=ACTION:BUTTON/...)", (int)(n > 60 ? 60 : n), o);
        }
        i += n;
    }
    *out = s;
    return CSF_OK;
}

typedef struct {
    csf_gamepad_spec spec;
    csf_pad_io io;
    int jid;
    uint64_t prev;
    int gone;
    csf_responder *keys; /* the window's keyboard beside the pad (NULL in tests / without a window) */
    csf_response q[PAD_QUEUE_CAP];
    int head, count;
} pad_state;

static int pad_poll(void *state, csf_response *out)
{
    pad_state *p = state;
    if (p->keys && csf_responder_poll(p->keys, out)) return 1; /* also runs glfwPollEvents */
    if (p->count == 0 && !p->gone) {
        uint64_t now = 0;
        double t = csf_responder_now();
        if (!p->io.buttons(&p->io, p->jid, &now)) {
            p->gone = 1;
            csf_response *ev = &p->q[(p->head + p->count++) % PAD_QUEUE_CAP];
            memset(ev, 0, sizeof *ev);
            ev->kind = CSF_RESP_ESCAPE;
            ev->key = CSF_RESP_KEY_GONE;
            ev->t_s = t;
        } else {
            csf_response ev[CSF_MAP_BUTTONS];
            int k = csf_button_events(&p->spec.map, p->prev, now, t, ev, CSF_MAP_BUTTONS);
            p->prev = now;
            for (int i = 0; i < k && p->count < PAD_QUEUE_CAP; i++) p->q[(p->head + p->count++) % PAD_QUEUE_CAP] = ev[i];
        }
    }
    if (p->count == 0) return 0;
    *out = p->q[p->head];
    p->head = (p->head + 1) % PAD_QUEUE_CAP;
    p->count--;
    return 1;
}

static void pad_close(void *state)
{
    pad_state *p = state;
    if (!p) return;
    csf_responder_close(p->keys);
    free(p);
}

static csf_status pick(pad_state *p, csf_error *err)
{
    uint64_t b;
    if (p->spec.joystick >= 0) {
        if (!p->io.buttons(&p->io, p->spec.joystick, &b))
            return csf_error_set(err, CSF_E_NOT_FOUND, "responder gamepad: joystick %d is not connected "
                                 "(csfcal devices lists the joysticks GLFW sees)", p->spec.joystick);
        p->jid = p->spec.joystick;
        return CSF_OK;
    }
    int any = -1;
    for (int j = 0; j <= GLFW_JOYSTICK_LAST; j++) {
        if (!p->io.buttons(&p->io, j, &b)) continue;
        if (p->io.is_gamepad(&p->io, j)) {
            p->jid = j;
            return CSF_OK;
        }
        if (any < 0) any = j;
    }
    if (any < 0)
        return csf_error_set(err, CSF_E_NOT_FOUND, "responder gamepad: no joystick or gamepad is connected "
                             "(csfcal devices lists what GLFW sees; /dev/input/event* must be readable)");
    p->jid = any;
    return CSF_OK;
}

/* the state at open: buttons already held then are not responses */
static csf_status open_on(const char *options, const csf_pad_io *io, pad_state **out, csf_error *err)
{
    pad_state *p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "responder gamepad: out of memory");
    csf_status st = csf_gamepad_spec_parse(options, &p->spec, err);
    p->io = *io;
    if (!st) st = pick(p, err);
    if (st) {
        free(p);
        return st;
    }
    p->io.buttons(&p->io, p->jid, &p->prev);
    *out = p;
    return CSF_OK;
}

csf_status csf_responder_open_gamepad_io(const char *options, const csf_pad_io *io, csf_responder **out,
                                         csf_error *err)
{
    *out = NULL;
    pad_state *p = NULL;
    csf_status st = open_on(options, io, &p, err);
    if (st) return st;
    return csf_responder_wrap(&csf_responder_gamepad, p, out, err);
}

/* GLFW transport */
static int glfw_buttons(csf_pad_io *io, int jid, uint64_t *bits)
{
    (void)io;
    if (!glfwJoystickPresent(jid)) return 0;
    uint64_t b = 0;
    GLFWgamepadstate gs;
    if (glfwJoystickIsGamepad(jid) && glfwGetGamepadState(jid, &gs)) {
        for (int i = 0; i <= GLFW_GAMEPAD_BUTTON_LAST; i++)
            if (gs.buttons[i] == GLFW_PRESS) b |= 1ull << i;
        /* triggers rest at -1 and reach +1 */
        if (gs.axes[GLFW_GAMEPAD_AXIS_LEFT_TRIGGER] > 0) b |= 1ull << PAD_LT;
        if (gs.axes[GLFW_GAMEPAD_AXIS_RIGHT_TRIGGER] > 0) b |= 1ull << PAD_RT;
    } else {
        int n = 0;
        const unsigned char *raw = glfwGetJoystickButtons(jid, &n);
        if (!raw) return 0;
        for (int i = 0; i < n && i < CSF_MAP_BUTTONS; i++)
            if (raw[i] == GLFW_PRESS) b |= 1ull << i;
    }
    *bits = b;
    return 1;
}

static int glfw_is_gamepad(csf_pad_io *io, int jid)
{
    (void)io;
    return glfwJoystickIsGamepad(jid);
}

static csf_status pad_open(const char *options, void *window, void **state, csf_error *err)
{
    if (!window)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "gamepad responses need a window (GLFW reads joysticks only once it runs): run "
                             "with a display (not --headless)");
    csf_pad_io io = {glfw_buttons, glfw_is_gamepad, NULL};
    pad_state *p = NULL;
    csf_status st = open_on(options, &io, &p, err);
    if (st) return st;
    /* the experimenter's keyboard (Escape pauses) and the mouse (fade's "where was it" click)
     * keep working beside the pad */
    if ((st = csf_responder_open("keyboard", window, &p->keys, err))) {
        free(p);
        return st;
    }
    *state = p;
    return CSF_OK;
}

/* The spec's options parse (csf_responder_check_spec): nothing is opened. */
static csf_status pad_check_options(const char *options, csf_error *err)
{
    csf_gamepad_spec g;
    return csf_gamepad_spec_parse(options, &g, err);
}

const csf_responder_backend csf_responder_gamepad = {"gamepad", pad_open, pad_poll, pad_close,
                                                     pad_check_options};
