/* The photometer driver interface (devices/photometer.h is what callers see): one struct of
 * function pointers per instrument file, the shape of libusb's os backends and ArgyllCMS's
 * instruments, and the byte transport real instruments talk through. devices/photometer.c opens
 * a spec through the driver table below; only drivers, transports and their tests include this. */
#ifndef CSF_PHOTOMETER_DRIVER_H
#define CSF_PHOTOMETER_DRIVER_H

#include <stddef.h>
#include <stdint.h>

#include "devices/photometer.h"

/* The driver interface: one static instance per instrument file. `state` is the driver's own. */
typedef struct csf_photometer_driver {
    const char *name; /* spec prefix: "sim", later "colorcal2", "colorhug2", "spotread" */
    const char *description;
    int caps;
    csf_status (*open)(const char *options /* text after "name:" or "" */, uint64_t seed, void **state,
                       csf_error *err);
    /* Model, serial number, firmware: one line. */
    csf_status (*identify)(void *state, char *buf, size_t len, csf_error *err);
    csf_status (*measure)(void *state, const csf_screen_source *src, csf_photometer_reading *out,
                          csf_error *err);
    /* Tells the instrument how many readings were already taken in this session and at which
     * clock time, so a resumed session continues where it left off (the simulator's noise draw
     * index is the reading number). May be NULL. */
    void (*resume_at)(void *state, uint64_t reading_index, double t_s);
    /* Lets time pass (warm-up). NULL: the caller sleeps on the real clock. The simulator
     * advances its virtual clock instead. */
    void (*wait)(void *state, double seconds);
    void (*close)(void *state);
    /* Seconds of light one reading integrates (a rendered source shows that many frames of a
     * dithered patch). NULL: unknown. */
    double (*integration_s)(void *state);
    /* Capabilities of this open instrument when they differ from `caps` (a USB driver talking to
     * its test emulator measures a simulated display). May be NULL. */
    int (*instance_caps)(void *state);
    /* The measuring field the patch must cover (csf_photometer_field): a spot meter's acceptance
     * angle in degrees, or a contact instrument's light-collecting face in mm (the other 0). */
    double field_deg, field_mm;
    /* This open instrument's field when its options change it (an aperture setting). May be NULL. */
    void (*instance_field)(void *state, double *field_deg, double *field_mm);
} csf_photometer_driver;

/* Byte transport for real instruments (USB bulk/HID/serial/process pipe); protocols are written
 * against it so emulators can stand in for the device in tests. */
typedef struct csf_transport {
    csf_status (*write)(struct csf_transport *t, const uint8_t *buf, size_t len, double timeout_s,
                        csf_error *err);
    /* Reads up to cap bytes; *got is what arrived before the timeout. */
    csf_status (*read)(struct csf_transport *t, uint8_t *buf, size_t cap, size_t *got, double timeout_s,
                       csf_error *err);
    void (*close)(struct csf_transport *t);
    void *user;
} csf_transport;

/* Registered drivers (NULL-terminated). */
const csf_photometer_driver *const *csf_photometer_drivers(void);

/* The simulator's driver (devices/photometer_sim.c). */
extern const csf_photometer_driver csf_photometer_sim_driver;
/* USB meters (devices/photometer_colorcal2.c, photometer_colorhug2.c; docs/instruments.md). */
extern const csf_photometer_driver csf_photometer_colorcal2_driver;
extern const csf_photometer_driver csf_photometer_colorhug2_driver;
/* Serial meters (devices/photometer_ls100.c, photometer_pr655.c) and the ArgyllCMS bridge
 * (devices/photometer_spotread.c). */
extern const csf_photometer_driver csf_photometer_ls100_driver;
extern const csf_photometer_driver csf_photometer_ls110_driver;
extern const csf_photometer_driver csf_photometer_cs100a_driver;
extern const csf_photometer_driver csf_photometer_pr655_driver;
extern const csf_photometer_driver csf_photometer_pr670_driver;
extern const csf_photometer_driver csf_photometer_spotread_driver;

#endif
