/* User-study report plots (see study_plot.h). */
#include "studies/study_plot.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/file_write.h"
#include "core/utf8_text.h"

#define PAGE_W CSF_STUDY_PAGE_W
#define PAGE_H CSF_STUDY_PAGE_H
#define PL CSF_STUDY_PLOT_L
#define PR CSF_STUDY_PLOT_R
#define PT CSF_STUDY_PLOT_T
#define PB CSF_STUDY_PLOT_B
#define TX 522.0 /* the table beside the plot */
#define TW (PAGE_W - 25.0 - TX)
#define CSF_STUDY_PLOT_MAX_LEVELS 256

typedef struct {
    FILE *fp;
    int errno_saved;
} sink_t;

static cairo_status_t sink_write(void *closure, const unsigned char *data, unsigned int len)
{
    sink_t *s = closure;
    if (fwrite(data, 1, len, s->fp) != len) {
        s->errno_saved = errno ? errno : EIO;
        return CAIRO_STATUS_WRITE_ERROR;
    }
    return CAIRO_STATUS_SUCCESS;
}

/* The longest label drawn, in bytes: what advance() and fit_text() measure at once. */
#define LABEL_MAX 511

static void text_at(cairo_t *cr, double x, double y, double size, const char *text, double align)
{
    /* names and codes come from the store, outside input: cairo refuses text that is not UTF-8 and
     * then draws nothing more on the page */
    char *s = csf_utf8_drawable(text, SIZE_MAX, LABEL_MAX);
    if (!s) return;
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.x_advance, y);
    cairo_show_text(cr, s);
    free(s);
}

static double advance(cairo_t *cr, const char *s, size_t len)
{
    char buf[LABEL_MAX + 1];
    if (len >= sizeof buf) len = sizeof buf - 1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    cairo_text_extents_t e;
    cairo_text_extents(cr, buf, &e);
    return e.x_advance;
}

/* The longest start of s (whole UTF-8 characters, at least one) that is no wider than w,
 * ending after a space, '_', '/', or a '-' or '.' not followed by a digit, where one allows it,
 * so a name breaks between its parts and a number never does. */
static size_t line_len(cairo_t *cr, const char *s, double w)
{
    size_t n = strlen(s), fit = 0, brk = 0;
    for (size_t i = 1; i <= n; i++) {
        if (i < n && ((unsigned char)s[i] & 0xC0) == 0x80) continue; /* inside a character */
        if (advance(cr, s, i) > w) break;
        fit = i;
        /* '-' and '.' inside a number ("-2.376", "0.5") are no place to break */
        int digit_next = s[i] >= '0' && s[i] <= '9';
        if (strchr(" _/", s[i - 1]) || (strchr("-.", s[i - 1]) && !digit_next)) brk = i;
    }
    if (fit == n) return n;
    if (brk > 0) return brk;
    if (fit > 0) return fit;
    size_t one = 1;
    while (one < n && ((unsigned char)s[one] & 0xC0) == 0x80) one++;
    return one;
}

/* Draws s in a box w wide whose first baseline is y: at size when it fits, else shrunk down to
 * min_size, else wrapped into lines (line_len). align: 0 left of x, 0.5 centred, 1 right.
 * Returns the height used (lines times the line pitch). */
static double fit_text(cairo_t *cr, double x, double y, double w, double size, double min_size,
                       const char *text, double align)
{
    /* as text_at; cut to whole characters here, so no part below cuts one */
    char *drawable = csf_utf8_drawable(text, SIZE_MAX, LABEL_MAX);
    if (!drawable) return 0;
    const char *s = drawable;
    cairo_set_font_size(cr, size);
    double full = advance(cr, s, strlen(s));
    if (full > w) {
        size = fmax(min_size, size * w / full);
        cairo_set_font_size(cr, size);
    }
    double pitch = size * 1.2, h = 0;
    while (*s) {
        size_t n = line_len(cr, s, w);
        char buf[LABEL_MAX + 1];
        snprintf(buf, sizeof buf, "%.*s", (int)(n < sizeof buf ? n : sizeof buf - 1), s);
        size_t end = strlen(buf);
        while (end > 0 && buf[end - 1] == ' ') buf[--end] = '\0';
        text_at(cr, x, y + h, size, buf, align);
        h += pitch;
        s += n;
        while (*s == ' ') s++;
    }
    free(drawable);
    return h;
}

