/* Plots of a user-study report (studies/study_report.c), drawn with cairo: one panel per
 * psychometric curve (proportion correct per level with exact binomial intervals, the fitted
 * Weibull, the threshold and its bootstrap interval) and one panel of every condition's
 * proportion correct with its interval against chance. .pdf: one page per panel; .png and .svg:
 * the panels stacked on one tall page. Written atomically (core/file_write.h). */
#ifndef CSF_STUDY_PLOT_H
#define CSF_STUDY_PLOT_H

#include "core/csf_status.h"
#include "studies/study_stats.h"

typedef struct {
    char title[320];
    const csf_psy_level *levels;   /* pooled per distinct level */
    int n_levels;
    csf_weibull_fit fit;
    int have_fit;
    double t_lo, t_hi;             /* bootstrap interval of t (log10), NaN when none */
} csf_study_plot_curve;

typedef struct {
    char label[80];
    double p, lo, hi;              /* proportion and its exact interval */
    double chance;
} csf_study_plot_bar;

csf_status csf_study_plot_write(const char *path, const char *title, const csf_study_plot_curve *curves,
                                int n_curves, const csf_study_plot_bar *bars, int n_bars,
                                const char *bar_axis, csf_error *err);

#endif
