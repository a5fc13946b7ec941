/* User-study report plots (see study_plot.h). */
#include "studies/study_plot.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "core/file_write.h"

#define PAGE_W 595.0
#define PAGE_H 420.0
#define ML 70.0
#define MR 30.0
#define MT 50.0
#define MB 60.0

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

static void text_at(cairo_t *cr, double x, double y, double size, const char *s, double align)
{
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.width, y);
    cairo_show_text(cr, s);
}

static void frame_axes(cairo_t *cr, const char *title, const char *xl, const char *yl)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, ML, MT, PAGE_W - ML - MR, PAGE_H - MT - MB);
    cairo_stroke(cr);
    text_at(cr, PAGE_W / 2, 28, 13, title, 0.5);
    text_at(cr, PAGE_W / 2, PAGE_H - 18, 11, xl, 0.5);
    cairo_save(cr);
    cairo_move_to(cr, 22, PAGE_H / 2);
    cairo_rotate(cr, -M_PI / 2);
    cairo_set_font_size(cr, 11);
    cairo_text_extents_t e;
    cairo_text_extents(cr, yl, &e);
    cairo_rel_move_to(cr, -e.width / 2, 0);
    cairo_show_text(cr, yl);
    cairo_restore(cr);
}

static double py(double p)
{
    return PAGE_H - MB - p * (PAGE_H - MT - MB);
}

static void y_ticks(cairo_t *cr)
{
    char b[16];
    for (int i = 0; i <= 4; i++) {
        double p = i / 4.0;
        snprintf(b, sizeof b, "%.2f", p);
        text_at(cr, ML - 6, py(p) + 4, 9, b, 1);
        cairo_move_to(cr, ML, py(p));
        cairo_line_to(cr, ML + 4, py(p));
        cairo_stroke(cr);
    }
}

static void draw_curve(cairo_t *cr, const csf_study_plot_curve *c)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < c->n_levels; i++) {
        lo = fmin(lo, c->levels[i].x_log10);
        hi = fmax(hi, c->levels[i].x_log10);
    }
    if (!(hi > lo)) {
        lo -= 0.5;
        hi += 0.5;
    }
    lo -= 0.1;
    hi += 0.1;
    double W = PAGE_W - ML - MR;
#define PX(x) (ML + ((x) - lo) / (hi - lo) * W)
    frame_axes(cr, c->title, "log10 Michelson contrast", "proportion correct / yes");
    y_ticks(cr);
    char b[32];
    /* ticks every 0.5, counted in halves: the same (exact) values as adding 0.5 each time */
    for (int h = (int)ceil(lo * 2); h / 2.0 <= hi; h++) {
        double x = h / 2.0;
        snprintf(b, sizeof b, "%.1f", x);
        text_at(cr, PX(x), PAGE_H - MB + 14, 9, b, 0.5);
    }
    if (c->have_fit) {
        if (isfinite(c->t_lo) && isfinite(c->t_hi)) {
            cairo_set_source_rgba(cr, 0.2, 0.4, 0.9, 0.15);
            double a = fmax(lo, c->t_lo), z = fmin(hi, c->t_hi);
            cairo_rectangle(cr, PX(a), MT, PX(z) - PX(a), PAGE_H - MT - MB);
            cairo_fill(cr);
        }
        cairo_set_source_rgb(cr, 0.1, 0.3, 0.8);
        cairo_set_line_width(cr, 1.5);
        for (int i = 0; i <= 200; i++) {
            double x = lo + (hi - lo) * i / 200.0;
            const csf_weibull_fit *f = &c->fit;
            double p = f->guess + (1 - f->guess - f->lapse) * (1 - exp(-pow(10.0, f->beta * (x - f->t_log10))));
            if (i == 0) cairo_move_to(cr, PX(x), py(p));
            else cairo_line_to(cr, PX(x), py(p));
        }
        cairo_stroke(cr);
        if (c->fit.t_log10 >= lo && c->fit.t_log10 <= hi) {
            cairo_set_dash(cr, (double[]){4, 3}, 2, 0);
            cairo_move_to(cr, PX(c->fit.t_log10), MT);
            cairo_line_to(cr, PX(c->fit.t_log10), PAGE_H - MB);
            cairo_stroke(cr);
            cairo_set_dash(cr, NULL, 0, 0);
        }
        snprintf(b, sizeof b, "t = %.3f, beta = %.2f", c->fit.t_log10, c->fit.beta);
        text_at(cr, PAGE_W - MR - 6, MT + 14, 10, b, 1);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    for (int i = 0; i < c->n_levels; i++) {
        const csf_psy_level *l = &c->levels[i];
        if (l->n <= 0) continue;
        double p = (double)l->k / l->n, elo, ehi;
        csf_stats_clopper_pearson(l->k, l->n, 0.95, &elo, &ehi);
        double x = PX(l->x_log10);
        cairo_move_to(cr, x, py(elo));
        cairo_line_to(cr, x, py(ehi));
        cairo_stroke(cr);
        /* area grows with the trials at the level */
        cairo_arc(cr, x, py(p), 1.5 + sqrt((double)l->n), 0, 2 * M_PI);
        cairo_fill(cr);
    }
#undef PX
}

static void draw_bars(cairo_t *cr, const char *title, const csf_study_plot_bar *b, int n, const char *axis)
{
    frame_axes(cr, title, "condition", axis);
    y_ticks(cr);
    double W = PAGE_W - ML - MR, step = W / (n > 0 ? n : 1);
    for (int i = 0; i < n; i++) {
        double x = ML + step * (i + 0.5);
        cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
        cairo_set_dash(cr, (double[]){3, 3}, 2, 0);
        cairo_move_to(cr, x - step * 0.4, py(b[i].chance));
        cairo_line_to(cr, x + step * 0.4, py(b[i].chance));
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, x, py(b[i].lo));
        cairo_line_to(cr, x, py(b[i].hi));
        cairo_stroke(cr);
        cairo_arc(cr, x, py(b[i].p), 3.5, 0, 2 * M_PI);
        cairo_fill(cr);
        cairo_save(cr);
        cairo_move_to(cr, x + 3, PAGE_H - MB + 10);
        cairo_rotate(cr, M_PI / 4);
        cairo_set_font_size(cr, 8);
        cairo_show_text(cr, b[i].label);
        cairo_restore(cr);
    }
}

csf_status csf_study_plot_write(const char *path, const char *title, const csf_study_plot_curve *curves,
                                int n_curves, const csf_study_plot_bar *bars, int n_bars,
                                const char *bar_axis, csf_error *err)
{
    const char *ext = strrchr(path, '.');
    int pdf = ext && !strcasecmp(ext, ".pdf"), svg = ext && !strcasecmp(ext, ".svg"),
        png = ext && !strcasecmp(ext, ".png");
    if (!pdf && !svg && !png)
        return csf_error_set(err, CSF_E_INVALID_ARG, "study report %s: unknown plot format '%s' (.pdf, .png, "
                             ".svg)", path, ext ? ext : "(none)");
    int np = n_curves + (n_bars > 0);
    if (np == 0) np = 1;
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
        if (i < n_curves) draw_curve(cr, &curves[i]);
        else if (n_bars > 0) draw_bars(cr, title, bars, n_bars, bar_axis);
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
