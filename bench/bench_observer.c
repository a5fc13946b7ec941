/* Observer calibration accuracy: RMS error of log10 threshold over the visible cells of the default
 * 6 x 4 grid against simulated people's truths, for each method and trial budget, beside per-cell
 * QUEST and joint QUEST+ (--honest: tuned-on vs held-out observers). Usage, options, the truths and
 * how the nineteen held-out sets were made: bench/data/README.md. Figures: BENCHMARKS.md. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/method_bayes.h"
#include "calib/procedure.h"
#include "model/observer_sdt.h"
#include "model/observer_sim.h"
#include "anchor_run.h"
#include "questplus.h"
#include "honest_sets.h"
#include "model/psychometric.h"
#include "tests/bayes/sim_2afc.h"

enum { MAX_BUDGETS = 16, MAX_METHODS = 4, N_OBS = 3, N_LAYOUTS = 2, MAX_SPECS = 8 };

/* What calib/observer_calib.c gives every method, whatever the person. */
#define SESSION_SLOPE 3.5
#define SESSION_LAPSE 0.02

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* One simulated session of a --sim observer: as sim2afc_run_alt, answers from devices/observer_sim
 * (trial k is the observer's trial index: fatigue, drift and lapse runs follow the session). */
static int run_sim_session(const csf_procedure_ops *ops, const csf_observer_sim *o, const csf_cell *cells,
                           int n_cells, const int *n_alt, int budget, uint64_t proc_seed,
                           double max_contrast, csf_cell_estimate *est)
{
    csf_procedure_setup setup = {.cells = cells, .n_cells = n_cells, .trial_budget = budget,
                                 .seed = proc_seed, .max_contrast = max_contrast,
                                 .min_contrast = 0.0005, .slope_beta = SESSION_SLOPE,
                                 .lapse = SESSION_LAPSE, .guess = 0.5, .n_alternatives = n_alt};
    /* diagnosis only (CSF_BENCH_ORACLE_PSY=1): the method is told the observer's own psychometric
     * function, which separates the cost of marginalising slope and lapse from the rest */
    const char *oracle = getenv("CSF_BENCH_ORACLE_PSY");
    if (oracle && *oracle == '1') {
        const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
        setup.fixed_psychometric = 1;
        setup.slope_beta = p->decision == CSF_SIM_SDT ? 1.21 * p->k_transducer : p->slope;
        setup.lapse = p->lapse;
    }
    const char *fix = getenv("CSF_BENCH_FIX");
    if (fix && *fix) {
        setup.fixed_psychometric = 1;
        sscanf(fix, "%lf,%lf", &setup.slope_beta, &setup.lapse);
    }
    csf_error err = {0};
    void *st = NULL;
    if (ops->create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "%s: create: %s\n", ops->name, err.msg);
        return -1;
    }
    const char *place = getenv("CSF_BENCH_PLACE");
    for (int k = 0; k < budget; k++) {
        csf_trial_plan plan;
        csf_status rc = ops->next(st, k, &plan);
        if (rc == CSF_E_ABORTED) break;
        int m = plan.n_alternatives == 4 ? 4 : 2;
        if (rc != CSF_OK || plan.cell < 0 || plan.cell >= n_cells || plan.signal_interval < 0 ||
            plan.signal_interval >= m) {
            fprintf(stderr, "%s: next failed at trial %d\n", ops->name, k);
            ops->destroy(st);
            return -1;
        }
        const csf_cell *c = &cells[plan.cell];
        double shown[4] = {0, 0, 0, 0}, rt;
        shown[plan.signal_interval] = plan.contrast;
        csf_trial_outcome out = {.rt_s = 0.6, .contrast_at_response = plan.contrast, .valid = 1};
        out.response = m == 4 ? csf_observer_sim_afc(o, (uint64_t)k, c->freq_cpd, c->ecc_deg, shown, 4, &rt)
                              : csf_observer_sim_2afc(o, (uint64_t)k, c->freq_cpd, c->ecc_deg, shown, &rt);
        ops->update(st, k, &plan, &out);
        if (place && *place == '1') /* diagnosis: where trials land against the truth */
            fprintf(stderr, "place: %d %.4f %d\n", m,
                    log10(plan.contrast) - log10(csf_observer_sim_threshold(o, c->freq_cpd, c->ecc_deg)),
                    out.response == plan.signal_interval);
    }
    csf_status rc = ops->estimate(st, est, &err);
    const char *psy = getenv("CSF_BENCH_PSY"); /* diagnosis: the slope and lapse bayes settled on */
    if (psy && *psy == '1' && ops == &csf_procedure_bayes) {
        double sl, la;
        csf_bayes_psychometric(st, &sl, &la);
        fprintf(stderr, "psy: slope %.2f lapse %.3f\n", sl, la);
    }
    ops->destroy(st);
    if (rc != CSF_OK) {
        fprintf(stderr, "%s: estimate: %s\n", ops->name, err.msg);
        return -1;
    }
    return 0;
}

/* RMS error of log10 threshold over the truly visible cells (as sim2afc_rms); also adds the signed
 * errors of the visible cells to bias_sum[0] (two-interval cells) or [1] (four places), and
 * counts them in bias_n. */
