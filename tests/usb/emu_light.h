/* What the USB instrument emulators share: the instrument's view of the simulated display (the
 * screen source the driver passes on, through model/display_model.h), its noise, its virtual
 * clock, the faults it can be told to have, and a pending reply with the transport's behaviour
 * (slow answers, timeouts, unplugging). Each protocol (emu_colorcal2.c, emu_colorhug2.c) turns
 * commands into reply bytes on top of it.
 *
 * Emulator options (after "colorcal2:emulator," / "colorhug2:emulator,"):
 *   display=crt|lcd|oled (lcd)  lmax= black= gamma= interaction=   the simulated monitor
 *   noise=REL (0.001)  abs_noise=CDM2 (0.0005)  seed=N (1)            per-reading noise
 *   serial=TEXT                                                       the device's serial number
 *   slow=S[@N]                  every answer (from measurement N on) takes S seconds of real time
 *                               (a timeout if S exceeds the driver's timeout_s)
 *   fault=KIND@N[+COUNT]        from measurement N (0-based): unplug, timeout, garbage, truncated,
 *                               error (an instrument error code), dark (sensor facing the desk),
 *   (ColorCAL only) uncapped=1  light reaches the sensor at open, so a zero calibration fails
 *                               saturate (a light far above range). timeout, garbage, truncated and
 *                               error hit measurement N only; the others persist, or last COUNT. */
#ifndef CSF_EMU_LIGHT_H
#define CSF_EMU_LIGHT_H

#include <stddef.h>
#include <stdint.h>

#include "model/display_model.h"
#include "devices/transport_emu.h"

enum { EMU_OK, EMU_UNPLUG, EMU_TIMEOUT, EMU_GARBAGE, EMU_TRUNCATED, EMU_ERROR, EMU_DARK, EMU_SATURATE };

typedef struct emu_common {
    csf_emu_device dev; /* first */
    const char *instrument;
    int hid;            /* messages in hidapi's words rather than libusb's */
    csf_display_model *display;
    uint64_t seed;
    double noise_rel, noise_abs_cdm2, slow_s;
    uint64_t slow_from; /* slow once this many measurements were taken (0: from the start) */
    int fault;
    uint64_t fault_at, fault_count;
    char serial[64];
    double t_s;         /* virtual clock */
    uint64_t n_meas;    /* measurements taken: the noise index */
    csf_screen_source src;
    int has_src;
    int gone;
    int reply_timeout;  /* the pending reply never comes */
    uint8_t reply[128];
    size_t reply_len;
    /* the protocol's command handler: sets reply/reply_len (or a fault) */
    void (*on_command)(struct emu_common *e, const uint8_t *buf, size_t len);
    void (*free_proto)(struct emu_common *e);
} emu_common;

/* Parses the common options into e; keys it does not know go to proto_key (NULL: refused). */
csf_status emu_common_init(emu_common *e, const char *instrument, const char *options,
                           int (*proto_key)(emu_common *e, const char *k, const char *v, csf_error *err),
                           csf_error *err);
/* The fault in force for measurement `idx` (EMU_OK when none). */
int emu_fault_for(const emu_common *e, uint64_t idx);
/* True XYZ (cd/m2) under the sensor now; 0 when nothing has been shown. */
void emu_sense(emu_common *e, double xyz[3]);
/* Relative and absolute noise draws for measurement idx. */
double emu_noise_rel(const emu_common *e, uint64_t idx, int channel);
double emu_noise_abs(const emu_common *e, uint64_t idx, int channel);
void emu_set_reply(emu_common *e, const void *bytes, size_t len);
/* Random bytes for the garbage fault (deterministic in seed and idx). */
void emu_garbage(emu_common *e, uint64_t idx, size_t len);

#endif
