/* hidapi transport (see transport_hidapi.h). */
#include "devices/transport_hidapi.h"

#include <hidapi/hidapi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

typedef struct {
    csf_transport t;
    hid_device *h;
    char instrument[64];
} hid_tr;

static int timeout_ms(double s)
{
    if (!(s > 0)) return 1;
    return s > 600 ? 600000 : (int)ceil(s * 1000.0);
}

static csf_status hid_fail(hid_tr *h, const char *what, csf_error *err)
{
    const wchar_t *w = hid_error(h->h);
    char why[160] = "no reason given";
    if (w) snprintf(why, sizeof why, "%ls", w);
    return csf_error_set(err, CSF_E_GONE, "%s disconnected or failed during %s (hid %s returned -1: %s)",
                         h->instrument, what, what[0] == 'a' ? "write" : "read", why);
}

static csf_status hid_tr_write(csf_transport *t, const uint8_t *buf, size_t len, double timeout_s, csf_error *err)
{
    hid_tr *h = t->user;
    (void)timeout_s; /* hidapi's write blocks on the interrupt endpoint with its own limit */
    uint8_t rep[65];
    if (len > 64) return csf_error_set(err, CSF_E_INVALID_ARG, "HID report of %zu bytes (max 64)", len);
    rep[0] = 0; /* the ColorHug2 has no numbered reports */
    memset(rep + 1, 0, 64);
    memcpy(rep + 1, buf, len);
    if (hid_write(h->h, rep, sizeof rep) < 0) return hid_fail(h, "a command", err);
    return CSF_OK;
}

static csf_status hid_tr_read(csf_transport *t, uint8_t *buf, size_t cap, size_t *got, double timeout_s,
                              csf_error *err)
{
    hid_tr *h = t->user;
    *got = 0;
    int n = hid_read_timeout(h->h, buf, cap, timeout_ms(timeout_s));
    if (n < 0) return hid_fail(h, "reply", err);
    if (n == 0)
        return csf_error_set(err, CSF_E_TIMEOUT, "%s did not answer within %.1f s", h->instrument, timeout_s);
    *got = (size_t)n;
    return CSF_OK;
}

static void hid_tr_close(csf_transport *t)
{
    if (!t) return;
    hid_tr *h = t->user;
    if (h->h) hid_close(h->h);
    /* no hid_exit(): hidapi's state is per process and a HID response box may still be using it */
    free(h);
}

csf_status csf_transport_hidapi_open(uint16_t vid, uint16_t pid, const char *serial, const char *instrument,
                                     csf_transport **out, csf_error *err)
{
    *out = NULL;
    if (hid_init() != 0)
        return csf_error_set(err, CSF_E_UNSUPPORTED, "%s: hidapi could not start", instrument);
    wchar_t wserial[64];
    if (serial && *serial) {
        if (mbstowcs(wserial, serial, 63) == (size_t)-1) {
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: serial number '%s' is not text", instrument, serial);
        }
        wserial[63] = 0;
    }
    hid_device *dev = hid_open(vid, pid, serial && *serial ? wserial : NULL);
    if (!dev) {
        /* present but unopenable is a permission problem nine times in ten: say which */
        struct hid_device_info *list = hid_enumerate(vid, pid);
        int present = list != NULL;
        hid_free_enumeration(list);
        if (present)
            return csf_error_set(err, CSF_E_DEVICE, "%s (USB %04x:%04x) found but could not be opened: permission "
                                 "denied or held by another program (install csfcal's udev rules and re-plug it)",
                                 instrument, vid, pid);
        if (serial && *serial)
            return csf_error_set(err, CSF_E_NOT_FOUND, "%s with serial number %s not found", instrument, serial);
        return csf_error_set(err, CSF_E_NOT_FOUND, "%s (USB %04x:%04x) not found: is it plugged in?", instrument,
                             vid, pid);
    }
    hid_tr *h = calloc(1, sizeof *h);
    if (!h) {
        hid_close(dev);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    h->h = dev;
    snprintf(h->instrument, sizeof h->instrument, "%s", instrument);
    h->t.write = hid_tr_write;
    h->t.read = hid_tr_read;
    h->t.close = hid_tr_close;
    h->t.user = h;
    *out = &h->t;
    return CSF_OK;
}
