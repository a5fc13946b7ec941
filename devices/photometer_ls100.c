/* Konica Minolta LS-100 / LS-110 / CS-100A driver (see devices/photometer_ls100.h). Protocol
 * (command bytes, reply parsing, error codes) here; bytes travel through devices/transport_serial. */
#include "devices/photometer_ls100.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_driver.h"
#include "devices/transport_serial.h"

enum { MODEL_LS100, MODEL_LS110, MODEL_CS100A };
static const char *const model_names[] = {"LS-100", "LS-110", "CS-100A"};

typedef struct {
    int model;
    csf_transport *t;
    char path[256];
    char who[320];    /* "Konica Minolta LS-100 on /dev/ttyUSB0" */
    double timeout_s; /* per command */
    double floor_cdm2;
    unsigned long n;  /* readings asked for */
} ls_state;

csf_status csf_minolta_parse(const char *line, size_t len, csf_minolta_reply *out, csf_error *err)
{
    memset(out, 0, sizeof *out);
    char buf[128];
    while (len > 0 && (line[len - 1] == ' ' || line[len - 1] == '\r' || line[len - 1] == '\n')) len--;
    if (len >= sizeof buf) return csf_error_set(err, CSF_E_PROTOCOL, "reply longer than %zu bytes", sizeof buf - 1);
    memcpy(buf, line, len);
    buf[len] = 0;
    if (memchr(buf, 0, len)) return csf_error_set(err, CSF_E_PROTOCOL, "reply holds a NUL byte");
    if (len < 4 || !((buf[0] == 'O' && buf[1] == 'K') || (buf[0] == 'E' && buf[1] == 'R')) ||
        buf[2] < '0' || buf[2] > '9' || buf[3] < '0' || buf[3] > '9')
        return csf_error_set(err, CSF_E_PROTOCOL, "reply is neither OKnn nor ERnn");
    out->ok = buf[0] == 'O';
    out->code = (buf[2] - '0') * 10 + (buf[3] - '0');
    if (!out->ok) {
        if (len != 4) return csf_error_set(err, CSF_E_PROTOCOL, "error reply ERnn followed by other bytes");
        return CSF_OK;
    }
    if (len == 4) return CSF_OK; /* an acknowledgement (MDS) */
    if (buf[4] != ',') return csf_error_set(err, CSF_E_PROTOCOL, "OKnn not followed by a comma");
    char *p = buf + 5;
    for (;;) {
        if (out->n_values == 3) return csf_error_set(err, CSF_E_PROTOCOL, "more than 3 values in the reply");
        while (*p == ' ') p++;
        char *end;
        errno = 0;
        double x = strtod(p, &end);
        if (end == p || errno == ERANGE || !isfinite(x))
            return csf_error_set(err, CSF_E_PROTOCOL, "value %d of the reply is not a number", out->n_values + 1);
        out->v[out->n_values++] = x;
        while (*end == ' ') end++;
        if (*end == 0) break;
        if (*end != ',') return csf_error_set(err, CSF_E_PROTOCOL, "unexpected byte after value %d", out->n_values);
        p = end + 1;
    }
    return CSF_OK;
}

const char *csf_minolta_error_text(int code)
{
    switch (code) {
    case 0: return "command error (the instrument did not understand the command)";
    case 1: return "setting error";
    case 10: return "measuring range over (too bright for the instrument)";
    case 11: return "memory value error";
    case 19: return "display range over (too bright to display)";
    case 20: return "EEPROM error (the instrument needs repair)";
    case 30: return "battery exhausted (replace the battery)";
    default: return "unknown error code";
    }
}

csf_status csf_minolta_error_status(int code)
{
    switch (code) {
    case 0: return CSF_E_PROTOCOL;
    case 10:
    case 19: return CSF_E_SATURATED;
    default: return CSF_E_DEVICE;
    }
}

static double num_opt(const char *v, double lo, double hi, int *bad)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    if (errno || end == v || *end || !isfinite(x) || x < lo || x > hi) *bad = 1;
    return x;
}

static csf_status command(ls_state *s, const char *cmd, csf_minolta_reply *r, csf_error *err)
{
    char line[128];
    size_t len;
    csf_status st = csf_transport_ask_line(s->t, cmd, "\r\n", s->timeout_s, s->timeout_s, line, sizeof line,
                                           &len, s->who, err);
    if (st) return st;
    csf_error perr;
    if (csf_minolta_parse(line, len, r, &perr))
        return csf_transport_unreadable(line, len, s->who, cmd, perr.msg, err);
    if (!r->ok)
        return csf_error_set(err, csf_minolta_error_status(r->code), "%s: ER%02d to %s: %s", s->who, r->code, cmd,
                             csf_minolta_error_text(r->code));
    return CSF_OK;
}

static void ls_close(void *state)
{
    ls_state *s = state;
    if (!s) return;
    if (s->t) s->t->close(s->t);
    free(s);
}

