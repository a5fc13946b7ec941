/* USB HID button boxes through hidapi: spec, report decoding and the transport seam.
 *
 * Spec: "hid:VID:PID[,serial=S][,report=ID][,offset=BYTE][,bytes=N][,active=low][,map=...]"
 *   VID, PID    the device's USB vendor and product id, hexadecimal (1 to 4 digits, e.g. 0x1b4f or 1b4f)
 *   serial=S    this unit only, when several of one kind are connected
 *   report=ID   the box sends numbered reports: only reports whose first byte is ID (1 to 255) are
 *               read, and the data starts after that byte. Default: unnumbered reports (hidapi
 *               then delivers the data alone)
 *   offset=BYTE the byte of the data where the button bits begin (0 to 63; default 0)
 *   bytes=N     how many bytes of button bits (1 to 8; default 1): bit k of byte j is button 8j + k,
 *               least significant bit first, the order of a HID report descriptor's Button usage page
 *   active=low  a 0 bit means pressed (default: 1 means pressed)
 *   map=...     which button means what (devices/responder_map.h); default
 *               press:0/first:1/second:2/ul:3/ur:4/ll:5/lr:6/pause:7
 * The format assumed is the common one of USB button boxes and arcade encoders that enumerate as
 * a HID gamepad or generic device: one input report per change, the buttons one bit each in
 * consecutive bytes. A box whose report differs is adapted with report=, offset=, bytes= and
 * active= (its report descriptor, e.g. from `usbhid-dump -e descriptor` or
 * /sys/class/hidraw/hidrawN/device/report_descriptor, says where its button bits are).
 * Boxes that enumerate as a keyboard (many do) need no hid responder: use "keyboard". */
#ifndef CSF_RESPONDER_HID_H
#define CSF_RESPONDER_HID_H

#include <stddef.h>
#include <stdint.h>

#include "devices/responder.h"
#include "devices/responder_map.h"

typedef struct {
    uint16_t vid, pid;
    char serial[64];   /* "" = any unit */
    int report_id;     /* -1: unnumbered reports */
    int offset;        /* first byte of the button bits in the data */
    int bytes;         /* bytes of button bits, 1 to 8 */
    int active_low;
    csf_button_map map;
} csf_hid_spec;

/* Parses the text after "hid:". Refused with the option, its range and exit-2 status
 * (CSF_E_INVALID_ARG). */
csf_status csf_hid_spec_parse(const char *options, csf_hid_spec *out, csf_error *err);

/* The buttons held in one input report (bit i = button i). Returns 0, or -1 when the report is
 * not one to read (another report id, or too short to hold the button bytes). */
int csf_hid_report_buttons(const csf_hid_spec *s, const uint8_t *report, size_t n, uint64_t *bits);

/* Where input reports come from: hidapi on a real device, an emulator in tests. */
typedef struct csf_hid_io {
    /* One input report into buf: its length, 0 when none came within timeout_ms, -1 when the
     * device has gone. Called from the responder's reader thread only. */
    int (*read)(struct csf_hid_io *io, uint8_t *buf, size_t cap, int timeout_ms);
    void (*close)(struct csf_hid_io *io);
    void *user;
} csf_hid_io;

/* Opens a hid responder on io instead of hidapi (options as after "hid:"; VID:PID are parsed and
 * kept but no device is opened). The responder owns io from here on (io->close at the end). */
csf_status csf_responder_open_hid_io(const char *options, csf_hid_io *io, csf_responder **out,
                                     csf_error *err);

#endif
