/* Plots of a user-study report (studies/study_report.c), drawn with cairo on A4 landscape pages,
 * each a plot on the left and a table beside it on the right:
 *   - one page per psychometric curve: proportion correct (or "yes") per level with exact binomial
 *     intervals against Michelson contrast in % on a log axis, the fitted Weibull, the threshold
 *     and its interval; markers of one size, hollow, so that an interval is never hidden (the
 *     trials per level are written under the axis instead); the fit's figures above the plot,
 *     never over the data; the table lists every curve of the page's scope (threshold, 95 %
 *     interval, beta, trials) and the page states what the threshold is on the fitted function;
 *   - bar pages: per condition a proportion with its interval (and, for hits against false
 *     alarms, a second one) against a chance line per condition, with a table of figures.
 * Every text is fitted to its box: shrunk to a floor size, then wrapped, never clipped.
 * .pdf: one page per panel; .png and .svg: the panels stacked on one tall page. Written
 * atomically (core/file_write.h). */
#ifndef CSF_STUDY_PLOT_H
#define CSF_STUDY_PLOT_H

#include "core/csf_status.h"
#include "studies/study_stats.h"

/* Page geometry in points (1 pt = 1 px in .png), exposed so that tests can find what is drawn. */
#define CSF_STUDY_PAGE_W 842.0
#define CSF_STUDY_PAGE_H 595.0
#define CSF_STUDY_PLOT_L 70.0 /* the plot frame */
#define CSF_STUDY_PLOT_R 500.0
#define CSF_STUDY_PLOT_T 80.0
#define CSF_STUDY_PLOT_B 480.0
#define CSF_STUDY_MARKER_R 3.5 /* every marker's radius */

typedef struct {
    char title[320];
    char scope[64];                /* "pooled" or the participant: the table lists the scope's curves */
    char name[64];                 /* the curve's name */
    const csf_psy_level *levels;   /* pooled per distinct level */
    int n_levels;
    csf_weibull_fit fit;
    int have_fit;
    double t_lo, t_hi; /* 95 % interval of t (log10), NaN when none */
} csf_study_plot_curve;

#define CSF_STUDY_PLOT_COLS 6

typedef struct {
    char label[80];
    double p, lo, hi; /* the point plotted and its exact interval */
    double chance;    /* the chance line drawn across the condition's slot; NaN: none */
    int second;       /* a second point (false alarms), hollow */
    double p2, lo2, hi2;
    char cells[CSF_STUDY_PLOT_COLS][80]; /* the row of the table beside (cells[0] is the label) */
} csf_study_plot_bar;

typedef struct {
    char title[320];
    const char *axis;                         /* the y axis */
    const char *legend;                       /* what the marks mean, under the table */
    const char *columns[CSF_STUDY_PLOT_COLS]; /* the table's header */
    int n_columns;
    const csf_study_plot_bar *bars;
    int n_bars;
} csf_study_plot_bar_page;

/* The log10 contrast range of curve c's x axis, and where a proportion p is drawn (y, points). */
void csf_study_plot_x_range(const csf_study_plot_curve *c, double *lo, double *hi);
double csf_study_plot_py(double p);

csf_status csf_study_plot_write(const char *path, const csf_study_plot_curve *curves, int n_curves,
                                const csf_study_plot_bar_page *pages, int n_pages, csf_error *err);

#endif