static double sim_rms(const csf_observer_sim *o, const csf_cell *cells, int n_cells, const int *n_alt,
                      const csf_cell_estimate *est, double max_contrast, int *n_wrong_vis,
                      double bias_sum[2], int bias_n[2])
{
    double se = 0.0;
    int n = 0, wrong = 0;
    for (int c = 0; c < n_cells; c++) {
        double th = csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg);
        int vis = th < max_contrast;
        int est_vis = isfinite(est[c].threshold);
        wrong += vis != est_vis;
        if (!vis) continue;
        double e = est_vis ? log10(est[c].threshold) : log10(max_contrast);
        se += (e - log10(th)) * (e - log10(th));
        n++;
        int four = n_alt[c] == 4;
        bias_sum[four] += e - log10(th);
        bias_n[four]++;
    }
    *n_wrong_vis = wrong;
    return n ? sqrt(se / n) : NAN;
}

/* The --sim observers: RMS per spec, truth, method and budget, printed as one table per layout. */
static int run_specs(const char *const *specs, int n_specs, const int *use_obs, const char *table,
                     const char *table2, const csf_procedure_ops *const *methods, int n_methods,
                     const int *budgets, int n_budgets, int first_seed, int n_seeds,
                     const csf_cell *cells, int n, const int *n_alt, double cmax)
{
    const char *truth_name[N_OBS] = {"parametric", "bumpy", "mscaled"};
    const char *truth_key[N_OBS] = {"", table, table2};
    printf("| observer spec | truth | method | trials | RMS | wrong | mean error, two intervals | mean error, four places | ms/session |\n"
           "|---|---|---|---|---|---|---|---|---|\n");
    for (int sp = 0; sp < n_specs; sp++)
        for (int ob = 0; ob < N_OBS; ob++) {
            if (!use_obs[ob]) continue;
            char spec[1300];
            snprintf(spec, sizeof spec, "%s%s%s%s", specs[sp], strchr(specs[sp], ':') ? "" : ":",
                     ob ? ",table=" : "", truth_key[ob]);
            if (spec[strlen(spec) - 1] == ':') spec[strlen(spec) - 1] = '\0';
            for (int m = 0; m < n_methods; m++)
                for (int b = 0; b < n_budgets; b++) {
                    double sum_sq = 0, t0 = now_s();
                    int wrong_total = 0, bias_n[2] = {0, 0};
                    double bias_sum[2] = {0, 0}, cell_e[24] = {0}, cell_e2[24] = {0}, cell_nt[24] = {0};
                    int cell_n[24] = {0};
                    for (int s = first_seed; s < first_seed + n_seeds; s++) {
                        csf_observer_sim *o;
                        csf_error err;
                        if (csf_observer_sim_create(spec, (uint64_t)s, &o, &err) != CSF_OK) {
                            fprintf(stderr, "bench_observer: --sim %s: %s\n", specs[sp], err.msg);
                            return 1;
                        }
                        csf_cell_estimate est[24];
                        int wrong;
                        if (run_sim_session(methods[m], o, cells, n, n_alt, budgets[b], 1000 + (uint64_t)s,
                                            cmax, est)) {
                            csf_observer_sim_free(o);
                            return 1;
                        }
                        double r = sim_rms(o, cells, n, n_alt, est, cmax, &wrong, bias_sum, bias_n);
                        sum_sq += r * r;
                        for (int c = 0; c < n; c++) { /* per-cell error, for CSF_BENCH_CELLS=1 */
                            double th = csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg);
                            if (!(th < cmax)) continue;
                            double e = (isfinite(est[c].threshold) ? log10(est[c].threshold) : log10(cmax)) - log10(th);
                            cell_e[c] += e, cell_e2[c] += e * e, cell_n[c]++, cell_nt[c] += est[c].n_trials;
                        }
                        wrong_total += wrong;
                        csf_observer_sim_free(o);
                    }
                    char b2[16] = "-", b4[16] = "-";
                    if (bias_n[0]) snprintf(b2, sizeof b2, "%+.3f", bias_sum[0] / bias_n[0]);
                    if (bias_n[1]) snprintf(b4, sizeof b4, "%+.3f", bias_sum[1] / bias_n[1]);
                    printf("| %s | %s | %s | %d | %.3f | %d | %s | %s | %.1f |\n", specs[sp], truth_name[ob],
                           methods[m]->name, budgets[b], sqrt(sum_sq / n_seeds), wrong_total, b2, b4,
                           (now_s() - t0) * 1000.0 / n_seeds);
                    const char *pc = getenv("CSF_BENCH_CELLS");
                    for (int c = 0; c < n && pc && *pc == '1'; c++)
                        if (cell_n[c])
                            printf("    cell %4.1f cpd %4.1f deg: mean %+.3f rms %.3f trials %.1f\n", cells[c].freq_cpd,
                                   cells[c].ecc_deg, cell_e[c] / cell_n[c], sqrt(cell_e2[c] / cell_n[c]),
                                   cell_nt[c] / cell_n[c]);
                    fflush(stdout);
                }
        }
    return 0;
}

/* ---- --honest: one table, tuned vs held-out observers, prior, bayes, QUEST, QUEST+ ----------- */

static const double QUEST_SDS[3] = {0.3, 0.5, 1.0};
enum { HM_PRIOR, HM_BAYES120, HM_BAYES240, HM_QUEST120, HM_QUEST240 = HM_QUEST120 + 3, HM_QPLUS120 = HM_QUEST240 + 3,
       N_HM };

