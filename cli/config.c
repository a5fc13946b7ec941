#include "cli/config.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/csv.h"
#include "core/file_read.h"
#include "core/spec.h"
#include "results/store/store.h"

void csf_config_defaults(csf_config *c)
{
    memset(c, 0, sizeof *c);
    c->screen_width_mm = 531.0;
    c->screen_height_mm = 299.0;
    c->screen_width_px = 1920;
    c->screen_height_px = 1080;
    c->viewing_distance_mm = 570.0;
    c->refresh_hz = 60.0;
    c->framebuffer_bits = 8;
    /* photometer left empty: a display calibration must be told which instrument to read (the
     * simulator is chosen by name, never by default: its "ok" would say nothing about the monitor) */
    /* observer left empty: the command picks a person at a display, the simulation without one */
    snprintf(c->responder, sizeof c->responder, "keyboard");
    c->profile_max_age_days = 30.0;
    snprintf(c->source, sizeof c->source, "(defaults)");
}

typedef enum { KEY_DOUBLE, KEY_INT, KEY_STRING } key_kind;

typedef struct {
    const char *name;
    key_kind kind;
    size_t offset;
    size_t size;      /* for strings */
    double lo, hi;    /* allowed range for numbers */
    const char *unit;
} key_spec;

#define DKEY(n, field, lo, hi, unit) {n, KEY_DOUBLE, offsetof(csf_config, field), 0, lo, hi, unit}
#define IKEY(n, field, lo, hi, unit) {n, KEY_INT, offsetof(csf_config, field), 0, lo, hi, unit}
#define SKEY(n, field) {n, KEY_STRING, offsetof(csf_config, field), sizeof(((csf_config *)0)->field), 0, 0, ""}

static const key_spec keys[] = {
    DKEY("screen_width_mm", screen_width_mm, 50, 10000, "mm"),
    DKEY("screen_height_mm", screen_height_mm, 30, 10000, "mm"),
    IKEY("screen_width_px", screen_width_px, 64, 16384, "px"),
    IKEY("screen_height_px", screen_height_px, 64, 16384, "px"),
    DKEY("viewing_distance_mm", viewing_distance_mm, 100, 10000, "mm"),
    DKEY("eye_offset_x_mm", eye_offset_x_mm, -5000, 5000, "mm"),
    DKEY("eye_offset_y_mm", eye_offset_y_mm, -5000, 5000, "mm"),
    DKEY("refresh_hz", refresh_hz, 20, 1000, "Hz"),
    IKEY("framebuffer_bits", framebuffer_bits, 8, 10, "bits per channel"),
    SKEY("monitor", monitor),
    SKEY("photometer", photometer),
    SKEY("observer", observer),
    SKEY("responder", responder),
    SKEY("store", store_path),
    SKEY("display_profile", display_profile),
    DKEY("profile_max_age_days", profile_max_age_days, 0, 3650, "days"),
};

csf_status csf_config_set(csf_config *c, const char *key, const char *value, const char *where,
                          csf_error *err)
{
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        const key_spec *k = &keys[i];
        if (strcmp(k->name, key) != 0) continue;
        char *base = (char *)c + k->offset;
        if (k->kind == KEY_STRING) {
            if (strlen(value) >= k->size)
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s is too long (at most %zu characters)",
                                     where, key, k->size - 1);
            /* Checked where they are read: these values are echoed in messages and stored with
             * sessions, and a store location must not carry a secret into either. */
            char w[1200];
            snprintf(w, sizeof w, "%s: %s", where, key);
            csf_status cs = k->offset == offsetof(csf_config, store_path) && *value
                                ? csf_store_check_location(value, w, err)
                                : csf_store_check_text(value, w, err);
            if (cs != CSF_OK) return cs;
            memcpy(base, value, strlen(value) + 1);
            return CSF_OK;
        }
        char num[1200]; /* white space around the number is layout, not part of it */
        snprintf(num, sizeof num, "%s", value);
        double v = 0;
        csf_num_result r = strlen(value) < sizeof num ? csf_number_parse(csf_trim(num), k->lo, k->hi, &v)
                                                      : CSF_NUM_NOT_A_NUMBER;
        if (r == CSF_NUM_NOT_A_NUMBER)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = '%s' is not a number (allowed %g to %g %s)",
                                 where, key, value, k->lo, k->hi, k->unit);
        if (r == CSF_NUM_OUT_OF_RANGE)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = %g is out of range (allowed %g to %g %s)",
                                 where, key, v, k->lo, k->hi, k->unit);
        if (k->kind == KEY_INT) {
            if (v != floor(v))
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = %g must be a whole number (%g to %g %s)",
                                     where, key, v, k->lo, k->hi, k->unit);
            if (k->offset == offsetof(csf_config, framebuffer_bits) && v != 8 && v != 10)
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s: framebuffer_bits = %g (allowed 8 or 10)", where, v);
            *(int *)base = (int)v;
        } else {
            *(double *)base = v;
        }
        return CSF_OK;
    }
    return csf_error_set(err, CSF_E_INVALID_ARG, "%s: unknown key '%s'", where, key);
}

