/* Hughski ColorHug2 (USB 273f:1004) through hidapi. Spec:
 *   colorhug2[:SERIAL][,integration_ms=MS][,calibration=N][,timeout_s=S]
 * At open: firmware version, serial number, integral time set (default 200 ms, 5..440), and the
 * calibration matrix N (default 0, the factory one) read back. Each reading: TAKE_READINGS on the
 * main sensor (dark offsets applied by the firmware), times the matrix = XYZ in cd/m2, applied
 * here so the matrix in use is the one csfcal read and logged. The firmware's underflow and
 * overflow codes are "too dark" and "over range". Protocol bytes: colorhug2_proto.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorhug2_proto.h"
#include "devices/photometer_driver.h"
#include "devices/transport_hidapi.h"
#include "devices/usb_common.h"

#define CH2_NAME "ColorHug2"

typedef struct {
    csf_usb_meter m;
    double matrix[3][3];
    char cal_desc[24];
    unsigned fw[3];
    double integration_ms;
    double cal_index;
} ch2_state;

static int ch2_key(void *state, const char *k, const char *v, csf_error *err)
{
    ch2_state *s = state;
    if (strcmp(k, "integration_ms") == 0)
        return csf_usb_number("colorhug2", k, v, 5, 440, &s->integration_ms, err) ? -1 : 1;
    if (strcmp(k, "calibration") == 0) {
        if (csf_usb_number("colorhug2", k, v, 0, 63, &s->cal_index, err)) return -1;
        if (s->cal_index != floor(s->cal_index)) {
            csf_error_set(err, CSF_E_INVALID_ARG, "colorhug2: calibration=%s must be a whole number 0..63", v);
            return -1;
        }
        return 1;
    }
    return 0;
}

static csf_status ch2_command(ch2_state *s, uint8_t cmd, const uint8_t *args, size_t n_args, uint8_t *reply,
                              size_t *got, const csf_screen_source *src, csf_error *err)
{
    uint8_t req[CSF_CH2_REPORT];
    csf_ch2_request(req, cmd, args, n_args);
    return csf_usb_exchange(&s->m, req, sizeof req, reply, CSF_CH2_REPORT, got, src, err);
}

static csf_status ch2_setup(ch2_state *s, csf_error *err)
{
    uint8_t reply[CSF_CH2_REPORT];
    size_t got;
    csf_status st = ch2_command(s, CSF_CH2_CMD_GET_FIRMWARE_VERSION, NULL, 0, reply, &got, NULL, err);
    if (!st) st = csf_ch2_parse_firmware(reply, got, s->fw, err);
    uint32_t serial = 0;
    if (!st) st = ch2_command(s, CSF_CH2_CMD_GET_SERIAL_NUMBER, NULL, 0, reply, &got, NULL, err);
    if (!st) st = csf_ch2_parse_serial(reply, got, &serial, err);
    if (st) return st;
    if (!s->m.serial[0]) snprintf(s->m.serial, sizeof s->m.serial, "%u", (unsigned)serial);
    unsigned it = (unsigned)lround(s->integration_ms * CSF_CH2_INTEGRAL_PER_MS);
    if (it > 0xffff) it = 0xffff;
    uint8_t a[2] = {(uint8_t)(it & 0xff), (uint8_t)(it >> 8)};
    st = ch2_command(s, CSF_CH2_CMD_SET_INTEGRAL_TIME, a, 2, reply, &got, NULL, err);
    if (!st) st = csf_ch2_parse_ack(CSF_CH2_CMD_SET_INTEGRAL_TIME, reply, got, err);
    unsigned ci = (unsigned)s->cal_index;
    uint8_t c[2] = {(uint8_t)(ci & 0xff), (uint8_t)(ci >> 8)};
    if (!st) st = ch2_command(s, CSF_CH2_CMD_GET_CALIBRATION, c, 2, reply, &got, NULL, err);
    if (!st) st = csf_ch2_parse_calibration(reply, got, s->matrix, s->cal_desc, err);
    if (st) return st;
    double det = s->matrix[0][0] * (s->matrix[1][1] * s->matrix[2][2] - s->matrix[1][2] * s->matrix[2][1]) -
                 s->matrix[0][1] * (s->matrix[1][0] * s->matrix[2][2] - s->matrix[1][2] * s->matrix[2][0]) +
                 s->matrix[0][2] * (s->matrix[1][0] * s->matrix[2][1] - s->matrix[1][1] * s->matrix[2][0]);
    if (!(fabs(det) > 1e-9))
        return csf_error_set(err, CSF_E_PROTOCOL, "calibration matrix %u read from the instrument is singular "
                             "(\"%s\"): use another calibration=N or restore its factory calibration", ci, s->cal_desc);
    return CSF_OK;
}

static csf_status ch2_open(const char *options, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    ch2_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    s->m.instrument = CH2_NAME;
    s->m.spec_name = "colorhug2";
    s->m.timeout_s = 5;
    s->integration_ms = 200;
    csf_status st = csf_usb_parse_options(&s->m, options, ch2_key, s, err);
    if (!st && !s->m.t)
        st = csf_transport_hidapi_open(CSF_CH2_USB_VID, CSF_CH2_USB_PID, s->m.serial, CH2_NAME, &s->m.t, err);
    if (!st) st = ch2_setup(s, err);
    if (st) {
        csf_usb_name_error(&s->m, st, err);
        csf_usb_close(&s->m);
        free(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static csf_status ch2_identify(void *state, char *buf, size_t len, csf_error *err)
{
    ch2_state *s = state;
    (void)err;
    snprintf(buf, len, "Hughski ColorHug2 serial %s, firmware %u.%u.%u, calibration %u \"%s\", integral time "
             "%g ms%s", s->m.serial, s->fw[0], s->fw[1], s->fw[2], (unsigned)s->cal_index, s->cal_desc,
             s->integration_ms, s->m.emu ? " (emulator)" : "");
    return CSF_OK;
}

static csf_status ch2_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out,
                              csf_error *err)
{
    ch2_state *s = state;
    uint64_t i = s->m.n++;
    uint8_t reply[CSF_CH2_REPORT];
    size_t got = 0;
    uint8_t kind = 0; /* main sensor */
    double rgb[3], xyz[3];
    csf_status st = ch2_command(s, CSF_CH2_CMD_TAKE_READINGS, &kind, 1, reply, &got, src, err);
    out->t_s = csf_usb_now(&s->m);
    out->integration_s = s->integration_ms / 1000.0;
    if (!st) st = csf_ch2_parse_readings(reply, got, rgb, err);
    if (!st) {
        for (int r = 0; r < 3; r++)
            xyz[r] = s->matrix[r][0] * rgb[0] + s->matrix[r][1] * rgb[1] + s->matrix[r][2] * rgb[2];
        if (!(xyz[1] > 0))
            st = csf_error_set(err, CSF_E_TOO_DARK, "too dark (Y %.4g cd/m2 after the matrix)", xyz[1]);
        else if (!(xyz[0] >= -0.05 * xyz[1] && xyz[2] >= -0.05 * xyz[1] && isfinite(xyz[0]) && isfinite(xyz[2])))
            st = csf_error_set(err, CSF_E_PROTOCOL, "absurd reading X %.4g Y %.4g Z %.4g cd/m2 (negative X or "
                               "Z)", xyz[0], xyz[1], xyz[2]);
    }
    if (st) {
        char what[64];
        snprintf(what, sizeof what, " at reading %llu", (unsigned long long)i);
        if (strlen(err->msg) + strlen(what) < sizeof err->msg) strcat(err->msg, what);
        return csf_usb_name_error(&s->m, st, err);
    }
    out->lum_cdm2 = xyz[1];
    memcpy(out->xyz, xyz, sizeof xyz);
    out->has_xyz = 1;
    return CSF_OK;
}

