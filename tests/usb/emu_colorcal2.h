/* CRS ColorCAL MkII emulator (tests only). */
#ifndef CSF_EMU_COLORCAL2_H
#define CSF_EMU_COLORCAL2_H

#include "tests/usb/emu_light.h"

csf_status emu_colorcal2_open(const char *options, csf_emu_device **out, csf_error *err);

#endif