double csf_study_plot_py(double p)
{
    return PB - p * (PB - PT);
}

/* The x axis's name, centred under the plot at baseline y. */
static void x_name(cairo_t *cr, const char *xl, double y)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    fit_text(cr, (PL + PR) / 2, y, PR - PL, 11, 7, xl, 0.5);
}

/* The frame, the title, the y axis's name and ticks. */
static void page_frame(cairo_t *cr, const char *title, const char *yl)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, PL, PT, PR - PL, PB - PT);
    cairo_stroke(cr);
    fit_text(cr, PAGE_W / 2, 26, PAGE_W - 60, 13, 8, title, 0.5);
    cairo_save(cr);
    cairo_translate(cr, 24, (PT + PB) / 2);
    cairo_rotate(cr, -M_PI / 2);
    fit_text(cr, 0, 0, PB - PT, 11, 7, yl, 0.5);
    cairo_restore(cr);
    char b[16];
    for (int i = 0; i <= 4; i++) {
        double p = i / 4.0, y = csf_study_plot_py(p);
        snprintf(b, sizeof b, "%.2f", p);
        text_at(cr, PL - 6, y + 3, 9, b, 1);
        cairo_move_to(cr, PL, y);
        cairo_line_to(cr, PL + 4, y);
        cairo_stroke(cr);
    }
}

void csf_study_plot_x_range(const csf_study_plot_curve *c, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int i = 0; i < c->n_levels; i++) {
        *lo = fmin(*lo, c->levels[i].x_log10);
        *hi = fmax(*hi, c->levels[i].x_log10);
    }
    if (!(*hi >= *lo)) *lo = *hi = -2;
    *lo -= 0.1;
    *hi += 0.1;
    /* at least 0.7 log10 wide: the 1-2-...-9 ticks are at most log10(1.5) = 0.18 apart, so three or
     * more of them always fall inside */
    if (*hi - *lo < 0.7) {
        double mid = 0.5 * (*lo + *hi);
        *lo = mid - 0.35;
        *hi = mid + 0.35;
    }
}

/* Log-axis ticks inside [lo, hi]: the sparsest of the 1-2-5 families that gives at least four,
 * else the densest's. Returns the count. */
static int x_ticks(double lo, double hi, double *ticks, int cap)
{
    static const double sets[4][10] = {{1}, {1, 2, 5}, {1, 2, 3, 5, 7}, {1, 1.5, 2, 3, 4, 5, 6, 7, 8, 9}};
    static const int sizes[4] = {1, 3, 5, 10};
    int n = 0;
    for (int k = 0; k < 4; k++) {
        n = 0;
        for (int dec = (int)floor(lo) - 1; dec <= (int)ceil(hi); dec++)
            for (int m = 0; m < sizes[k]; m++) {
                double v = dec + log10(sets[k][m]);
                if (v >= lo - 1e-9 && v <= hi + 1e-9 && n < cap) ticks[n++] = v;
            }
        if (n >= 4) break;
    }
    return n;
}

/* A contrast in % with no more digits than it needs. */
static void pct(char *b, size_t cap, double x_log10)
{
    snprintf(b, cap, "%.3g", 100 * pow(10.0, x_log10));
}

static double weibull(const csf_weibull_fit *f, double x)
{
    return f->guess + (1 - f->guess - f->lapse) * (1 - exp(-pow(10.0, f->beta * (x - f->t_log10))));
}