static void ch2_resume_at(void *state, uint64_t idx, double t_s) { csf_usb_resume_at(&((ch2_state *)state)->m, idx, t_s); }
static void ch2_wait(void *state, double seconds) { csf_usb_wait(&((ch2_state *)state)->m, seconds); }
static double ch2_integration_s(void *state) { return ((ch2_state *)state)->integration_ms / 1000.0; }
static int ch2_caps(void *state)
{
    return CSF_PHOT_CAP_XYZ | (((ch2_state *)state)->m.emu ? CSF_PHOT_CAP_SIMULATED : 0);
}

static void ch2_close(void *state)
{
    ch2_state *s = state;
    if (!s) return;
    csf_usb_close(&s->m);
    free(s);
}

/* A contact colorimeter rests its face on the screen: the patch must cover that face. Hughski
 * publishes no aperture for the ColorHug2 that we could find; 20 mm is our working figure for
 * the light-collecting face of a puck-shaped display colorimeter, not the maker's. */
const csf_photometer_driver csf_photometer_colorhug2_driver = {
    .name = "colorhug2",
    .description = "Hughski ColorHug2 colorimeter (USB 273f:1004, hidapi)",
    .caps = CSF_PHOT_CAP_XYZ,
    .open = ch2_open,
    .identify = ch2_identify,
    .measure = ch2_measure,
    .resume_at = ch2_resume_at,
    .wait = ch2_wait,
    .close = ch2_close,
    .integration_s = ch2_integration_s,
    .instance_caps = ch2_caps,
    .field_mm = 20.0,
};
