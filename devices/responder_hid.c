/* USB HID button boxes through hidapi (see devices/responder_hid.h). A reader thread blocks on
 * the device and stamps each input report on CLOCK_MONOTONIC the moment it returns, so a response's
 * time does not wait for the session's next poll (a frame); the thread turns button edges into
 * responses and queues them for csf_responder_poll. */
#include "devices/responder_hid.h"

#include <errno.h>
#include <hidapi.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "devices/responder_backend.h"

#define HID_QUEUE_CAP 256

static int hexval(const char *p, size_t n, uint16_t *out)
{
    if (n > 2 && p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
        p += 2;
        n -= 2;
    }
    if (n == 0 || n > 4) return -1;
    unsigned v = 0;
    for (size_t i = 0; i < n; i++) {
        char c = p[i];
        int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (d < 0) return -1;
        v = v * 16 + (unsigned)d;
    }
    *out = (uint16_t)v;
    return 0;
}

static int intval(const char *p, size_t n, int lo, int hi, int *out)
{
    if (n == 0 || n > 3) return -1;
    int v = 0;
    for (size_t i = 0; i < n; i++) {
        if (p[i] < '0' || p[i] > '9') return -1;
        v = v * 10 + (p[i] - '0');
    }
    if (v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

static void default_map(csf_button_map *m)
{
    memset(m, 0, sizeof *m);
    static const unsigned char acts[8] = {CSF_ACT_PRESS, CSF_ACT_FIRST, CSF_ACT_SECOND, CSF_ACT_UL,
                                          CSF_ACT_UR, CSF_ACT_LL, CSF_ACT_LR, CSF_ACT_PAUSE};
    memcpy(m->action, acts, sizeof acts);
}

static csf_status bad(csf_error *err, const char *what, const char *p, size_t n)
{
    return csf_error_set(err, CSF_E_INVALID_ARG, "responder hid: %s (got '%.*s')", what, (int)(n > 60 ? 60 : n), p);
}

csf_status csf_hid_spec_parse(const char *options, csf_hid_spec *out, csf_error *err)
{
    csf_hid_spec s;
    memset(&s, 0, sizeof s);
    s.report_id = -1;
    s.bytes = 1;
    default_map(&s.map);
    const char *p = options ? options : "";
    size_t len = strlen(p);
    size_t comma = strcspn(p, ",");
    const char *colon = memchr(p, ':', comma);
    if (!colon || hexval(p, (size_t)(colon - p), &s.vid) || hexval(colon + 1, (size_t)(p + comma - colon - 1), &s.pid))
        return bad(err, "expected hid:VID:PID with hexadecimal ids of 1 to 4 digits, e.g. hid:1b4f:9206", p, comma);
    size_t i = comma;
    while (i < len) {
        i++; /* the comma */
        const char *o = p + i;
        size_t n = strcspn(o, ",");
        const char *eq = memchr(o, '=', n);
        if (!eq) return bad(err, "option is not key=value", o, n);
        size_t kn = (size_t)(eq - o), vn = n - kn - 1;
        const char *v = eq + 1;
        if (kn == 6 && !memcmp(o, "serial", 6)) {
            if (vn == 0 || vn >= sizeof s.serial) return bad(err, "serial= must have 1 to 63 characters", o, n);
            memcpy(s.serial, v, vn);
            s.serial[vn] = 0;
        } else if (kn == 6 && !memcmp(o, "report", 6)) {
            if (intval(v, vn, 1, 255, &s.report_id)) return bad(err, "report= is a report id, 1 to 255", o, n);
        } else if (kn == 6 && !memcmp(o, "offset", 6)) {
            if (intval(v, vn, 0, 63, &s.offset)) return bad(err, "offset= is a byte, 0 to 63", o, n);
        } else if (kn == 5 && !memcmp(o, "bytes", 5)) {
            if (intval(v, vn, 1, 8, &s.bytes)) return bad(err, "bytes= is 1 to 8", o, n);
        } else if (kn == 6 && !memcmp(o, "active", 6)) {
            if (vn == 3 && !memcmp(v, "low", 3)) s.active_low = 1;
            else if (vn == 4 && !memcmp(v, "high", 4)) s.active_low = 0;
            else return bad(err, "active= is low or high", o, n);
        } else if (kn == 3 && !memcmp(o, "map", 3)) {
            csf_status st = csf_button_map_parse(v, vn, &s.map, err);
            if (st) return st;
        } else {
            return bad(err, "unknown option (known: serial, report, offset, bytes, active, map)", o, n);
        }
        i += n;
    }
    *out = s;
    return CSF_OK;
}

int csf_hid_report_buttons(const csf_hid_spec *s, const uint8_t *report, size_t n, uint64_t *bits)
{
    const uint8_t *data = report;
    if (s->report_id >= 0) {
        if (n < 1 || report[0] != s->report_id) return -1;
        data++;
        n--;
    }
    if ((size_t)s->offset + (size_t)s->bytes > n) return -1;
    uint64_t b = 0;
    for (int j = 0; j < s->bytes; j++) {
        uint8_t v = data[s->offset + j];
        if (s->active_low) v = (uint8_t)~v;
        b |= (uint64_t)v << (8 * j);
    }
    *bits = b;
    return 0;
}

typedef struct {
    csf_hid_spec spec;
    csf_hid_io io;
    pthread_t thread;
    int thread_started;
    pthread_mutex_t mu;
    int stop;           /* under mu */
    int gone_reported;  /* under mu */
    csf_response q[HID_QUEUE_CAP];
    int head, count;    /* under mu */
    csf_responder *keys; /* the window's keyboard and mouse beside the box (Escape, fade's click) */
} hid_state;

static void enqueue(hid_state *h, const csf_response *ev, int n)
{
    pthread_mutex_lock(&h->mu);
    for (int i = 0; i < n && h->count < HID_QUEUE_CAP; i++) {
        h->q[(h->head + h->count) % HID_QUEUE_CAP] = ev[i];
        h->count++;
    }
    pthread_mutex_unlock(&h->mu);
}

static int stopping(hid_state *h)
{
    pthread_mutex_lock(&h->mu);
    int s = h->stop;
    pthread_mutex_unlock(&h->mu);
    return s;
}

static void *reader(void *arg)
{
    hid_state *h = arg;
    uint64_t prev = 0;
    uint8_t buf[256];
    while (!stopping(h)) {
        int n = h->io.read(&h->io, buf, sizeof buf, 50);
        double t = csf_responder_now(); /* the report's time: as soon as the read returns */
        if (n < 0) {
            csf_response gone;
            memset(&gone, 0, sizeof gone);
            gone.kind = CSF_RESP_ESCAPE;
            gone.key = CSF_RESP_KEY_GONE;
            gone.t_s = t;
            enqueue(h, &gone, 1);
            break;
        }
        uint64_t now;
        if (n == 0 || csf_hid_report_buttons(&h->spec, buf, (size_t)n, &now)) continue;
        csf_response ev[CSF_MAP_BUTTONS];
        int k = csf_button_events(&h->spec.map, prev, now, t, ev, CSF_MAP_BUTTONS);
        prev = now;
        if (k) enqueue(h, ev, k);
    }
    return NULL;
}

static int hid_poll(void *state, csf_response *out)
{
    hid_state *h = state;
    if (h->keys && csf_responder_poll(h->keys, out)) return 1; /* also runs glfwPollEvents */
    pthread_mutex_lock(&h->mu);
    int got = h->count > 0;
    if (got) {
        *out = h->q[h->head];
        h->head = (h->head + 1) % HID_QUEUE_CAP;
        h->count--;
    }
    pthread_mutex_unlock(&h->mu);
    return got;
}

static void hidr_close(void *state)
{
    hid_state *h = state;
    if (!h) return;
    if (h->thread_started) {
        pthread_mutex_lock(&h->mu);
        h->stop = 1;
        pthread_mutex_unlock(&h->mu);
        pthread_join(h->thread, NULL);
    }
    if (h->io.close) h->io.close(&h->io);
    csf_responder_close(h->keys);
    pthread_mutex_destroy(&h->mu);
    free(h);
}

static csf_status start(const csf_hid_spec *spec, csf_hid_io *io, void **state, csf_error *err)
{
    hid_state *h = calloc(1, sizeof *h);
    if (!h) {
        if (io->close) io->close(io);
        return csf_error_set(err, CSF_E_NOMEM, "responder hid: out of memory");
    }
    h->spec = *spec;
    h->io = *io;
    pthread_mutex_init(&h->mu, NULL);
    int rc = pthread_create(&h->thread, NULL, reader, h);
    if (rc) {
        hidr_close(h);
        return csf_error_set(err, CSF_E_DEVICE, "responder hid: cannot start its reader thread: %s", strerror(rc));
    }
    h->thread_started = 1;
    *state = h;
    return CSF_OK;
}

csf_status csf_responder_open_hid_io(const char *options, csf_hid_io *io, csf_responder **out,
                                     csf_error *err)
{
    *out = NULL;
    csf_hid_spec spec;
    csf_status st = csf_hid_spec_parse(options, &spec, err);
    if (st) {
        if (io->close) io->close(io);
        return st;
    }
    void *state = NULL;
    if ((st = start(&spec, io, &state, err))) return st;
    return csf_responder_wrap(&csf_responder_hid, state, out, err);
}

/* hidapi transport */
static int hidapi_read(csf_hid_io *io, uint8_t *buf, size_t cap, int timeout_ms)
{
    return hid_read_timeout((hid_device *)io->user, buf, cap, timeout_ms);
}

static void hidapi_close(csf_hid_io *io)
{
    /* no hid_exit(): hidapi's state is per process and a HID photometer (ColorHug2) may share it */
    hid_close((hid_device *)io->user);
}

static csf_status hid_open_backend(const char *options, void *window, void **state, csf_error *err)
{
    csf_hid_spec spec;
    csf_status st = csf_hid_spec_parse(options, &spec, err);
    if (st) return st;
    if (hid_init() != 0) return csf_error_set(err, CSF_E_DEVICE, "responder hid: hidapi could not start");
    wchar_t wserial[64];
    if (spec.serial[0]) mbstowcs(wserial, spec.serial, 64);
    wserial[63] = 0;
    /* hid_enumerate first: it tells "not connected" from "connected but not openable" */
    struct hid_device_info *list = hid_enumerate(spec.vid, spec.pid);
    int present = list != NULL;
    hid_free_enumeration(list);
    hid_device *dev = present ? hid_open(spec.vid, spec.pid, spec.serial[0] ? wserial : NULL) : NULL;
    if (!dev) {
        int e = errno;
        if (!present)
            return csf_error_set(err, CSF_E_NOT_FOUND, "responder hid: no HID device %04x:%04x is connected "
                                 "(csfcal devices lists what is)", spec.vid, spec.pid);
        return csf_error_set(err, CSF_E_DEVICE, "responder hid: HID device %04x:%04x is connected but cannot be "
                             "opened (%s): install csfcal's udev rules (scripts/setup.sh, data/udev/70-csfcal.rules) "
                             "and add a rule for this VID:PID, or check `csfcal devices`", spec.vid, spec.pid,
                             e ? strerror(e) : "permission denied or held by another program");
    }
    csf_hid_io io = {hidapi_read, hidapi_close, dev};
    if ((st = start(&spec, &io, state, err))) return st;
    /* the experimenter's Escape and the mouse (fade's "where was it" click) keep working */
    if (window && (st = csf_responder_open("keyboard", window, &((hid_state *)*state)->keys, err))) {
        hidr_close(*state);
        *state = NULL;
        return st;
    }
    return CSF_OK;
}

/* The spec's options parse (csf_responder_check_spec): nothing is opened. */
static csf_status hid_check_options(const char *options, csf_error *err)
{
    csf_hid_spec h;
    return csf_hid_spec_parse(options, &h, err);
}

const csf_responder_backend csf_responder_hid = {"hid", hid_open_backend, hid_poll, hidr_close,
                                                 hid_check_options};
