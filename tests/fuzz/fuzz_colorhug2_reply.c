/* ColorHug2 input reports (devices/colorhug2_proto.h) are outside input: bytes from a HID device.
 * Every parser must refuse with a message or give finite numbers and a printable description. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorhug2_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_error e;
    /* the parsers see at most one report, as read */
    if (size > CSF_CH2_REPORT) size = CSF_CH2_REPORT;
    uint8_t buf[CSF_CH2_REPORT];
    memcpy(buf, data, size);
    /* the first byte chooses which command the reply is taken to answer, so every parser sees
     * replies that echo its command */
    static const uint8_t cmds[] = {CSF_CH2_CMD_GET_FIRMWARE_VERSION, CSF_CH2_CMD_GET_SERIAL_NUMBER,
                                   CSF_CH2_CMD_GET_CALIBRATION, CSF_CH2_CMD_TAKE_READINGS,
                                   CSF_CH2_CMD_SET_INTEGRAL_TIME};
    for (size_t c = 0; c < sizeof cmds; c++) {
        if (size >= 2) buf[1] = (data[1] & 1) ? data[1] : cmds[c];
        e.msg[0] = '\0';
        csf_status st;
        switch (cmds[c]) {
        case CSF_CH2_CMD_GET_FIRMWARE_VERSION: {
            unsigned v[3];
            st = csf_ch2_parse_firmware(buf, size, v, &e);
            if (!st && (v[0] > 0xffff || v[1] > 0xffff || v[2] > 0xffff)) abort();
            break;
        }
        case CSF_CH2_CMD_GET_SERIAL_NUMBER: {
            uint32_t s;
            st = csf_ch2_parse_serial(buf, size, &s, &e);
            break;
        }
        case CSF_CH2_CMD_GET_CALIBRATION: {
            double m[3][3];
            char desc[24];
            st = csf_ch2_parse_calibration(buf, size, m, desc, &e);
            if (!st) {
                for (int i = 0; i < 9; i++)
                    if (!isfinite(m[i / 3][i % 3]) || fabs(m[i / 3][i % 3]) > 32768) abort();
                if (strlen(desc) > 23) abort();
                for (const char *p = desc; *p; p++)
                    if (*p < 0x20 || *p > 0x7e) abort();
            }
            break;
        }
        case CSF_CH2_CMD_TAKE_READINGS: {
            double rgb[3];
            st = csf_ch2_parse_readings(buf, size, rgb, &e);
            if (!st)
                for (int k = 0; k < 3; k++)
                    if (!isfinite(rgb[k])) abort();
            break;
        }
        default:
            st = csf_ch2_parse_ack(cmds[c], buf, size, &e);
            break;
        }
        if (st && !e.msg[0]) abort();
    }
    return 0;
}
