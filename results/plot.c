/* Session reports with cairo (see results/plot.h). A report answers "did this session go well?"
 * at a glance: a summary page with verdict lines first, then the data plots. */
#include "results/plot.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <ctype.h>
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "results/display_profile.h"
#include "core/file_write.h"
#include "core/utf8_text.h"

#ifndef CSF_VERSION
#define CSF_VERSION "unknown"
#endif

/* Page size in cairo units: PDF points (A4 landscape) or pixels for PNG/SVG. */
#define PAGE_W 842.0
#define PAGE_H 595.0

typedef enum { OUT_PDF, OUT_PNG, OUT_SVG } out_kind;

typedef struct {
    csf_session_info info;
    char created[32], updated[32];
    csf_trial *trials;
    size_t n_trials;
    csf_reading *readings;
    size_t n_readings;
    csf_threshold_row *th;
    size_t n_th;
    double *frames;
    size_t n_frames;
    csf_display_profile *profile; /* from the session's "profile" artifact, if it parses */
    int frames_inline;            /* the frame-timing histogram is on the summary page */
    char kind[64], state[64];     /* the session's stored kind and state, escaped to be shown */
} report_data;

/* ---- log-parabola fit ---------------------------------------------------------------------
 * In x = log10 f the model is a downward parabola y = c0 + c1 x + c2 x^2, so a weighted linear
 * least-squares fit of the quadratic gives it exactly; the parameters follow from the vertex
 * (x = log10 fmax, y = log10 Smax) and the curvature c2 = -4 / (log10(2) beta^2). */
static int solve3(double a[3][4], double out[3])
{
    for (int c = 0; c < 3; c++) {
        int piv = c;
        for (int r = c + 1; r < 3; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
        if (fabs(a[piv][c]) < 1e-300) return -1;
        for (int k = 0; k < 4; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        for (int r = 0; r < 3; r++) {
            if (r == c) continue;
            double f = a[r][c] / a[c][c];
            for (int k = c; k < 4; k++) a[r][k] -= f * a[c][k];
        }
    }
    for (int c = 0; c < 3; c++) out[c] = a[c][3] / a[c][c];
    return 0;
}

csf_status csf_fit_log_parabola(const double *freq_cpd, const double *log10_s, const double *w,
                                int n, double *log10_smax, double *fmax_cpd, double *beta_oct)
{
    if (!freq_cpd || !log10_s || n < 3) return CSF_E_INSUFFICIENT;
    /* Distinct frequencies and centring (conditioning of the normal equations). */
    double xm = 0, wsum = 0;
    int distinct = 0;
    for (int i = 0; i < n; i++) {
        if (!(freq_cpd[i] > 0) || !isfinite(log10_s[i])) return CSF_E_INVALID_ARG;
        double wi = w ? w[i] : 1.0;
        if (!(wi > 0) || !isfinite(wi)) return CSF_E_INVALID_ARG;
        xm += wi * log10(freq_cpd[i]);
        wsum += wi;
        int seen = 0;
        for (int j = 0; j < i; j++)
            if (fabs(log10(freq_cpd[j]) - log10(freq_cpd[i])) < 1e-9) seen = 1;
        distinct += !seen;
    }
    if (distinct < 3) return CSF_E_INSUFFICIENT;
    xm /= wsum;
    double a[3][4] = {{0}};
    for (int i = 0; i < n; i++) {
        double wi = w ? w[i] : 1.0, x = log10(freq_cpd[i]) - xm, y = log10_s[i];
        double p[3] = {1, x, x * x};
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++) a[r][c] += wi * p[r] * p[c];
            a[r][3] += wi * p[r] * y;
        }
    }
    double c[3];
    if (solve3(a, c) < 0) return CSF_E_INSUFFICIENT;
    if (!(c[2] < 0)) return CSF_E_INSUFFICIENT; /* not a peaked curve: no log-parabola */
    double xv = -c[1] / (2 * c[2]);
    double yv = c[0] - c[1] * c[1] / (4 * c[2]);
    double beta = sqrt(-4.0 / (log10(2.0) * c[2]));
    if (!isfinite(xv) || !isfinite(yv) || !isfinite(beta)) return CSF_E_INSUFFICIENT;
    if (log10_smax) *log10_smax = yv;
    if (fmax_cpd) *fmax_cpd = pow(10.0, xv + xm);
    if (beta_oct) *beta_oct = beta;
    return CSF_OK;
}

static double log_parabola(double log10_smax, double fmax, double beta, double f)
{
    double k = (log10(f) - log10(fmax)) / (beta * log10(2.0) / 2.0);
    return log10_smax - log10(2.0) * k * k;
}

/* ---- drawing helpers ---------------------------------------------------------------------- */

typedef struct {
    double x, y, w, h;          /* plot area in page units */
    double x0, x1, y0, y1;      /* data range (log10 values when the axis is logarithmic) */
    int xlog, ylog;
} axes;

static const double palette[][3] = {
    {0.00, 0.45, 0.70}, {0.84, 0.37, 0.00}, {0.00, 0.62, 0.45}, {0.80, 0.47, 0.65},
    {0.34, 0.71, 0.91}, {0.90, 0.62, 0.00}, {0.35, 0.35, 0.35}, {0.60, 0.20, 0.20},
};
#define N_PALETTE (sizeof palette / sizeof palette[0])

static void set_rgb(cairo_t *cr, const double *c) { cairo_set_source_rgb(cr, c[0], c[1], c[2]); }

static double ax_px(const axes *a, double v)
{
    double t = a->xlog ? log10(v) : v;
    return a->x + (t - a->x0) / (a->x1 - a->x0) * a->w;
}

static double ax_py(const axes *a, double v)
{
    double t = a->ylog ? log10(v) : v;
    return a->y + a->h - (t - a->y0) / (a->y1 - a->y0) * a->h;
}

/* The longest outside text a report draws (a session's settings as stored, when they are not a
 * JSON object): a page holds far less. */
#define DRAWN_TEXT_MAX 65536

static void text_at(cairo_t *cr, double x, double y, double size, int bold, double align, const char *text)
{
    /* cairo refuses text that is not UTF-8 and then draws nothing more on the page: a name from
     * another station's store must not cost the whole report */
    char *s = csf_utf8_drawable(text, SIZE_MAX, DRAWN_TEXT_MAX);
    if (!s) return;
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.x_advance, y);
    cairo_show_text(cr, s);
    /* show_text leaves the current point at the end of the text: the next arc would otherwise
     * start with a line from there. */
    cairo_new_path(cr);
    free(s);
}

static void title(cairo_t *cr, const char *s)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, 40, 36, 16, 1, 0, s);
}

/* Nice linear tick step for a range. */
static double nice_step(double range, int target)
{
    double raw = range / target, mag = pow(10.0, floor(log10(raw))), r = raw / mag;
    return (r < 1.5 ? 1 : r < 3.5 ? 2 : r < 7.5 ? 5 : 10) * mag;
}

