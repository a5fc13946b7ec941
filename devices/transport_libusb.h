/* A csf_transport over libusb vendor control transfers (the ColorCAL MkII's command channel):
 * write() is one host-to-device transfer carrying the bytes, read() one device-to-host transfer.
 * While open, the kernel drivers bound to the device's interfaces (cdc_acm for the ColorCAL, which
 * also presents itself as a serial port) are detached; closing re-attaches them. */
#ifndef CSF_TRANSPORT_LIBUSB_H
#define CSF_TRANSPORT_LIBUSB_H

#include <stdint.h>

#include "devices/photometer_driver.h"

typedef struct {
    uint16_t vid, pid;
    const char *serial;       /* NULL or "": the first matching device */
    const char *instrument;   /* for messages: "ColorCAL MkII" */
    uint8_t request_out, request_in; /* bmRequestType of the two transfers (0x40, 0xC0) */
    uint8_t b_request;
    uint16_t w_value, w_index;
} csf_usb_control_config;

csf_status csf_transport_libusb_open(const csf_usb_control_config *cfg, csf_transport **out, csf_error *err);

/* libusb error code -> csfcal status (NO_DEVICE: gone, TIMEOUT: timeout, ACCESS: a permission
 * problem worded as such, BUSY: another program holds it, else a device error). */
csf_status csf_usb_status(int libusb_rc);

#endif