static const char *honest_method_name(int m, char *buf, size_t len)
{
    if (m == HM_PRIOR) snprintf(buf, len, "bayes, prior only");
    else if (m == HM_BAYES120 || m == HM_BAYES240) snprintf(buf, len, "bayes");
    else if (m >= HM_QUEST120 && m < HM_QPLUS120)
        snprintf(buf, len, "QUEST per cell, prior sd %.1f", QUEST_SDS[(m - HM_QUEST120) % 3]);
    else snprintf(buf, len, "QUEST+ joint qCSF x stelaCSF");
    return buf;
}

static int screen_trials; /* CSF_BENCH_SCREEN=N, N >= 2: bayes's 120-trial row runs N trials */

static int honest_trials(int m)
{
    if (m == HM_PRIOR) return 0;
    if (m == HM_BAYES120 && screen_trials) return screen_trials;
    if (m == HM_BAYES120 || m == HM_QPLUS120 || (m >= HM_QUEST120 && m < HM_QUEST240)) return 120;
    return 240;
}

/* An anchor run of the whole budget, answered by the simulated person, contrasts from 0.0005 to
 * cmax. */
static anchor_run budget_run(const csf_cell *cells, int n, const int *n_alt, uint64_t seed, double cmax,
                             anchor_person *person, const int *budget)
{
    return (anchor_run){.cells = cells,
                        .n_cells = n,
                        .n_alt = n_alt,
                        .log10_cmin = log10(0.0005),
                        .log10_cmax = log10(cmax),
                        .seed = seed,
                        .answer = anchor_person_answer,
                        .answer_ctx = person,
                        .checkpoints = budget,
                        .n_checkpoints = 1};
}

/* Per-cell QUEST at a fixed budget (bench/anchor_run.h: allocation, never-visible calls). */
static void run_quest_cells(const csf_observer_sim *o, uint64_t seed, const csf_cell *cells, int n,
                            const int *n_alt, int budget, double sd, double cmax, csf_cell_estimate *est)
{
    double slope, lapse, guess[24], lt[24];
    int trials[24];
    anchor_psychometric(o, &slope, &lapse);
    for (int c = 0; c < n; c++) guess[c] = anchor_static_guess_log10(&cells[c]);
    anchor_person person = {o, seed, cells, n_alt};
    anchor_run r = budget_run(cells, n, n_alt, seed, cmax, &person, &budget);
    anchor_quest_cells(&r, guess, sd, slope, lapse, lt, trials);
    for (int c = 0; c < n; c++) {
        est[c].threshold = isfinite(lt[c]) ? pow(10.0, lt[c]) : INFINITY;
        est[c].n_trials = trials[c];
    }
}

static int run_questplus(const csf_observer_sim *o, uint64_t seed, const csf_cell *cells, int n, const int *n_alt,
                         int budget, double cmax, csf_cell_estimate *est)
{
    double slope, lapse, lt[24];
    anchor_psychometric(o, &slope, &lapse); /* the slope is QUEST+'s own parameter; lapse given */
    questplus *q = questplus_create(cells, n, n_alt, lapse, log10(0.0005), log10(cmax));
    if (!q) return -1;
    anchor_person person = {o, seed, cells, n_alt};
    anchor_run r = budget_run(cells, n, n_alt, seed, cmax, &person, &budget);
    anchor_questplus(&r, q, lt);
    for (int c = 0; c < n; c++) est[c].threshold = isfinite(lt[c]) ? pow(10.0, lt[c]) : INFINITY;
    questplus_free(q);
    return 0;
}

/* The person's P(correct) with m alternatives at d = x - t (log10), as devices/observer_sim
 * answers (lapse runs, fatigue and drift left out). */
static double person_pc(const csf_observer_sim_params *p, int m, double d)
{
    if (p->decision == CSF_SIM_SDT) {
        double guess_share = p->lapse * m / (m - 1);
        return guess_share / m + (1.0 - guess_share) *
                                     csf_psy_sdt_pc_mafc(CSF_SDT_D_AT_T * pow(10.0, p->k_transducer * d), m);
    }
    return csf_psy_p4(d, 0.0, p->slope, 1.0 / m, p->lapse);
}

/* What no per-cell method can beat on average without prior knowledge of the surface: the
 * Cramer-Rao bound for cells measured independently, each trial at its cell's most informative
 * contrast (the display's reach allowing), the person's slope and lapse known, and the budget split
 * over the truly visible cells in the proportions that minimise the mean variance (n_c ~ I_c^-1/2,
 * invisible cells getting none). Mean variance (sum_c I_c^-1/2)^2 / (N n_vis); returns its root.
 * Asymptotic (a handful of trials per cell is not), so a method whose prior knows the surface can
 * go below it, and that is the only way below it. */
static double independent_floor(const csf_observer_sim *o, const csf_cell *cells, int n, const int *n_alt,
                                double cmax, int budget)
{
    const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
    double sum_a = 0.0;
    int n_vis = 0;
    for (int c = 0; c < n; c++) {
        double th = csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg);
        if (!(th < cmax)) continue;
        double d_max = log10(cmax) - log10(th), best = 0.0, h = 1e-4;
        for (double d = -1.5; d <= fmin(d_max, 1.5); d += 0.005) {
            double pc = person_pc(p, n_alt[c], d);
            double dp = (person_pc(p, n_alt[c], d + h) - person_pc(p, n_alt[c], d - h)) / (2.0 * h);
            if (pc > 0.0 && pc < 1.0) best = fmax(best, dp * dp / (pc * (1.0 - pc)));
        }
        if (!(best > 0.0)) continue;
        sum_a += 1.0 / sqrt(best);
        n_vis++;
    }
    return n_vis ? sum_a / sqrt((double)budget * n_vis) : NAN;
}

