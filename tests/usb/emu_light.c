/* Shared instrument emulation (see emu_light.h). */
#include "tests/usb/emu_light.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/rng.h"

enum { STREAM_REL = 0xe301, STREAM_ABS = 0xe311, STREAM_GARBAGE = 0xe321 };

static const char *fault_names[] = {"none", "unplug", "timeout", "garbage", "truncated", "error", "dark", "saturate"};

static int num(const char *v, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    if (errno || end == v || *end || !isfinite(x) || x < lo || x > hi) return -1;
    *out = x;
    return 0;
}

static void sleep_s(double s)
{
    if (!(s > 0)) return;
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {
    }
}

static csf_status emu_write(csf_transport *t, const uint8_t *buf, size_t len, double timeout_s, csf_error *err)
{
    emu_common *e = t->user;
    (void)timeout_s;
    if (e->gone)
        return e->hid ? csf_error_set(err, CSF_E_GONE, "%s disconnected or failed during a command (hid write "
                                      "returned -1: emulated unplug)", e->instrument)
                      : csf_error_set(err, CSF_E_GONE, "%s disconnected during a command (LIBUSB_ERROR_NO_DEVICE)",
                                      e->instrument);
    e->reply_len = 0;
    e->reply_timeout = 0;
    e->on_command(e, buf, len);
    if (e->gone) return emu_write(t, buf, len, timeout_s, err);
    return CSF_OK;
}

static csf_status emu_timeout(emu_common *e, double timeout_s, csf_error *err)
{
    return e->hid ? csf_error_set(err, CSF_E_TIMEOUT, "%s did not answer within %.1f s", e->instrument, timeout_s)
                  : csf_error_set(err, CSF_E_TIMEOUT, "%s did not answer in time during a reply "
                                  "(LIBUSB_ERROR_TIMEOUT)", e->instrument);
}

static csf_status emu_read(csf_transport *t, uint8_t *buf, size_t cap, size_t *got, double timeout_s,
                           csf_error *err)
{
    emu_common *e = t->user;
    *got = 0;
    if (e->gone)
        return e->hid ? csf_error_set(err, CSF_E_GONE, "%s disconnected or failed during reply (hid read returned "
                                      "-1: emulated unplug)", e->instrument)
                      : csf_error_set(err, CSF_E_GONE, "%s disconnected during a reply (LIBUSB_ERROR_NO_DEVICE)",
                                      e->instrument);
    if (e->slow_s > 0 && e->n_meas >= e->slow_from) {
        /* a slow instrument: the answer takes real time, and past the limit it never comes */
        sleep_s(e->slow_s < timeout_s ? e->slow_s : timeout_s);
        if (e->slow_s >= timeout_s) return emu_timeout(e, timeout_s, err);
    }
    if (e->reply_timeout) return emu_timeout(e, timeout_s, err);
    size_t n = e->reply_len < cap ? e->reply_len : cap;
    memcpy(buf, e->reply, n);
    *got = n;
    e->reply_len = 0;
    return CSF_OK;
}

static void emu_close(csf_transport *t)
{
    emu_common *e = t->user;
    if (e->free_proto) e->free_proto(e);
    csf_display_model_free(e->display);
    free(e);
}

static void emu_show(csf_emu_device *d, const csf_screen_source *src)
{
    emu_common *e = (emu_common *)d;
    e->src = *src;
    e->has_src = src->patch || src->pixels;
}

static const char *emu_serial(csf_emu_device *d) { return ((emu_common *)d)->serial; }
static double emu_now(csf_emu_device *d) { return ((emu_common *)d)->t_s; }
static void emu_wait(csf_emu_device *d, double s) { ((emu_common *)d)->t_s += s; }
static void emu_resume(csf_emu_device *d, uint64_t idx, double t_s)
{
    emu_common *e = (emu_common *)d;
    e->n_meas = idx;
    if (t_s > e->t_s) e->t_s = t_s;
}

