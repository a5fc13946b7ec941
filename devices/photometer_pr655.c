/* Photo Research PR-655 / PR-670 driver (see devices/photometer_pr655.h). Protocol here; bytes
 * through devices/transport_serial. */
#include "devices/photometer_pr655.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_driver.h"
#include "devices/transport_serial.h"

typedef struct {
    const char *name; /* "PR-655" */
    csf_transport *t;
    char path[256];
    char who[320];
    char model[40], serial[40];
    double timeout_s;    /* a measurement: adaptive exposure in dim light takes long */
    double aperture_deg; /* the measuring aperture set on the instrument (aperture=) */
    unsigned long n;
} pr_state;

csf_status csf_pr_parse(const char *line, size_t len, csf_pr_reply *out, csf_error *err)
{
    memset(out, 0, sizeof *out);
    char buf[512];
    while (len > 0 && (line[len - 1] == ' ' || line[len - 1] == '\r' || line[len - 1] == '\n')) len--;
    size_t start = 0;
    while (start < len && line[start] == ' ') start++;
    if (len - start >= sizeof buf) return csf_error_set(err, CSF_E_PROTOCOL, "reply longer than %zu bytes", sizeof buf - 1);
    if (memchr(line + start, 0, len - start)) return csf_error_set(err, CSF_E_PROTOCOL, "reply holds a NUL byte");
    memcpy(buf, line + start, len - start);
    buf[len - start] = 0;
    char *p = buf, *end;
    if (!((*p >= '0' && *p <= '9') || *p == '-' || *p == '+'))
        return csf_error_set(err, CSF_E_PROTOCOL, "reply does not begin with an error code");
    errno = 0;
    long code = strtol(p, &end, 10);
    if (end == p || errno || end - p > 6) return csf_error_set(err, CSF_E_PROTOCOL, "error code is not a short integer");
    out->code = code;
    p = end;
    while (*p == ' ') p++;
    if (*p == 0) return CSF_OK;
    if (*p != ',') return csf_error_set(err, CSF_E_PROTOCOL, "error code not followed by a comma");
    while (*p == ',') {
        p++;
        if (out->n_fields == CSF_PR_MAX_FIELDS)
            return csf_error_set(err, CSF_E_PROTOCOL, "more than %d fields in the reply", CSF_PR_MAX_FIELDS);
        while (*p == ' ') p++;
        size_t n = strcspn(p, ",");
        size_t m = n;
        while (m > 0 && p[m - 1] == ' ') m--;
        if (m >= sizeof out->field[0])
            return csf_error_set(err, CSF_E_PROTOCOL, "field %d longer than %zu bytes", out->n_fields + 1,
                                 sizeof out->field[0] - 1);
        for (size_t k = 0; k < m; k++)
            if ((unsigned char)p[k] < 0x20 || (unsigned char)p[k] > 0x7e)
                return csf_error_set(err, CSF_E_PROTOCOL, "field %d holds a non-printable byte", out->n_fields + 1);
        memcpy(out->field[out->n_fields], p, m);
        out->field[out->n_fields][m] = 0;
        out->n_fields++;
        p += n;
    }
    return CSF_OK;
}

int csf_pr_field_num(const csf_pr_reply *r, int i, double *out)
{
    if (i < 0 || i >= r->n_fields || !r->field[i][0]) return -1;
    char *end;
    errno = 0;
    double x = strtod(r->field[i], &end);
    if (*end || errno == ERANGE || !isfinite(x)) return -1;
    *out = x;
    return 0;
}

const char *csf_pr_error_text(long code)
{
    switch (labs(code)) {
    case 0: return "no error";
    case 1: return "light source not constant";
    case 2: return "light overload: signal too intense";
    case 3: return "cannot sync to the light source";
    case 4: return "adaptive mode error";
    case 8: return "weak light: insufficient signal";
    case 9: return "sync error";
    case 10: return "cannot auto sync to the light source";
    case 12: return "adaptive mode time out: light source not constant";
    default: return labs(code) >= 1000 && labs(code) < 3000 ? "command or setup error" : "unknown error code";
    }
}

csf_status csf_pr_error_status(long code)
{
    switch (labs(code)) {
    case 8: return CSF_E_TOO_DARK;
    case 2: return CSF_E_SATURATED;
    default: return labs(code) >= 1000 && labs(code) < 3000 ? CSF_E_PROTOCOL : CSF_E_DEVICE;
    }
}