static void default_config_path(char *out, size_t len)
{
    const char *xdg = getenv("XDG_CONFIG_HOME");
    const char *home = getenv("HOME");
    if (xdg && *xdg) snprintf(out, len, "%s/csfcal/station.conf", xdg);
    else snprintf(out, len, "%s/.config/csfcal/station.conf", home ? home : ".");
}

void csf_config_default_store_path(char *out, unsigned long out_len)
{
    const char *xdg = getenv("XDG_DATA_HOME");
    const char *home = getenv("HOME");
    if (xdg && *xdg) snprintf(out, out_len, "%s/csfcal/csfcal.sqlite", xdg);
    else snprintf(out, out_len, "%s/.local/share/csfcal/csfcal.sqlite", home ? home : ".");
}

/* Larger than any station configuration; a bigger file is something else given by mistake. */
#define CONFIG_MAX_BYTES ((size_t)1 << 20)
#define CONFIG_MAX_LINE 2046

static int key_index(const char *name)
{
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (strcmp(keys[i].name, name) == 0) return (int)i;
    return -1;
}

/* A configuration file is text: a NUL byte or another control character (tab, CR and LF apart)
 * means a binary file was given, which deserves that name rather than a complaint about its
 * "line length". Returns the offset of the first such byte, or -1. */
static long first_binary_byte(const char *data, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)data[i];
        if ((ch < 0x20 && ch != '\t' && ch != '\r' && ch != '\n') || ch == 0x7f) return (long)i;
    }
    return -1;
}

static csf_status parse_config_text(csf_config *c, const char *path, char *data, size_t len,
                                    csf_error *err)
{
    long bin = first_binary_byte(data, len);
    if (bin >= 0) {
        int line = 1;
        for (long i = 0; i < bin; i++) line += data[i] == '\n';
        return csf_error_set(err, CSF_E_FORMAT, "%s:%d: not a text file (byte 0x%02x at offset %ld): a "
                             "configuration file holds 'key = value' lines", path, line,
                             (unsigned char)data[bin], bin);
    }
    int set_on_line[sizeof keys / sizeof keys[0]] = {0};
    csf_lines lines;
    if (csf_lines_open(&lines, data, strlen(data), CONFIG_MAX_LINE))
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    lines.hash_comments = 1;
    char *s;
    int got;
    csf_status st = CSF_OK;
    while (st == CSF_OK && (got = csf_lines_next(&lines, &s)) != 0) {
        int lineno = lines.line;
        char where[1100];
        snprintf(where, sizeof where, "%.1080s:%d", path, lineno);
        if (got < 0) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: %s", where, lines.why);
            break;
        }
        if (*s == '[') {
            if (strcmp(s, "[station]") != 0)
                st = csf_error_set(err, CSF_E_FORMAT, "%s: unknown section %s (only [station])", where, s);
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: expected 'key = value'", where);
            break;
        }
        *eq = '\0';
        char *key = csf_trim(s);
        int k = key_index(key);
        if (k >= 0 && set_on_line[k])
            st = csf_error_set(err, CSF_E_FORMAT, "%s: %s is set twice (first on line %d): keep one line",
                               where, key, set_on_line[k]);
        else st = csf_config_set(c, key, csf_trim(eq + 1), where, err);
        if (st == CSF_OK) set_on_line[k] = lineno;
    }
    csf_lines_close(&lines);
    return st;
}

csf_status csf_config_load(csf_config *c, const char *path, csf_error *err)
{
    char defpath[1024];
    int explicit_path = path != NULL;
    if (!path) {
        default_config_path(defpath, sizeof defpath);
        path = defpath;
    }
    if (explicit_path && *path == '\0') {
        default_config_path(defpath, sizeof defpath);
        return csf_error_set(err, CSF_E_INVALID_ARG, "--config: empty path (give a configuration file, or "
                             "leave --config out for the default %s)", defpath);
    }
    struct stat sb;
    if (stat(path, &sb) != 0) {
        if (!explicit_path && errno == ENOENT) return CSF_OK;
        return csf_error_set(err, CSF_E_IO, "cannot open configuration file %s: %s", path, strerror(errno));
    }
    /* fopen() accepts a folder and reading it yields nothing: it would pass as an empty file and
     * every value would silently be a default. */
    if (S_ISDIR(sb.st_mode))
        return csf_error_set(err, CSF_E_INVALID_ARG, "configuration file %s is a folder, not a file", path);
    char *data = NULL;
    size_t len = 0;
    csf_status st = csf_read_file(path, "configuration file", CONFIG_MAX_BYTES, &data, &len, err);
    if (st != CSF_OK) return st;
    st = parse_config_text(c, path, data, len, err);
    free(data);
    if (st == CSF_OK) snprintf(c->source, sizeof c->source, "%s", path);
    return st;
}
