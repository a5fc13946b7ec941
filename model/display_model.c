/* Simulated display truth. Each kind is a physical-ish model with its own flaws (offset and
 * per-channel gamma for CRTs, a dark toe and channel interaction for LCDs, power limiting for
 * OLEDs) so that a calibration cannot succeed by assuming one power law. */
#include "model/display_model.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/file_read.h"
#include "core/csv.h"
#include "core/spec.h"

enum { KIND_CRT, KIND_LCD, KIND_OLED, KIND_CSV };

#define CSV_LEVELS 256

struct csf_display_model {
    int kind;
    double lmax_cdm2;      /* white luminance above black */
    double black_cdm2;
    double gamma[3];
    double weight[3];      /* channel share of white (luminance) */
    double interaction;    /* lcd: fraction white falls short of the channel sum */
    double csv[3][CSV_LEVELS]; /* csv: channel luminance (black excluded) per level */
    double xyz_per_y[3][3];    /* XYZ per unit Y for each primary */
    double black_xyz_per_y[3];
};

/* sRGB / Rec.709 primaries and D65: chromaticities are facts of the standard. */
static const double prim_xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
static const double white_xy[2] = {0.3127, 0.3290};

static void xy_to_xyz_per_y(double x, double y, double out[3])
{
    out[0] = x / y;
    out[1] = 1.0;
    out[2] = (1.0 - x - y) / y;
}

static double clamp01(double v)
{
    if (!(v > 0.0)) return 0.0; /* also maps NaN to 0 */
    return v > 1.0 ? 1.0 : v;
}

/* Normalised channel response (0 at v=0 up to 1 at v=1) before interaction. */
static double channel_resp(const csf_display_model *m, int c, double v)
{
    v = clamp01(v);
    switch (m->kind) {
    case KIND_CRT: {
        /* gain-offset-gamma with a small negative offset: the beam cuts off below ~2 % drive */
        const double a = 1.02, b = -0.02;
        double x = a * v + b;
        return x > 0.0 ? pow(x, m->gamma[c]) : 0.0;
    }
    case KIND_LCD: {
        /* power law times a logistic: the S-shaped toe of a liquid-crystal panel near black */
        const double v0 = 0.08, w = 0.035;
        double s = 1.0 / (1.0 + exp(-(v - v0) / w));
        double s1 = 1.0 / (1.0 + exp(-(1.0 - v0) / w));
        double s0 = 1.0 / (1.0 + exp(v0 / w));
        return pow(v, m->gamma[c]) * (s - s0) / (s1 - s0);
    }
    case KIND_OLED: {
        /* emission starts only above a threshold current, then a power law */
        double x = (v - 0.015) / 0.985;
        return x > 0.0 ? pow(x, m->gamma[c]) : 0.0;
    }
    default: {
        double pos = v * (CSV_LEVELS - 1);
        int i = (int)floor(pos);
        if (i >= CSV_LEVELS - 1) return m->csv[c][CSV_LEVELS - 1];
        double f = pos - i;
        return m->csv[c][i] + f * (m->csv[c][i + 1] - m->csv[c][i]);
    }
    }
}

/* Returns per-channel luminance (black excluded) after interaction/power limiting. */
static void channel_lums(const csf_display_model *m, double r01, double g01, double b01,
                         double out[3])
{
    double v[3] = {r01, g01, b01};
    double g[3];
    for (int c = 0; c < 3; c++) g[c] = channel_resp(m, c, v[c]);
    if (m->kind == KIND_CSV) {
        for (int c = 0; c < 3; c++) out[c] = g[c];
        return;
    }
    double scale = 1.0;
    if (m->kind == KIND_LCD) {
        /* crosstalk: each lit channel dims the others slightly (shared backlight/driver load) */
        double p = (g[0] * g[1] + g[1] * g[2] + g[0] * g[2]) / 3.0;
        /* normalised so white is lmax; a channel alone is then a few % above its share, so
         * R + G + B measured separately exceeds white: the additivity error a calibration sees */
        scale = (1.0 - m->interaction * p) / (1.0 - m->interaction);
    } else if (m->kind == KIND_OLED) {
        /* automatic brightness limiting: large bright areas droop by up to 4 % */
        double s = m->weight[0] * g[0] + m->weight[1] * g[1] + m->weight[2] * g[2];
        scale = (1.0 - 0.04 * s * s);
    }
    for (int c = 0; c < 3; c++) out[c] = m->lmax_cdm2 * m->weight[c] * g[c] * scale;
}