/* Sends cmd + CR and reads the reply line; an error code in it becomes the error. */
static csf_status command(pr_state *s, const char *cmd, double timeout_s, csf_pr_reply *r, csf_error *err)
{
    char line[512];
    size_t len;
    csf_status st =
        csf_transport_ask_line(s->t, cmd, "\r", 5, timeout_s, line, sizeof line, &len, s->who, err);
    if (st) return st;
    csf_error perr;
    if (csf_pr_parse(line, len, r, &perr))
        return csf_transport_unreadable(line, len, s->who, cmd, perr.msg, err);
    if (r->code != 0)
        return csf_error_set(err, csf_pr_error_status(r->code), "%s: error %ld to %s: %s", s->who, r->code, cmd,
                             csf_pr_error_text(r->code));
    return CSF_OK;
}

static void pr_close(void *state)
{
    pr_state *s = state;
    if (!s) return;
    if (s->t) {
        csf_error e;
        s->t->write(s->t, (const uint8_t *)"Q", 1, 1, &e); /* back to local mode */
        s->t->close(s->t);
    }
    free(s);
}

static csf_status remote_mode(pr_state *s, csf_error *err)
{
    csf_transport_drain(s->t);
    /* the manual: the letters one at a time, no line ending */
    for (const char *c = "PHOTO"; *c; c++) {
        csf_status st = s->t->write(s->t, (const uint8_t *)c, 1, 5, err);
        if (st) return st;
    }
    char line[128];
    size_t len;
    csf_status st = csf_transport_read_line(s->t, line, sizeof line, &len, 5, s->who, "PHOTO (remote mode)", err);
    if (st) return st;
    if (!strstr(line, "REMOTE MODE")) {
        char q[160];
        csf_quote_bytes(line, len, q, sizeof q);
        return csf_error_set(err, CSF_E_PROTOCOL, "%s: answered '%s' to PHOTO, not REMOTE MODE (is this a "
                             "Photo Research instrument?)", s->who, q);
    }
    return CSF_OK;
}

/* The PR-670's aperture wheel holds 1, 1/2, 1/4 and 1/8 deg (the names its remote mode reports,
 * PR-655/670 and PR-7xx user manuals, Photo Research); the PR-655 has the 1 deg one. csfcal does
 * not switch it: aperture= says which one is set, so the patch can be checked against it. */
static csf_status parse_aperture(const char *v, double *deg)
{
    static const struct {
        const char *name;
        double deg;
    } ap[] = {{"1", 1.0}, {"1/2", 0.5}, {"1/4", 0.25}, {"1/8", 0.125}};
    for (size_t i = 0; i < sizeof ap / sizeof ap[0]; i++)
        if (strcmp(v, ap[i].name) == 0) {
            *deg = ap[i].deg;
            return CSF_OK;
        }
    return CSF_E_INVALID_ARG;
}

csf_status csf_pr_parse_options(const char *spec_name, const char *opts, double *timeout_s,
                                double *aperture_deg, csf_error *err)
{
    int has_wheel = strcmp(spec_name, "pr670") == 0;
    if (!*opts) return csf_error_set(err, CSF_E_INVALID_ARG, "%s: empty option after ','", spec_name);
    while (*opts) {
        const char *comma = strchr(opts, ',');
        size_t len = comma ? (size_t)(comma - opts) : strlen(opts);
        char item[64];
        int ok = len < sizeof item;
        if (ok) {
            memcpy(item, opts, len);
            item[len] = 0;
        }
        if (ok && strncmp(item, "timeout_s=", 10) == 0) {
            char *end = NULL;
            errno = 0;
            double x = strtod(item + 10, &end);
            ok = end && !*end && !errno && x >= 0.1 && x <= 600;
            if (ok) *timeout_s = x;
        } else if (ok && has_wheel && strncmp(item, "aperture=", 9) == 0) {
            ok = parse_aperture(item + 9, aperture_deg) == CSF_OK;
        } else {
            ok = 0;
        }
        if (!ok)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s: option '%.*s' not understood (known: timeout_s=S, "
                                 "0.1 to 600 s%s)",
                                 spec_name, (int)(len > 60 ? 60 : len), opts,
                                 has_wheel ? "; aperture=1|1/2|1/4|1/8 deg" : "");
        opts += len + (comma ? 1 : 0);
        if (comma && !*opts)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: empty option after ','", spec_name);
    }
    return CSF_OK;
}