static void draw_axes(cairo_t *cr, const axes *a, const char *xlabel, const char *ylabel)
{
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_rectangle(cr, a->x, a->y, a->w, a->h);
    cairo_fill(cr);
    cairo_set_line_width(cr, 0.5);
    char buf[32];
    /* x ticks and grid */
    if (a->xlog) {
        for (int d = (int)floor(a->x0); d <= (int)ceil(a->x1); d++)
            for (int m = 1; m < 10; m++) {
                double v = log10(m) + d;
                if (v < a->x0 - 1e-9 || v > a->x1 + 1e-9) continue;
                double px = a->x + (v - a->x0) / (a->x1 - a->x0) * a->w;
                cairo_set_source_rgb(cr, m == 1 ? 0.75 : 0.9, m == 1 ? 0.75 : 0.9, m == 1 ? 0.75 : 0.9);
                cairo_move_to(cr, px, a->y);
                cairo_line_to(cr, px, a->y + a->h);
                cairo_stroke(cr);
                if (m == 1 || m == 2 || m == 5) {
                    snprintf(buf, sizeof buf, "%g", pow(10.0, v));
                    cairo_set_source_rgb(cr, 0, 0, 0);
                    text_at(cr, px, a->y + a->h + 13, 9, 0, 0.5, buf);
                }
            }
    } else {
        double st = nice_step(a->x1 - a->x0, 8);
        /* the tick values are the running sums these pages have always drawn; counted in
         * steps instead, rounding would move some ticks */
        for (double v = ceil(a->x0 / st) * st; v <= a->x1 + 1e-9 * st; v += st) { // NOLINT(clang-analyzer-security.FloatLoopCounter)
            double px = a->x + (v - a->x0) / (a->x1 - a->x0) * a->w;
            cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
            cairo_move_to(cr, px, a->y);
            cairo_line_to(cr, px, a->y + a->h);
            cairo_stroke(cr);
            snprintf(buf, sizeof buf, "%g", fabs(v) < 1e-12 * st ? 0.0 : v);
            cairo_set_source_rgb(cr, 0, 0, 0);
            text_at(cr, px, a->y + a->h + 13, 9, 0, 0.5, buf);
        }
    }
    /* y ticks and grid */
    if (a->ylog) {
        for (int d = (int)floor(a->y0); d <= (int)ceil(a->y1); d++)
            for (int m = 1; m < 10; m++) {
                double v = log10(m) + d;
                if (v < a->y0 - 1e-9 || v > a->y1 + 1e-9) continue;
                double py = a->y + a->h - (v - a->y0) / (a->y1 - a->y0) * a->h;
                cairo_set_source_rgb(cr, m == 1 ? 0.75 : 0.9, m == 1 ? 0.75 : 0.9, m == 1 ? 0.75 : 0.9);
                cairo_move_to(cr, a->x, py);
                cairo_line_to(cr, a->x + a->w, py);
                cairo_stroke(cr);
                if (m == 1 || m == 3) {
                    snprintf(buf, sizeof buf, "%g", pow(10.0, v));
                    cairo_set_source_rgb(cr, 0, 0, 0);
                    text_at(cr, a->x - 4, py + 3, 9, 0, 1.0, buf);
                }
            }
    } else {
        double st = nice_step(a->y1 - a->y0, 6);
        /* running sums, as for the x axis above */
        for (double v = ceil(a->y0 / st) * st; v <= a->y1 + 1e-9 * st; v += st) { // NOLINT(clang-analyzer-security.FloatLoopCounter)
            double py = a->y + a->h - (v - a->y0) / (a->y1 - a->y0) * a->h;
            cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
            cairo_move_to(cr, a->x, py);
            cairo_line_to(cr, a->x + a->w, py);
            cairo_stroke(cr);
            snprintf(buf, sizeof buf, "%g", fabs(v) < 1e-12 * st ? 0.0 : v);
            cairo_set_source_rgb(cr, 0, 0, 0);
            text_at(cr, a->x - 4, py + 3, 9, 0, 1.0, buf);
        }
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, a->x, a->y, a->w, a->h);
    cairo_stroke(cr);
    text_at(cr, a->x + a->w / 2, a->y + a->h + 30, 11, 0, 0.5, xlabel);
    cairo_save(cr);
    cairo_translate(cr, a->x - 42, a->y + a->h / 2);
    cairo_rotate(cr, -M_PI / 2);
    text_at(cr, 0, 0, 11, 0, 0.5, ylabel);
    cairo_restore(cr);
}

static void clip_to(cairo_t *cr, const axes *a)
{
    cairo_save(cr);
    cairo_rectangle(cr, a->x, a->y, a->w, a->h);
    cairo_clip(cr);
}

static void message_page(cairo_t *cr, const char *head, const char *msg)
{
    title(cr, head);
    cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
    text_at(cr, 40, 80, 12, 0, 0, msg);
}

/* ---- summary page ------------------------------------------------------------------------- */

typedef struct {
    int level; /* 0 ok, 1 warning, 2 problem */
    char text[200];
} verdict;

static double iso_to_unix(const char *iso)
{
    struct tm tm;
    memset(&tm, 0, sizeof tm);
    if (sscanf(iso, "%d-%d-%dT%d:%d:%d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
               &tm.tm_min, &tm.tm_sec) != 6)
        return NAN;
    tm.tm_year -= 1900;
    tm.tm_mon -= 1;
    return (double)timegm(&tm);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median_of(const double *v, size_t n)
{
    if (n == 0) return NAN;
    double *c = malloc(n * sizeof *c);
    if (!c) return NAN;
    memcpy(c, v, n * sizeof *c);
    qsort(c, n, sizeof *c, cmp_double);
    double m = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
    free(c);
    return m;
}

/* Whether a line may end after text[i - 1]: after a space, comma or semicolon; after a hyphen,
 * underscore or slash joining two letters or digits (so "lcd-20261123-e0315651", a profile id,
 * breaks at its parts, while "-0.5" keeps its sign); before an opening parenthesis. */
static int break_after(const char *text, size_t i, size_t len)
{
    char c = text[i - 1];
    if (c == ' ' || c == ',' || c == ';') return 1;
    if (i < len && text[i] == '(' && i >= 1 && c != '(') return 1;
    if ((c == '-' || c == '_' || c == '/') && i >= 2 && i < len)
        return isalnum((unsigned char)text[i - 2]) && isalnum((unsigned char)text[i]);
    return 0;
}

/* Draws text from (x, y) in lines no wider than width_pt, breaking where break_after allows
 * (inside a word only when the word alone is wider than a line); draw = 0 only measures.
 * Returns the baseline of the line after the last one. */
static double wrap_text_ex(cairo_t *cr, double x, double y, double width_pt, double size, int bold,
                           double line_h, const char *outside_text, int draw)
{
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    char *text = csf_utf8_drawable(outside_text, SIZE_MAX, DRAWN_TEXT_MAX); /* as text_at */
    size_t len = text ? strlen(text) : 0;
    char *buf = text ? malloc(len + 1) : NULL;
    if (!buf) {
        free(text);
        return y + line_h;
    }
    size_t start = 0;
    while (start < len) {
        /* Longest run from start that fits, ending at a break point if there is one. */
        size_t end = start, last_break = 0, last_space = 0, last_fit = start;
        double space_w = 0;
        while (end < len) {
            size_t next = end + 1;
            while (next < len && ((unsigned char)text[next] & 0xC0) == 0x80) next++;
            memcpy(buf, text + start, next - start);
            buf[next - start] = '\0';
            cairo_text_extents_t e;
            cairo_text_extents(cr, buf, &e);
            if (e.x_advance > width_pt && end > start) break;
            end = next;
            last_fit = end;
            if (break_after(text, end, len)) {
                last_break = end;
                if (text[end - 1] == ' ') last_space = end, space_w = e.x_advance;
            }
        }
        /* between words rather than inside a hyphenated one, unless that leaves the line short */
        if (last_space > start && space_w >= 0.6 * width_pt) last_break = last_space;
        size_t stop = end >= len ? len : last_break > start ? last_break : last_fit;
        memcpy(buf, text + start, stop - start);
        buf[stop - start] = '\0';
        if (draw) {
            cairo_move_to(cr, x, y);
            cairo_show_text(cr, buf);
            cairo_new_path(cr);
        }
        y += line_h;
        start = stop;
        while (start < len && text[start] == ' ') start++;
    }
    free(buf);
    free(text);
    return len ? y : y + line_h;
}

static double wrap_text(cairo_t *cr, double x, double y, double width_pt, double size, int bold,
                        double line_h, const char *text)
{
    return wrap_text_ex(cr, x, y, width_pt, size, bold, line_h, text, 1);
}

/* One setting's value as the report shows it: a string as it is, anything else as compact JSON,
 * numbers at the 17 digits the store writes them with. NULL when out of memory. */
static char *setting_text(const json_t *v)
{
    if (json_is_string(v)) return strdup(json_string_value(v));
    return json_dumps(v, JSON_ENCODE_ANY | JSON_COMPACT | JSON_REAL_PRECISION(17));
}

/* The settings the session ran with, as a table of key and value in three columns, each value
 * wrapped inside its column; rows that do not fit the page are counted at the bottom. */
static double draw_settings(cairo_t *cr, const char *js, double y)
{
    const double x0 = 40, gap = 18, bottom = PAGE_H - 44;
    const double col_w = (PAGE_W - 2 * x0 - 2 * gap) / 3, key_w = 92;
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, x0, y, 12, 1, 0, "Settings");
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, x0, y + 5);
    cairo_line_to(cr, PAGE_W - x0, y + 5);
    cairo_stroke(cr);
    y += 20;
    /* read through jansson: the store is outside input once on disk, and a value that is not
     * text (a hostile or damaged row) must not reach the page */
    json_t *doc = json_loads(js, 0, NULL);
    const char *key;
    json_t *value;
    int col = 0, left_out = 0, parsed = 0;
    double row_bottom = y;
    json_object_foreach(json_is_object(doc) ? doc : NULL, key, value)
    {
        parsed++;
        char *text = setting_text(value);
        /* a value of more than a kilobyte is cut there, a key at 63 bytes (the table's columns) */
        char *val = csf_utf8_drawable(text ? text : "", SIZE_MAX, 1023);
        free(text);
        if (!val) continue;
        double x = x0 + col * (col_w + gap);
        double h = wrap_text_ex(cr, x + key_w, y, col_w - key_w, 8.5, 0, 11, val, 0) - y;
        if (y + h - 11 > bottom) {
            left_out++;
            free(val);
            continue;
        }
        char *k = csf_utf8_drawable(key, SIZE_MAX, 63);
        cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
        wrap_text(cr, x, y, key_w - 4, 8.5, 0, 11, k ? k : "");
        cairo_set_source_rgb(cr, 0, 0, 0);
        row_bottom = fmax(row_bottom, wrap_text(cr, x + key_w, y, col_w - key_w, 8.5, 0, 11, val));
        free(k);
        free(val);
        if (++col == 3) {
            col = 0;
            y = row_bottom + 3;
        }
    }
    json_decref(doc);
    if (col) y = row_bottom;
    if (!parsed) { /* not a flat object: the text as stored, wrapped at word boundaries */
        cairo_set_source_rgb(cr, 0, 0, 0);
        y = wrap_text(cr, x0, y, PAGE_W - 2 * x0, 8.5, 0, 11, js);
    }
    if (left_out) {
        char note[96];
        snprintf(note, sizeof note, "%d more settings did not fit: csfcal sessions show ID lists them all",
                 left_out);
        cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
        text_at(cr, x0, bottom + 12, 8.5, 0, 0, note);
        y = bottom + 12;
    }
    return y;
}