double csf_display_model_lum(const csf_display_model *m, double r01, double g01, double b01)
{
    double l[3];
    channel_lums(m, r01, g01, b01, l);
    return m->black_cdm2 + l[0] + l[1] + l[2];
}

void csf_display_model_xyz(const csf_display_model *m, double r01, double g01, double b01,
                           double xyz[3])
{
    double l[3];
    channel_lums(m, r01, g01, b01, l);
    for (int k = 0; k < 3; k++) {
        xyz[k] = m->black_cdm2 * m->black_xyz_per_y[k];
        for (int c = 0; c < 3; c++) xyz[k] += l[c] * m->xyz_per_y[c][k];
    }
}

const char *csf_display_model_kind(const csf_display_model *m)
{
    static const char *names[] = {"crt", "lcd", "oled", "csv"};
    return names[m->kind];
}

void csf_display_model_free(csf_display_model *m)
{
    free(m);
}

static csf_display_model *model_new(int kind)
{
    csf_display_model *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->kind = kind;
    static const double w709[3] = {0.2126, 0.7152, 0.0722};
    for (int c = 0; c < 3; c++) {
        m->weight[c] = w709[c];
        xy_to_xyz_per_y(prim_xy[c][0], prim_xy[c][1], m->xyz_per_y[c]);
    }
    xy_to_xyz_per_y(white_xy[0], white_xy[1], m->black_xyz_per_y);
    switch (kind) {
    case KIND_CRT:
        m->lmax_cdm2 = 95.0; m->black_cdm2 = 0.05;
        m->gamma[0] = 2.35; m->gamma[1] = 2.45; m->gamma[2] = 2.28;
        break;
    case KIND_LCD:
        m->lmax_cdm2 = 180.0; m->black_cdm2 = 0.35; m->interaction = 0.03;
        m->gamma[0] = 2.15; m->gamma[1] = 2.25; m->gamma[2] = 2.05;
        break;
    case KIND_OLED:
        m->lmax_cdm2 = 250.0; m->black_cdm2 = 0.0005;
        m->gamma[0] = 2.2; m->gamma[1] = 2.2; m->gamma[2] = 2.25;
        break;
    default:
        m->black_cdm2 = 0.2;
        break;
    }
    return m;
}

/* The four comma-separated numbers of a data line into f. */
static csf_status csv_fields(const char *s, const char *name, int line_no, double f[4], csf_error *err)
{
    char fields[5][CSF_CSV_FIELD_MAX];
    const char *why;
    int n = csf_csv_split(s, fields, 5, &why);
    if (n < 0 && strcmp(why, "too many columns") != 0)
        return csf_error_set(err, CSF_E_FORMAT, "%s:%d: %s", name, line_no, why);
    if (n < 0 || n > 4)
        return csf_error_set(err, CSF_E_FORMAT, "%s:%d: trailing text after 4 fields", name, line_no);
    if (n != 4)
        return csf_error_set(err, CSF_E_FORMAT, "%s:%d: expected 4 comma-separated fields", name, line_no);
    for (int k = 0; k < 4; k++)
        if (csf_number_parse(fields[k], -INFINITY, INFINITY, &f[k]) != CSF_NUM_OK)
            return csf_error_set(err, CSF_E_FORMAT, "%s:%d: field %d is not a number", name, line_no, k + 1);
    return CSF_OK;
}

/* One row's level and three channel luminances into m; seen marks the levels given so far. */
static csf_status csv_store_row(csf_display_model *m, int *seen, const double f[4], const char *name,
                                int line_no, csf_error *err)
{
    if (f[0] != floor(f[0]) || f[0] < 0 || f[0] > CSV_LEVELS - 1)
        return csf_error_set(err, CSF_E_FORMAT, "%s:%d: level must be an integer 0..255", name, line_no);
    int lv = (int)f[0];
    if (seen[lv]) return csf_error_set(err, CSF_E_FORMAT, "%s:%d: level %d given twice", name, line_no, lv);
    for (int c = 0; c < 3; c++) {
        if (f[c + 1] < 0 || f[c + 1] > 10000)
            return csf_error_set(err, CSF_E_FORMAT, "%s:%d: luminance %g out of range (0 to 10000 cd/m2)",
                                 name, line_no, f[c + 1]);
        m->csv[c][lv] = f[c + 1];
    }
    seen[lv] = 1;
    return CSF_OK;
}

