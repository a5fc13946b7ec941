/* Photometers: one instrument per file behind one struct of function pointers
 * (devices/photometer_driver.h, the shape of libusb's os backends and ArgyllCMS's instruments). A
 * driver is split into protocol (bytes) and transport (libusb / hidapi / serial / process) so real
 * meters can be tested against emulators that speak the same bytes; the simulated meter needs
 * neither. This header is the callers' side.
 *
 * Open by spec: "sim[:key=value,...]" (see devices/photometer_sim.c and docs/display-profile.md).
 * Errors: CSF_E_TOO_DARK, CSF_E_SATURATED, CSF_E_TIMEOUT, CSF_E_GONE, CSF_E_PROTOCOL, each with a
 * sentence in the csf_error. */
#ifndef CSF_PHOTOMETER_H
#define CSF_PHOTOMETER_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

typedef struct csf_photometer csf_photometer;

typedef struct {
    double lum_cdm2;   /* luminance, cd/m2 */
    double xyz[3];     /* CIE 1931 XYZ (Y = lum_cdm2) when has_xyz */
    int has_xyz;
    double t_s;        /* instrument clock at the end of the reading (virtual for the simulator) */
    double integration_s;
} csf_photometer_reading;

/* How an instrument learns what is on screen. A real instrument just measures the light; the
 * simulated one asks this source what is under its sensor and runs it through its display model.
 * Give at least one of the two callbacks:
 *  - patch: the drive values (0..1) of a uniform patch under the sensor (the calibration
 *    procedure, which shows uniform patches);
 *  - pixels: the framebuffer pixels under the sensor as packed RGB triples of `bits` per channel
 *    (8: unsigned char; 9..16: uint16_t), e.g. the presenter's readback of the rendered frame;
 *    the simulator averages luminance (not drive) over them, as a real sensor integrates light. */
typedef struct {
    csf_status (*patch)(void *user, double rgb01[3]);
    csf_status (*pixels)(void *user, const void **rgb, size_t *n_px, int *bits);
    void *user;
} csf_screen_source;

/* Capabilities. */
enum { CSF_PHOT_CAP_XYZ = 1, CSF_PHOT_CAP_SIMULATED = 2 };

/* Opens by spec "name[:options]". Unknown name: CSF_E_NOT_FOUND with the list of known ones. */
csf_status csf_photometer_open(const char *spec, uint64_t seed, csf_photometer **out, csf_error *err);
void csf_photometer_close(csf_photometer *p);
csf_status csf_photometer_identify(csf_photometer *p, char *buf, size_t len, csf_error *err);
/* Measures what the current screen source shows. */
csf_status csf_photometer_measure(csf_photometer *p, csf_photometer_reading *out, csf_error *err);
/* Sets the screen source (copied); NULL restores the built-in uniform patch source. */
void csf_photometer_set_source(csf_photometer *p, const csf_screen_source *src);
/* Built-in source: a uniform patch with these drive values (what the calibration shows). */
void csf_photometer_show_patch(csf_photometer *p, double r01, double g01, double b01);
void csf_photometer_resume_at(csf_photometer *p, uint64_t reading_index, double t_s);
/* Waits (real time for real instruments, virtual time for the simulator). */
void csf_photometer_wait(csf_photometer *p, double seconds);
int csf_photometer_caps(const csf_photometer *p);
/* Integration time of one reading in seconds; 0 when the instrument does not say. */
double csf_photometer_integration_s(const csf_photometer *p);
const char *csf_photometer_driver_name(const csf_photometer *p);
/* What the instrument measures on the screen: a spot meter's acceptance angle in degrees
 * (*field_deg > 0, *field_mm 0), measured from where the meter stands; or a contact instrument's
 * light-collecting face in mm (*field_mm > 0, *field_deg 0), which rests on the screen. The
 * figures and their sources are in each driver and in docs/instruments.md. */
void csf_photometer_field(const csf_photometer *p, double *field_deg, double *field_mm);
/* The spec the photometer was opened with (for the store / profile). */
const char *csf_photometer_spec(const csf_photometer *p);

#endif