static void draw_frames_area(cairo_t *cr, const report_data *d, double top_pt, double bottom_pt);

/* Title, facts, verdicts and settings; returns the y below the last line. */
/* What the summary page counts in a session. */
typedef struct {
    int valid, invalid, catch_n, catch_resp, practice, rd_bad, th_inf;
    long planned, missed; /* frames */
} session_counts;

static session_counts count_session(const report_data *d)
{
    session_counts k = {0};
    for (size_t i = 0; i < d->n_trials; i++) {
        const csf_trial *t = &d->trials[i];
        if (t->valid) k.valid++;
        else k.invalid++;
        if (t->is_catch) {
            k.catch_n++;
            k.catch_resp += t->response != 0;
        }
        k.practice += t->is_practice != 0;
        k.planned += t->frames_planned;
        k.missed += t->frames_missed;
    }
    for (size_t i = 0; i < d->n_readings; i++) k.rd_bad += d->readings[i].status != CSF_READING_OK;
    for (size_t i = 0; i < d->n_th; i++) k.th_inf += !isfinite(d->th[i].threshold);
    return k;
}

/* The left column: the session's facts. Returns where it ends. */
static double draw_facts(cairo_t *cr, const report_data *d, const session_counts *k)
{
    const csf_session_info *si = &d->info;
    double dur_s = iso_to_unix(d->updated) - iso_to_unix(d->created);
    const char *lines[][2] = {
        {"Kind / state", NULL},
        {"Observer", si->observer[0] ? si->observer : "-"},
        {"Display", si->display[0] ? si->display : "-"},
        {"Started (UTC)", d->created},
        {"Last write (UTC)", d->updated},
        {"Duration (wall clock)", NULL},
        {"Person time", NULL},
        {"Seed", NULL},
        {"Tool version", si->tool_version},
        {"Trials", NULL},
        {"Frames", NULL},
        {"Photometer readings", NULL},
        {"Thresholds", NULL},
    };
    char v_state[136], v_dur[64], v_person[64], v_seed[32], v_trials[160], v_frames[128];
    char v_read[160], v_th[96];
    snprintf(v_state, sizeof v_state, "%s / %s", d->kind, d->state);
    if (isfinite(dur_s)) snprintf(v_dur, sizeof v_dur, "%.0f min %02.0f s", floor(dur_s / 60), fmod(dur_s, 60));
    else snprintf(v_dur, sizeof v_dur, "unknown");
    /* The participant's own time in the session (every run added up), which the wall clock
     * from start to last write overstates when the session was paused between runs. */
    if (isfinite(si->person_s)) snprintf(v_person, sizeof v_person, "%.1f min", si->person_s / 60.0);
    else snprintf(v_person, sizeof v_person, "unknown");
    snprintf(v_seed, sizeof v_seed, "%llu", (unsigned long long)si->seed);
    snprintf(v_trials, sizeof v_trials, "%zu (%d valid, %d invalid; %d practice, %d catch of which %d responded)",
             d->n_trials, k->valid, k->invalid, k->practice, k->catch_n, k->catch_resp);
    snprintf(v_frames, sizeof v_frames, "%ld planned, %ld missed (%.2f %%); %zu intervals recorded",
             k->planned, k->missed, k->planned ? 100.0 * k->missed / k->planned : 0.0, d->n_frames);
    double last_t = NAN;
    for (size_t i = 0; i < d->n_readings; i++)
        if (isfinite(d->readings[i].t_s) && !(d->readings[i].t_s <= last_t)) last_t = d->readings[i].t_s;
    if (d->n_readings && isfinite(last_t))
        snprintf(v_read, sizeof v_read, "%zu (%d not ok), last at t = %.1f s of the session clock",
                 d->n_readings, k->rd_bad, last_t);
    else
        snprintf(v_read, sizeof v_read, "%zu (%d not ok)", d->n_readings, k->rd_bad);
    snprintf(v_th, sizeof v_th, "%zu (%d never visible)", d->n_th, k->th_inf);
    lines[0][1] = v_state;
    lines[5][1] = v_dur;
    lines[6][1] = v_person;
    lines[7][1] = v_seed;
    lines[9][1] = v_trials;
    lines[10][1] = v_frames;
    lines[11][1] = v_read;
    lines[12][1] = v_th;
    double y = 72;
    /* A display session has no trials, an observer session no readings: rows that would only
     * say "0" are left out (a count that is not 0 is always shown). */
    int is_display = si->kind == CSF_SESSION_DISPLAY;
    int skip[sizeof lines / sizeof lines[0]] = {0};
    skip[1] = is_display && !si->observer[0];
    skip[6] = is_display && !isfinite(si->person_s); /* a display session has no participant */
    skip[9] = skip[10] = is_display && !d->n_trials && !k->planned;
    skip[11] = !is_display && !d->n_readings;
    skip[12] = is_display && !d->n_th;
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        if (skip[i]) continue;
        cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
        text_at(cr, 40, y, 10, 0, 0, lines[i][0]);
        cairo_set_source_rgb(cr, 0, 0, 0);
        y = wrap_text(cr, 160, y, 300, 10, 0, 13, lines[i][1]) + 2;
        if (i == 2 && si->profile_id[0]) { /* after Display */
            cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
            text_at(cr, 40, y, 10, 0, 0, "Display profile");
            cairo_set_source_rgb(cr, 0, 0, 0);
            y = wrap_text(cr, 160, y, 300, 10, 0, 13, si->profile_id) + 2;
        }
    }
    return y;
}

