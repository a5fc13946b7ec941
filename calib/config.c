#include "calib/config.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    snprintf(c->photometer, sizeof c->photometer, "sim");
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
    DKEY("viewing_distance_mm", viewing_distance_mm, 100, 20000, "mm"),
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

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    return s;
}

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
            memcpy(base, value, strlen(value) + 1);
            return CSF_OK;
        }
        char *end = NULL;
        errno = 0;
        double v = strtod(value, &end);
        if (end == value || *trim(end) != '\0' || errno == ERANGE || !isfinite(v))
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = '%s' is not a number (allowed %g to %g %s)",
                                 where, key, value, k->lo, k->hi, k->unit);
        if (v < k->lo || v > k->hi)
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

csf_status csf_config_load(csf_config *c, const char *path, csf_error *err)
{
    char defpath[1024];
    int explicit_path = path != NULL;
    if (!path) {
        default_config_path(defpath, sizeof defpath);
        path = defpath;
    }
    FILE *f = fopen(path, "r");
    if (!f) {
        if (!explicit_path) return CSF_OK;
        return csf_error_set(err, CSF_E_IO, "cannot open configuration file %s: %s", path, strerror(errno));
    }
    char line[2048];
    int lineno = 0;
    csf_status st = CSF_OK;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char where[1100];
        snprintf(where, sizeof where, "%s:%d", path, lineno);
        if (!strchr(line, '\n') && !feof(f)) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: line longer than %zu characters", where, sizeof line - 2);
            break;
        }
        char *hash = strchr(line, '#');
        if (hash) *hash = '\0';
        char *s = trim(line);
        if (*s == '\0') continue;
        if (*s == '[') {
            if (strcmp(s, "[station]") != 0) {
                st = csf_error_set(err, CSF_E_FORMAT, "%s: unknown section %s (only [station])", where, s);
                break;
            }
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: expected 'key = value'", where);
            break;
        }
        *eq = '\0';
        st = csf_config_set(c, trim(s), trim(eq + 1), where, err);
        if (st != CSF_OK) break;
    }
    fclose(f);
    if (st == CSF_OK) snprintf(c->source, sizeof c->source, "%s", path);
    return st;
}
