/* USB photometers: the reply parsers on good, bad and hostile bytes; the Minolta and packed-float
 * number formats; libusb error mapping; and each driver against its emulator -- identify, readings
 * against the simulated display's truth (the matrix read from the device applied), and every fault
 * (unplug, timeout, garbage, truncated, instrument error, too dark, over range, slow) ending in a
 * message that names the instrument. Needs CSFCAL_TEST_USB_EMULATOR (set by meson). */
#include <libusb-1.0/libusb.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorcal2_proto.h"
#include "devices/colorhug2_proto.h"
#include "model/display_model.h"
#include "devices/photometer.h"
#include "devices/transport_libusb.h"
#include "tests/check.h"

#define B(s) (const unsigned char *)(s), strlen(s)

static void test_cc2_parsers(void)
{
    csf_error e;
    double raw[3], row[3];
    long serial, rom, build;
    CHECK(csf_cc2_parse_measurement(B("OK00,12.3456,-0.0012,  7.5\r\n"), raw, &e) == CSF_OK);
    CHECK_NEAR(raw[0], 12.3456, 1e-12);
    CHECK_NEAR(raw[1], -0.0012, 1e-12);
    CHECK_NEAR(raw[2], 7.5, 1e-12);
    /* padded control transfer and the serial prompt */
    unsigned char padded[32] = "OK00,1.0,2.0,3.0\n\r>";
    CHECK(csf_cc2_parse_measurement(padded, sizeof padded, raw, &e) == CSF_OK);
    CHECK(csf_cc2_parse_measurement(B("ER11"), raw, &e) == CSF_E_DEVICE);
    CHECK(strstr(e.msg, "ER11") != NULL);
    CHECK(csf_cc2_parse_measurement(B("OK00,1.0,2.0"), raw, &e) == CSF_E_PROTOCOL);  /* truncated */
    CHECK(strstr(e.msg, "2 numbers") != NULL);
    CHECK(csf_cc2_parse_measurement(B("OK00,1e5,2,3"), raw, &e) == CSF_E_PROTOCOL);  /* no exponents */
    CHECK(csf_cc2_parse_measurement(B("OK00,nan,2,3"), raw, &e) == CSF_E_PROTOCOL);
    CHECK(csf_cc2_parse_measurement(B("OK00,1,,3"), raw, &e) == CSF_E_PROTOCOL);
    CHECK(csf_cc2_parse_measurement(B("\x01\xff garbage"), raw, &e) == CSF_E_PROTOCOL);
    CHECK(strstr(e.msg, "\\x01\\xff") != NULL); /* the bytes are shown, escaped */
    CHECK(csf_cc2_parse_measurement(B(""), raw, &e) == CSF_E_PROTOCOL);
    CHECK(csf_cc2_parse_measurement(B("OK00,99999999,1,1"), raw, &e) == CSF_E_PROTOCOL); /* absurd */
    CHECK(csf_cc2_parse_matrix_row(B("OK00,10412,50523,131"), 1, row, &e) == CSF_OK);
    CHECK_NEAR(row[0], 1.0412, 1e-12);
    CHECK_NEAR(row[1], -0.0523, 1e-12);
    CHECK_NEAR(row[2], 0.0131, 1e-12);
    CHECK(csf_cc2_parse_matrix_row(B("OK00,1.5,2,3"), 1, row, &e) == CSF_E_PROTOCOL);
    CHECK(csf_cc2_parse_identity(B("OK00,1,105,100.10,10230157,27"), &serial, &rom, &build, &e) == CSF_OK);
    CHECK_INT_EQ(serial, 10230157);
    CHECK_INT_EQ(rom, 105);
    CHECK_INT_EQ(build, 27);
    CHECK(csf_cc2_parse_identity(B("OK00,1,105"), &serial, &rom, &build, &e) == CSF_E_PROTOCOL);
    /* Minolta format both ways (PsychoPy's documented examples) */
    CHECK_NEAR(csf_cc2_minolta_to_double(50347), -0.0347, 1e-12);
    CHECK_NEAR(csf_cc2_minolta_to_double(10630), 1.0630, 1e-12);
    CHECK_INT_EQ(csf_cc2_double_to_minolta(-0.0631), 50631);
    CHECK_INT_EQ(csf_cc2_double_to_minolta(1.0635), 10635);
    double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, sing[3][3] = {{1, 2, 3}, {2, 4, 6}, {0, 0, 1}};
    CHECK(csf_cc2_matrix_usable(id));
    CHECK(!csf_cc2_matrix_usable(sing));
}

