/* Shared plumbing of the USB photometer drivers (see usb_common.h). */
#include "devices/usb_common.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

int csf_usb_number(const char *spec_name, const char *key, const char *v, double lo, double hi, double *out,
                   csf_error *err)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    if (errno || end == v || *end || !isfinite(x) || x < lo || x > hi) {
        csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s=%s out of range (%g to %g)", spec_name, key, v, lo, hi);
        return -1;
    }
    *out = x;
    return 0;
}

static int serial_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n > 63) return 0;
    for (size_t i = 0; i < n; i++)
        if (!isalnum((unsigned char)s[i]) && s[i] != '-' && s[i] != '_' && s[i] != '.') return 0;
    return 1;
}

csf_status csf_usb_parse_options(csf_usb_meter *m, const char *options, csf_usb_key_fn key_fn, void *drv_state,
                                 csf_error *err)
{
    char buf[600], emu_opts[600] = "";
    if (strlen(options) >= sizeof buf)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s options longer than %zu characters", m->spec_name,
                             sizeof buf - 1);
    strcpy(buf, options);
    int emulator = 0, first = 1;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save), first = 0) {
        char *eq = strchr(tok, '=');
        if (!eq) {
            if (first && strcmp(tok, "emulator") == 0) {
                emulator = 1;
                continue;
            }
            if (first && serial_ok(tok)) {
                snprintf(m->serial, sizeof m->serial, "%s", tok);
                continue;
            }
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: '%s' is neither a serial number (letters, digits, "
                                 "- _ . up to 63, first after the colon) nor key=value", m->spec_name, tok);
        }
        *eq = '\0';
        const char *k = tok, *v = eq + 1;
        if (strcmp(k, "timeout_s") == 0) {
            if (csf_usb_number(m->spec_name, k, v, 0.05, 120, &m->timeout_s, err)) return err->code;
            continue;
        }
        int took = key_fn ? key_fn(drv_state, k, v, err) : 0;
        if (took < 0) return err->code;
        if (took) continue;
        if (!emulator)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: unknown option '%s' (see docs/instruments.md)",
                                 m->spec_name, k);
        size_t l = strlen(emu_opts);
        snprintf(emu_opts + l, sizeof emu_opts - l, "%s%s=%s", l ? "," : "", k, v);
    }
    if (!emulator) return CSF_OK;
    csf_status st = csf_transport_emu_open(m->spec_name, emu_opts, &m->emu, err);
    if (st) return st;
    m->t = &m->emu->t;
    return CSF_OK;
}

csf_status csf_usb_exchange(csf_usb_meter *m, const uint8_t *cmd, size_t cmd_len, uint8_t *reply, size_t cap,
                            size_t *got, const csf_screen_source *src, csf_error *err)
{
    if (m->emu && src) m->emu->show(m->emu, src);
    csf_status st = m->t->write(m->t, cmd, cmd_len, m->timeout_s, err);
    if (st) return st;
    st = m->t->read(m->t, reply, cap, got, m->timeout_s, err);
    if (st) return st;
    if (*got == 0)
        return csf_error_set(err, CSF_E_TIMEOUT, "no answer within %.1f s", m->timeout_s);
    return CSF_OK;
}

double csf_usb_now(csf_usb_meter *m)
{
    if (m->emu) return m->emu->now_s(m->emu);
    return m->t_base_s + (mono_s() - m->t_open_mono_s);
}

void csf_usb_wait(csf_usb_meter *m, double seconds)
{
    if (!(seconds > 0)) return;
    if (m->emu) {
        m->emu->wait(m->emu, seconds);
        return;
    }
    struct timespec ts = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {
    }
}

void csf_usb_resume_at(csf_usb_meter *m, uint64_t reading_index, double t_s)
{
    m->n = reading_index;
    if (m->emu) {
        m->emu->resume_at(m->emu, reading_index, t_s);
        return;
    }
    /* a real instrument's clock is the wall clock: continue the session's time from t_s */
    if (t_s > csf_usb_now(m)) {
        m->t_base_s = t_s;
        m->t_open_mono_s = mono_s();
    }
}

void csf_usb_close(csf_usb_meter *m)
{
    if (m->t) m->t->close(m->t);
    m->t = NULL;
    m->emu = NULL;
}

csf_status csf_usb_name_error(const csf_usb_meter *m, csf_status st, csf_error *err)
{
    if (!st) return st;
    char msg[sizeof err->msg];
    snprintf(msg, sizeof msg, "%s", err->msg);
    /* the transports already name the instrument; do not say it twice */
    if (strncmp(msg, m->instrument, strlen(m->instrument)) == 0)
        return csf_error_set(err, st, "%s", msg);
    if (m->serial[0])
        return csf_error_set(err, st, "%s %s: %s", m->instrument, m->serial, msg);
    return csf_error_set(err, st, "%s: %s", m->instrument, msg);
}
