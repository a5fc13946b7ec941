/* What the USB photometer drivers share: the spec's options (SERIAL, emulator, keys), the clock
 * a real instrument's readings are stamped with, and opening the transport. */
#ifndef CSF_USB_COMMON_H
#define CSF_USB_COMMON_H

#include <stdint.h>

#include "devices/photometer_driver.h"
#include "devices/transport_emu.h"

typedef struct {
    const char *instrument;   /* "ColorCAL MkII" */
    const char *spec_name;    /* "colorcal2" */
    csf_transport *t;
    csf_emu_device *emu;      /* non-NULL when an emulator stands in for the device */
    char serial[64];          /* from the spec ("" = first found), later the device's own */
    double timeout_s;         /* per reply */
    double t_base_s, t_open_mono_s; /* real clock: t = t_base + (now - t_open) */
    uint64_t n;               /* readings attempted */
} csf_usb_meter;

/* A driver key=value the caller understands: returns 1 if it took it, 0 if not, -1 on error. */
typedef int (*csf_usb_key_fn)(void *drv_state, const char *key, const char *value, csf_error *err);

/* Parses "[SERIAL|emulator][,key=value...]": driver keys go to key_fn (timeout_s is handled
 * here); in emulator mode the keys key_fn does not take are handed to the emulator. Then opens
 * the emulator (emulator mode) and leaves m->t NULL otherwise (the driver opens the real
 * transport). */
csf_status csf_usb_parse_options(csf_usb_meter *m, const char *options, csf_usb_key_fn key_fn, void *drv_state,
                                 csf_error *err);
/* Reads one reply; a reply that does not come is CSF_E_TIMEOUT naming the instrument. */
csf_status csf_usb_exchange(csf_usb_meter *m, const uint8_t *cmd, size_t cmd_len, uint8_t *reply, size_t cap,
                            size_t *got, const csf_screen_source *src, csf_error *err);
double csf_usb_now(csf_usb_meter *m);
void csf_usb_wait(csf_usb_meter *m, double seconds);
void csf_usb_resume_at(csf_usb_meter *m, uint64_t reading_index, double t_s);
void csf_usb_close(csf_usb_meter *m);
/* Prefixes err's message with the instrument's name and serial ("ColorCAL MkII 12345678: ..."). */
csf_status csf_usb_name_error(const csf_usb_meter *m, csf_status st, csf_error *err);
/* Number within [lo, hi] or an error naming the spec key and the range. */
int csf_usb_number(const char *spec_name, const char *key, const char *v, double lo, double hi, double *out,
                   csf_error *err);

#endif