csf_status emu_common_init(emu_common *e, const char *instrument, const char *options,
                           int (*proto_key)(emu_common *e, const char *k, const char *v, csf_error *err),
                           csf_error *err)
{
    e->instrument = instrument;
    e->seed = 1;
    e->noise_rel = 0.001;
    e->noise_abs_cdm2 = 0.0005;
    e->dev.t.write = emu_write;
    e->dev.t.read = emu_read;
    e->dev.t.close = emu_close;
    e->dev.t.user = e;
    e->dev.show = emu_show;
    e->dev.usb_serial = emu_serial;
    e->dev.now_s = emu_now;
    e->dev.wait = emu_wait;
    e->dev.resume_at = emu_resume;
    char kind[64] = "lcd", extra[400] = "", buf[600];
    if (strlen(options) >= sizeof buf)
        return csf_error_set(err, CSF_E_INVALID_ARG, "emulator options longer than %zu characters", sizeof buf - 1);
    strcpy(buf, options);
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq) return csf_error_set(err, CSF_E_INVALID_ARG, "emulator option '%s' is not key=value", tok);
        *eq = '\0';
        const char *k = tok, *v = eq + 1;
        double x;
        if (!strcmp(k, "display")) {
            if (strcmp(v, "crt") && strcmp(v, "lcd") && strcmp(v, "oled"))
                return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: display=%s (crt, lcd or oled)", v);
            snprintf(kind, sizeof kind, "%s", v);
        } else if (!strcmp(k, "lmax") || !strcmp(k, "black") || !strcmp(k, "gamma") || !strcmp(k, "interaction")) {
            size_t l = strlen(extra);
            snprintf(extra + l, sizeof extra - l, ",%s=%s", k, v);
        } else if (!strcmp(k, "noise")) {
            if (num(v, 0, 0.2, &e->noise_rel)) return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: noise=%s (0..0.2)", v);
        } else if (!strcmp(k, "abs_noise")) {
            if (num(v, 0, 10, &e->noise_abs_cdm2))
                return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: abs_noise=%s (0..10 cd/m2)", v);
        } else if (!strcmp(k, "seed")) {
            if (num(v, 0, 1e15, &x)) return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: seed=%s", v);
            e->seed = (uint64_t)x;
        } else if (!strcmp(k, "slow")) {
            char sb[64];
            snprintf(sb, sizeof sb, "%s", v);
            char *at = strchr(sb, '@');
            if (at) *at = '\0';
            if (num(sb, 0, 600, &e->slow_s) || (at && num(at + 1, 0, 1e9, &x)))
                return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: slow=%s (S[@N]: 0..600 s, from measurement N)", v);
            e->slow_from = at ? (uint64_t)x + 1 : 0;
        } else if (!strcmp(k, "serial")) {
            snprintf(e->serial, sizeof e->serial, "%s", v);
        } else if (!strcmp(k, "fault")) {
            const char *at = strchr(v, '@');
            size_t kl = at ? (size_t)(at - v) : strlen(v);
            e->fault = -1;
            for (int f = 1; f <= EMU_SATURATE; f++)
                if (strlen(fault_names[f]) == kl && !strncmp(v, fault_names[f], kl)) e->fault = f;
            const char *plus = at ? strchr(at + 1, '+') : NULL;
            char nbuf[32] = "";
            double cnt = 0;
            if (at) snprintf(nbuf, sizeof nbuf, "%.*s", plus ? (int)(plus - at - 1) : (int)strlen(at + 1), at + 1);
            if (e->fault < 0 || !at || num(nbuf, 0, 1e9, &x) || (plus && num(plus + 1, 1, 1e9, &cnt)))
                return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: fault=%s (KIND@N[+COUNT], KIND one of unplug, "
                                     "timeout, garbage, truncated, error, dark, saturate)", v);
            e->fault_at = (uint64_t)x;
            e->fault_count = (uint64_t)cnt;
        } else {
            int took = proto_key ? proto_key(e, k, v, err) : 0;
            if (took < 0) return err->code;
            if (!took)
                return csf_error_set(err, CSF_E_INVALID_ARG, "emulator: unknown option '%s' (display, lmax, black, "
                                     "gamma, interaction, noise, abs_noise, seed, serial, slow, fault)", k);
        }
    }
    char spec[500];
    snprintf(spec, sizeof spec, "%s%s", kind, extra);
    return csf_display_model_create(spec, &e->display, err);
}

int emu_fault_for(const emu_common *e, uint64_t idx)
{
    if (!e->fault || idx < e->fault_at) return EMU_OK;
    if (e->fault_count) return idx - e->fault_at < e->fault_count ? e->fault : EMU_OK;
    switch (e->fault) {
    case EMU_UNPLUG:
    case EMU_DARK:
    case EMU_SATURATE: return e->fault;
    default: return idx == e->fault_at ? e->fault : EMU_OK;
    }
}

void emu_sense(emu_common *e, double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0;
    if (!e->has_src) return;
    if (e->src.pixels) {
        const void *px;
        size_t n = 0;
        int bits = 8;
        if (e->src.pixels(e->src.user, &px, &n, &bits) || n == 0 || bits < 1 || bits > 16) return;
        double maxv = (double)((1u << bits) - 1), acc[3] = {0, 0, 0};
        for (size_t i = 0; i < n; i++) {
            double v[3], x[3];
            for (int c = 0; c < 3; c++)
                v[c] = bits <= 8 ? ((const unsigned char *)px)[3 * i + c] / maxv : ((const uint16_t *)px)[3 * i + c] / maxv;
            csf_display_model_xyz(e->display, v[0], v[1], v[2], x);
            for (int k = 0; k < 3; k++) acc[k] += x[k];
        }
        for (int k = 0; k < 3; k++) xyz[k] = acc[k] / (double)n;
        return;
    }
    double rgb[3];
    if (e->src.patch && e->src.patch(e->src.user, rgb) == CSF_OK)
        csf_display_model_xyz(e->display, rgb[0], rgb[1], rgb[2], xyz);
}

double emu_noise_rel(const emu_common *e, uint64_t idx, int channel)
{
    return e->noise_rel * csf_rng_normal(e->seed, STREAM_REL + (uint64_t)channel, idx);
}

double emu_noise_abs(const emu_common *e, uint64_t idx, int channel)
{
    return e->noise_abs_cdm2 * csf_rng_normal(e->seed, STREAM_ABS + (uint64_t)channel, idx);
}

void emu_set_reply(emu_common *e, const void *bytes, size_t len)
{
    if (len > sizeof e->reply) len = sizeof e->reply;
    memcpy(e->reply, bytes, len);
    e->reply_len = len;
}

void emu_garbage(emu_common *e, uint64_t idx, size_t len)
{
    if (len > sizeof e->reply) len = sizeof e->reply;
    for (size_t i = 0; i < len; i++) e->reply[i] = (uint8_t)(csf_rng_u64(e->seed, STREAM_GARBAGE + i, idx) & 0xff);
    e->reply_len = len;
}
