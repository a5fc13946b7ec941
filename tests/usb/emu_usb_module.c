/* The emulator module csfcal loads when CSFCAL_TEST_USB_EMULATOR names it (devices/transport_emu.h):
 * one entry point that opens the emulated instrument the driver asks for. */
#include <string.h>

#include "tests/usb/emu_colorcal2.h"
#include "tests/usb/emu_colorhug2.h"

csf_status csf_emu_open_device(const char *device, const char *options, csf_emu_device **out, csf_error *err);

__attribute__((visibility("default"))) csf_status csf_emu_open_device(const char *device, const char *options,
                                                                      csf_emu_device **out, csf_error *err)
{
    *out = NULL;
    if (strcmp(device, "colorcal2") == 0) return emu_colorcal2_open(options, out, err);
    if (strcmp(device, "colorhug2") == 0) return emu_colorhug2_open(options, out, err);
    return csf_error_set(err, CSF_E_NOT_FOUND, "no emulator for '%s' (colorcal2, colorhug2)", device);
}