/* The verdicts (OK / CHECK / PROBLEM) on what a person looks at first; returns how many. */
static int collect_verdicts(const report_data *d, const session_counts *k, verdict v[8])
{
    const csf_session_info *si = &d->info;
    int nv = 0;
    if (si->state != CSF_SESSION_FINISHED)
        snprintf(v[nv].text, sizeof v[nv].text, "Session is %s, not finished: continue it with --resume %lld",
                 d->state, (long long)si->id),
            v[nv++].level = si->state == CSF_SESSION_ABORTED ? 2 : 1;
    if (d->n_trials) {
        double f = (double)k->invalid / (double)d->n_trials;
        v[nv].level = f > 0.10 ? 2 : f > 0.02 ? 1 : 0;
        snprintf(v[nv++].text, sizeof v[0].text, "%.1f %% of trials invalid", 100 * f);
    }
    if (k->planned) {
        double f = (double)k->missed / (double)k->planned;
        v[nv].level = f > 0.01 ? 2 : f > 0.001 ? 1 : 0;
        snprintf(v[nv++].text, sizeof v[0].text, "%.2f %% of frames missed", 100 * f);
    }
    if (k->catch_n) {
        double f = (double)k->catch_resp / k->catch_n;
        /* With few catch trials one false alarm is a large fraction: only a warning then. */
        v[nv].level = f > 0.2 && k->catch_n >= 10 ? 2 : f > 0.1 ? 1 : 0;
        snprintf(v[nv++].text, sizeof v[0].text, "%d of %d catch trials drew a response (%.0f %%)",
                 k->catch_resp, k->catch_n, 100 * f);
    }
    if (d->n_readings) {
        v[nv].level = k->rd_bad ? 1 : 0;
        snprintf(v[nv++].text, sizeof v[0].text, "%d of %zu photometer readings failed", k->rd_bad, d->n_readings);
    }
    if (si->kind == CSF_SESSION_OBSERVER) {
        v[nv].level = d->n_th ? 0 : 1;
        if (d->n_th) snprintf(v[nv++].text, sizeof v[0].text, "%zu thresholds measured", d->n_th);
        else snprintf(v[nv++].text, sizeof v[0].text, "no thresholds stored yet");
    }
    return nv;
}

/* The right column: the verdicts. Returns where it ends. */
static double draw_verdicts(cairo_t *cr, const verdict *v, int nv)
{
    static const double lvl_col[3][3] = {{0.1, 0.55, 0.2}, {0.85, 0.55, 0.0}, {0.8, 0.1, 0.1}};
    static const char *lvl_name[3] = {"OK", "CHECK", "PROBLEM"};
    const double gx = 500;
    double y = 72;
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, gx, y, 12, 1, 0, "At a glance");
    y += 20;
    for (int i = 0; i < nv; i++) {
        set_rgb(cr, lvl_col[v[i].level]);
        cairo_new_path(cr);
        cairo_arc(cr, gx + 5, y - 3.5, 4.5, 0, 2 * M_PI);
        cairo_fill(cr);
        text_at(cr, gx + 15, y, 9, 1, 0, lvl_name[v[i].level]);
        cairo_set_source_rgb(cr, 0, 0, 0);
        y = wrap_text(cr, gx + 72, y, PAGE_W - 40 - (gx + 72), 10, 0, 13, v[i].text) + 6;
    }
    return y;
}

static double summary_body(cairo_t *cr, const report_data *d)
{
    const csf_session_info *si = &d->info;
    char buf[512];
    snprintf(buf, sizeof buf, "csfcal session %lld: %s calibration report", (long long)si->id, d->kind);
    title(cr, buf);
    session_counts k = count_session(d);
    /* Left column: the facts; right column: the verdicts, what a person looks at first. */
    double y_left = draw_facts(cr, d, &k);
    verdict v[8];
    int nv = collect_verdicts(d, &k, v);
    double y = fmax(draw_verdicts(cr, v, nv), y_left) + 10;
    return draw_settings(cr, si->settings_json ? si->settings_json : "{}", y);
}

/* Where the summary's text ends, measured by drawing it on a scratch surface (the toy font
 * API measures the same on every surface). */
static double summary_height(const report_data *d)
{
    cairo_surface_t *scratch = cairo_image_surface_create(CAIRO_FORMAT_A8, 1, 1);
    cairo_t *cr = cairo_create(scratch);
    double y = summary_body(cr, d);
    cairo_destroy(cr);
    cairo_surface_destroy(scratch);
    return y;
}

/* The frame-timing histogram goes under the summary when it has the room (a printed summary
 * with half a page blank helps nobody); else it gets its own page. */
#define FRAMES_INLINE_MIN_PT 150.0

/* The channels of a display session, in one order with one colour each, for both the readings
 * table and the plot's legend, so that the two name and count the same readings. */
static const struct {
    const char *name;
    double rgb[3];
    int curve; /* profile curve drawn for it: -1 none, -2 grey, else CSF_CH_R/G/B */
} disp_chan[] = {{"dark", {0, 0, 0}, -1},           {"white", {0.55, 0.55, 0.55}, -2},
                 {"grey", {0.25, 0.25, 0.25}, -2},   {"r", {0.85, 0.1, 0.1}, CSF_CH_R},
                 {"g", {0.1, 0.6, 0.1}, CSF_CH_G},   {"b", {0.1, 0.2, 0.85}, CSF_CH_B}};
#define N_DISP_CHAN (sizeof disp_chan / sizeof disp_chan[0])

/* How many readings a channel has, and how many of them are not "ok". */
static int channel_count(const report_data *d, const char *chan, int *not_ok)
{
    int n = 0, bad = 0;
    for (size_t i = 0; i < d->n_readings; i++) {
        if (strcmp(d->readings[i].channel, chan)) continue;
        n++;
        bad += d->readings[i].status != CSF_READING_OK;
    }
    *not_ok = bad;
    return n;
}

/* Display sessions: per channel, how many readings, how many failed, and the luminance at the
 * lowest and highest drive measured; what a printed summary of a calibration should show. */
static void draw_readings_table(cairo_t *cr, const report_data *d, double y)
{
    static const char *const head[] = {"channel", "readings", "not ok", "lowest drive",
                                       "cd/m\xc2\xb2 there", "highest drive", "cd/m\xc2\xb2 there"};
    static const double col_x[] = {40, 130, 210, 290, 390, 500, 600};
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, 40, y, 12, 1, 0, "Photometer readings");
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, 40, y + 5);
    cairo_line_to(cr, PAGE_W - 40, y + 5);
    cairo_stroke(cr);
    y += 20;
    cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
    for (int c = 0; c < 7; c++) text_at(cr, col_x[c], y, 9, 1, 0, head[c]);
    for (size_t k = 0; k < N_DISP_CHAN; k++) {
        int bad, n = channel_count(d, disp_chan[k].name, &bad);
        double lo_v = INFINITY, hi_v = -INFINITY, lo_l = NAN, hi_l = NAN;
        for (size_t i = 0; i < d->n_readings; i++) {
            const csf_reading *r = &d->readings[i];
            if (strcmp(r->channel, disp_chan[k].name) || r->status != CSF_READING_OK) continue;
            if (r->drive01 < lo_v) lo_v = r->drive01, lo_l = r->lum_cdm2;
            if (r->drive01 > hi_v) hi_v = r->drive01, hi_l = r->lum_cdm2;
        }
        if (!n) continue;
        y += 14;
        char cell[7][32];
        snprintf(cell[0], 32, "%s", disp_chan[k].name);
        snprintf(cell[1], 32, "%d", n);
        snprintf(cell[2], 32, "%d", bad);
        snprintf(cell[3], 32, isfinite(lo_v) ? "%.3f" : "-", lo_v);
        snprintf(cell[4], 32, isfinite(lo_l) ? "%.4g" : "-", lo_l);
        snprintf(cell[5], 32, isfinite(hi_v) ? "%.3f" : "-", hi_v);
        snprintf(cell[6], 32, isfinite(hi_l) ? "%.4g" : "-", hi_l);
        for (int c = 0; c < 7; c++) {
            if (c == 2 && bad) cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
            else cairo_set_source_rgb(cr, 0, 0, 0);
            text_at(cr, col_x[c], y, 9.5, 0, 0, cell[c]);
        }
    }
}

static void draw_summary(cairo_t *cr, const report_data *d)
{
    double y = summary_body(cr, d);
    if (!d->frames_inline && d->n_readings && !d->n_frames) draw_readings_table(cr, d, y + 14);
    if (d->frames_inline && d->n_frames) {
        y += 14;
        cairo_set_source_rgb(cr, 0, 0, 0);
        text_at(cr, 40, y, 12, 1, 0, "Frame timing");
        cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
        cairo_set_line_width(cr, 0.5);
        cairo_move_to(cr, 40, y + 5);
        cairo_line_to(cr, PAGE_W - 40, y + 5);
        cairo_stroke(cr);
        draw_frames_area(cr, d, y + 22, PAGE_H - 80);
    }
}