/* The fit: the threshold's interval shaded, the function, the threshold dashed. */
static void draw_fit(cairo_t *cr, const csf_study_plot_curve *c, double lo, double hi)
{
#define PX(x) (PL + ((x)-lo) / (hi - lo) * (PR - PL))
    if (isfinite(c->t_lo) && isfinite(c->t_hi)) {
        cairo_set_source_rgba(cr, 0.2, 0.4, 0.9, 0.15);
        double a = fmax(lo, c->t_lo), z = fmin(hi, c->t_hi);
        if (z > a) {
            cairo_rectangle(cr, PX(a), PT, PX(z) - PX(a), PB - PT);
            cairo_fill(cr);
        }
    }
    cairo_set_source_rgb(cr, 0.1, 0.3, 0.8);
    cairo_set_line_width(cr, 1.5);
    for (int i = 0; i <= 200; i++) {
        double x = lo + (hi - lo) * i / 200.0;
        double y = csf_study_plot_py(weibull(&c->fit, x));
        if (i == 0) cairo_move_to(cr, PX(x), y);
        else cairo_line_to(cr, PX(x), y);
    }
    cairo_stroke(cr);
    if (c->fit.t_log10 >= lo && c->fit.t_log10 <= hi) {
        cairo_set_dash(cr, (double[]){4, 3}, 2, 0);
        cairo_move_to(cr, PX(c->fit.t_log10), PT);
        cairo_line_to(cr, PX(c->fit.t_log10), PB);
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
    }
#undef PX
}

/* A vertical interval with caps, and a marker of one size over it: hollow (white inside,
 * outlined) so the interval's ends stay visible whatever the trials behind it. square: a square
 * marker (the second series of a bar page). */
static void point(cairo_t *cr, double x, double y, double y_lo, double y_hi, int square)
{
    cairo_set_line_width(cr, 1);
    cairo_move_to(cr, x, y_lo);
    cairo_line_to(cr, x, y_hi);
    cairo_move_to(cr, x - 3, y_lo);
    cairo_line_to(cr, x + 3, y_lo);
    cairo_move_to(cr, x - 3, y_hi);
    cairo_line_to(cr, x + 3, y_hi);
    cairo_stroke(cr);
    const double r = CSF_STUDY_MARKER_R;
    if (square) cairo_rectangle(cr, x - r, y - r, 2 * r, 2 * r);
    else cairo_arc(cr, x, y, r, 0, 2 * M_PI);
    cairo_save(cr);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_fill_preserve(cr);
    cairo_restore(cr);
    cairo_set_line_width(cr, 1.3);
    cairo_stroke(cr);
}

/* The x axis of a curve page: ticks in % contrast, then each level's trial count under them
 * (a count that would overlap the previous one is left out and the row says so). */
static void curve_axis(cairo_t *cr, const csf_study_plot_curve *c, double lo, double hi)
{
#define PX(x) (PL + ((x)-lo) / (hi - lo) * (PR - PL))
    double ticks[64];
    int nt = x_ticks(lo, hi, ticks, 64);
    char b[32];
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    for (int i = 0; i < nt; i++) {
        pct(b, sizeof b, ticks[i]);
        strcat(b, "%");
        text_at(cr, PX(ticks[i]), PB + 14, 9, b, 0.5);
        cairo_move_to(cr, PX(ticks[i]), PB);
        cairo_line_to(cr, PX(ticks[i]), PB - 4);
        cairo_stroke(cr);
    }
    text_at(cr, PL - 6, PB + 30, 7, "trials", 1);
    double last = -INFINITY;
    int skipped = 0, order[CSF_STUDY_PLOT_MAX_LEVELS], n = 0;
    /* left to right: levels are stored in the order the trials first met them */
    for (int i = 0; i < c->n_levels && n < CSF_STUDY_PLOT_MAX_LEVELS; i++) {
        int j = n++;
        for (; j > 0 && c->levels[order[j - 1]].x_log10 > c->levels[i].x_log10; j--) order[j] = order[j - 1];
        order[j] = i;
    }
    cairo_set_font_size(cr, 7);
    for (int o = 0; o < n; o++) {
        const csf_psy_level *l = &c->levels[order[o]];
        double x = PX(l->x_log10);
        snprintf(b, sizeof b, "%d", l->n);
        double w = advance(cr, b, strlen(b));
        if (x - w / 2 < last + 2) {
            skipped++;
            continue;
        }
        text_at(cr, x, PB + 30, 7, b, 0.5);
        last = x + w / 2;
    }
    if (skipped)
        fit_text(cr, PR, PB + 40, PR - PL, 7, 6, "(levels too close to label each: all counts in the JSON)",
                 1);
#undef PX
}

