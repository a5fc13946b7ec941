/* Test-only transport: an instrument emulator loaded into the process (tests/usb/, built as a
 * shared module) stands where the USB device would be, speaking the same bytes. It is chosen by a
 * driver spec whose options start with "emulator" (colorcal2:emulator,..., colorhug2:emulator,...)
 * and only when the environment names the module in CSFCAL_TEST_USB_EMULATOR; without that variable
 * such a spec is refused, so a station cannot measure against an emulator by accident.
 *
 * Why in-process rather than umockdev: umockdev replays recorded usbdevfs ioctls and hidraw
 * reads, but a calibration is a closed loop -- each answer depends on the patch csfcal has just
 * drawn -- so a recording cannot answer it; the emulator needs the screen source the driver is
 * given (docs/instruments.md). */
#ifndef CSF_TRANSPORT_EMU_H
#define CSF_TRANSPORT_EMU_H

#include "devices/photometer_driver.h"

#define CSF_EMU_ENV "CSFCAL_TEST_USB_EMULATOR"
#define CSF_EMU_OPEN_SYMBOL "csf_emu_open_device"

typedef struct csf_emu_device {
    csf_transport t; /* first: the driver talks to it like any transport */
    /* What is under the sensor from now on (the driver calls it before each command). */
    void (*show)(struct csf_emu_device *d, const csf_screen_source *src);
    /* Identity the emulator reports as a USB device (serial string), for the spec's SERIAL. */
    const char *(*usb_serial)(struct csf_emu_device *d);
    /* The emulated instrument's clock runs on virtual time (a calibration's warm-up waits would
     * otherwise take minutes of test time): now, wait, and where a resumed session continues. */
    double (*now_s)(struct csf_emu_device *d);
    void (*wait)(struct csf_emu_device *d, double seconds);
    void (*resume_at)(struct csf_emu_device *d, uint64_t reading_index, double t_s);
} csf_emu_device;

/* Signature of the module's CSF_EMU_OPEN_SYMBOL: device is "colorcal2" or "colorhug2"; options
 * the text after "emulator," (emulator keys: display, fault, slow, seed, ...). */
typedef csf_status (*csf_emu_open_fn)(const char *device, const char *options, csf_emu_device **out,
                                      csf_error *err);

/* Loads the module named by CSFCAL_TEST_USB_EMULATOR and opens `device` in it. */
csf_status csf_transport_emu_open(const char *device, const char *options, csf_emu_device **out,
                                  csf_error *err);

#endif
