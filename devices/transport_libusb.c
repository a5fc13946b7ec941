/* libusb control-transfer transport (see transport_libusb.h). */
#include "devices/transport_libusb.h"

#include <libusb-1.0/libusb.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_IFACES = 8 };

typedef struct {
    csf_transport t;
    libusb_context *ctx;
    libusb_device_handle *h;
    csf_usb_control_config cfg;
    char instrument[64];
    int n_ifaces;
    int claimed[MAX_IFACES];
    int detached[MAX_IFACES];
} usb_tr;

csf_status csf_usb_status(int rc)
{
    switch (rc) {
    case LIBUSB_ERROR_NO_DEVICE: return CSF_E_GONE;
    case LIBUSB_ERROR_TIMEOUT: return CSF_E_TIMEOUT;
    case LIBUSB_ERROR_ACCESS: return CSF_E_DEVICE;
    case LIBUSB_ERROR_NOT_FOUND: return CSF_E_NOT_FOUND;
    default: return CSF_E_DEVICE;
    }
}

static unsigned timeout_ms(double s)
{
    if (!(s > 0)) return 1;
    return s > 600 ? 600000u : (unsigned)ceil(s * 1000.0);
}

static csf_status usb_fail(usb_tr *u, int rc, const char *what, csf_error *err)
{
    csf_status st = csf_usb_status(rc);
    if (rc == LIBUSB_ERROR_NO_DEVICE)
        return csf_error_set(err, st, "%s disconnected during %s (LIBUSB_ERROR_NO_DEVICE)", u->instrument, what);
    if (rc == LIBUSB_ERROR_TIMEOUT)
        return csf_error_set(err, st, "%s did not answer in time during %s (LIBUSB_ERROR_TIMEOUT)",
                             u->instrument, what);
    return csf_error_set(err, st, "%s: USB %s failed: %s (%s)", u->instrument, what, libusb_strerror(rc),
                         libusb_error_name(rc));
}

static csf_status usb_write(csf_transport *t, const uint8_t *buf, size_t len, double timeout_s, csf_error *err)
{
    usb_tr *u = t->user;
    if (len > 0xffff) return csf_error_set(err, CSF_E_INVALID_ARG, "USB control transfer of %zu bytes (max 65535)", len);
    int rc = libusb_control_transfer(u->h, u->cfg.request_out, u->cfg.b_request, u->cfg.w_value, u->cfg.w_index,
                                     (unsigned char *)buf, (uint16_t)len, timeout_ms(timeout_s));
    if (rc < 0) return usb_fail(u, rc, "a command", err);
    if ((size_t)rc != len)
        return csf_error_set(err, CSF_E_DEVICE, "%s took %d of %zu command bytes", u->instrument, rc, len);
    return CSF_OK;
}

static csf_status usb_read(csf_transport *t, uint8_t *buf, size_t cap, size_t *got, double timeout_s,
                           csf_error *err)
{
    usb_tr *u = t->user;
    *got = 0;
    if (cap > 0xffff) cap = 0xffff;
    int rc = libusb_control_transfer(u->h, u->cfg.request_in, u->cfg.b_request, u->cfg.w_value, u->cfg.w_index,
                                     buf, (uint16_t)cap, timeout_ms(timeout_s));
    if (rc < 0) return usb_fail(u, rc, "a reply", err);
    *got = (size_t)rc;
    return CSF_OK;
}

/* Gives the interfaces back and re-attaches the kernel drivers that were bound to them, so the
 * ColorCAL is a serial port again for other programs. */
static void usb_close(csf_transport *t)
{
    if (!t) return;
    usb_tr *u = t->user;
    for (int i = 0; i < u->n_ifaces; i++) {
        if (u->claimed[i]) libusb_release_interface(u->h, i);
        if (u->detached[i]) libusb_attach_kernel_driver(u->h, i);
    }
    if (u->h) libusb_close(u->h);
    if (u->ctx) libusb_exit(u->ctx);
    free(u);
}

