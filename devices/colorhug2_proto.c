/* Hughski ColorHug2 report building and reply parsing (see colorhug2_proto.h). */
#include "devices/colorhug2_proto.h"

#include <math.h>
#include <string.h>

static const char *const err_names[] = {
    "none", "unknown command", "wrong unlock code", "not implemented", "underflow sensor (too dark)",
    "no serial", "watchdog", "invalid address", "invalid length", "invalid checksum", "invalid value",
    "unknown command for bootloader", "no calibration", "overflow multiply", "overflow addition",
    "overflow sensor (too bright)", "overflow stack", "device deactivated", "incomplete request",
    "self test sensor", "self test red", "self test green", "self test blue", "self test color select",
    "self test multiplier", "invalid calibration", "sram failed", "out of memory",
    "self test temperature", "self test i2c", "self test adc vdd", "self test adc vss",
    "self test adc vref",
};

const char *csf_ch2_error_name(unsigned code)
{
    return code < sizeof err_names / sizeof err_names[0] ? err_names[code] : "unknown";
}

void csf_ch2_request(uint8_t report[CSF_CH2_REPORT], uint8_t cmd, const uint8_t *args, size_t n_args)
{
    memset(report, 0, CSF_CH2_REPORT);
    report[0] = cmd;
    if (n_args > CSF_CH2_REPORT - 1) n_args = CSF_CH2_REPORT - 1;
    if (n_args) memcpy(report + 1, args, n_args);
}

csf_status csf_ch2_check_reply(uint8_t cmd, const uint8_t *buf, size_t len, size_t need, const uint8_t **data,
                               csf_error *err)
{
    if (len < 2)
        return csf_error_set(err, CSF_E_PROTOCOL, "truncated answer to command 0x%02x (%zu bytes, need at "
                             "least 2)", cmd, len);
    unsigned rc = buf[0];
    if (buf[1] != cmd)
        return csf_error_set(err, CSF_E_PROTOCOL, "answer to command 0x%02x echoes command 0x%02x (retval "
                             "0x%02x): out of step or garbage", cmd, buf[1], rc);
    if (rc == CSF_CH2_ERR_UNDERFLOW_SENSOR)
        return csf_error_set(err, CSF_E_TOO_DARK, "too dark: the sensor underflowed (error %u) on command "
                             "0x%02x", rc, cmd);
    if (rc == CSF_CH2_ERR_OVERFLOW_SENSOR || rc == CSF_CH2_ERR_OVERFLOW_MULTIPLY ||
        rc == CSF_CH2_ERR_OVERFLOW_ADDITION)
        return csf_error_set(err, CSF_E_SATURATED, "over range: %s (error %u) on command 0x%02x",
                             csf_ch2_error_name(rc), rc, cmd);
    if (rc != 0)
        return csf_error_set(err, CSF_E_DEVICE, "instrument error %u (%s) on command 0x%02x", rc,
                             csf_ch2_error_name(rc), cmd);
    if (len < 2 + need)
        return csf_error_set(err, CSF_E_PROTOCOL, "truncated answer to command 0x%02x (%zu bytes, need %zu)",
                             cmd, len, 2 + need);
    if (data) *data = buf + 2;
    return CSF_OK;
}

double csf_ch2_packed_to_double(const uint8_t p[4])
{
    uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    int64_t s = u >= 0x80000000u ? (int64_t)u - 0x100000000LL : (int64_t)u;
    return (double)s / 65536.0;
}

void csf_ch2_double_to_packed(double x, uint8_t p[4])
{
    double v = round(x * 65536.0);
    if (!(v >= -2147483648.0)) v = -2147483648.0;
    if (v > 2147483647.0) v = 2147483647.0;
    int64_t s = (int64_t)v;
    uint32_t u = (uint32_t)(s < 0 ? s + 0x100000000LL : s);
    for (int k = 0; k < 4; k++) p[k] = (uint8_t)(u >> (8 * k));
}

csf_status csf_ch2_parse_firmware(const uint8_t *buf, size_t len, unsigned ver[3], csf_error *err)
{
    const uint8_t *d = NULL;
    csf_status st = csf_ch2_check_reply(CSF_CH2_CMD_GET_FIRMWARE_VERSION, buf, len, 6, &d, err);
    if (st) return st;
    for (int k = 0; k < 3; k++) ver[k] = (unsigned)d[2 * k] | (unsigned)d[2 * k + 1] << 8;
    return CSF_OK;
}

csf_status csf_ch2_parse_serial(const uint8_t *buf, size_t len, uint32_t *serial, csf_error *err)
{
    const uint8_t *d = NULL;
    csf_status st = csf_ch2_check_reply(CSF_CH2_CMD_GET_SERIAL_NUMBER, buf, len, 4, &d, err);
    if (st) return st;
    *serial = (uint32_t)d[0] | (uint32_t)d[1] << 8 | (uint32_t)d[2] << 16 | (uint32_t)d[3] << 24;
    return CSF_OK;
}

csf_status csf_ch2_parse_calibration(const uint8_t *buf, size_t len, double m[3][3], char desc[24],
                                     csf_error *err)
{
    const uint8_t *d = NULL;
    csf_status st = csf_ch2_check_reply(CSF_CH2_CMD_GET_CALIBRATION, buf, len, 36 + 1 + 23, &d, err);
    if (st) return st;
    for (int i = 0; i < 9; i++) m[i / 3][i % 3] = csf_ch2_packed_to_double(d + 4 * i);
    size_t k = 0;
    for (; k < 23 && d[37 + k]; k++) desc[k] = (d[37 + k] >= 0x20 && d[37 + k] < 0x7f) ? (char)d[37 + k] : '?';
    desc[k] = '\0';
    return CSF_OK;
}

csf_status csf_ch2_parse_readings(const uint8_t *buf, size_t len, double rgb[3], csf_error *err)
{
    const uint8_t *d = NULL;
    csf_status st = csf_ch2_check_reply(CSF_CH2_CMD_TAKE_READINGS, buf, len, 12, &d, err);
    if (st) return st;
    for (int k = 0; k < 3; k++) rgb[k] = csf_ch2_packed_to_double(d + 4 * k);
    return CSF_OK;
}

csf_status csf_ch2_parse_ack(uint8_t cmd, const uint8_t *buf, size_t len, csf_error *err)
{
    return csf_ch2_check_reply(cmd, buf, len, 0, NULL, err);
}
