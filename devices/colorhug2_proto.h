/* Hughski ColorHug2 protocol: the bytes, without the HID. Every exchange is one 64-byte output
 * report [cmd][args...] and one 64-byte input report [retval][cmd][data...]; retval 0 is success,
 * anything else an error code (below). Multi-byte numbers are little-endian; "packed floats" are
 * signed 16.16 fixed point in 4 bytes. Facts from the public colorhug-client ch-common.h and
 * ArgyllCMS colorhug.c; the code is ours.
 *
 *   0x07 GET_FIRMWARE_VERSION  -> [2 major][2 minor][2 micro]
 *   0x0b GET_SERIAL_NUMBER     -> [4 serial]
 *   0x06 SET_INTEGRAL_TIME [2] -> (nothing)
 *   0x09 GET_CALIBRATION [2 index] -> [9 x 4 packed float matrix][1 types][23 description]
 *   0x22 TAKE_READINGS [1 sensor kind] -> [3 x 4 packed float] dark-corrected sensor values
 * The driver applies the calibration matrix itself: XYZ = M * readings (cd/m2). */
#ifndef CSF_COLORHUG2_PROTO_H
#define CSF_COLORHUG2_PROTO_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

enum {
    CSF_CH2_USB_VID = 0x273f,
    CSF_CH2_USB_PID = 0x1004,
    CSF_CH2_REPORT = 64,
    CSF_CH2_CMD_SET_INTEGRAL_TIME = 0x06,
    CSF_CH2_CMD_GET_FIRMWARE_VERSION = 0x07,
    CSF_CH2_CMD_GET_CALIBRATION = 0x09,
    CSF_CH2_CMD_GET_SERIAL_NUMBER = 0x0b,
    CSF_CH2_CMD_TAKE_READINGS = 0x22,
    /* error codes the driver treats specially */
    CSF_CH2_ERR_UNDERFLOW_SENSOR = 4,
    CSF_CH2_ERR_NO_CALIBRATION = 12,
    CSF_CH2_ERR_OVERFLOW_MULTIPLY = 13,
    CSF_CH2_ERR_OVERFLOW_ADDITION = 14,
    CSF_CH2_ERR_OVERFLOW_SENSOR = 15,
    /* integral time: the firmware's 0x3a00 is about 100 ms */
    CSF_CH2_INTEGRAL_PER_MS = 0x3a00 / 100,
};

/* Fills a 64-byte request: cmd then n_args bytes of args, zero padded. */
void csf_ch2_request(uint8_t report[CSF_CH2_REPORT], uint8_t cmd, const uint8_t *args, size_t n_args);

/* Name of an error code ("underflow sensor", ...; "unknown" past the list). */
const char *csf_ch2_error_name(unsigned code);

/* Checks a reply to `cmd` (len bytes, as read): at least 2 + need bytes, echo of cmd, retval 0.
 * Returns CSF_E_TOO_DARK (underflow), CSF_E_SATURATED (overflow), CSF_E_DEVICE (another code) or
 * CSF_E_PROTOCOL (short, wrong echo), each with a message; *data points at the payload. */
csf_status csf_ch2_check_reply(uint8_t cmd, const uint8_t *buf, size_t len, size_t need, const uint8_t **data,
                               csf_error *err);

double csf_ch2_packed_to_double(const uint8_t p[4]);
/* The inverse, clamped to the representable range (emulator, tests). */
void csf_ch2_double_to_packed(double x, uint8_t p[4]);

csf_status csf_ch2_parse_firmware(const uint8_t *buf, size_t len, unsigned ver[3], csf_error *err);
csf_status csf_ch2_parse_serial(const uint8_t *buf, size_t len, uint32_t *serial, csf_error *err);
/* Matrix (row-major) and the description (NUL-terminated, printable characters only). */
csf_status csf_ch2_parse_calibration(const uint8_t *buf, size_t len, double m[3][3], char desc[24],
                                     csf_error *err);
csf_status csf_ch2_parse_readings(const uint8_t *buf, size_t len, double rgb[3], csf_error *err);
csf_status csf_ch2_parse_ack(uint8_t cmd, const uint8_t *buf, size_t len, csf_error *err);

#endif
