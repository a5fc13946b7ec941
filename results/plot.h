/* Session reports drawn with cairo from what the store holds.
 *   observer sessions: CSF plot (sensitivity vs frequency, log-log, one curve per eccentricity,
 *                      measured points with error bars from stderr_log10, fitted log-parabola);
 *   display sessions:  luminance vs drive per channel and residuals from a monotone fit;
 *   every session:     frame-timing histogram and a summary (counts, valid/invalid trials,
 *                      missed frames, duration).
 * Output format by extension of out_path: .pdf (one page per panel), .png, .svg (panels stacked
 * on one tall page). */
#ifndef CSF_PLOT_H
#define CSF_PLOT_H

#include <stdint.h>

#include "core/csf_status.h"
#include "results/store/store.h"

csf_status csf_report_write(csf_store *s, int64_t session_id, const char *out_path, csf_error *err);

/* Least-squares fit of the log-parabola log10 S(f) = log10 Smax - log10(2) *
 * ((log10 f - log10 fmax) / (beta * log10(2) / 2))^2 to points (freq_cpd[i], log10 S[i]) with
 * weights w[i] (NULL = equal). Needs at least 3 distinct frequencies; returns CSF_E_INSUFFICIENT
 * otherwise (the report then draws a straight log-log line). */
csf_status csf_fit_log_parabola(const double *freq_cpd, const double *log10_s, const double *w,
                                int n, double *log10_smax, double *fmax_cpd, double *beta_oct);

#endif
