/* Hughski ColorHug2 emulator: 64-byte HID reports as the firmware answers them
 * (devices/colorhug2_proto.h), measuring the simulated display under its sensor. The readings it
 * returns are the sensor's (matrix inverse times the light), so the driver must apply the matrix it
 * read; below its floor the firmware's underflow error comes back, above its range overflow. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorhug2_proto.h"
#include "tests/usb/emu_colorhug2.h"

#define CH2_FLOOR_CDM2 0.003
#define CH2_RANGE_CDM2 1500.0

typedef struct {
    emu_common c; /* first */
    double m[3][3], minv[3][3];
    unsigned integral;
} ch2_emu;

static const double factory[3][3] = {{0.71875, 0.1875, 0.09375}, {0.28125, 0.65625, 0.0625}, {0.015625, 0.09375, 1.125}};

static void invert3(const double a[3][3], double r[3][3])
{
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            r[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
        }
}

static void answer(emu_common *e, uint8_t retval, uint8_t cmd, const uint8_t *data, size_t n)
{
    uint8_t r[CSF_CH2_REPORT] = {0};
    r[0] = retval;
    r[1] = cmd;
    if (n > CSF_CH2_REPORT - 2) n = CSF_CH2_REPORT - 2;
    if (n) memcpy(r + 2, data, n);
    emu_set_reply(e, r, sizeof r);
}

static void measure(ch2_emu *s, uint8_t cmd)
{
    emu_common *e = &s->c;
    uint64_t i = e->n_meas++;
    e->t_s += s->integral / (double)CSF_CH2_INTEGRAL_PER_MS / 1000.0;
    int f = emu_fault_for(e, i);
    switch (f) {
    case EMU_UNPLUG: e->gone = 1; return;
    case EMU_TIMEOUT: e->reply_timeout = 1; return;
    case EMU_GARBAGE: emu_garbage(e, i, CSF_CH2_REPORT); return;
    case EMU_ERROR: answer(e, 6 /* watchdog */, cmd, NULL, 0); return;
    default: break;
    }
    double xyz[3];
    emu_sense(e, xyz);
    if (f == EMU_DARK) xyz[0] = xyz[1] = xyz[2] = 0;
    if (f == EMU_SATURATE) xyz[0] = xyz[1] = xyz[2] = 5000;
    double meas[3];
    for (int k = 0; k < 3; k++) meas[k] = xyz[k] * (1 + emu_noise_rel(e, i, k)) + emu_noise_abs(e, i, k);
    if (meas[1] < CH2_FLOOR_CDM2) {
        answer(e, CSF_CH2_ERR_UNDERFLOW_SENSOR, cmd, NULL, 0);
        return;
    }
    if (meas[1] > CH2_RANGE_CDM2) {
        answer(e, CSF_CH2_ERR_OVERFLOW_SENSOR, cmd, NULL, 0);
        return;
    }
    uint8_t d[12];
    for (int r = 0; r < 3; r++)
        csf_ch2_double_to_packed(s->minv[r][0] * meas[0] + s->minv[r][1] * meas[1] + s->minv[r][2] * meas[2], d + 4 * r);
    answer(e, 0, cmd, d, sizeof d);
    if (f == EMU_TRUNCATED) e->reply_len = 7; /* the report ended early */
}

static void on_command(emu_common *e, const uint8_t *buf, size_t len)
{
    ch2_emu *s = (ch2_emu *)e;
    if (len < 1) {
        answer(e, 18 /* incomplete request */, 0, NULL, 0);
        return;
    }
    uint8_t cmd = buf[0];
    uint8_t d[60] = {0};
    switch (cmd) {
    case CSF_CH2_CMD_GET_FIRMWARE_VERSION:
        d[0] = 2; d[2] = 0; d[4] = 6;
        answer(e, 0, cmd, d, 6);
        break;
    case CSF_CH2_CMD_GET_SERIAL_NUMBER: {
        unsigned long sn = strtoul(e->serial, NULL, 10);
        for (int k = 0; k < 4; k++) d[k] = (uint8_t)(sn >> (8 * k));
        answer(e, 0, cmd, d, 4);
        break;
    }
    case CSF_CH2_CMD_SET_INTEGRAL_TIME: {
        unsigned v = len >= 3 ? (unsigned)buf[1] | (unsigned)buf[2] << 8 : 0;
        if (v == 0) {
            answer(e, 10 /* invalid value */, cmd, NULL, 0);
        } else {
            s->integral = v;
            answer(e, 0, cmd, NULL, 0);
        }
        break;
    }
    case CSF_CH2_CMD_GET_CALIBRATION: {
        unsigned idx = len >= 3 ? (unsigned)buf[1] | (unsigned)buf[2] << 8 : 0;
        if (idx > 63) {
            answer(e, 10, cmd, NULL, 0);
            break;
        }
        if (idx != 0) { /* only the factory slot is written on this unit */
            answer(e, CSF_CH2_ERR_NO_CALIBRATION, cmd, NULL, 0);
            break;
        }
        for (int k = 0; k < 9; k++) csf_ch2_double_to_packed(s->m[k / 3][k % 3], d + 4 * k);
        d[36] = 0x0f; /* LCD, CRT, projector, LED */
        memcpy(d + 37, "Factory Calibration", 19);
        answer(e, 0, cmd, d, 60);
        break;
    }
    case CSF_CH2_CMD_TAKE_READINGS: measure(s, cmd); break;
    default: answer(e, 1 /* unknown command */, cmd, NULL, 0); break;
    }
}

csf_status emu_colorhug2_open(const char *options, csf_emu_device **out, csf_error *err)
{
    ch2_emu *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    memcpy(s->m, factory, sizeof factory);
    invert3(s->m, s->minv);
    s->integral = 0x7500;
    snprintf(s->c.serial, sizeof s->c.serial, "%s", "4711");
    s->c.hid = 1;
    s->c.on_command = on_command;
    csf_status st = emu_common_init(&s->c, "ColorHug2", options, NULL, err);
    if (st) {
        csf_display_model_free(s->c.display);
        free(s);
        return st;
    }
    *out = &s->c.dev;
    return CSF_OK;
}