static void pr_field(void *state, double *field_deg, double *field_mm)
{
    const pr_state *s = state;
    *field_deg = s->aperture_deg;
    *field_mm = 0;
}

static csf_status pr_open_model(const char *name, const char *spec_name, const char *options, void **state,
                                csf_error *err)
{
    pr_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    const char *opts;
    csf_status pst =
        csf_serial_spec_port(options, name, spec_name, "/dev/ttyACM0", s->path, sizeof s->path, &opts, err);
    if (pst) {
        free(s);
        return pst;
    }
    s->name = name;
    s->timeout_s = 60;
    snprintf(s->who, sizeof s->who, "Photo Research %s on %s", name, s->path);
    s->aperture_deg = 1.0;
    csf_status st =
        opts ? csf_pr_parse_options(spec_name, opts, &s->timeout_s, &s->aperture_deg, err) : CSF_OK;
    if (st) {
        free(s);
        return st;
    }
    csf_serial_params sp = {9600, 8, 'N', 1}; /* USB CDC: the rate is not used on the wire */
    st = csf_serial_open(s->path, &sp, s->who, &s->t, err);
    if (!st) st = remote_mode(s, err);
    csf_pr_reply r;
    if (!st) st = command(s, "D111", 5, &r, err);
    if (!st) snprintf(s->model, sizeof s->model, "%s", r.n_fields ? r.field[r.n_fields - 1] : "?");
    if (!st) st = command(s, "D110", 5, &r, err);
    if (!st) snprintf(s->serial, sizeof s->serial, "%s", r.n_fields ? r.field[r.n_fields - 1] : "?");
    if (st) {
        pr_close(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static csf_status pr655_open(const char *o, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    return pr_open_model("PR-655", "pr655", o, state, err);
}
static csf_status pr670_open(const char *o, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    return pr_open_model("PR-670", "pr670", o, state, err);
}

static csf_status pr_identify(void *state, char *buf, size_t len, csf_error *err)
{
    pr_state *s = state;
    (void)err;
    snprintf(buf, len, "%s: reports model %s, serial number %s (remote mode, M0 + D2 XYZ)", s->who, s->model,
             s->serial);
    return CSF_OK;
}

static csf_status pr_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out, csf_error *err)
{
    pr_state *s = state;
    (void)src;
    unsigned long i = s->n++;
    csf_pr_reply r;
    csf_status st = command(s, "M0", s->timeout_s, &r, err);
    if (!st) st = command(s, "D2", s->timeout_s < 5 ? s->timeout_s : 5, &r, err);
    if (st) {
        size_t l = strlen(err->msg);
        snprintf(err->msg + l, sizeof err->msg - l, " (reading %lu of this connection)", i);
        return st;
    }
    double xyz[3];
    if (r.n_fields != 4 || csf_pr_field_num(&r, 1, &xyz[0]) || csf_pr_field_num(&r, 2, &xyz[1]) ||
        csf_pr_field_num(&r, 3, &xyz[2]))
        return csf_error_set(err, CSF_E_PROTOCOL, "%s: answer to D2 is not 'code,units,X,Y,Z' (%d fields)", s->who,
                             r.n_fields);
    if (xyz[1] < 0 || xyz[0] < 0 || xyz[2] < 0)
        return csf_error_set(err, CSF_E_PROTOCOL, "%s: negative tristimulus value in the answer to D2 (X %g Y %g Z %g)",
                             s->who, xyz[0], xyz[1], xyz[2]);
    memcpy(out->xyz, xyz, sizeof xyz);
    out->lum_cdm2 = xyz[1];
    out->has_xyz = 1;
    return CSF_OK;
}

const csf_photometer_driver csf_photometer_pr655_driver = {
    .name = "pr655",
    .description = "Photo Research PR-655 spectroradiometer (USB serial: pr655:/dev/ttyACM0)",
    .caps = CSF_PHOT_CAP_XYZ,
    .open = pr655_open,
    .identify = pr_identify,
    .measure = pr_measure,
    .close = pr_close,
    .field_deg = 1.0,
    .instance_field = pr_field,
};
const csf_photometer_driver csf_photometer_pr670_driver = {
    .name = "pr670",
    .description = "Photo Research PR-670 spectroradiometer (USB serial: pr670:/dev/ttyACM0)",
    .caps = CSF_PHOT_CAP_XYZ,
    .open = pr670_open,
    .identify = pr_identify,
    .measure = pr_measure,
    .close = pr_close,
    .field_deg = 1.0,
    .instance_field = pr_field,
};