/* ---- CSF plot -----------------------------------------------------------------------------
 * One curve per (eccentricity, velocity, luminance) condition: measured sensitivities with error
 * bars of +-1 standard error in log10 units, and the least-squares log-parabola through them
 * (a straight log-log line when fewer than 3 frequencies or no peak). */

typedef struct {
    double ecc, vel, lum;
} condition;

static int same_cond(const condition *a, const csf_threshold_row *r)
{
    return fabs(a->ecc - r->ecc_deg) < 1e-9 && fabs(a->vel - r->velocity_dps) < 1e-9 &&
           fabs(a->lum - r->lum_cdm2) < 1e-9;
}

static void marker(cairo_t *cr, double x, double y, int shape, double r)
{
    cairo_new_path(cr);
    switch (shape % 3) {
    case 0: cairo_arc(cr, x, y, r, 0, 2 * M_PI); break;
    case 1: cairo_rectangle(cr, x - r, y - r, 2 * r, 2 * r); break;
    default:
        cairo_move_to(cr, x, y - r * 1.2);
        cairo_line_to(cr, x + r * 1.1, y + r * 0.8);
        cairo_line_to(cr, x - r * 1.1, y + r * 0.8);
        cairo_close_path(cr);
    }
    cairo_fill(cr);
}

/* The CSF page's axes: log frequency and log sensitivity spanning every finite threshold and
 * its standard error bar. Returns 0 when there is nothing to plot. */
static int csf_axes(const report_data *d, axes *a)
{
    double fmin = INFINITY, fmax = 0, smin = INFINITY, smax = 0;
    for (size_t i = 0; i < d->n_th; i++) {
        const csf_threshold_row *r = &d->th[i];
        if (!(r->freq_cpd > 0) || !isfinite(r->freq_cpd)) continue;
        fmin = r->freq_cpd < fmin ? r->freq_cpd : fmin;
        fmax = r->freq_cpd > fmax ? r->freq_cpd : fmax;
        if (r->threshold > 0 && isfinite(r->threshold)) {
            double se = isfinite(r->stderr_log10) && r->stderr_log10 > 0 ? r->stderr_log10 : 0;
            double lo = 1.0 / r->threshold * pow(10, -se), hi = 1.0 / r->threshold * pow(10, se);
            smin = lo < smin ? lo : smin;
            smax = hi > smax ? hi : smax;
        }
    }
    if (!(fmax > 0) || !(smax > 0)) return 0;
    *a = (axes){80, 60, 560, PAGE_H - 130, 0, 0, 0, 0, 1, 1};
    a->x0 = floor(log10(fmin / 1.5) * 2) / 2;
    a->x1 = ceil(log10(fmax * 1.5) * 2) / 2;
    a->y0 = floor(log10(smin / 2));
    a->y1 = ceil(log10(smax * 1.5));
    if (a->y0 < -1) a->y0 = -1;
    if (a->y1 <= a->y0) a->y1 = a->y0 + 1;
    return 1;
}

/* One condition's points: a marker with its standard-error bar per finite threshold, an open
 * circle on the bottom edge per never-visible cell. Fills the fit's inputs (frequency, log
 * sensitivity, weight); returns how many, *n_inf the never-visible ones. */
static int draw_condition_points(cairo_t *cr, const axes *a, const report_data *d, const condition *cond, int c,
                                 double *fx, double *ly, double *wt, int *n_inf)
{
    const double *col = palette[c % N_PALETTE];
    int m = 0;
    *n_inf = 0;
    for (size_t i = 0; i < d->n_th; i++) {
        const csf_threshold_row *r = &d->th[i];
        if (!same_cond(cond, r) || !(r->freq_cpd > 0)) continue;
        double px = ax_px(a, r->freq_cpd);
        set_rgb(cr, col);
        if (!(r->threshold > 0) || !isfinite(r->threshold)) {
            (*n_inf)++;
            cairo_set_line_width(cr, 1.2);
            cairo_arc(cr, px, a->y + a->h - 6, 4, 0, 2 * M_PI);
            cairo_stroke(cr);
            continue;
        }
        double s = 1.0 / r->threshold, py = ax_py(a, s);
        if (isfinite(r->stderr_log10) && r->stderr_log10 > 0) {
            double up = ax_py(a, s * pow(10, r->stderr_log10));
            double dn = ax_py(a, s * pow(10, -r->stderr_log10));
            cairo_set_line_width(cr, 1.2);
            cairo_move_to(cr, px, up);
            cairo_line_to(cr, px, dn);
            cairo_move_to(cr, px - 3, up);
            cairo_line_to(cr, px + 3, up);
            cairo_move_to(cr, px - 3, dn);
            cairo_line_to(cr, px + 3, dn);
            cairo_stroke(cr);
        }
        marker(cr, px, py, c, 3.5);
        fx[m] = r->freq_cpd;
        ly[m] = log10(s);
        double se = isfinite(r->stderr_log10) && r->stderr_log10 > 0.01 ? r->stderr_log10 : 0.01;
        wt[m] = 1.0 / (se * se);
        m++;
    }
    return m;
}

/* A curve through one condition's points: a weighted log-parabola from three points, a log-log
 * line from two. */
typedef struct {
    int have_fit, have_line;
    double l_smax, f_peak, beta; /* the log-parabola */
    double slope, icpt;          /* the line */
} csf_curve;

static csf_curve fit_condition(const double *fx, const double *ly, const double *wt, int m)
{
    csf_curve k = {0};
    k.have_fit = m >= 3 && csf_fit_log_parabola(fx, ly, wt, m, &k.l_smax, &k.f_peak, &k.beta) == CSF_OK;
    if (!k.have_fit && m >= 2) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (int i = 0; i < m; i++) {
            double x = log10(fx[i]);
            sx += x, sy += ly[i], sxx += x * x, sxy += x * ly[i];
        }
        double den = m * sxx - sx * sx;
        if (fabs(den) > 1e-12) {
            k.slope = (m * sxy - sx * sy) / den;
            k.icpt = (sy - k.slope * sx) / m;
            k.have_line = 1;
        }
    }
    return k;
}

static void draw_curve(cairo_t *cr, const axes *a, const csf_curve *k, const double *col)
{
    if (!k->have_fit && !k->have_line) return;
    set_rgb(cr, col);
    cairo_set_line_width(cr, 1.8);
    int started = 0;
    for (int i = 0; i <= 200; i++) {
        double lx = a->x0 + (a->x1 - a->x0) * i / 200.0, f = pow(10, lx);
        double lys = k->have_fit ? log_parabola(k->l_smax, k->f_peak, k->beta, f) : k->icpt + k->slope * lx;
        double px = a->x + (lx - a->x0) / (a->x1 - a->x0) * a->w;
        double py = a->y + a->h - (lys - a->y0) / (a->y1 - a->y0) * a->h;
        if (!isfinite(py)) continue;
        if (!started) cairo_move_to(cr, px, py);
        else cairo_line_to(cr, px, py);
        started = 1;
    }
    cairo_stroke(cr);
}

/* The legend entry of condition c, with its fitted parameters; returns the next entry's y. */
static double draw_legend_entry(cairo_t *cr, const axes *a, const condition *conds, int nc, int c,
                                const csf_curve *k, int n_inf, double y)
{
    char lab[160];
    int off = snprintf(lab, sizeof lab, "ecc %g deg", conds[c].ecc);
    if (conds[c].vel != 0) off += snprintf(lab + off, sizeof lab - (size_t)off, ", %g deg/s", conds[c].vel);
    if (nc > 1 && conds[c].lum != conds[0].lum)
        snprintf(lab + off, sizeof lab - (size_t)off, ", %g cd/m2", conds[c].lum);
    set_rgb(cr, palette[c % N_PALETTE]);
    marker(cr, a->x + a->w + 20, y - 4, c, 3.5);
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, a->x + a->w + 30, y, 10, 1, 0, lab);
    y += 13;
    if (k->have_fit)
        snprintf(lab, sizeof lab, "Smax %.0f at %.2g cpd, %.1f oct", pow(10, k->l_smax), k->f_peak, k->beta);
    else if (k->have_line)
        snprintf(lab, sizeof lab, "log-log line, slope %.2f", k->slope);
    else
        snprintf(lab, sizeof lab, "too few points to fit");
    text_at(cr, a->x + a->w + 30, y, 9, 0, 0, lab);
    y += 12;
    if (n_inf) {
        snprintf(lab, sizeof lab, "%d never visible (open circles)", n_inf);
        text_at(cr, a->x + a->w + 30, y, 9, 0, 0, lab);
        y += 12;
    }
    return y + 6;
}

