/* CRS ColorCAL MkII reply parsing and matrix arithmetic (see colorcal2_proto.h). Replies are
 * outside input: every byte is checked, numbers are plain decimals only (no exponents, inf or
 * nan), and a reply that is not understood is shown (escaped) in the error. */
#include "devices/colorcal2_proto.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Up to 24 bytes of a reply, non-printable bytes as \xNN, for messages. */
static void show_bytes(const unsigned char *buf, size_t len, char *out, size_t cap)
{
    size_t o = 0;
    out[0] = '\0';
    for (size_t i = 0; i < len && i < 24 && o + 5 < cap; i++) {
        unsigned char c = buf[i];
        if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') out[o++] = (char)c;
        else o += (size_t)snprintf(out + o, cap - o, "\\x%02x", c);
        out[o] = '\0';
    }
    if (len > 24 && o + 4 < cap) strcat(out, "...");
}

/* A decimal: optional sign, digits, optional '.' and digits; at least one digit. Spaces before
 * it are allowed (the instrument pads fixed-width fields). Returns the bytes used, 0 if none. */
static size_t parse_decimal(const char *s, size_t len, double *out)
{
    size_t i = 0;
    while (i < len && s[i] == ' ') i++;
    size_t start = i;
    if (i < len && (s[i] == '-' || s[i] == '+')) i++;
    size_t digits = 0;
    while (i < len && isdigit((unsigned char)s[i])) i++, digits++;
    if (i < len && s[i] == '.') {
        i++;
        while (i < len && isdigit((unsigned char)s[i])) i++, digits++;
    }
    if (digits == 0 || digits > 15) return 0;
    char tmp[32];
    memcpy(tmp, s + start, i - start);
    tmp[i - start] = '\0';
    *out = strtod(tmp, NULL);
    return i;
}

csf_status csf_cc2_parse_reply(const char *cmd, const unsigned char *buf, size_t len, csf_cc2_reply *out,
                               csf_error *err)
{
    memset(out, 0, sizeof *out);
    char shown[128];
    show_bytes(buf, len, shown, sizeof shown);
    /* trailing line ends, NULs (a fixed-size control transfer is padded) and the serial prompt */
    while (len > 0 && (buf[len - 1] == '\r' || buf[len - 1] == '\n' || buf[len - 1] == '\0' ||
                       buf[len - 1] == '>' || buf[len - 1] == ' '))
        len--;
    const char *s = (const char *)buf;
    if (len < 4 || !(memcmp(s, "OK", 2) == 0 || memcmp(s, "ER", 2) == 0) || !isdigit((unsigned char)s[2]) ||
        !isdigit((unsigned char)s[3]))
        return csf_error_set(err, CSF_E_PROTOCOL, "unreadable answer to %s: \"%s\" (%zu bytes; expected "
                             "OKnn or ERnn)", cmd, shown, len);
    out->ok = s[0] == 'O';
    out->code = (s[2] - '0') * 10 + (s[3] - '0');
    size_t i = 4;
    while (i < len) {
        if (s[i] != ',')
            return csf_error_set(err, CSF_E_PROTOCOL, "unreadable answer to %s: \"%s\" (byte %zu is not a "
                                 "comma)", cmd, shown, i);
        i++;
        if (out->n_fields >= (int)(sizeof out->field / sizeof out->field[0]))
            return csf_error_set(err, CSF_E_PROTOCOL, "answer to %s has more than %zu fields: \"%s\"", cmd,
                                 sizeof out->field / sizeof out->field[0], shown);
        double v;
        size_t used = parse_decimal(s + i, len - i, &v);
        if (!used)
            return csf_error_set(err, CSF_E_PROTOCOL, "unreadable answer to %s: \"%s\" (field %d is not a "
                                 "decimal number)", cmd, shown, out->n_fields + 1);
        out->field[out->n_fields++] = v;
        i += used;
    }
    return CSF_OK;
}

double csf_cc2_minolta_to_double(long v)
{
    return v < 50000 ? (double)v / 10000.0 : -((double)v - 50000.0) / 10000.0;
}

long csf_cc2_double_to_minolta(double x)
{
    long v = lround(fabs(x) * 10000.0);
    return x < 0 && v > 0 ? v + 50000 : v;
}

static csf_status expect_ok(const char *cmd, const csf_cc2_reply *r, int n_fields, csf_error *err)
{
    if (!r->ok)
        return csf_error_set(err, CSF_E_DEVICE, "instrument error ER%02d in answer to %s", r->code, cmd);
    if (r->code != 0)
        return csf_error_set(err, CSF_E_PROTOCOL, "unexpected status OK%02d in answer to %s", r->code, cmd);
    if (r->n_fields != n_fields)
        return csf_error_set(err, CSF_E_PROTOCOL, "answer to %s has %d numbers (expected %d)", cmd,
                             r->n_fields, n_fields);
    return CSF_OK;
}

csf_status csf_cc2_parse_matrix_row(const unsigned char *buf, size_t len, int row1, double out[3],
                                    csf_error *err)
{
    char cmd[8];
    snprintf(cmd, sizeof cmd, "r0%d", row1 % 10);
    csf_cc2_reply r;
    csf_status st = csf_cc2_parse_reply(cmd, buf, len, &r, err);
    if (!st) st = expect_ok(cmd, &r, 3, err);
    if (st) return st;
    for (int k = 0; k < 3; k++) {
        double v = r.field[k];
        if (v != floor(v) || v < 0 || v > 99999)
            return csf_error_set(err, CSF_E_PROTOCOL, "matrix row %d value %g is not a Minolta number "
                                 "(an integer 0..99999)", row1, v);
        out[k] = csf_cc2_minolta_to_double((long)v);
    }
    return CSF_OK;
}

csf_status csf_cc2_parse_identity(const unsigned char *buf, size_t len, long *serial, long *rom, long *build,
                                  csf_error *err)
{
    csf_cc2_reply r;
    csf_status st = csf_cc2_parse_reply("IDR", buf, len, &r, err);
    if (!st) st = expect_ok("IDR", &r, 5, err);
    if (st) return st;
    for (int k = 0; k < 5; k++)
        if (k != 2 && (r.field[k] != floor(r.field[k]) || r.field[k] < 0 || r.field[k] > 1e9))
            return csf_error_set(err, CSF_E_PROTOCOL, "identity field %d (%g) is not a whole number "
                                 "0..1e9", k + 1, r.field[k]);
    *rom = (long)r.field[1];
    *serial = (long)r.field[3];
    *build = (long)r.field[4];
    return CSF_OK;
}

csf_status csf_cc2_parse_measurement(const unsigned char *buf, size_t len, double raw[3], csf_error *err)
{
    csf_cc2_reply r;
    csf_status st = csf_cc2_parse_reply("MES", buf, len, &r, err);
    if (!st) st = expect_ok("MES", &r, 3, err);
    if (st) return st;
    for (int k = 0; k < 3; k++) {
        if (fabs(r.field[k]) > 1e7)
            return csf_error_set(err, CSF_E_PROTOCOL, "measurement value %g is beyond any reading the "
                                 "instrument makes (|v| <= 1e7)", r.field[k]);
        raw[k] = r.field[k];
    }
    return CSF_OK;
}

int csf_cc2_matrix_usable(const double m[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!isfinite(m[i][j])) return 0;
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return fabs(det) > 1e-6;
}

void csf_cc2_apply(const double m[3][3], const double raw[3], double xyz[3])
{
    for (int i = 0; i < 3; i++) xyz[i] = m[i][0] * raw[0] + m[i][1] * raw[1] + m[i][2] * raw[2];
}
