/* A csf_transport over hidapi (the ColorHug2's 64-byte reports): write() sends one output report
 * (report id 0 is added here), read() returns one input report. hid read -1 means the device is
 * gone; a read that times out returns CSF_E_TIMEOUT. */
#ifndef CSF_TRANSPORT_HIDAPI_H
#define CSF_TRANSPORT_HIDAPI_H

#include <stdint.h>

#include "devices/photometer_driver.h"

/* serial: NULL or "" for the first device with this VID:PID; instrument names it in messages. */
csf_status csf_transport_hidapi_open(uint16_t vid, uint16_t pid, const char *serial, const char *instrument,
                                     csf_transport **out, csf_error *err);

#endif