/* The table beside a plot: header, then rows; hl: the row to highlight (-1: none). Rows past the
 * page's foot are left out with a note. Returns the y under the table. */
static double table(cairo_t *cr, const char *const *head, int ncol, const double *colw,
                    const char (*cells)[80], int stride, int nrow, int hl, double y)
{
    double x = TX;
    cairo_set_source_rgb(cr, 0, 0, 0);
    double hh = 0;
    for (int j = 0; j < ncol; j++) {
        hh = fmax(hh, fit_text(cr, x + 1, y, colw[j] - 3, 8, 6, head[j], 0));
        x += colw[j];
    }
    y += hh;
    cairo_move_to(cr, TX, y - 6);
    cairo_line_to(cr, TX + TW, y - 6);
    cairo_stroke(cr);
    y += 4;
    for (int i = 0; i < nrow; i++) {
        if (y > PAGE_H - 70) {
            fit_text(cr, TX, y, TW, 8, 6, "(more rows in the CSV and the JSON)", 0);
            return y + 12;
        }
        if (i == hl) {
            cairo_set_source_rgb(cr, 0.85, 0.9, 1);
            cairo_rectangle(cr, TX, y - 9, TW, 12);
            cairo_fill(cr);
            cairo_set_source_rgb(cr, 0, 0, 0);
        }
        double rh = 0;
        x = TX;
        for (int j = 0; j < ncol; j++) {
            rh = fmax(rh, fit_text(cr, x + 1, y, colw[j] - 3, 8, 5, cells[i * stride + j], 0));
            x += colw[j];
        }
        y += rh + 2;
    }
    return y;
}

/* The table of a curve page: every curve of the page's scope. */
static double curve_table(cairo_t *cr, const csf_study_plot_curve *all, int n_all,
                          const csf_study_plot_curve *c)
{
    static const char *const head[5] = {"curve", "threshold (%)", "95% interval (%)", "beta", "trials"};
    static const double colw[5] = {70, 80, 70, 30, 32};
    char(*cells)[80] = calloc((size_t)n_all * 5 + 1, sizeof *cells);
    if (!cells) return PT;
    int nrow = 0, hl = -1;
    for (int i = 0; i < n_all; i++) {
        const csf_study_plot_curve *o = &all[i];
        if (strcmp(o->scope, c->scope)) continue;
        if (o == c) hl = nrow;
        char(*r)[80] = &cells[nrow++ * 5];
        int n = 0;
        for (int j = 0; j < o->n_levels; j++) n += o->levels[j].n;
        snprintf(r[0], 80, "%s", o->name);
        snprintf(r[4], 80, "%d", n);
        if (!o->have_fit) {
            snprintf(r[1], 80, "no fit");
            continue;
        }
        char a[16], b[16];
        pct(r[1], 80, o->fit.t_log10);
        pct(a, sizeof a, o->t_lo);
        pct(b, sizeof b, o->t_hi);
        snprintf(r[2], 80, "[%s, %s]", a, b);
        snprintf(r[3], 80, "%.2f", o->fit.beta);
    }
    char title[128];
    snprintf(title, sizeof title, "Curves (%s)", c->scope);
    fit_text(cr, TX, PT - 2, TW, 10, 7, title, 0);
    double y = table(cr, head, 5, colw, (const char(*)[80])cells, 5, nrow, hl, PT + 14);
    free(cells);
    return y;
}

/* What the threshold is on the fitted function, as csf_weibull_fit_ml defines t, and the marks. */
static void curve_notes(cairo_t *cr, const csf_study_plot_curve *c, double y)
{
    char b[700];
    if (c->have_fit)
        snprintf(
            b, sizeof b,
            "Threshold criterion: t is the contrast at which the fitted Weibull P(x) = g + (1 - g - l)(1 - "
            "exp(-10^(beta (x - log10 t)))) has risen 1 - 1/e = 63.2 %% of the way from the guess rate g "
            "to its ceiling 1 - l: here P(t) = %.3f (g = %.3f, l = %.3f). Interval: 95 %% marginal "
            "posterior, flat priors on log10 t, 1/beta and l.",
            weibull(&c->fit, c->fit.t_log10), c->fit.guess, c->fit.lapse);
    else snprintf(b, sizeof b, "No fit: fewer than two contrast levels.");
    y += 10 + fit_text(cr, TX, y + 10, TW, 8, 8, b, 0);
    fit_text(cr, TX, y + 8, TW, 8, 8,
             "Circles: proportion correct (yes/no: proportion yes) at each level, 95 % exact interval; "
             "trials per level under the axis. Line: the fit; dashed: t; shaded: its 95 % interval.",
             0);
}