static void draw_csf(cairo_t *cr, const report_data *d)
{
    size_t n = d->n_th;
    axes a;
    if (!csf_axes(d, &a)) {
        message_page(cr, "Contrast sensitivity function",
                     "No thresholds stored for this session yet (is it still running?).");
        return;
    }
    title(cr, "Contrast sensitivity function (sensitivity = 1 / Michelson threshold)");
    draw_axes(cr, &a, "spatial frequency (cycles per degree)", "sensitivity (1 / Michelson contrast)");
    /* one curve per condition (eccentricity, velocity, luminance) */
    condition conds[32];
    int nc = 0;
    for (size_t i = 0; i < n && nc < 32; i++) {
        int found = 0;
        for (int c = 0; c < nc; c++) found |= same_cond(&conds[c], &d->th[i]);
        if (!found) conds[nc++] = (condition){d->th[i].ecc_deg, d->th[i].velocity_dps, d->th[i].lum_cdm2};
    }
    /* n >= 1: csf_axes found thresholds to draw */
    double *fx = malloc(n * sizeof *fx), *ly = malloc(n * sizeof *ly), *wt = malloc(n * sizeof *wt); // NOLINT(clang-analyzer-optin.portability.UnixAPI)
    if (!fx || !ly || !wt) {
        free(fx), free(ly), free(wt);
        return;
    }
    double legend_y = a.y + 10;
    for (int c = 0; c < nc; c++) {
        int n_inf;
        clip_to(cr, &a);
        int m = draw_condition_points(cr, &a, d, &conds[c], c, fx, ly, wt, &n_inf);
        csf_curve k = fit_condition(fx, ly, wt, m);
        draw_curve(cr, &a, &k, palette[c % N_PALETTE]);
        cairo_restore(cr);
        legend_y = draw_legend_entry(cr, &a, conds, nc, c, &k, n_inf, legend_y);
    }
    free(fx), free(ly), free(wt);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    text_at(cr, a.x, PAGE_H - 22, 9, 0, 0,
            "Points: measured thresholds, bars +-1 standard error (log10). Lines: least-squares "
            "log-parabola per eccentricity.");
}

/* ---- display plot -------------------------------------------------------------------------- */

/* Model luminance for a reading: the stored profile when there is one, else leave-one-out
 * linear interpolation between the neighbouring readings of the same channel (so each residual
 * says how far a reading is from what its neighbours predict). */
static double model_lum(const report_data *d, size_t idx, double black)
{
    const csf_reading *r = &d->readings[idx];
    if (d->profile) {
        if (!strcmp(r->channel, "grey") || !strcmp(r->channel, "white") || !strcmp(r->channel, "dark"))
            return csf_profile_grey_lum(d->profile, r->drive01);
        int ch = !strcmp(r->channel, "r") ? CSF_CH_R : !strcmp(r->channel, "g") ? CSF_CH_G : CSF_CH_B;
        if (csf_profile_has_channels(d->profile))
            return csf_profile_lum_black(d->profile) + csf_profile_channel_lum(d->profile, ch, r->drive01);
        return NAN;
    }
    double lo_x = -1, lo_y = NAN, hi_x = 2, hi_y = NAN;
    int grey_like = !strcmp(r->channel, "grey") || !strcmp(r->channel, "white");
    for (size_t j = 0; j < d->n_readings; j++) {
        const csf_reading *q = &d->readings[j];
        if (j == idx || !isfinite(q->lum_cdm2) || q->status != CSF_READING_OK) continue;
        int same = !strcmp(q->channel, r->channel) ||
                   (grey_like && (!strcmp(q->channel, "grey") || !strcmp(q->channel, "white"))) ||
                   (!strcmp(q->channel, "dark") && q->drive01 == 0);
        if (!same || q->drive01 == r->drive01) continue;
        if (q->drive01 < r->drive01 && q->drive01 > lo_x) lo_x = q->drive01, lo_y = q->lum_cdm2;
        if (q->drive01 > r->drive01 && q->drive01 < hi_x) hi_x = q->drive01, hi_y = q->lum_cdm2;
    }
    if (!strcmp(r->channel, "dark") || r->drive01 == 0) {
        (void)black;
        return NAN;
    }
    if (isnan(lo_y) || isnan(hi_y)) return NAN; /* an end point: nothing on both sides */
    /* Display curves are close to power laws, which are straight in log-log: interpolating there
     * keeps a curved but clean response from showing up as residual. */
    if (lo_x > 0 && lo_y > 0 && hi_y > 0) {
        double t = (log(r->drive01) - log(lo_x)) / (log(hi_x) - log(lo_x));
        return exp(log(lo_y) + t * (log(hi_y) - log(lo_y)));
    }
    return lo_y + (hi_y - lo_y) * (r->drive01 - lo_x) / (hi_x - lo_x);
}

static void draw_display(cairo_t *cr, const report_data *d)
{
    double lmin = INFINITY, lmax = 0, black = NAN;
    for (size_t i = 0; i < d->n_readings; i++) {
        const csf_reading *r = &d->readings[i];
        if (!(r->lum_cdm2 > 0) || !isfinite(r->lum_cdm2)) continue;
        lmin = r->lum_cdm2 < lmin ? r->lum_cdm2 : lmin;
        lmax = r->lum_cdm2 > lmax ? r->lum_cdm2 : lmax;
        if (!strcmp(r->channel, "dark")) black = r->lum_cdm2;
    }
    if (!(lmax > 0)) {
        message_page(cr, "Display luminance", "No successful photometer readings in this session.");
        return;
    }
    title(cr, "Display luminance vs drive level, per channel");
    axes a = {80, 55, 520, 280, 0, 1, floor(log10(lmin)), ceil(log10(lmax * 1.05)), 0, 1};
    if (a.y1 <= a.y0) a.y1 = a.y0 + 1;
    draw_axes(cr, &a, "drive level (0..1)", "luminance (cd/m\xc2\xb2)");
    /* n_readings >= 1: lmax > 0 came from one of them */
    double *res = calloc(d->n_readings, sizeof *res); // NOLINT(clang-analyzer-optin.portability.UnixAPI)
    if (!res) return;
    double rmax = 0.5;
    for (size_t i = 0; i < d->n_readings; i++) {
        double m = model_lum(d, i, black);
        res[i] = isfinite(m) && m > 0 && isfinite(d->readings[i].lum_cdm2)
            ? 100.0 * (d->readings[i].lum_cdm2 - m) / m : NAN;
        if (!(fabs(res[i]) <= 1000.0)) res[i] = NAN; /* off any useful scale: not plotted */
        if (isfinite(res[i]) && fabs(res[i]) > rmax) rmax = fabs(res[i]);
    }
    axes b = {80, 400, 520, 130, 0, 1, -rmax * 1.15, rmax * 1.15, 0, 0};
    draw_axes(cr, &b, "drive level (0..1)", "residual (%)");
    double ly = a.y + 10;
    for (size_t c = 0; c < N_DISP_CHAN; c++) {
        int bad, cnt = channel_count(d, disp_chan[c].name, &bad);
        /* Profile model curve for this channel. */
        int ch = disp_chan[c].curve;
        if (d->profile && cnt && ch != -1) {
            if (ch == -2 || csf_profile_has_channels(d->profile)) {
                clip_to(cr, &a);
                set_rgb(cr, disp_chan[c].rgb);
                cairo_set_line_width(cr, 1.2);
                int started = 0;
                for (int k = 0; k <= 200; k++) {
                    double v = k / 200.0;
                    double L = ch == -2 ? csf_profile_grey_lum(d->profile, v)
                                      : csf_profile_lum_black(d->profile) + csf_profile_channel_lum(d->profile, ch, v);
                    if (!(L > 0)) continue;
                    if (!started) cairo_move_to(cr, ax_px(&a, v), ax_py(&a, L));
                    else cairo_line_to(cr, ax_px(&a, v), ax_py(&a, L));
                    started = 1;
                }
                cairo_stroke(cr);
                cairo_restore(cr);
            }
        }
        for (size_t i = 0; i < d->n_readings; i++) {
            const csf_reading *r = &d->readings[i];
            if (strcmp(r->channel, disp_chan[c].name)) continue;
            set_rgb(cr, disp_chan[c].rgb);
            if (r->lum_cdm2 > 0 && isfinite(r->lum_cdm2)) {
                clip_to(cr, &a);
                marker(cr, ax_px(&a, r->drive01), ax_py(&a, r->lum_cdm2), (int)c, 3);
                cairo_restore(cr);
            }
            if (isfinite(res[i])) {
                clip_to(cr, &b);
                marker(cr, ax_px(&b, r->drive01), ax_py(&b, res[i]), (int)c, 2.5);
                cairo_restore(cr);
            }
        }
        if (cnt) { /* the same name and counts as the readings table */
            char lab[64];
            const char *noun = cnt == 1 ? "reading" : "readings";
            if (bad) snprintf(lab, sizeof lab, "%s (%d %s, %d not ok)", disp_chan[c].name, cnt, noun, bad);
            else snprintf(lab, sizeof lab, "%s (%d %s)", disp_chan[c].name, cnt, noun);
            set_rgb(cr, disp_chan[c].rgb);
            marker(cr, a.x + a.w + 20, ly - 4, (int)c, 3.5);
            cairo_set_source_rgb(cr, 0, 0, 0);
            text_at(cr, a.x + a.w + 30, ly, 10, 0, 0, lab);
            ly += 15;
        }
    }
    free(res);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    text_at(cr, a.x + a.w + 20, ly + 10, 9, 0, 0,
            d->profile ? "Lines and residuals: stored display profile" :
                         "Residuals: vs. log-log interpolation of neighbours");
    if (d->profile) {
        char lab[128];
        snprintf(lab, sizeof lab, "profile %s", csf_profile_id(d->profile));
        text_at(cr, a.x + a.w + 20, ly + 23, 8, 0, 0, lab);
    }
}

