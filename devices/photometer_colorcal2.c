/* CRS ColorCAL MkII (USB 0861:1001) through libusb. Spec:
 *   colorcal2[:SERIAL][,zero=1][,zero_wait_s=S][,timeout_s=S]
 * At open: identify (IDR), read the factory calibration matrix (rows r01..r03, Minolta format)
 * and, with zero=1, zero-calibrate (UZC: the sensor must be in the dark -- capped or covered),
 * then give the person zero_wait_s (15 s) to uncap it and put it on the screen.
 * Each reading: MES, raw x y z, times the matrix = XYZ in cd/m2. The kernel's cdc_acm driver is
 * detached while csfcal holds the meter and re-attached when it lets go (transport_libusb.c).
 * Range as this driver enforces it: below 0.005 cd/m2 is "too dark", above 2000 cd/m2 "over range"
 * (docs/instruments.md). Protocol bytes: colorcal2_proto.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorcal2_proto.h"
#include "devices/photometer_driver.h"
#include "devices/transport_libusb.h"
#include "devices/usb_common.h"

#define CC2_NAME "ColorCAL MkII"
#define CC2_FLOOR_CDM2 0.005
#define CC2_MAX_CDM2 2000.0
/* one MES integrates for about 0.3 s at the instrument's fixed timing (frames of a 60 Hz display) */
#define CC2_INTEGRATION_S 0.3

typedef struct {
    csf_usb_meter m;
    double matrix[3][3];
    long rom, build;
    int zero;
    double zero_wait_s; /* after UZC: time to take the cap off and put the meter on the screen */
} cc2_state;

static int cc2_key(void *state, const char *k, const char *v, csf_error *err)
{
    cc2_state *s = state;
    if (strcmp(k, "zero") == 0) {
        double x;
        if (csf_usb_number("colorcal2", k, v, 0, 1, &x, err) || (x != 0 && x != 1)) {
            csf_error_set(err, CSF_E_INVALID_ARG, "colorcal2: zero=%s must be 0 or 1", v);
            return -1;
        }
        s->zero = (int)x;
        return 1;
    }
    if (strcmp(k, "zero_wait_s") == 0)
        return csf_usb_number("colorcal2", k, v, 0, 600, &s->zero_wait_s, err) ? -1 : 1;
    return 0;
}

static csf_status cc2_command(cc2_state *s, const char *cmd, uint8_t *reply, size_t *got,
                              const csf_screen_source *src, csf_error *err)
{
    csf_status st = csf_usb_exchange(&s->m, (const uint8_t *)cmd, strlen(cmd), reply, CSF_CC2_REPLY_MAX, got, src,
                                     err);
    return st;
}

static csf_status cc2_setup(cc2_state *s, csf_error *err)
{
    uint8_t reply[CSF_CC2_REPLY_MAX];
    size_t got;
    csf_status st = cc2_command(s, "IDR", reply, &got, NULL, err);
    long serial = 0;
    if (!st) st = csf_cc2_parse_identity(reply, got, &serial, &s->rom, &s->build, err);
    if (st) return st;
    if (!s->m.serial[0]) snprintf(s->m.serial, sizeof s->m.serial, "%08ld", serial);
    for (int row = 1; row <= 3 && !st; row++) {
        char cmd[8];
        snprintf(cmd, sizeof cmd, "r0%d", row);
        st = cc2_command(s, cmd, reply, &got, NULL, err);
        if (!st) st = csf_cc2_parse_matrix_row(reply, got, row, s->matrix[row - 1], err);
    }
    if (st) return st;
    if (!csf_cc2_matrix_usable(s->matrix))
        return csf_error_set(err, CSF_E_PROTOCOL, "the calibration matrix read from the instrument is singular "
                             "(rows r01..r03): its factory calibration is damaged");
    if (s->zero) {
        csf_screen_source none = {0};
        st = cc2_command(s, "UZC", reply, &got, &none, err);
        csf_cc2_reply r;
        if (!st) st = csf_cc2_parse_reply("UZC", reply, got, &r, err);
        if (st) return st;
        if (!r.ok && r.code == 11)
            return csf_error_set(err, CSF_E_SATURATED, "zero calibration failed (ER11): the sensor is not in the "
                                 "dark; cover it or fit its cap and open it again with zero=1");
        if (!r.ok || r.code != 0)
            return csf_error_set(err, CSF_E_DEVICE, "zero calibration failed (%s%02d)", r.ok ? "OK" : "ER", r.code);
        if (s->zero_wait_s > 0) {
            /* the cap is still on: the person needs a moment before the first reading */
            if (!s->m.emu)
                fprintf(stderr, "csfcal: %s %s zeroed; take the cap off and put it on the screen: the first "
                        "reading follows in %.0f s\n", CC2_NAME, s->m.serial, s->zero_wait_s);
            csf_usb_wait(&s->m, s->zero_wait_s);
        }
    }
    return CSF_OK;
}