/* Every level present, and no channel darker at a higher level. */
static csf_status csv_check_levels(const csf_display_model *m, const int *seen, const char *name,
                                   csf_error *err)
{
    for (int lv = 0; lv < CSV_LEVELS; lv++) {
        if (!seen[lv])
            return csf_error_set(err, CSF_E_FORMAT, "%s: level %d missing (need all levels 0..255)", name,
                                 lv);
        if (lv > 0)
            for (int c = 0; c < 3; c++)
                if (m->csv[c][lv] < m->csv[c][lv - 1])
                    return csf_error_set(err, CSF_E_FORMAT,
                                         "%s: channel %c decreases at level %d (a display curve must not)",
                                         name, "rgb"[c], lv);
    }
    return CSF_OK;
}

/* Every data line of a display CSV into m: comments and blank lines skipped, one optional header
 * ("level,...") before the first row. */
static csf_status csv_read_rows(csf_display_model *m, int *seen, const char *text, size_t len,
                                const char *name, csf_error *err)
{
    csf_lines lines;
    if (csf_lines_open(&lines, text, len, 255))
        return csf_error_set(err, CSF_E_NOMEM, "out of memory reading display CSV");
    int n_rows = 0, got;
    char *s;
    csf_status rc = CSF_OK;
    while (rc == CSF_OK && (got = csf_lines_next(&lines, &s)) != 0) {
        int line_no = lines.line;
        if (got < 0) rc = csf_error_set(err, CSF_E_FORMAT, "%s:%d: %s", name, line_no, lines.why);
        else if (isalpha((unsigned char)*s)) {
            if (n_rows == 0 && strncmp(s, "level", 5) == 0) continue; /* header */
            rc =
                csf_error_set(err, CSF_E_FORMAT, "%s:%d: expected level,r_cdm2,g_cdm2,b_cdm2", name, line_no);
        } else {
            double f[4];
            rc = csv_fields(s, name, line_no, f, err);
            if (!rc) rc = csv_store_row(m, seen, f, name, line_no, err);
            n_rows++;
        }
    }
    csf_lines_close(&lines);
    return rc;
}

csf_status csf_display_model_from_csv(const char *text, size_t len, const char *name,
                                      csf_display_model **out, csf_error *err)
{
    *out = NULL;
    csf_display_model *m = model_new(KIND_CSV);
    if (!m) return csf_error_set(err, CSF_E_NOMEM, "out of memory reading display CSV");
    int seen[CSV_LEVELS] = {0};
    csf_status rc = csv_read_rows(m, seen, text, len, name, err);
    if (rc) {
        free(m);
        return rc;
    }
    rc = csv_check_levels(m, seen, name, err);
    if (rc) {
        free(m);
        return rc;
    }
    double white = m->csv[0][255] + m->csv[1][255] + m->csv[2][255];
    if (!(white > 0)) {
        free(m);
        return csf_error_set(err, CSF_E_FORMAT, "%s: white (level 255) has zero luminance", name);
    }
    m->lmax_cdm2 = white;
    for (int c = 0; c < 3; c++) m->weight[c] = m->csv[c][255] / white;
    *out = m;
    return CSF_OK;
}

static csf_status load_csv_file(const char *path, csf_display_model **out, csf_error *err)
{
    char *buf;
    size_t n;
    csf_status st = csf_read_file(path, "display CSV", (size_t)1 << 20, &buf, &n, err);
    if (st != CSF_OK) return st;
    st = csf_display_model_from_csv(buf, n, path, out, err);
    free(buf);
    return st;
}

/* The spec's first item: a kind, or a measured curve (file=PATH.csv, or a path ending .csv). */
static csf_status open_kind(const char *item, csf_display_model **out, csf_error *err)
{
    if (strcmp(item, "crt") == 0) *out = model_new(KIND_CRT);
    else if (strcmp(item, "lcd") == 0) *out = model_new(KIND_LCD);
    else if (strcmp(item, "oled") == 0) *out = model_new(KIND_OLED);
    else {
        const char *path = NULL;
        if (strncmp(item, "file=", 5) == 0) path = item + 5;
        else if (strlen(item) > 4 && strcmp(item + strlen(item) - 4, ".csv") == 0) path = item;
        if (!path)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "unknown display kind '%s' (known: crt, lcd, oled, file=PATH.csv)", item);
        return load_csv_file(path, out, err);
    }
    return *out ? CSF_OK : csf_error_set(err, CSF_E_NOMEM, "out of memory");
}