/* The best the QUEST+ surface family can fit this truth (RMS over visible cells). */
static double questplus_floor(const csf_observer_sim *o, const csf_cell *cells, int n, const int *n_alt, double cmax)
{
    double truth[24];
    questplus *q = questplus_create(cells, n, n_alt, 0.02, log10(0.0005), log10(cmax));
    if (!q) return NAN;
    for (int c = 0; c < n; c++) {
        double th = csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg);
        truth[c] = th < cmax ? log10(th) : log10(cmax);
    }
    double r = questplus_best_fit_rms(q, truth);
    questplus_free(q);
    return r;
}

static int run_honest(const csf_procedure_ops *bayes, int heldout_set, int first_seed, int n_seeds, const csf_cell *cells,
                      int n, const int *n_alt, double cmax, const char *layout_name)
{
    const honest_observer *HONEST = HONEST_SETS[heldout_set - 1].obs;
    const int N_HONEST = HONEST_SETS[heldout_set - 1].n;
    static double sq[MAX_HONEST_OBS][N_HM], ms[N_HM], bias[MAX_HONEST_OBS][2];
    const char *screen_env = getenv("CSF_BENCH_SCREEN");
    int screen = screen_env && atoi(screen_env) >= 1;
    if (screen && atoi(screen_env) >= 2) screen_trials = atoi(screen_env) > 5000 ? 5000 : atoi(screen_env);
    static int bias_n[MAX_HONEST_OBS][2];
    double floor_rms[MAX_HONEST_OBS], cr_floor[MAX_HONEST_OBS];
    memset(sq, 0, sizeof sq);
    memset(ms, 0, sizeof ms);
    memset(bias, 0, sizeof bias);
    memset(bias_n, 0, sizeof bias_n);
    for (int ob = 0; ob < N_HONEST; ob++) {
        floor_rms[ob] = 0.0;
        for (int s = first_seed; s < first_seed + n_seeds; s++) {
            csf_observer_sim *o;
            csf_error err;
            if (csf_observer_sim_create(HONEST[ob].spec, (uint64_t)s, &o, &err) != CSF_OK) {
                fprintf(stderr, "bench_observer: %s: %s\n", HONEST[ob].spec, err.msg);
                return 1;
            }
            if (s == first_seed) {
                floor_rms[ob] = questplus_floor(o, cells, n, n_alt, cmax);
                cr_floor[ob] = independent_floor(o, cells, n, n_alt, cmax, 120);
            }
            for (int m = 0; m < N_HM; m++) {
                if (screen && m != HM_PRIOR && m != HM_BAYES120) continue;
                csf_cell_estimate est[24];
                memset(est, 0, sizeof est);
                double t0 = now_s();
                uint64_t pseed = 1000 + (uint64_t)s;
                int rc = 0;
                if (m == HM_PRIOR) {
                    csf_procedure_setup setup = {.cells = cells, .n_cells = n, .trial_budget = 0, .seed = pseed,
                                                 .max_contrast = cmax, .min_contrast = 0.0005,
                                                 .slope_beta = SESSION_SLOPE, .lapse = SESSION_LAPSE, .guess = 0.5,
                                                 .n_alternatives = n_alt};
                    void *st = NULL;
                    rc = bayes->create(&setup, &st, &err) != CSF_OK || bayes->estimate(st, est, &err) != CSF_OK;
                    if (st) bayes->destroy(st);
                } else if (m == HM_BAYES120 || m == HM_BAYES240) {
                    rc = run_sim_session(bayes, o, cells, n, n_alt, honest_trials(m), pseed, cmax, est);
                } else if (m < HM_QPLUS120) {
                    run_quest_cells(o, pseed, cells, n, n_alt, honest_trials(m), QUEST_SDS[(m - HM_QUEST120) % 3], cmax, est);
                } else {
                    rc = run_questplus(o, pseed, cells, n, n_alt, honest_trials(m), cmax, est);
                }
                if (rc) {
                    fprintf(stderr, "bench_observer: method %d failed on %s\n", m, HONEST[ob].name);
                    csf_observer_sim_free(o);
                    return 1;
                }
                ms[m] += (now_s() - t0) * 1000.0;
                int wrong, bn[2] = {0, 0};
                double bs[2] = {0, 0};
                double r = sim_rms(o, cells, n, n_alt, est, cmax, &wrong, bs, bn);
                sq[ob][m] += r * r;
                if (m == HM_BAYES120)
                    for (int k = 0; k < 2; k++) bias[ob][k] += bs[k], bias_n[ob][k] += bn[k];
            }
            csf_observer_sim_free(o);
        }
        fprintf(stderr, "  %s done\n", HONEST[ob].name);
    }
    printf("\n== layout: %s ==\n", layout_name);
    printf("RMS error of log10 threshold over the truly visible cells (6 x 4 grid), RMS over observers x seeds; "
           "seeds %d-%d; bayes set up as a session (slope %.1f, lapse %.2f); QUEST and QUEST+ given the "
           "observer's own Weibull lapse (and QUEST its slope; sdt observers: slope 1.21 k)\n\n",
           first_seed, first_seed + n_seeds - 1, SESSION_SLOPE, SESSION_LAPSE);
    int n_narrow = 0;
    for (int ob = 0; ob < N_HONEST; ob++) n_narrow += HONEST[ob].held_out && HONEST[ob].narrow;
    printf("| method | trials | tuned-on observers (%d) | held-out observers (%d) | held-out, slope 2-5 & lapse <= 0.05 (%d) "
           "| worst held-out observer | ms/session |\n"
           "|---|---|---|---|---|---|---|\n", 3, N_HONEST - 3, n_narrow);
    double group[N_HM][3];
    for (int m = 0; m < N_HM; m++) {
        double g[3] = {0, 0, 0}, worst = 0;
        int gn[3] = {0, 0, 0};
        for (int ob = 0; ob < N_HONEST; ob++) {
            int h = HONEST[ob].held_out;
            g[h] += sq[ob][m], gn[h] += n_seeds;
            if (h && HONEST[ob].narrow) g[2] += sq[ob][m], gn[2] += n_seeds;
            if (h && sqrt(sq[ob][m] / n_seeds) > worst) worst = sqrt(sq[ob][m] / n_seeds);
        }
        for (int k = 0; k < 3; k++) group[m][k] = gn[k] ? sqrt(g[k] / gn[k]) : NAN;
        char nb[64];
        printf("| %s | %d | %.3f | %.3f | %.3f | %.3f | %.1f |\n", honest_method_name(m, nb, sizeof nb), honest_trials(m),
               group[m][0], group[m][1], group[m][2], worst, ms[m] / (N_HONEST * n_seeds));
    }
    for (int b = 0; b < 2; b++) {
        int first = HM_QUEST120 + 3 * b, best = first;
        for (int m = first; m < first + 3; m++)
            if (group[m][1] < group[best][1]) best = m;
        int bm = b ? HM_BAYES240 : HM_BAYES120;
        printf("best QUEST at %d trials (held-out): prior sd %.1f, %.3f; bayes at %d: %.3f (%s)\n", 120 * (b + 1),
               QUEST_SDS[(best - HM_QUEST120) % 3], group[best][1], 120 * (b + 1), group[bm][1],
               group[bm][1] < group[best][1] ? "bayes better" : "bayes NOT better");
        if (b == 1)
            printf("bayes at 120 vs best QUEST at 240 (held-out): %.3f vs %.3f (%s)\n", group[HM_BAYES120][1],
                   group[best][1], group[HM_BAYES120][1] < group[best][1] ? "bayes better" : "bayes NOT better");
    }
    printf("target bayes 120 <= 0.10, held-out slope 2-5 & lapse <= 0.05, both decision models: %.3f (%s)\n",
           group[HM_BAYES120][2], group[HM_BAYES120][2] <= 0.10 ? "met" : "NOT met");
    printf("target bayes 120 <= 0.12, held-out slope 1.5-6 & lapse <= 0.08 (all held-out): %.3f (%s)\n",
           group[HM_BAYES120][1], group[HM_BAYES120][1] <= 0.12 ? "met" : "NOT met");
    printf("QUEST+ at 120 (held-out): %.3f; bayes at 120: %.3f (%s)\n", group[HM_QPLUS120][1],
           group[HM_BAYES120][1], group[HM_BAYES120][1] < group[HM_QPLUS120][1] ? "bayes better" : "bayes NOT better");
    double cr[3] = {0, 0, 0};
    int crn[3] = {0, 0, 0};
    for (int ob = 0; ob < N_HONEST; ob++) {
        int h = HONEST[ob].held_out;
        cr[h] += cr_floor[ob] * cr_floor[ob], crn[h]++;
        if (h && HONEST[ob].narrow) cr[2] += cr_floor[ob] * cr_floor[ob], crn[2]++;
    }
    printf("independent-cell floor at 120 trials (Cramer-Rao: every cell on its own, slope and lapse known, every "
           "trial at the best contrast; only a prior that knows the surface goes below it): tuned-on %.3f, "
           "held-out %.3f, narrow %.3f\n\n",
           sqrt(cr[0] / crn[0]), sqrt(cr[1] / crn[1]), crn[2] ? sqrt(cr[2] / crn[2]) : NAN);
    printf("per observer (RMS over seeds; * = held out of all tuning; floor = best fit of the QUEST+ surface grid; "
           "CR 120 = the independent-cell floor above)\n\n"
           "| observer | floor | CR 120 | prior | bayes 120 | bayes 120 mean error 2 / 4 places | bayes 240 | QUEST 120 sd .3/.5/1 "
           "| QUEST 240 sd .3/.5/1 | QUEST+ 120 |\n"
           "|---|---|---|---|---|---|---|---|---|---|\n");
    for (int ob = 0; ob < N_HONEST; ob++) {
        double r[N_HM];
        for (int m = 0; m < N_HM; m++) r[m] = sqrt(sq[ob][m] / n_seeds);
        char b2[16] = "-", b4[16] = "-";
        if (bias_n[ob][0]) snprintf(b2, sizeof b2, "%+.3f", bias[ob][0] / bias_n[ob][0]);
        if (bias_n[ob][1]) snprintf(b4, sizeof b4, "%+.3f", bias[ob][1] / bias_n[ob][1]);
        printf("| %s%s | %.3f | %.3f | %.3f | %.3f | %s / %s | %.3f | %.3f/%.3f/%.3f | %.3f/%.3f/%.3f | %.3f |\n",
               HONEST[ob].name, HONEST[ob].held_out ? " *" : "", floor_rms[ob], cr_floor[ob], r[HM_PRIOR], r[HM_BAYES120],
               b2, b4, r[HM_BAYES240],
               r[HM_QUEST120], r[HM_QUEST120 + 1], r[HM_QUEST120 + 2], r[HM_QUEST240], r[HM_QUEST240 + 1],
               r[HM_QUEST240 + 2], r[HM_QPLUS120]);
    }
    fflush(stdout);
    return 0;
}

