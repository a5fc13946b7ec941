/* CRS ColorCAL MkII emulator: answers IDR, r01..r09, UZC and MES the way the instrument does
 * (devices/colorcal2_proto.h), measuring the simulated display under its sensor. Its factory
 * matrix is fixed and ordinary (near identity, a little cross-talk), so a driver that skipped the
 * matrix would read the wrong XYZ; until UZC is run every raw channel carries a small zero offset. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorcal2_proto.h"
#include "tests/usb/emu_colorcal2.h"

#define CC2_INTEGRATION_S 0.3
#define CC2_ZERO_OFFSET 0.004 /* raw units before UZC */

typedef struct {
    emu_common c; /* first */
    double m[3][3], minv[3][3];
    int zeroed;
    int uncapped; /* uncapped=1: light reaches the sensor before csfcal shows anything */
} cc2_emu;

/* Minolta-representable: the driver reads these exactly */
static const double factory[3][3] = {{1.0412, 0.0523, -0.0131}, {0.0207, 0.9874, 0.0105}, {-0.0046, 0.0318, 1.0655}};

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

static void reply_text(emu_common *e, const char *s)
{
    char buf[96];
    int n = snprintf(buf, sizeof buf, "%s\r\n", s);
    emu_set_reply(e, buf, (size_t)n);
}

static void measure(cc2_emu *s)
{
    emu_common *e = &s->c;
    uint64_t i = e->n_meas++;
    e->t_s += CC2_INTEGRATION_S;
    int f = emu_fault_for(e, i);
    switch (f) {
    case EMU_UNPLUG: e->gone = 1; return;
    case EMU_TIMEOUT: e->reply_timeout = 1; return;
    case EMU_GARBAGE: emu_garbage(e, i, 20); return;
    case EMU_ERROR: reply_text(e, "ER03"); return; /* an instrument error code the driver does not know */
    default: break;
    }
    double xyz[3];
    emu_sense(e, xyz);
    if (f == EMU_DARK) xyz[0] = xyz[1] = xyz[2] = 0;
    if (f == EMU_SATURATE) xyz[0] = xyz[1] = xyz[2] = 5000;
    double meas[3], raw[3];
    for (int k = 0; k < 3; k++) meas[k] = xyz[k] * (1 + emu_noise_rel(e, i, k)) + emu_noise_abs(e, i, k);
    for (int r = 0; r < 3; r++) {
        raw[r] = s->minv[r][0] * meas[0] + s->minv[r][1] * meas[1] + s->minv[r][2] * meas[2];
        if (!s->zeroed) raw[r] += CC2_ZERO_OFFSET;
    }
    char buf[96];
    snprintf(buf, sizeof buf, "OK00,%.4f,%.4f,%.4f", raw[0], raw[1], raw[2]);
    if (f == EMU_TRUNCATED) buf[9] = '\0'; /* the transfer ended early */
    reply_text(e, buf);
}

static void on_command(emu_common *e, const uint8_t *buf, size_t len)
{
    cc2_emu *s = (cc2_emu *)e;
    char cmd[8] = "";
    if (len == 3) memcpy(cmd, buf, 3);
    if (!strcmp(cmd, "MES")) {
        measure(s);
    } else if (!strcmp(cmd, "IDR")) {
        char r[96];
        snprintf(r, sizeof r, "OK00,1,105,100.10,%s,27", e->serial);
        reply_text(e, r);
    } else if (cmd[0] == 'r' && cmd[1] == '0' && cmd[2] >= '1' && cmd[2] <= '9') {
        int row = cmd[2] - '1';
        /* matrices 2 and 3 (rows 4-9): unity, as on a meter with only a factory matrix */
        double v[3];
        for (int k = 0; k < 3; k++) v[k] = row < 3 ? s->m[row][k] : (row % 3 == k ? 1.0 : 0.0);
        char r[96];
        snprintf(r, sizeof r, "OK00,%ld,%ld,%ld", csf_cc2_double_to_minolta(v[0]), csf_cc2_double_to_minolta(v[1]),
                 csf_cc2_double_to_minolta(v[2]));
        reply_text(e, r);
    } else if (!strcmp(cmd, "UZC")) {
        double xyz[3];
        emu_sense(e, xyz);
        if (s->uncapped && !e->has_src) xyz[1] = 120; /* room light */
        if (xyz[1] > 0.05) {
            reply_text(e, "ER11");
        } else {
            s->zeroed = 1;
            reply_text(e, "OK00");
        }
    } else {
        reply_text(e, "ER01");
    }
}

static int proto_key(emu_common *e, const char *k, const char *v, csf_error *err)
{
    if (strcmp(k, "uncapped") != 0) return 0;
    if (strcmp(v, "0") && strcmp(v, "1")) {
        csf_error_set(err, CSF_E_INVALID_ARG, "emulator: uncapped=%s (0 or 1)", v);
        return -1;
    }
    ((cc2_emu *)e)->uncapped = v[0] == '1';
    return 1;
}

csf_status emu_colorcal2_open(const char *options, csf_emu_device **out, csf_error *err)
{
    cc2_emu *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    memcpy(s->m, factory, sizeof factory);
    invert3(s->m, s->minv);
    snprintf(s->c.serial, sizeof s->c.serial, "%s", "10230157");
    s->c.on_command = on_command;
    csf_status st = emu_common_init(&s->c, "ColorCAL MkII", options, proto_key, err);
    if (st) {
        csf_display_model_free(s->c.display);
        free(s);
        return st;
    }
    *out = &s->c.dev;
    return CSF_OK;
}