static csf_status ls_open_model(int model, const char *options, void **state, csf_error *err)
{
    const char *name = model_names[model];
    const char *spec_name = model == MODEL_CS100A ? "cs100a" : model == MODEL_LS110 ? "ls110" : "ls100";
    ls_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    const char *opts;
    csf_status pst =
        csf_serial_spec_port(options, name, spec_name, "/dev/ttyUSB0", s->path, sizeof s->path, &opts, err);
    if (pst) {
        free(s);
        return pst;
    }
    s->model = model;
    s->timeout_s = 10;  /* a reading takes about 1 s; slow mode and dim light longer */
    s->floor_cdm2 = model == MODEL_CS100A ? 0.01 : 0.001; /* lower end of the measuring range */
    snprintf(s->who, sizeof s->who, "Konica Minolta %s on %s", name, s->path);
    char buf[256];
    snprintf(buf, sizeof buf, "%s", opts ? opts : "");
    char *save = NULL;
    for (char *tok = opts ? strtok_r(buf, ",", &save) : NULL; tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        int bad = 0;
        if (eq) *eq = 0;
        if (eq && strcmp(tok, "timeout_s") == 0) s->timeout_s = num_opt(eq + 1, 0.1, 600, &bad);
        else if (eq && strcmp(tok, "floor_cdm2") == 0) s->floor_cdm2 = num_opt(eq + 1, 0, 100, &bad);
        else {
            free(s);
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: unknown option '%s' (known: timeout_s=S 0.1 to 600, "
                                 "floor_cdm2=L 0 to 100)", name, tok);
        }
        if (bad) {
            csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s=%s out of range (timeout_s 0.1 to 600 s, floor_cdm2 0 "
                          "to 100 cd/m2)", name, tok, eq + 1);
            free(s);
            return CSF_E_INVALID_ARG;
        }
    }
    csf_serial_params sp = {4800, 7, 'E', 2};
    csf_status st = csf_serial_open(s->path, &sp, s->who, &s->t, err);
    if (st) {
        free(s);
        return st;
    }
    csf_minolta_reply r;
    st = command(s, "MDS,04", &r, err); /* absolute measurement mode */
    if (st) {
        ls_close(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static csf_status ls100_open(const char *o, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    return ls_open_model(MODEL_LS100, o, state, err);
}
static csf_status ls110_open(const char *o, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    return ls_open_model(MODEL_LS110, o, state, err);
}
static csf_status cs100a_open(const char *o, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    return ls_open_model(MODEL_CS100A, o, state, err);
}

static csf_status ls_identify(void *state, char *buf, size_t len, csf_error *err)
{
    ls_state *s = state;
    (void)err;
    snprintf(buf, len, "%s (serial 4800 baud 7E2, absolute mode%s)", s->who,
             s->model == MODEL_CS100A ? ", Yxy" : ", luminance only");
    return CSF_OK;
}

static csf_status ls_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out, csf_error *err)
{
    ls_state *s = state;
    (void)src; /* a real instrument measures the light itself */
    unsigned long i = s->n++;
    csf_minolta_reply r;
    csf_status st = command(s, "MES", &r, err);
    if (st) {
        size_t l = strlen(err->msg);
        snprintf(err->msg + l, sizeof err->msg - l, " (reading %lu of this connection)", i);
        return st;
    }
    int need = s->model == MODEL_CS100A ? 3 : 1;
    if (r.n_values != need)
        return csf_error_set(err, CSF_E_PROTOCOL, "%s: answer to MES has %d values, expected %d (%s)", s->who,
                             r.n_values, need, need == 3 ? "luminance, x, y" : "luminance");
    double Y = r.v[0];
    if (Y < s->floor_cdm2)
        return csf_error_set(err, CSF_E_TOO_DARK, "%s: too dark: %g cd/m2 is below its %g cd/m2 measuring range",
                             s->who, Y, s->floor_cdm2);
    out->lum_cdm2 = Y;
    out->xyz[1] = Y;
    if (s->model == MODEL_CS100A) {
        double x = r.v[1], y = r.v[2];
        if (!(x > 0 && y > 0 && x + y <= 1))
            return csf_error_set(err, CSF_E_PROTOCOL, "%s: chromaticity x=%g y=%g outside the spectrum locus's "
                                 "range in the answer to MES", s->who, x, y);
        out->xyz[0] = x * Y / y;
        out->xyz[2] = (1 - x - y) * Y / y;
        out->has_xyz = 1;
    }
    return CSF_OK;
}

/* Acceptance angles from Konica Minolta's specifications: LS-100 and CS-100A 1 deg, LS-110 1/3 deg
 * (through the reflex viewfinder, which shows the measuring circle). */
#define LS_DRIVER(var, nm, desc, openfn, capv, fdeg)                                                         \
    const csf_photometer_driver var = {                                                                      \
        .name = (nm),                                                                                        \
        .description = (desc),                                                                               \
        .caps = (capv),                                                                                      \
        .open = (openfn),                                                                                    \
        .identify = ls_identify,                                                                             \
        .measure = ls_measure,                                                                               \
        .close = ls_close,                                                                                   \
        .field_deg = (fdeg),                                                                                 \
    }
LS_DRIVER(csf_photometer_ls100_driver, "ls100",
          "Konica Minolta LS-100 luminance meter (serial: ls100:/dev/ttyUSB0)", ls100_open, 0, 1.0);
LS_DRIVER(csf_photometer_ls110_driver, "ls110",
          "Konica Minolta LS-110 luminance meter (serial: ls110:/dev/ttyUSB0)", ls110_open, 0, 1.0 / 3.0);
LS_DRIVER(csf_photometer_cs100a_driver, "cs100a",
          "Konica Minolta CS-100A chroma meter (serial: cs100a:/dev/ttyUSB0)", cs100a_open, CSF_PHOT_CAP_XYZ,
          1.0);