static void test_ch2_parsers(void)
{
    csf_error e;
    uint8_t r[64] = {0}, p[4];
    csf_ch2_double_to_packed(-1.5, p);
    CHECK_NEAR(csf_ch2_packed_to_double(p), -1.5, 0);
    csf_ch2_double_to_packed(123.456, p);
    CHECK_NEAR(csf_ch2_packed_to_double(p), 123.456, 1.0 / 65536);
    r[1] = CSF_CH2_CMD_TAKE_READINGS;
    for (int k = 0; k < 3; k++) csf_ch2_double_to_packed(k + 0.25, r + 2 + 4 * k);
    double rgb[3];
    CHECK(csf_ch2_parse_readings(r, 64, rgb, &e) == CSF_OK);
    CHECK_NEAR(rgb[2], 2.25, 0);
    CHECK(csf_ch2_parse_readings(r, 9, rgb, &e) == CSF_E_PROTOCOL); /* truncated */
    CHECK(strstr(e.msg, "truncated") != NULL);
    r[0] = CSF_CH2_ERR_UNDERFLOW_SENSOR;
    CHECK(csf_ch2_parse_readings(r, 64, rgb, &e) == CSF_E_TOO_DARK);
    r[0] = CSF_CH2_ERR_OVERFLOW_SENSOR;
    CHECK(csf_ch2_parse_readings(r, 64, rgb, &e) == CSF_E_SATURATED);
    r[0] = 6;
    CHECK(csf_ch2_parse_readings(r, 64, rgb, &e) == CSF_E_DEVICE);
    CHECK(strstr(e.msg, "watchdog") != NULL);
    r[0] = 0;
    r[1] = 0x07; /* answer to another command: out of step */
    CHECK(csf_ch2_parse_readings(r, 64, rgb, &e) == CSF_E_PROTOCOL);
    CHECK(strstr(e.msg, "echoes") != NULL);
    uint8_t fw[64] = {0, CSF_CH2_CMD_GET_FIRMWARE_VERSION, 2, 0, 0, 0, 6, 0};
    unsigned ver[3];
    CHECK(csf_ch2_parse_firmware(fw, 64, ver, &e) == CSF_OK);
    CHECK(ver[0] == 2 && ver[1] == 0 && ver[2] == 6);
    uint8_t sn[64] = {0, CSF_CH2_CMD_GET_SERIAL_NUMBER, 0x67, 0x12, 0, 0};
    uint32_t serial;
    CHECK(csf_ch2_parse_serial(sn, 64, &serial, &e) == CSF_OK);
    CHECK_INT_EQ(serial, 0x1267);
    uint8_t cal[64] = {0, CSF_CH2_CMD_GET_CALIBRATION};
    for (int k = 0; k < 9; k++) csf_ch2_double_to_packed(k * 0.5, cal + 2 + 4 * k);
    memcpy(cal + 2 + 37, "LCD\x01x", 5);
    double m[3][3];
    char desc[24];
    CHECK(csf_ch2_parse_calibration(cal, 64, m, desc, &e) == CSF_OK);
    CHECK_NEAR(m[2][1], 3.5, 0);
    CHECK(strcmp(desc, "LCD?x") == 0); /* control bytes do not reach the terminal */
    CHECK(csf_ch2_parse_calibration(cal, 40, m, desc, &e) == CSF_E_PROTOCOL);
}

static void test_usb_errors(void)
{
    CHECK(csf_usb_status(LIBUSB_ERROR_NO_DEVICE) == CSF_E_GONE);
    CHECK(csf_usb_status(LIBUSB_ERROR_TIMEOUT) == CSF_E_TIMEOUT);
    CHECK(csf_usb_status(LIBUSB_ERROR_IO) == CSF_E_DEVICE);
}

/* One open-measure round; returns the status of the measurement and leaves the message in e. */
static csf_status measure_patch(csf_photometer *p, double v, csf_photometer_reading *r, csf_error *e)
{
    csf_photometer_show_patch(p, v, v, v);
    csf_error_clear(e);
    return csf_photometer_measure(p, r, e);
}

