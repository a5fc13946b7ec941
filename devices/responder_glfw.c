/* Keyboard and mouse responses through the presenter's GLFW window. GLFW delivers input in
 * callbacks during glfwPollEvents and passes no time with them (X11 and Wayland events carry one;
 * GLFW 3.3 drops it), so each callback stamps the event on CLOCK_MONOTONIC at once and queues it:
 * the timestamp is when the poll that handed the event over ran, at most one poll interval (the
 * session polls every frame) after the key went down, plus the window system's own delay. See
 * docs/instruments.md, "Response devices". The window's user pointer belongs to the presenter, so the queue is reached
 * through a small table keyed by window. */
#include <GLFW/glfw3.h>
#include <stdlib.h>

#include "devices/responder_backend.h"

#define GLFW_QUEUE_CAP 128
#define MAX_WINDOWS 4

typedef struct {
    GLFWwindow *win;
    int mouse_only;
    csf_response ev[GLFW_QUEUE_CAP];
    int head, count;
    GLFWkeyfun prev_key;
    GLFWmousebuttonfun prev_button;
} glfw_state;

static glfw_state *by_window[MAX_WINDOWS];

static glfw_state *lookup(GLFWwindow *w)
{
    for (int i = 0; i < MAX_WINDOWS; i++)
        if (by_window[i] && by_window[i]->win == w) return by_window[i];
    return NULL;
}

static void push(glfw_state *s, const csf_response *ev)
{
    if (s->count == GLFW_QUEUE_CAP) return; /* a person cannot outrun 128 events per poll */
    s->ev[(s->head + s->count) % GLFW_QUEUE_CAP] = *ev;
    s->count++;
}

static void key_cb(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    glfw_state *s = lookup(w);
    if (s && s->prev_key) s->prev_key(w, key, scancode, action, mods);
    if (!s || action != GLFW_PRESS) return;
    csf_response ev = {CSF_RESP_KEY, 0, key, 0, 0, csf_responder_now(), 0};
    if (key == GLFW_KEY_ESCAPE) ev.kind = CSF_RESP_ESCAPE;
    else if (s->mouse_only) ev.kind = CSF_RESP_KEY;
    else if (key == GLFW_KEY_SPACE) ev.kind = CSF_RESP_PRESS;
    else if (key == GLFW_KEY_LEFT || key == GLFW_KEY_1) ev.kind = CSF_RESP_CHOICE, ev.choice = 0;
    else if (key == GLFW_KEY_RIGHT || key == GLFW_KEY_2) ev.kind = CSF_RESP_CHOICE, ev.choice = 1;
    /* Four places shown at once: the keypad keys at the places' corners (9 upper right, 7 upper
     * left, 1 lower left, 3 lower right; GLFW reports them whatever the Num Lock state), and the
     * same square on the letters: U I over J K (U upper left, I upper right, J lower left, K
     * lower right). The interval keys above keep their meaning. */
    else if (key == GLFW_KEY_KP_9 || key == GLFW_KEY_I) ev.kind = CSF_RESP_CHOICE, ev.choice = 0, ev.places = 4;
    else if (key == GLFW_KEY_KP_7 || key == GLFW_KEY_U) ev.kind = CSF_RESP_CHOICE, ev.choice = 1, ev.places = 4;
    else if (key == GLFW_KEY_KP_1 || key == GLFW_KEY_J) ev.kind = CSF_RESP_CHOICE, ev.choice = 2, ev.places = 4;
    else if (key == GLFW_KEY_KP_3 || key == GLFW_KEY_K) ev.kind = CSF_RESP_CHOICE, ev.choice = 3, ev.places = 4;
    push(s, &ev);
}

static void button_cb(GLFWwindow *w, int button, int action, int mods)
{
    glfw_state *s = lookup(w);
    if (s && s->prev_button) s->prev_button(w, button, action, mods);
    if (!s || action != GLFW_PRESS) return;
    double t = csf_responder_now(), x, y;
    glfwGetCursorPos(w, &x, &y);
    /* The cursor is in screen coordinates; the drawing is in framebuffer pixels (they differ on
     * scaled / HiDPI outputs). */
    int ww, wh, fw, fh;
    glfwGetWindowSize(w, &ww, &wh);
    glfwGetFramebufferSize(w, &fw, &fh);
    if (ww > 0 && wh > 0) {
        x *= (double)fw / ww;
        y *= (double)fh / wh;
    }
    /* A click is both the press (detection) and, when the session asks for a position, the
     * click; the session takes whichever it is waiting for. */
    csf_response ev = {CSF_RESP_CLICK, button, 0, x, y, t, 0};
    push(s, &ev);
}

static csf_status open_common(void *window, void **state, int mouse_only, csf_error *err)
{
    if (!window)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "keyboard/mouse responses need a window: run with a display (not --headless)");
    glfw_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "responder: out of memory");
    int slot = -1;
    for (int i = 0; i < MAX_WINDOWS; i++)
        if (!by_window[i]) { slot = i; break; }
    if (slot < 0) {
        free(s);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "responder: more than %d responders open", MAX_WINDOWS);
    }
    s->win = window;
    s->mouse_only = mouse_only;
    by_window[slot] = s;
    s->prev_key = glfwSetKeyCallback(s->win, key_cb);
    s->prev_button = glfwSetMouseButtonCallback(s->win, button_cb);
    *state = s;
    return CSF_OK;
}

static csf_status open_keyboard(const char *options, void *window, void **state, csf_error *err)
{
    if (*options) return csf_error_set(err, CSF_E_INVALID_ARG, "responder keyboard takes no options (got '%s')", options);
    return open_common(window, state, 0, err);
}

static csf_status open_mouse(const char *options, void *window, void **state, csf_error *err)
{
    if (*options) return csf_error_set(err, CSF_E_INVALID_ARG, "responder mouse takes no options (got '%s')", options);
    return open_common(window, state, 1, err);
}

static int glfw_poll(void *state, csf_response *out)
{
    glfw_state *s = state;
    glfwPollEvents();
    if (s->count == 0) return 0;
    *out = s->ev[s->head];
    s->head = (s->head + 1) % GLFW_QUEUE_CAP;
    s->count--;
    return 1;
}

static void glfw_close(void *state)
{
    glfw_state *s = state;
    if (!s) return;
    glfwSetKeyCallback(s->win, s->prev_key);
    glfwSetMouseButtonCallback(s->win, s->prev_button);
    for (int i = 0; i < MAX_WINDOWS; i++)
        if (by_window[i] == s) by_window[i] = NULL;
    free(s);
}

const csf_responder_backend csf_responder_glfw_keyboard = {"keyboard", open_keyboard, glfw_poll, glfw_close,
                                                           NULL};
const csf_responder_backend csf_responder_glfw_mouse = {"mouse", open_mouse, glfw_poll, glfw_close, NULL};