static csf_status cc2_open(const char *options, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    cc2_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    s->m.instrument = CC2_NAME;
    s->m.spec_name = "colorcal2";
    s->m.timeout_s = 5;
    s->zero_wait_s = 15;
    csf_status st = csf_usb_parse_options(&s->m, options, cc2_key, s, err);
    if (!st && !s->m.t) {
        csf_usb_control_config cfg = {
            .vid = CSF_CC2_USB_VID, .pid = CSF_CC2_USB_PID, .serial = s->m.serial, .instrument = CC2_NAME,
            .request_out = 0x40, .request_in = 0xC0, .b_request = 0, .w_value = 1, .w_index = 0,
        };
        st = csf_transport_libusb_open(&cfg, &s->m.t, err);
    }
    if (!st) st = cc2_setup(s, err);
    if (st) {
        csf_usb_name_error(&s->m, st, err);
        csf_usb_close(&s->m);
        free(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static csf_status cc2_identify(void *state, char *buf, size_t len, csf_error *err)
{
    cc2_state *s = state;
    (void)err;
    snprintf(buf, len, "CRS ColorCAL MkII serial %s, firmware %ld build %ld%s%s", s->m.serial, s->rom, s->build,
             s->zero ? ", zeroed at open" : "", s->m.emu ? " (emulator)" : "");
    return CSF_OK;
}

static csf_status cc2_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out,
                              csf_error *err)
{
    cc2_state *s = state;
    uint64_t i = s->m.n++;
    uint8_t reply[CSF_CC2_REPLY_MAX];
    size_t got = 0;
    double raw[3], xyz[3];
    csf_status st = cc2_command(s, "MES", reply, &got, src, err);
    out->t_s = csf_usb_now(&s->m);
    out->integration_s = CC2_INTEGRATION_S;
    if (!st) st = csf_cc2_parse_measurement(reply, got, raw, err);
    if (!st) {
        csf_cc2_apply(s->matrix, raw, xyz);
        if (!(xyz[1] >= CC2_FLOOR_CDM2) && isfinite(xyz[1]))
            st = csf_error_set(err, CSF_E_TOO_DARK, "too dark (Y %.4g cd/m2, below %g)", xyz[1], CC2_FLOOR_CDM2);
        else if (!(xyz[1] <= CC2_MAX_CDM2))
            st = csf_error_set(err, CSF_E_SATURATED, "over range (Y %.4g cd/m2, above %g)", xyz[1], CC2_MAX_CDM2);
        else if (!(xyz[0] >= -0.05 * xyz[1] && xyz[2] >= -0.05 * xyz[1]))
            st = csf_error_set(err, CSF_E_PROTOCOL, "absurd reading X %.4g Y %.4g Z %.4g cd/m2 (negative X or "
                               "Z)", xyz[0], xyz[1], xyz[2]);
    }
    if (st) {
        char what[64];
        snprintf(what, sizeof what, " at reading %llu", (unsigned long long)i);
        size_t l = strlen(err->msg);
        if (l + strlen(what) < sizeof err->msg) strcat(err->msg, what);
        return csf_usb_name_error(&s->m, st, err);
    }
    out->lum_cdm2 = xyz[1];
    memcpy(out->xyz, xyz, sizeof xyz);
    out->has_xyz = 1;
    return CSF_OK;
}

static void cc2_resume_at(void *state, uint64_t idx, double t_s) { csf_usb_resume_at(&((cc2_state *)state)->m, idx, t_s); }
static void cc2_wait(void *state, double seconds) { csf_usb_wait(&((cc2_state *)state)->m, seconds); }
static double cc2_integration_s(void *state)
{
    (void)state;
    return CC2_INTEGRATION_S;
}
static int cc2_caps(void *state)
{
    return CSF_PHOT_CAP_XYZ | (((cc2_state *)state)->m.emu ? CSF_PHOT_CAP_SIMULATED : 0);
}

static void cc2_close(void *state)
{
    cc2_state *s = state;
    if (!s) return;
    csf_usb_close(&s->m);
    free(s);
}

/* A contact colorimeter rests its face on the screen: the patch must cover that face. CRS
 * publishes no aperture for the ColorCAL MkII that we could find; 20 mm is our working figure for
 * the light-collecting face of a puck-shaped display colorimeter, not the maker's. */
const csf_photometer_driver csf_photometer_colorcal2_driver = {
    .name = "colorcal2",
    .description = "CRS ColorCAL MkII colorimeter (USB 0861:1001, libusb)",
    .caps = CSF_PHOT_CAP_XYZ,
    .open = cc2_open,
    .identify = cc2_identify,
    .measure = cc2_measure,
    .resume_at = cc2_resume_at,
    .wait = cc2_wait,
    .close = cc2_close,
    .integration_s = cc2_integration_s,
    .instance_caps = cc2_caps,
    .field_mm = 20.0,
};
