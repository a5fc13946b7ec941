/* Responder registry and the "queue" backend (events pushed by the program). */
#include "devices/responder.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "devices/responder_backend.h"

#define QUEUE_CAP 256

typedef struct {
    csf_response ev[QUEUE_CAP];
    int head, count;
} queue_state;

static csf_status queue_open(const char *options, void *window, void **state, csf_error *err)
{
    (void)window;
    if (*options) return csf_error_set(err, CSF_E_INVALID_ARG, "responder queue takes no options (got '%s')", options);
    queue_state *q = calloc(1, sizeof *q);
    if (!q) return csf_error_set(err, CSF_E_NOMEM, "responder: out of memory");
    *state = q;
    return CSF_OK;
}

static int queue_poll(void *state, csf_response *out)
{
    queue_state *q = state;
    if (q->count == 0) return 0;
    *out = q->ev[q->head];
    q->head = (q->head + 1) % QUEUE_CAP;
    q->count--;
    return 1;
}

static void queue_close(void *state)
{
    free(state);
}

static const csf_responder_backend queue_backend = {"queue", queue_open, queue_poll, queue_close, NULL};

struct csf_responder {
    const csf_responder_backend *b;
    void *state;
};

static const csf_responder_backend *const backends[] = {
    &csf_responder_glfw_keyboard, &csf_responder_glfw_mouse, &csf_responder_gamepad, &csf_responder_hid,
    &queue_backend,
};

csf_status csf_responder_wrap(const csf_responder_backend *b, void *state, csf_responder **out, csf_error *err)
{
    csf_responder *r = calloc(1, sizeof *r);
    if (!r) {
        b->close(state);
        return csf_error_set(err, CSF_E_NOMEM, "responder: out of memory");
    }
    r->b = b;
    r->state = state;
    *out = r;
    return CSF_OK;
}

csf_status csf_responder_check_spec(const char *spec, csf_error *err)
{
    const char *colon = spec ? strchr(spec, ':') : NULL;
    size_t nl = spec ? (colon ? (size_t)(colon - spec) : strlen(spec)) : 0;
    const char *opts = colon ? colon + 1 : "";
    for (size_t i = 0; spec && i < sizeof backends / sizeof backends[0]; i++)
        if (strlen(backends[i]->name) == nl && strncmp(spec, backends[i]->name, nl) == 0) {
            if (backends[i]->check_options) return backends[i]->check_options(opts, err);
            if (*opts)
                return csf_error_set(err, CSF_E_INVALID_ARG, "responder %s takes no options (got '%.60s')",
                                     backends[i]->name, opts);
            return CSF_OK;
        }
    return csf_error_set(err, CSF_E_INVALID_ARG, "responder '%.100s' is unknown (known: keyboard, mouse, "
                         "gamepad[:N], hid:VID:PID[,map=...], queue)", spec ? spec : "(none)");
}

csf_status csf_responder_open(const char *spec, void *window, csf_responder **out, csf_error *err)
{
    *out = NULL;
    const csf_responder_backend *b = NULL;
    const char *colon = spec ? strchr(spec, ':') : NULL;
    size_t nl = spec ? (colon ? (size_t)(colon - spec) : strlen(spec)) : 0;
    for (size_t i = 0; spec && i < sizeof backends / sizeof backends[0]; i++)
        if (strlen(backends[i]->name) == nl && strncmp(spec, backends[i]->name, nl) == 0) b = backends[i];
    if (!b)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "responder '%.100s' is unknown (known: keyboard, mouse, gamepad[:N], "
                             "hid:VID:PID[,map=...], queue)", spec ? spec : "(none)");
    void *state = NULL;
    csf_status st = b->open(colon ? colon + 1 : "", window, &state, err);
    if (st != CSF_OK) return st;
    return csf_responder_wrap(b, state, out, err);
}

int csf_responder_poll(csf_responder *r, csf_response *out)
{
    return r->b->poll(r->state, out);
}

int csf_responder_push(csf_responder *r, const csf_response *ev)
{
    if (r->b != &queue_backend) return -1;
    queue_state *q = r->state;
    if (q->count == QUEUE_CAP) return -1;
    q->ev[(q->head + q->count) % QUEUE_CAP] = *ev;
    q->count++;
    return 0;
}

const char *csf_responder_name(const csf_responder *r)
{
    return r->b->name;
}

void csf_responder_close(csf_responder *r)
{
    if (!r) return;
    r->b->close(r->state);
    free(r);
}

double csf_responder_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}
