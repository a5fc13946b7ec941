/* Hughski ColorHug2 emulator (tests only). */
#ifndef CSF_EMU_COLORHUG2_H
#define CSF_EMU_COLORHUG2_H

#include "tests/usb/emu_light.h"

csf_status emu_colorhug2_open(const char *options, csf_emu_device **out, csf_error *err);

#endif