static int serial_matches(libusb_device_handle *h, uint8_t idx, const char *want)
{
    if (!want || !*want) return 1;
    unsigned char s[128];
    if (idx == 0 || libusb_get_string_descriptor_ascii(h, idx, s, sizeof s) < 0) return 0;
    return strcmp((const char *)s, want) == 0;
}

csf_status csf_transport_libusb_open(const csf_usb_control_config *cfg, csf_transport **out, csf_error *err)
{
    *out = NULL;
    usb_tr *u = calloc(1, sizeof *u);
    if (!u) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    u->cfg = *cfg;
    snprintf(u->instrument, sizeof u->instrument, "%s", cfg->instrument);
    u->t.write = usb_write;
    u->t.read = usb_read;
    u->t.close = usb_close;
    u->t.user = u;
    int rc = libusb_init(&u->ctx);
    if (rc) {
        free(u);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "%s: libusb could not start: %s", cfg->instrument,
                             libusb_error_name(rc));
    }
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(u->ctx, &list);
    int seen = 0, denied = 0;
    for (ssize_t i = 0; i < n && !u->h; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) || d.idVendor != cfg->vid || d.idProduct != cfg->pid) continue;
        seen++;
        libusb_device_handle *h = NULL;
        rc = libusb_open(list[i], &h);
        if (rc) {
            if (rc == LIBUSB_ERROR_ACCESS) denied++;
            continue;
        }
        if (serial_matches(h, d.iSerialNumber, cfg->serial)) {
            u->h = h;
            struct libusb_config_descriptor *c = NULL;
            if (libusb_get_active_config_descriptor(list[i], &c) == 0) {
                u->n_ifaces = c->bNumInterfaces < MAX_IFACES ? c->bNumInterfaces : MAX_IFACES;
                libusb_free_config_descriptor(c);
            }
        } else {
            libusb_close(h);
        }
    }
    if (n >= 0) libusb_free_device_list(list, 1);
    if (!u->h) {
        libusb_exit(u->ctx);
        free(u);
        if (denied)
            return csf_error_set(err, CSF_E_DEVICE, "%s (USB %04x:%04x) found but not accessible: permission "
                                 "denied (install csfcal's udev rules and re-plug it, or join the group they name)",
                                 cfg->instrument, cfg->vid, cfg->pid);
        if (seen && cfg->serial && *cfg->serial)
            return csf_error_set(err, CSF_E_NOT_FOUND, "%s with serial number %s not found (%d other %s "
                                 "connected)", cfg->instrument, cfg->serial, seen, seen == 1 ? "is" : "are");
        return csf_error_set(err, CSF_E_NOT_FOUND, "%s (USB %04x:%04x) not found: is it plugged in?",
                             cfg->instrument, cfg->vid, cfg->pid);
    }
    /* the kernel's cdc_acm owns the interfaces: detach it for as long as we hold the device */
    for (int i = 0; i < u->n_ifaces; i++) {
        if (libusb_kernel_driver_active(u->h, i) == 1) {
            rc = libusb_detach_kernel_driver(u->h, i);
            if (rc && rc != LIBUSB_ERROR_NOT_FOUND) {
                csf_status st = csf_error_set(err, csf_usb_status(rc), "%s: could not detach the kernel driver "
                                              "from interface %d: %s", cfg->instrument, i, libusb_error_name(rc));
                usb_close(&u->t);
                return st;
            }
            u->detached[i] = rc == 0;
        }
        rc = libusb_claim_interface(u->h, i);
        if (rc) {
            csf_status st = csf_error_set(err, csf_usb_status(rc), "%s: interface %d is held by another program "
                                          "(%s)", cfg->instrument, i, libusb_error_name(rc));
            usb_close(&u->t);
            return st;
        }
        u->claimed[i] = 1;
    }
    *out = &u->t;
    return CSF_OK;
}