/* One key=value after the kind; a measured curve keeps its own peak and gamma. */
static csf_status apply_option(csf_display_model *m, const char *k, const char *v, csf_error *err)
{
    if (!v) return csf_error_set(err, CSF_E_INVALID_ARG, "display option '%s' is not key=value", k);
    double x = 0;
    csf_num_result r;
    if (strcmp(k, "lmax") == 0 && m->kind != KIND_CSV) {
        if ((r = csf_number_parse(v, 1, 10000, &x)) == CSF_NUM_OK) m->lmax_cdm2 = x;
    } else if (strcmp(k, "black") == 0) {
        if ((r = csf_number_parse(v, 0, 50, &x)) == CSF_NUM_OK) m->black_cdm2 = x;
    } else if (strcmp(k, "gamma") == 0 && m->kind != KIND_CSV) {
        /* keep the per-channel spread of the kind around the requested value */
        if ((r = csf_number_parse(v, 1, 4, &x)) == CSF_NUM_OK) {
            double mean = (m->gamma[0] + m->gamma[1] + m->gamma[2]) / 3.0;
            for (int c = 0; c < 3; c++) m->gamma[c] += x - mean;
        }
    } else if (strcmp(k, "interaction") == 0 && m->kind == KIND_LCD) {
        if ((r = csf_number_parse(v, 0, 0.2, &x)) == CSF_NUM_OK) m->interaction = x;
    } else {
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "unknown display option '%s' for %s (known: lmax, black, gamma%s)", k,
                             csf_display_model_kind(m), m->kind == KIND_LCD ? ", interaction" : "");
    }
    if (r != CSF_NUM_OK)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "display option %s=%s out of range (lmax 1..10000 cd/m2, black 0..50 cd/m2, "
                             "gamma 1..4, interaction 0..0.2)",
                             k, v);
    return CSF_OK;
}

csf_status csf_display_model_create(const char *spec, csf_display_model **out, csf_error *err)
{
    *out = NULL;
    if (!spec || !*spec) spec = "lcd";
    if (strlen(spec) >= 1024)
        return csf_error_set(err, CSF_E_INVALID_ARG, "display spec longer than %d characters", 1023);
    csf_spec *items = malloc(sizeof *items);
    if (!items) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = csf_spec_split(spec, "display", items, err);
    /* the kind is the first item whole: "file=PATH.csv" names a curve, not an option */
    char kind[1024];
    if (st == CSF_OK) {
        snprintf(kind, sizeof kind, "%s%s%s", items->item[0].key, items->item[0].value ? "=" : "",
                 items->item[0].value ? items->item[0].value : "");
        st = open_kind(kind, out, err);
    }
    for (int i = 1; st == CSF_OK && i < items->n; i++)
        st = apply_option(*out, items->item[i].key, items->item[i].value, err);
    free(items);
    if (st != CSF_OK) {
        free(*out);
        *out = NULL;
    }
    return st;
}

int csf_display_model_spec_from_sim_photometer(const char *phot, char *out, size_t len)
{
    if (!phot || strncmp(phot, "sim", 3) != 0 || (phot[3] != '\0' && phot[3] != ':')) return -1;
    char kind[300] = "lcd", extra[600] = "";
    csf_spec *items = malloc(sizeof *items);
    if (!items) return -1;
    char buf[1024];
    snprintf(buf, sizeof buf, "%.1000s", phot[3] ? phot + 4 : "");
    /* a spec the photometer itself refuses names no display either */
    if (csf_spec_split(buf, "--photometer", items, NULL) != CSF_OK) {
        free(items);
        return -1;
    }
    for (int i = 0; i < items->n; i++) {
        const char *k = items->item[i].key, *v = items->item[i].value;
        if (!v) continue;
        if (!strcmp(k, "display")) snprintf(kind, sizeof kind, "%.250s", v);
        else if (!strcmp(k, "file")) snprintf(kind, sizeof kind, "file=%.250s", v);
        else if (!strcmp(k, "lmax") || !strcmp(k, "black") || !strcmp(k, "gamma") || !strcmp(k, "interaction")) {
            size_t l = strlen(extra);
            snprintf(extra + l, sizeof extra - l, ",%s=%.40s", k, v);
        }
    }
    free(items);
    snprintf(out, len, "%s%s", kind, extra);
    return 0;
}
