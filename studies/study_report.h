/* The analysis of a user study (`csfcal study report STUDY`, docs/studies.md) from what the store
 * holds: every session of the study (its stored copy of the study files rebuilds the trial plan,
 * so each stored trial is matched to its condition), practice and invalid trials left out.
 *
 * Per condition, pooled over participants and per participant:
 *   - proportion correct (2afc, 2ifc; yes/no and same/different: hits + correct rejections) with
 *     its exact Clopper-Pearson interval;
 *   - forced choice: an exact binomial test against chance (0.5), one-sided p(X >= k) and
 *     two-sided;
 *   - yes/no and same/different: hit and false-alarm rates, Fisher's exact test of hits against
 *     false alarms (chance is the false-alarm rate, whatever the person's bias), and d' with its
 *     95 % interval (yes/no: z(H) - z(F); same/different: the differencing model, or the
 *     independent-observation model when the study says sd_model = independent; intervals as
 *     csf_stats_dprime_yesno_ci and csf_stats_dprime_sd_ci; a negative d' means more
 *     "yes"/"different" answers without a signal than with one, in both); rates of 0 or 1 are
 *     moved by 1/(2N) first.
 * Per psychometric curve (conditions sharing a `curve` name, or one adaptive condition): the
 * maximum-likelihood Weibull fit (threshold t in log10 contrast, slope beta, lapse <= max_lapse;
 * guess 0.5 in forced choice, the curve's false-alarm rate in yes/no) with 95 % intervals for t
 * and beta from the marginal posterior under flat priors on t, the width 1/beta and lapse (the interval
 * whose coverage is nearest nominal, bench/bench_study_coverage; psignifit 4's kind), and the
 * parametric-bootstrap percentile intervals as well (they under-cover: BENCHMARKS.md). Image conditions sharing a `curve` name (say every
 * view's "imperceptible" pair) are also pooled into a group row with the condition statistics. */
#ifndef CSF_STUDY_REPORT_H
#define CSF_STUDY_REPORT_H

#include <stdio.h>

#include "studies/study_file.h"
#include "core/csf_status.h"
#include "studies/study_stats.h"

#define CSF_REPORT_MAX_LEVELS 128

typedef struct {
    char scope[64];            /* "pooled" or the participant code */
    int is_curve;              /* 0 condition, 1 psychometric curve (gratings), 2 group: image
                                  conditions pooled by their curve name */
    char name[CSF_STUDY_LABEL_MAX];
    double freq_cpd, ecc_deg;  /* the condition's (curves: the first condition's) */
    int n, k;                  /* scored trials and correct ones */
    double p, ci_lo, ci_hi, p_greater, p_two_sided;
    int hits, n_signal, false_alarms, n_noise;
    double hit_rate, fa_rate, dprime;
    double dprime_lo, dprime_hi; /* 95 % interval of d' (yes/no, same/different; NaN otherwise) */
    /* curves */
    csf_psy_level levels[CSF_REPORT_MAX_LEVELS];
    int n_levels;
    int have_fit;
    csf_weibull_fit fit;
    double t_lo, t_hi, beta_lo, beta_hi;      /* 95 % marginal-posterior intervals (the report's) */
    double tb_lo, tb_hi, bb_lo, bb_hi;        /* 95 % parametric-bootstrap percentile intervals */
    int n_boot_ok;
} csf_study_row;

/* One analysed session: who, which version, whether it ran to its end. */
typedef struct {
    int64_t id;
    char participant[64];
    int version;
    int finished;
    int n_trials;
    int participant_index;              /* its place in the version; with latin_row >= 0 it picked that row */
    int latin_row;                      /* the Latin-square row of a counterbalanced study; -1 without one */
    char experimenter[256], notes[256]; /* study run --set; "" when not given */
} csf_study_session_row;

typedef struct {
    char name[128];
    int version;     /* the version analysed */
    char sha256[65]; /* its identity (legacy: the 16-hex hash of its two files) */
    int legacy;
    char other_versions[2048]; /* the versions the store holds besides ("" when none) */
    csf_study_session_row *sessions;
    int n_session_rows;
    csf_study_design design;
    int sd_differencing;
    int n_sessions, n_finished, n_trials, n_excluded;
    char participants[1024];   /* comma-separated */
    uint64_t hash;
    csf_study_row *rows;       /* pooled first, then per participant */
    int n_rows;
} csf_study_report;

/* study: a settings file (exactly the sessions that ran these files, byte for byte, images
 * included) or a study name with version (0: the one version held); studies/study_sessions.h.
 * n_boot < 0: the study's bootstrap setting. CSF_E_NOT_FOUND when the store holds no such
 * session (the message lists the versions it holds). */
csf_status csf_study_report_build(const char *store_path, const char *study, int version, int n_boot,
                                  csf_study_report **out, csf_error *err);
void csf_study_report_free(csf_study_report *r);

/* The statistics of one row from its counts (n, k; hits and false alarms; a curve's levels), as
 * the report computes them: what csf_study_report_build does for every row (exposed for the
 * coverage test, tests/study/test_study_coverage.c). seed: the row's bootstrap seed. */
void csf_study_row_finish(csf_study_row *w, const csf_study *s, int n_boot, uint64_t seed);

void csf_study_report_print(const csf_study_report *r, FILE *fp);
/* One JSON document (jansson), malloc'd. */
char *csf_study_report_json(const csf_study_report *r);
/* Tidy CSV: one row per (scope, condition or curve). */
csf_status csf_study_report_csv(const csf_study_report *r, const char *path, csf_error *err);
csf_status csf_study_report_plot(const csf_study_report *r, const char *path, csf_error *err);

#endif