/* ---- frame timing ------------------------------------------------------------------------- */

/* The histogram and its figures with the plot area from y top_pt to bottom_pt. */
static void draw_frames_area(cairo_t *cr, const report_data *d, double top_pt, double bottom_pt)
{
    double med = median_of(d->frames, d->n_frames);
    double vmax = 0;
    size_t late = 0;
    for (size_t i = 0; i < d->n_frames; i++) {
        vmax = d->frames[i] > vmax ? d->frames[i] : vmax;
        late += d->frames[i] > 1.5 * med;
    }
    double *sorted = malloc(d->n_frames * sizeof *sorted);
    if (!sorted) return;
    memcpy(sorted, d->frames, d->n_frames * sizeof *sorted);
    qsort(sorted, d->n_frames, sizeof *sorted, cmp_double);
    double p99 = sorted[(size_t)floor(0.99 * (double)(d->n_frames - 1))];
    free(sorted);
    /* Histogram in ms: 0 .. max(3 x median, largest), 60 bins; counts on a log scale so that a
     * handful of dropped frames stays visible next to thousands of good ones. */
    double hi_ms = 1000.0 * (vmax > 3 * med ? vmax * 1.05 : 3 * med);
    if (!(hi_ms > 0)) hi_ms = 1;
    enum { NB = 60 };
    size_t bins[NB] = {0}, bmax = 1;
    for (size_t i = 0; i < d->n_frames; i++) {
        int k = (int)(1000.0 * d->frames[i] / hi_ms * NB);
        k = k < 0 ? 0 : k >= NB ? NB - 1 : k;
        bins[k]++;
    }
    for (int k = 0; k < NB; k++) bmax = bins[k] > bmax ? bins[k] : bmax;
    axes a = {80, top_pt, 560, bottom_pt - top_pt, 0, hi_ms, 0, ceil(log10((double)bmax * 2)), 0, 1};
    draw_axes(cr, &a, "frame interval (ms)", "frames");
    cairo_set_source_rgb(cr, 0.0, 0.45, 0.70);
    for (int k = 0; k < NB; k++) {
        if (!bins[k]) continue;
        double x0 = ax_px(&a, hi_ms * k / NB), x1 = ax_px(&a, hi_ms * (k + 1) / NB);
        double top = ax_py(&a, (double)bins[k]), base = a.y + a.h;
        /* A single frame sits at log10(1) = 0, the axis floor: give it a visible sliver. */
        if (top > base - 3) top = base - 3;
        cairo_rectangle(cr, x0 + 0.5, top, x1 - x0 - 1, base - top);
    }
    cairo_fill(cr);
    /* The refresh interval (median) and the missed-frame criterion (1.5 x median). */
    cairo_set_line_width(cr, 1);
    double dash[] = {4, 3};
    cairo_set_dash(cr, dash, 2, 0);
    cairo_set_source_rgb(cr, 0.1, 0.6, 0.2);
    cairo_move_to(cr, ax_px(&a, 1000 * med), a.y);
    cairo_line_to(cr, ax_px(&a, 1000 * med), a.y + a.h);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
    cairo_move_to(cr, ax_px(&a, 1500 * med), a.y);
    cairo_line_to(cr, ax_px(&a, 1500 * med), a.y + a.h);
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
    char lab[160];
    double tx = a.x + a.w + 15, ty = a.y + 12;
    cairo_set_source_rgb(cr, 0, 0, 0);
    snprintf(lab, sizeof lab, "%zu intervals", d->n_frames);
    text_at(cr, tx, ty, 10, 0, 0, lab);
    snprintf(lab, sizeof lab, "median %.2f ms (%.1f Hz)", 1000 * med, med > 0 ? 1 / med : 0.0);
    text_at(cr, tx, ty += 15, 10, 0, 0, lab);
    snprintf(lab, sizeof lab, "99th percentile %.2f ms", 1000 * p99);
    text_at(cr, tx, ty += 15, 10, 0, 0, lab);
    snprintf(lab, sizeof lab, "longest %.2f ms", 1000 * vmax);
    text_at(cr, tx, ty += 15, 10, 0, 0, lab);
    if (late) cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
    snprintf(lab, sizeof lab, "%zu late (> 1.5 x median, %.2f %%)", late, 100.0 * (double)late / (double)d->n_frames);
    text_at(cr, tx, ty += 15, 10, late ? 1 : 0, 0, lab);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    text_at(cr, tx, ty += 22, 9, 0, 0, "green: median interval");
    text_at(cr, tx, ty + 12, 9, 0, 0, "red: missed-frame limit");
}

static void draw_frames(cairo_t *cr, const report_data *d)
{
    if (d->n_frames == 0) {
        message_page(cr, "Frame timing", "No frame intervals recorded for this session.");
        return;
    }
    title(cr, "Frame timing");
    draw_frames_area(cr, d, 60, PAGE_H - 80);
}

/* ---- driver ------------------------------------------------------------------------------- */

static void free_data(report_data *d)
{
    csf_session_info_free(&d->info);
    free(d->trials);
    free(d->readings);
    free(d->th);
    free(d->frames);
    csf_profile_free(d->profile);
}

/* The store file is outside input: keep only values a plot can place, so that axis ranges stay
 * finite and bounded (no conversion of NaN or huge values to integers, no endless tick loops). */
static void sanitize(report_data *d)
{
    size_t k = 0;
    for (size_t i = 0; i < d->n_th; i++) {
        csf_threshold_row r = d->th[i];
        if (!(r.freq_cpd >= 1e-6 && r.freq_cpd <= 1e6)) continue;
        if (!(r.threshold >= 1e-9)) continue; /* NaN, zero, negative: no sensitivity to plot */
        if (!(r.stderr_log10 >= 0 && r.stderr_log10 <= 5)) r.stderr_log10 = NAN;
        if (!isfinite(r.ecc_deg) || !isfinite(r.velocity_dps) || !isfinite(r.lum_cdm2)) continue;
        d->th[k++] = r;
    }
    d->n_th = k;
    k = 0;
    for (size_t i = 0; i < d->n_frames; i++)
        if (d->frames[i] >= 0 && d->frames[i] <= 10.0) d->frames[k++] = d->frames[i];
    d->n_frames = k;
    csf_store_printable(d->info.kind_text, d->kind, sizeof d->kind);
    csf_store_printable(d->info.state_text, d->state, sizeof d->state);
    for (size_t i = 0; i < d->n_readings; i++) {
        csf_reading *r = &d->readings[i];
        if (!(r->drive01 >= 0 && r->drive01 <= 1)) r->drive01 = 0, r->lum_cdm2 = NAN;
        if (!(r->lum_cdm2 >= 1e-6 && r->lum_cdm2 <= 1e6)) r->lum_cdm2 = NAN;
    }
}