static void draw_curve(cairo_t *cr, const csf_study_plot_curve *all, int n_all, const csf_study_plot_curve *c)
{
    double lo, hi;
    csf_study_plot_x_range(c, &lo, &hi);
#define PX(x) (PL + ((x)-lo) / (hi - lo) * (PR - PL))
    page_frame(cr, c->title, "proportion correct / yes");
    x_name(cr, "Michelson contrast (%, log scale)", PB + 52);
    curve_axis(cr, c, lo, hi);
    if (c->have_fit) {
        char b[200], t[16], a[16], z[16];
        pct(t, sizeof t, c->fit.t_log10);
        pct(a, sizeof a, c->t_lo);
        pct(z, sizeof z, c->t_hi);
        /* above the frame: never over the data */
        snprintf(b, sizeof b, "threshold %s %% [%s, %s] (t = %.3f log10), beta = %.2f, lapse = %.3f", t, a, z,
                 c->fit.t_log10, c->fit.beta, c->fit.lapse);
        cairo_set_source_rgb(cr, 0.1, 0.3, 0.8);
        fit_text(cr, PL, PT - 12, PR - PL, 10, 7, b, 0);
        draw_fit(cr, c, lo, hi);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    for (int i = 0; i < c->n_levels; i++) {
        const csf_psy_level *l = &c->levels[i];
        if (l->n <= 0) continue;
        double elo, ehi;
        csf_stats_clopper_pearson(l->k, l->n, 0.95, &elo, &ehi);
        point(cr, PX(l->x_log10), csf_study_plot_py((double)l->k / l->n), csf_study_plot_py(elo),
              csf_study_plot_py(ehi), 0);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    curve_notes(cr, c, curve_table(cr, all, n_all, c));
#undef PX
}

/* One condition's slot: its chance line, its point(s), its label under the axis. Returns the
 * label's height. */
static double draw_slot(cairo_t *cr, const csf_study_plot_bar *b, double x, double step)
{
    if (isfinite(b->chance)) {
        cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
        cairo_set_line_width(cr, 1);
        cairo_set_dash(cr, (double[]){3, 3}, 2, 0);
        cairo_move_to(cr, x - step * 0.4, csf_study_plot_py(b->chance));
        cairo_line_to(cr, x + step * 0.4, csf_study_plot_py(b->chance));
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
    }
    double dx = b->second ? fmin(8, step * 0.15) : 0;
    if (isfinite(b->p)) {
        cairo_set_source_rgb(cr, 0, 0, 0);
        point(cr, x - dx, csf_study_plot_py(b->p), csf_study_plot_py(b->lo), csf_study_plot_py(b->hi), 0);
    }
    if (b->second && isfinite(b->p2)) {
        cairo_set_source_rgb(cr, 0.75, 0.2, 0.1);
        point(cr, x + dx, csf_study_plot_py(b->p2), csf_study_plot_py(b->lo2), csf_study_plot_py(b->hi2), 1);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    return fit_text(cr, x, PB + 14, step - 4, 9, 6, b->label, 0.5);
}

static void draw_bars(cairo_t *cr, const csf_study_plot_bar_page *pg)
{
    page_frame(cr, pg->title, pg->axis);
    double step = (PR - PL) / (pg->n_bars > 0 ? pg->n_bars : 1), label_h = 0;
    for (int i = 0; i < pg->n_bars; i++)
        label_h = fmax(label_h, draw_slot(cr, &pg->bars[i], PL + step * (i + 0.5), step));
    /* the axis's name under the longest label, wrapped as it may be */
    x_name(cr, "condition", fmax(PB + 52, PB + 14 + label_h + 12));
    static const double w6[6] = {70, 58, 58, 30, 48, 31}, w5[5] = {84, 40, 50, 80, 41};
    const double *colw = pg->n_columns == 6 ? w6 : w5;
    char(*cells)[80] = calloc((size_t)pg->n_bars * CSF_STUDY_PLOT_COLS + 1, sizeof *cells);
    double y = PT + 14;
    if (cells) {
        for (int i = 0; i < pg->n_bars; i++)
            memcpy(cells[i * CSF_STUDY_PLOT_COLS], pg->bars[i].cells, sizeof pg->bars[i].cells);
        y = table(cr, pg->columns, pg->n_columns, colw, (const char(*)[80])cells, CSF_STUDY_PLOT_COLS,
                  pg->n_bars, -1, y);
        free(cells);
    }
    if (pg->legend) fit_text(cr, TX, y + 10, TW, 8, 8, pg->legend, 0);
}

csf_status csf_study_plot_write(const char *path, const csf_study_plot_curve *curves, int n_curves,
                                const csf_study_plot_bar_page *pages, int n_pages, csf_error *err)
{
    const char *ext = strrchr(path, '.');
    int pdf = ext && !strcasecmp(ext, ".pdf"), svg = ext && !strcasecmp(ext, ".svg"),
        png = ext && !strcasecmp(ext, ".png");
    if (!pdf && !svg && !png)
        return csf_error_set(err, CSF_E_INVALID_ARG, "study report %s: unknown plot format '%s' (.pdf, .png, "
                             ".svg)", path, ext ? ext : "(none)");
    int np = n_curves + n_pages;
    if (np == 0) np = 1;
    /* A PNG stacks the pages in one image, and cairo's images are at most 32767 px tall. */
    int png_max_pages = (int)(32767 / PAGE_H);
    if (png && np > png_max_pages)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "study report %s: %d pages do not fit in one PNG image (at most %d pages, "
                             "32767 px); write the report as .pdf (a page each) or .svg",
                             path, np, png_max_pages);
    csf_atomic_file af = {0};
    csf_status st = csf_atomic_open(&af, path, "study report plot", err);
    if (st != CSF_OK) return st;
    sink_t sink = {af.fp, 0};
    cairo_surface_t *surf = pdf ? cairo_pdf_surface_create_for_stream(sink_write, &sink, PAGE_W, PAGE_H)
                          : svg ? cairo_svg_surface_create_for_stream(sink_write, &sink, PAGE_W, PAGE_H * np)
                                : cairo_image_surface_create(CAIRO_FORMAT_RGB24, (int)PAGE_W, (int)(PAGE_H * np));
    cairo_t *cr = cairo_create(surf);
    for (int i = 0; i < np; i++) {
        cairo_save(cr);
        if (!pdf) cairo_translate(cr, 0, PAGE_H * i);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_rectangle(cr, 0, 0, PAGE_W, PAGE_H);
        cairo_fill(cr);
        cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
        if (i < n_curves) draw_curve(cr, curves, n_curves, &curves[i]);
        else if (i - n_curves < n_pages) draw_bars(cr, &pages[i - n_curves]);
        else {
            cairo_set_source_rgb(cr, 0, 0, 0);
            text_at(cr, PAGE_W / 2, PAGE_H / 2, 12, "no trials to plot", 0.5);
        }
        cairo_restore(cr);
        if (pdf) cairo_show_page(cr);
    }
    cairo_status_t cst = cairo_status(cr);
    cairo_destroy(cr);
    if (cst == CAIRO_STATUS_SUCCESS && png) cst = cairo_surface_write_to_png_stream(surf, sink_write, &sink);
    cairo_surface_finish(surf);
    if (cst == CAIRO_STATUS_SUCCESS) cst = cairo_surface_status(surf);
    cairo_surface_destroy(surf);
    if (cst != CAIRO_STATUS_SUCCESS) {
        csf_atomic_abort(&af);
        return csf_error_set(err, CSF_E_IO, "study report %s: %s", path,
                             sink.errno_saved ? strerror(sink.errno_saved) : cairo_status_to_string(cst));
    }
    return csf_atomic_commit(&af, err);
}