static void test_driver(const char *name, const char *instrument)
{
    char spec[256];
    csf_error e;
    csf_photometer *p = NULL;
    csf_display_model *truth = NULL;
    CHECK(csf_display_model_create("lcd", &truth, &e) == CSF_OK);
    snprintf(spec, sizeof spec, "%s:emulator,display=lcd,noise=0", name);
    CHECK_MSG(csf_photometer_open(spec, 1, &p, &e) == CSF_OK, "%s: %s", spec, e.msg);
    if (!p) return;
    char id[256];
    CHECK(csf_photometer_identify(p, id, sizeof id, &e) == CSF_OK);
    CHECK_MSG(strstr(id, "serial") && strstr(id, "emulator"), "%s", id);
    CHECK(csf_photometer_caps(p) & CSF_PHOT_CAP_SIMULATED); /* it measures the simulated display */
    CHECK(csf_photometer_integration_s(p) > 0);
    double levels[] = {0.1, 0.5, 1.0};
    for (int i = 0; i < 3; i++) {
        csf_photometer_reading r;
        CHECK_MSG(measure_patch(p, levels[i], &r, &e) == CSF_OK, "%s", e.msg);
        double xyz[3];
        csf_display_model_xyz(truth, levels[i], levels[i], levels[i], xyz);
        /* noise off: what is left is the reply's resolution and the zero offset */
        CHECK_NEAR(r.lum_cdm2, xyz[1], 0.002 * xyz[1] + 0.01);
        CHECK_NEAR(r.xyz[0], xyz[0], 0.002 * xyz[0] + 0.01);
        CHECK_NEAR(r.xyz[2], xyz[2], 0.002 * xyz[2] + 0.01);
    }
    double t0 = 0;
    {
        csf_photometer_reading r;
        measure_patch(p, 1, &r, &e);
        t0 = r.t_s;
        csf_photometer_wait(p, 100); /* virtual: returns at once */
        measure_patch(p, 1, &r, &e);
        CHECK(r.t_s >= t0 + 100);
    }
    csf_photometer_close(p);

    /* faults: each ends in a message naming the instrument and the problem */
    static const struct {
        const char *fault;
        csf_status want;
        const char *says;
    } faults[] = {
        {"fault=unplug@2", CSF_E_GONE, "disconnected"},
        {"fault=timeout@2", CSF_E_TIMEOUT, "answer"},
        {"fault=garbage@2", CSF_E_PROTOCOL, ""},
        {"fault=truncated@2", CSF_E_PROTOCOL, ""},
        {"fault=error@2", CSF_E_DEVICE, "error"},
        {"fault=dark@2", CSF_E_TOO_DARK, "too dark"},
        {"fault=saturate@2", CSF_E_SATURATED, "over range"},
        {"slow=1,timeout_s=0.2", CSF_E_TIMEOUT, "answer"},
    };
    for (size_t f = 0; f < sizeof faults / sizeof faults[0]; f++) {
        snprintf(spec, sizeof spec, "%s:emulator,%s", name, faults[f].fault);
        p = NULL;
        csf_status ost = csf_photometer_open(spec, 1, &p, &e);
        if (strstr(faults[f].fault, "slow")) {
            /* too slow for the limit: already the identify at open times out */
            CHECK_MSG(ost == faults[f].want, "%s: open gave %d (%s)", spec, ost, e.msg);
            CHECK_MSG(strstr(e.msg, instrument) != NULL, "%s: %s", spec, e.msg);
            continue;
        }
        CHECK_MSG(ost == CSF_OK, "%s: %s", spec, e.msg);
        if (!p) continue;
        csf_photometer_reading r;
        CHECK(measure_patch(p, 0.5, &r, &e) == CSF_OK);
        CHECK(measure_patch(p, 0.5, &r, &e) == CSF_OK);
        csf_status st = measure_patch(p, 0.5, &r, &e);
        CHECK_MSG(st == faults[f].want, "%s: got %d (%s)", spec, st, e.msg);
        CHECK_MSG(strstr(e.msg, instrument) != NULL && strstr(e.msg, faults[f].says) != NULL,
                  "%s: message '%s'", spec, e.msg);
        st = measure_patch(p, 0.5, &r, &e);
        if (strstr(faults[f].fault, "unplug") || strstr(faults[f].fault, "dark") || strstr(faults[f].fault, "saturate"))
            CHECK_MSG(st == faults[f].want, "%s: fault should persist, got %d", spec, st);
        else
            CHECK_MSG(st == CSF_OK, "%s: one-reading fault should pass, got %d (%s)", spec, st, e.msg);
        csf_photometer_close(p);
    }
    /* a slow device within the limit is only slow */
    snprintf(spec, sizeof spec, "%s:emulator,slow=0.05,timeout_s=2", name);
    CHECK_MSG(csf_photometer_open(spec, 1, &p, &e) == CSF_OK, "%s", e.msg);
    if (p) {
        csf_photometer_reading r;
        CHECK(measure_patch(p, 0.5, &r, &e) == CSF_OK);
        csf_photometer_close(p);
    }
    /* bad specs */
    snprintf(spec, sizeof spec, "%s:emulator,timeout_s=0", name);
    CHECK(csf_photometer_open(spec, 1, &p, &e) == CSF_E_INVALID_ARG && strstr(e.msg, "timeout_s"));
    snprintf(spec, sizeof spec, "%s:emulator,bogus=1", name);
    CHECK(csf_photometer_open(spec, 1, &p, &e) == CSF_E_INVALID_ARG && strstr(e.msg, "bogus"));
    snprintf(spec, sizeof spec, "%s:bad serial!", name);
    CHECK(csf_photometer_open(spec, 1, &p, &e) == CSF_E_INVALID_ARG);
    snprintf(spec, sizeof spec, "%s:ABC123,bogus=1", name);
    CHECK(csf_photometer_open(spec, 1, &p, &e) == CSF_E_INVALID_ARG && strstr(e.msg, "unknown option"));
    csf_display_model_free(truth);
}