static int parse_budgets(const char *s, int *b)
{
    int n = 0;
    while (*s && n < MAX_BUDGETS) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 5000) return -1;
        b[n++] = (int)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',') return -1;
    }
    return n;
}

int main(int argc, char **argv)
{
    int n_seeds = 20, budgets[MAX_BUDGETS] = {60, 80, 120, 240, 480}, n_budgets = 5, quest = 0;
    const char *table = "bench/data/observer_bumpy.csv", *methods_arg = "bayes,2afc";
    const char *table2 = "bench/data/observer_mscaled.csv";
    int use_obs[N_OBS] = {1, 1, 1};
    const char *octave = "octave-cli";
    double quest_sd = 1.0; /* QUEST's prior sd (log10) around the guess */
    int first_seed = 1;    /* tuning runs use other seeds than the published table */
    int use_layout[N_LAYOUTS] = {1, 1}; /* [0]: four places off the fovea, [1]: two intervals */
    int per_cell = 0, honest = 0, heldout_set = 1, quick = 0, seeds_given = 0;
    const char *specs[MAX_SPECS];
    int n_specs = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seeds") && i + 1 < argc) {
            n_seeds = atoi(argv[++i]);
            seeds_given = 1;
            if (n_seeds < 1 || n_seeds > 1000) {
                fprintf(stderr, "bench_observer: --seeds must be 1-1000\n");
                return 1;
            }
        } else if (!strcmp(argv[i], "--budgets") && i + 1 < argc) {
            n_budgets = parse_budgets(argv[++i], budgets);
            if (n_budgets < 1) {
                fprintf(stderr, "bench_observer: --budgets wants up to %d numbers 1-5000, comma-separated\n", MAX_BUDGETS);
                return 1;
            }
        } else if (!strcmp(argv[i], "--table") && i + 1 < argc) {
            table = argv[++i];
        } else if (!strcmp(argv[i], "--table2") && i + 1 < argc) {
            table2 = argv[++i];
        } else if (!strcmp(argv[i], "--observers") && i + 1 < argc) {
            const char *o = argv[++i];
            for (int k = 0; k < N_OBS; k++) use_obs[k] = 0;
            for (; *o; o++)
                if (*o >= '0' && *o < '0' + N_OBS) use_obs[*o - '0'] = 1;
        } else if (!strcmp(argv[i], "--layouts") && i + 1 < argc) {
            const char *o = argv[++i];
            use_layout[0] = strchr(o, '4') != NULL;
            use_layout[1] = strchr(o, '2') != NULL;
            if (!use_layout[0] && !use_layout[1]) {
                fprintf(stderr, "bench_observer: --layouts wants 4, 2 or 4,2\n");
                return 1;
            }
        } else if (!strcmp(argv[i], "--methods") && i + 1 < argc) {
            methods_arg = argv[++i];
        } else if (!strcmp(argv[i], "--octave") && i + 1 < argc) {
            octave = argv[++i];
        } else if (!strcmp(argv[i], "--quest-sd") && i + 1 < argc) {
            quest_sd = atof(argv[++i]);
            if (!(quest_sd >= 0.05 && quest_sd <= 5.0)) {
                fprintf(stderr, "bench_observer: --quest-sd must be 0.05-5 log10 units\n");
                return 1;
            }
        } else if (!strcmp(argv[i], "--first-seed") && i + 1 < argc) {
            first_seed = atoi(argv[++i]);
            if (first_seed < 1 || first_seed > 1000000) {
                fprintf(stderr, "bench_observer: --first-seed must be 1-1000000\n");
                return 1;
            }
        } else if (!strcmp(argv[i], "--sim") && i + 1 < argc) {
            if (n_specs == MAX_SPECS) {
                fprintf(stderr, "bench_observer: at most %d --sim observers\n", MAX_SPECS);
                return 1;
            }
            specs[n_specs++] = argv[++i];
        } else if (!strcmp(argv[i], "--honest")) {
            honest = 1;
        } else if (!strcmp(argv[i], "--quick")) {
            quick = 1;
        } else if (!strcmp(argv[i], "--fresh")) {
            honest = 1, heldout_set = 2;
        } else if (!strcmp(argv[i], "--heldout") && i + 1 < argc) {
            heldout_set = atoi(argv[++i]);
            if (heldout_set < 1 || heldout_set > N_HONEST_SETS) {
                fprintf(stderr, "bench_observer: --heldout takes 1 to %d\n", (int)N_HONEST_SETS);
                return 1;
            }
            honest = 1;
        } else if (!strcmp(argv[i], "--cells")) {
            per_cell = 1;
        } else if (!strcmp(argv[i], "--quest")) {
            quest = 1;
        } else {
            fprintf(stderr, "usage: bench_observer [--seeds N] [--budgets 60,80,120,240,480] "
                            "[--table CSV] [--table2 CSV] [--observers 0,1,2] [--quest] [--quest-sd SD] "
                            "[--methods bayes,2afc] [--octave PATH] [--first-seed N] [--layouts 4,2] "
                            "[--cells] [--sim SPEC ...] [--honest [--fresh | --heldout 1-19] [--quick]]\n");
            return !!strcmp(argv[i], "--help");
        }
    }
    const csf_procedure_ops *methods[MAX_METHODS];
    int n_methods = 0;
    char mbuf[256];
    snprintf(mbuf, sizeof mbuf, "%s", methods_arg);
    for (char *tok = strtok(mbuf, ","); tok && n_methods < MAX_METHODS; tok = strtok(NULL, ",")) {
        const csf_procedure_ops *ops = csf_procedure_find(tok);
        if (!ops) {
            fprintf(stderr, "bench_observer: no method '%s' in this build (skipped)\n", tok);
        } else if (ops->task != CSF_TASK_2AFC) {
            fprintf(stderr, "bench_observer: method '%s' is not 2AFC; this bench's observer answers 2AFC only (skipped)\n", tok);
        } else {
            methods[n_methods++] = ops;
        }
    }
    csf_cell cells[24];
    int n = sim2afc_default_grid(cells);
    const double cmax = 1.0;
    const char *obs_name[N_OBS] = {"parametric (default CSF model)", "table (bench/data bumpy)",
                                   "table (bench/data mscaled: Barten x Rovamo-Virsu M(e))"};
    sim2afc probe[N_OBS];
    sim2afc_parametric(&probe[0], csf_model_default(), 0);
    if (sim2afc_table(&probe[1], table, 0) != 0) return 1;
    if (sim2afc_table(&probe[2], table2, 0) != 0) return 1;

    const char *layout_name[N_LAYOUTS] = {"four places off the fovea (session default on the default station), two intervals at the fovea",
                                          "two intervals in every cell (2IFC)"};
    for (int ly = 0; ly < N_LAYOUTS; ly++) {
        if (!use_layout[ly]) continue;
        int n_alt[24]; /* on the default station of a session */
        if (sim2afc_default_layouts(cells, n, ly == 0 ? 4 : 2, n_alt)) return 1;
        if (honest) {
            const csf_procedure_ops *bayes = csf_procedure_find("bayes");
            if (!bayes) {
                fprintf(stderr, "bench_observer: --honest needs the bayes method\n");
                return 1;
            }
            if (run_honest(bayes, heldout_set, first_seed, seeds_given ? n_seeds : quick ? 3 : 10, cells, n, n_alt, cmax, layout_name[ly])) return 1;
            continue;
        }
        if (n_specs > 0) {
            printf("\n== layout: %s ==\n", layout_name[ly]);
            printf("observers that are not the method: devices/observer_sim answers, methods set up as a "
                   "session (slope %.1f, lapse %.2f); RMS of log10 threshold over visible cells, "
                   "seeds %d-%d\n\n", SESSION_SLOPE, SESSION_LAPSE, first_seed, first_seed + n_seeds - 1);
            if (run_specs(specs, n_specs, use_obs, table, table2, methods, n_methods, budgets, n_budgets,
                          first_seed, n_seeds, cells, n, n_alt, cmax))
                return 1;
            continue;
        }
        double rms[N_OBS][MAX_METHODS][MAX_BUDGETS], ms_per_session[N_OBS][MAX_METHODS][MAX_BUDGETS];
        int wrong_vis[N_OBS][MAX_METHODS][MAX_BUDGETS];
        for (int ob = 0; ob < N_OBS; ob++)
            for (int m = 0; m < n_methods && use_obs[ob]; m++)
                for (int b = 0; b < n_budgets; b++) {
                    double sum_sq = 0.0, t0 = now_s();
                    double cell_err[24] = {0}, cell_sq[24] = {0}, cell_trials[24] = {0};
                    int wrong_total = 0;
                    for (int s = first_seed; s < first_seed + n_seeds; s++) {
                        sim2afc o = probe[ob];
                        o.seed = (uint64_t)s;
                        csf_cell_estimate est[24];
                        if (sim2afc_run_alt(methods[m], &o, cells, n, n_alt, budgets[b], 1000 + (uint64_t)s, cmax, est))
                            return 1;
                        int wrong;
                        double r = sim2afc_rms(&o, cells, n, est, cmax, &wrong);
                        sum_sq += r * r;
                        wrong_total += wrong;
                        for (int c = 0; c < n && per_cell; c++) {
                            double t = sim2afc_log10_threshold(&o, cells[c].freq_cpd, cells[c].ecc_deg);
                            double e = isfinite(est[c].threshold) ? log10(est[c].threshold) : log10(cmax);
                            cell_err[c] += e - t, cell_sq[c] += (e - t) * (e - t);
                            cell_trials[c] += est[c].n_trials;
                        }
                    }
                    if (per_cell) {
                        printf("per cell: layout %d, observer %d, %s, %d trials, %d seeds (invisible cells: -)\n",
                               ly == 0 ? 4 : 2, ob, methods[m]->name, budgets[b], n_seeds);
                        for (int c = 0; c < n; c++) {
                            double t = sim2afc_log10_threshold(&probe[ob], cells[c].freq_cpd, cells[c].ecc_deg);
                            if (t >= log10(cmax))
                                printf("  %5.2f cpd %4.1f deg  -\n", cells[c].freq_cpd, cells[c].ecc_deg);
                            else
                                printf("  %5.2f cpd %4.1f deg  truth %+.3f  bias %+.3f  RMS %.3f  trials %4.1f  (%d places)\n",
                                       cells[c].freq_cpd, cells[c].ecc_deg, t, cell_err[c] / n_seeds,
                                       sqrt(cell_sq[c] / n_seeds), cell_trials[c] / n_seeds, n_alt[c]);
                        }
                    }
                    rms[ob][m][b] = sqrt(sum_sq / n_seeds);
                    ms_per_session[ob][m][b] = (now_s() - t0) * 1000.0 / n_seeds;
                    wrong_vis[ob][m][b] = wrong_total;
                }

        double qrms[N_OBS][MAX_BUDGETS];
        int have_quest = 0;
        if (quest) {
            char truth_path[] = "/tmp/bench_observer_truth_XXXXXX";
            int fd = mkstemp(truth_path);
            FILE *tf = fd >= 0 ? fdopen(fd, "w") : NULL;
            if (!tf) {
                fprintf(stderr, "bench_observer: cannot write a temporary file for QUEST\n");
                return 1;
            }
            fprintf(tf, "#params,%g,%g,%g,%g,%g,%d", probe[0].slope, probe[0].lapse, log10(cmax), log10(0.0005),
                    quest_sd, n_seeds);
            for (int b = 0; b < n_budgets; b++) fprintf(tf, ",%d", budgets[b]);
            fprintf(tf, "\n");
            for (int ob = 0; ob < N_OBS; ob++)
                for (int c = 0; c < n && use_obs[ob]; c++) {
                    double t = sim2afc_log10_threshold(&probe[ob], cells[c].freq_cpd, cells[c].ecc_deg);
                    fprintf(tf, "%d,%d,%.6f,%.6f,%d,%d\n", ob, c, t, anchor_static_guess_log10(&cells[c]),
                            t < log10(cmax), n_alt[c]);
                }
            fclose(tf);
            char out_path[64], cmd[512];
            snprintf(out_path, sizeof out_path, "%s.out", truth_path);
            snprintf(cmd, sizeof cmd, "%s -q bench/quest/run_quest.m %s %s 2>/dev/null", octave, truth_path, out_path);
            double t0 = now_s();
            int rc = system(cmd);
            FILE *of = fopen(out_path, "r");
            if (!of) {
                fprintf(stderr, "bench_observer: QUEST run failed (exit %d): is octave-psychtoolbox-3 installed? "
                                "See docs/bayes-method.md\n", rc);
            } else {
                int ob, bud;
                double r;
                for (int ob2 = 0; ob2 < N_OBS; ob2++)
                    for (int b = 0; b < n_budgets; b++) qrms[ob2][b] = NAN;
                while (fscanf(of, "%d,%d,%lf", &ob, &bud, &r) == 3)
                    for (int b = 0; b < n_budgets; b++)
                        if (ob >= 0 && ob < N_OBS && budgets[b] == bud) qrms[ob][b] = r;
                fclose(of);
                have_quest = 1;
                printf("QUEST (octave) ran in %.1f s\n", now_s() - t0);
            }
            remove(truth_path);
            remove(out_path);
        }

        printf("\n== layout: %s ==\n", layout_name[ly]);
        printf("RMS error of log10 threshold over visible cells, default 6x4 grid, %d seeds per entry\n", n_seeds);
        printf("(forced choice, Weibull slope %.1f, lapse %.2f, max contrast %.2f; wrong = cells with the wrong "
               "visibility, summed over seeds)\n\n", probe[0].slope, probe[0].lapse, cmax);
        for (int ob = 0; ob < N_OBS; ob++) {
            if (!use_obs[ob]) continue;
            printf("observer: %s\n", obs_name[ob]);
            printf("| trials |");
            for (int m = 0; m < n_methods; m++) printf(" %-6s RMS | wrong | ms/session |", methods[m]->name);
            if (have_quest) printf(" QUEST RMS (sd %.1f) |", quest_sd);
            printf("\n|---|");
            for (int m = 0; m < n_methods; m++) printf("---|---|---|");
            if (have_quest) printf("---|");
            printf("\n");
            for (int b = 0; b < n_budgets; b++) {
                printf("| %6d |", budgets[b]);
                for (int m = 0; m < n_methods; m++)
                    printf(" %10.3f | %5d | %10.1f |", rms[ob][m][b], wrong_vis[ob][m][b], ms_per_session[ob][m][b]);
                if (have_quest) printf(" %18.3f |", qrms[ob][b]);
                printf("\n");
            }
            if (have_quest && n_methods > 0 && !strcmp(methods[0]->name, "bayes")) {
                /* fewest trials at which bayes is at least as accurate as QUEST at 240 trials
                 * (log-linear interpolation between the measured budgets) */
                int b240 = -1;
                for (int b = 0; b < n_budgets; b++)
                    if (budgets[b] == 240) b240 = b;
                if (b240 >= 0) {
                    double target = qrms[ob][b240], need = NAN;
                    for (int b = 0; b < n_budgets; b++) {
                        if (rms[ob][0][b] <= target) {
                            if (b == 0) need = budgets[0];
                            else {
                                double r0 = rms[ob][0][b - 1], r1 = rms[ob][0][b];
                                double a = (r0 - target) / (r0 - r1);
                                need = pow(10.0, log10(budgets[b - 1]) + a * (log10(budgets[b]) - log10(budgets[b - 1])));
                            }
                            break;
                        }
                    }
                    if (need == budgets[0])
                        printf("bayes reaches QUEST's 240-trial RMS (%.3f) at %d trials or fewer (the smallest budget run)\n",
                               target, budgets[0]);
                    else
                        printf("bayes reaches QUEST's 240-trial RMS (%.3f) at about %.0f trials\n", target, need);
                }
            }
            printf("\n");
        }
    }
    return 0;
}