static csf_status load_data(csf_store *s, int64_t id, report_data *d, csf_error *err)
{
    csf_status st = csf_store_get_session(s, id, &d->info, err);
    if (st == CSF_OK) st = csf_store_session_times(s, id, d->created, d->updated, err);
    if (st == CSF_OK) st = csf_store_get_trials(s, id, &d->trials, &d->n_trials, err);
    if (st == CSF_OK) st = csf_store_get_readings(s, id, &d->readings, &d->n_readings, err);
    if (st == CSF_OK) st = csf_store_get_thresholds(s, id, &d->th, &d->n_th, err);
    if (st == CSF_OK) st = csf_store_get_frame_intervals(s, id, &d->frames, &d->n_frames, err);
    if (st != CSF_OK) return st;
    sanitize(d);
    void *blob = NULL;
    size_t len = 0;
    csf_error perr;
    if (csf_store_get_artifact(s, id, "profile", &blob, &len, NULL, 0, &perr) == CSF_OK) {
        /* A profile that does not parse is not fatal: the plot falls back to interpolation. */
        if (csf_profile_parse((const char *)blob, len, &d->profile, &perr) != CSF_OK) d->profile = NULL;
        free(blob);
    }
    return CSF_OK;
}

typedef void (*panel_fn)(cairo_t *, const report_data *);

/* cairo writes the file through this into the temporary file; the OS error of a failed write
 * (a full disk) is kept for the message. */
typedef struct {
    FILE *fp;
    int errno_saved;
} stream_sink;

static cairo_status_t sink_write(void *closure, const unsigned char *data, unsigned int len)
{
    stream_sink *k = closure;
    errno = 0;
    if (fwrite(data, 1, len, k->fp) == len) return CAIRO_STATUS_SUCCESS;
    k->errno_saved = errno ? errno : EIO;
    return CAIRO_STATUS_WRITE_ERROR;
}

/* What a printed page needs to be found again: which report, which page. */
static void draw_footer(cairo_t *cr, const char *doc_title, int page, int n_pages)
{
    char right[64];
    snprintf(right, sizeof right, "page %d of %d", page, n_pages);
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, 40, PAGE_H - 28);
    cairo_line_to(cr, PAGE_W - 40, PAGE_H - 28);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
    text_at(cr, 40, PAGE_H - 16, 8, 0, 0, doc_title);
    text_at(cr, PAGE_W - 40, PAGE_H - 16, 8, 0, 1, right);
}

csf_status csf_report_write(csf_store *s, int64_t session_id, const char *out_path, csf_error *err)
{
    csf_error_clear(err);
    if (!s || !out_path || !*out_path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "report: no store or no output file");
    const char *ext = strrchr(out_path, '.');
    out_kind kind;
    if (ext && !strcasecmp(ext, ".pdf")) kind = OUT_PDF;
    else if (ext && !strcasecmp(ext, ".png")) kind = OUT_PNG;
    else if (ext && !strcasecmp(ext, ".svg")) kind = OUT_SVG;
    else
        return csf_error_set(err, CSF_E_INVALID_ARG, "report: %s: unknown file type '%s' (allowed "
                             ".pdf, .png, .svg)", out_path, ext ? ext : "(none)");

    report_data d;
    memset(&d, 0, sizeof d);
    csf_status st = load_data(s, session_id, &d, err);
    if (st != CSF_OK) {
        free_data(&d);
        return st;
    }
    panel_fn panels[4];
    int np = 0;
    panels[np++] = draw_summary;
    if (d.info.kind == CSF_SESSION_OBSERVER || d.info.kind == CSF_SESSION_STUDY || d.n_th)
        panels[np++] = draw_csf;
    if (d.info.kind == CSF_SESSION_DISPLAY || d.n_readings) panels[np++] = draw_display;
    d.frames_inline = d.n_frames && PAGE_H - 80 - summary_height(&d) >= FRAMES_INLINE_MIN_PT;
    /* A session without frame intervals (display sessions) gets no page that says so. */
    if (!d.frames_inline && d.n_frames) panels[np++] = draw_frames;

    /* The file is written through a temporary beside it (core/file_write.h) and renamed
     * when complete: a full disk or a failed draw leaves no partial report. */
    csf_atomic_file af = {0};
    st = csf_atomic_open(&af, out_path, "report", err);
    if (st != CSF_OK) {
        free_data(&d);
        return st;
    }
    stream_sink sink = {af.fp, 0};
    cairo_surface_t *surf = NULL;
    if (kind == OUT_PDF) surf = cairo_pdf_surface_create_for_stream(sink_write, &sink, PAGE_W, PAGE_H);
    else if (kind == OUT_SVG) surf = cairo_svg_surface_create_for_stream(sink_write, &sink, PAGE_W, PAGE_H * np);
    else surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, (int)PAGE_W, (int)PAGE_H * np);
    if (cairo_surface_status(surf) != CAIRO_STATUS_SUCCESS) {
        st = csf_error_set(err, CSF_E_IO, "report: cannot create %s (%s)", out_path,
                           cairo_status_to_string(cairo_surface_status(surf)));
        cairo_surface_destroy(surf);
        csf_atomic_abort(&af);
        free_data(&d);
        return st;
    }
    char doc_title[160];
    snprintf(doc_title, sizeof doc_title, "csfcal session %lld: %s calibration report", (long long)d.info.id,
             d.kind);
    if (kind == OUT_PDF) {
        cairo_pdf_surface_set_metadata(surf, CAIRO_PDF_METADATA_TITLE, doc_title);
        cairo_pdf_surface_set_metadata(surf, CAIRO_PDF_METADATA_SUBJECT,
                                       "Session summary, verdicts, measurements and frame timing");
        cairo_pdf_surface_set_metadata(surf, CAIRO_PDF_METADATA_CREATOR, "csfcal " CSF_VERSION);
    }
    cairo_t *cr = cairo_create(surf);
    for (int i = 0; i < np; i++) {
        cairo_save(cr);
        if (kind != OUT_PDF) cairo_translate(cr, 0, PAGE_H * i);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_rectangle(cr, 0, 0, PAGE_W, PAGE_H);
        cairo_fill(cr);
        /* The panels are drawn for the whole page; shrunk by 4 % about the top centre they
         * leave the bottom 24 pt to the footer, inside a printer's margin. */
        cairo_save(cr);
        cairo_translate(cr, PAGE_W * 0.02, 0);
        cairo_scale(cr, 0.96, 0.96);
        panels[i](cr, &d);
        cairo_restore(cr);
        draw_footer(cr, doc_title, i + 1, np);
        cairo_restore(cr);
        if (kind == OUT_PDF) cairo_show_page(cr);
    }
    cairo_status_t cst = cairo_status(cr);
    cairo_destroy(cr);
    if (cst == CAIRO_STATUS_SUCCESS && kind == OUT_PNG)
        cst = cairo_surface_write_to_png_stream(surf, sink_write, &sink);
    cairo_surface_finish(surf);
    if (cst == CAIRO_STATUS_SUCCESS) cst = cairo_surface_status(surf);
    cairo_surface_destroy(surf);
    free_data(&d);
    if (cst != CAIRO_STATUS_SUCCESS) {
        csf_atomic_abort(&af);
        if (sink.errno_saved)
            return csf_error_set(err, CSF_E_IO, "report: writing %s failed (%s)", out_path,
                                 strerror(sink.errno_saved));
        return csf_error_set(err, CSF_E_IO, "report: drawing %s failed (%s)", out_path,
                             cairo_status_to_string(cst));
    }
    return csf_atomic_commit(&af, err);
}