static void test_driver_options(void)
{
    csf_error e;
    csf_photometer *p = NULL;
    CHECK(csf_photometer_open("colorhug2:emulator,integration_ms=1000", 1, &p, &e) == CSF_E_INVALID_ARG);
    CHECK(strstr(e.msg, "integration_ms") != NULL);
    CHECK(csf_photometer_open("colorhug2:emulator,calibration=3", 1, &p, &e) == CSF_E_DEVICE);
    CHECK_MSG(strstr(e.msg, "ColorHug2") && strstr(e.msg, "no calibration"), "%s", e.msg);
    CHECK(csf_photometer_open("colorhug2:emulator,integration_ms=100", 1, &p, &e) == CSF_OK);
    if (p) {
        CHECK_NEAR(csf_photometer_integration_s(p), 0.1, 1e-12);
        csf_photometer_close(p);
    }
    /* zero calibration needs the dark: nothing shown yet is dark, and it succeeds */
    CHECK_MSG(csf_photometer_open("colorcal2:emulator,zero=1", 1, &p, &e) == CSF_OK, "%s", e.msg);
    if (p) {
        char id[256];
        csf_photometer_identify(p, id, sizeof id, &e);
        CHECK(strstr(id, "zeroed") != NULL);
        csf_photometer_close(p);
    }
    CHECK(csf_photometer_open("colorcal2:emulator,zero=2", 1, &p, &e) == CSF_E_INVALID_ARG);
    /* the person gets zero_wait_s to uncap the meter: the first reading comes after it */
    CHECK(csf_photometer_open("colorcal2:emulator,zero=1,zero_wait_s=30", 1, &p, &e) == CSF_OK);
    if (p) {
        csf_photometer_reading r;
        CHECK(measure_patch(p, 1, &r, &e) == CSF_OK);
        CHECK(r.t_s >= 30);
        csf_photometer_close(p);
    }
    /* zeroing with the cap off: ER11, said as such */
    CHECK(csf_photometer_open("colorcal2:emulator,zero=1,uncapped=1", 1, &p, &e) == CSF_E_SATURATED);
    CHECK_MSG(strstr(e.msg, "ColorCAL MkII") && strstr(e.msg, "ER11") && strstr(e.msg, "dark"), "%s", e.msg);
    /* without zeroing the offset stays in the reading (the emulator's 0.004 raw units) */
    double dark_unzeroed = 0, dark_zeroed = 0;
    for (int z = 0; z < 2; z++) {
        CHECK(csf_photometer_open(z ? "colorcal2:emulator,noise=0,abs_noise=0,zero=1,zero_wait_s=0"
                                    : "colorcal2:emulator,noise=0,abs_noise=0", 1, &p, &e) == CSF_OK);
        if (!p) continue;
        csf_photometer_reading r;
        CHECK(measure_patch(p, 0.3, &r, &e) == CSF_OK);
        *(z ? &dark_zeroed : &dark_unzeroed) = r.lum_cdm2;
        csf_photometer_close(p);
    }
    CHECK_NEAR(dark_unzeroed - dark_zeroed, 0.004 * (0.0207 + 0.9874 + 0.0105), 2e-4);
    /* without the test variable an emulator spec is refused */
    const char *mod = getenv("CSFCAL_TEST_USB_EMULATOR");
    char saved[1024] = "";
    if (mod) snprintf(saved, sizeof saved, "%s", mod);
    unsetenv("CSFCAL_TEST_USB_EMULATOR");
    CHECK(csf_photometer_open("colorcal2:emulator", 1, &p, &e) == CSF_E_INVALID_ARG);
    CHECK(strstr(e.msg, "CSFCAL_TEST_USB_EMULATOR") != NULL);
    if (saved[0]) setenv("CSFCAL_TEST_USB_EMULATOR", saved, 1);
}

int main(void)
{
    test_cc2_parsers();
    test_ch2_parsers();
    test_usb_errors();
    if (!getenv("CSFCAL_TEST_USB_EMULATOR")) {
        fprintf(stderr, "CSFCAL_TEST_USB_EMULATOR not set: the driver tests need the emulator module\n");
        return 1;
    }
    test_driver("colorcal2", "ColorCAL MkII");
    test_driver("colorhug2", "ColorHug2");
    test_driver_options();
    return CHECK_RESULT();
}
