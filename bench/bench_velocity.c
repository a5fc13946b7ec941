/* Velocity calibration accuracy: RMS error of log10 threshold over the cells a 120 Hz station can
 * show (6 frequencies 0.5-16 cpd x 0, 5, 10, 20 deg x 0, 4, 12 deg/s; f v >= refresh / 2 cannot be
 * drawn and is not scored; nor is a cell the person never sees), against held-out simulated people
 * whose motion shapes were built from measurements, not from the prior's formula
 * (bench/data/velocity/README.md). Side by side at equal trials:
 *   - bayes through a whole session (calib/observer_calib.h, vels_dps), set up as a session sets
 *     it up: not told the person's slope or lapse;
 *   - QUEST per cell (bench/quest_cell.h), told the person's own slope and lapse, its guess the
 *     static prior-mean surface times the published Kelly-Daly gain, the best of three prior sds
 *     picked per budget on these people (favours QUEST);
 *   - joint QUEST+ over a static surface x Kelly-Daly gain with two free knobs
 *     (bench/questplus_v.h), told the person's lapse.
 * Usage: bench_velocity [--seeds N] [--first-seed N] [--budgets 240,360,480] [--observers 0,1,..]
 *                       [--methods bayes,bayesproc,quest,qplus] [--refresh HZ]; run from the source root. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "calib/observer_calib.h"
#include "calib/procedure.h"
#include "cli/config.h"
#include "model/csf_model.h"
#include "model/csf_velocity.h"
#include "model/observer_sim.h"
#include "anchor_run.h"
#include "questplus_v.h"
#include "results/csflut/csflut.h"
#include "tests/bayes/sim_2afc.h"

enum { N_F = 6, N_E = 4, N_V = 3, MAX_CELLS = N_F * N_E * N_V, MAX_BUDGETS = 4, MAX_SEEDS = 64 };
enum { M_BAYES, M_BAYESP, M_QUEST, M_QPLUS, N_METHODS };
static const double FREQS[N_F] = {0.5, 1, 2, 4, 8, 16}, ECCS[N_E] = {0, 5, 10, 20}, VELS[N_V] = {0, 4, 12};
static const double QUEST_SDS[3] = {0.3, 0.5, 1.0};
#define CMAX 1.0
#define CMIN 0.0005

typedef struct {
    const char *name, *spec;
} vel_observer;

/* bench/data/velocity/make_velocity.py prints these lines */
static const vel_observer VEL_OBSERVERS[] = {
    {"robson/robson66, Weibull 4.06/0.008",
     "sim:slope=4.056,lapse=0.008,table=bench/data/velocity/observer_v_robson.csv"},
    {"older/robson66, sdt k 1.27/0.008",
     "sim:decision=sdt,k=1.272,lapse=0.008,table=bench/data/velocity/observer_v_older.csv"},
    {"mkgp/tolhurst73, Weibull 3.34/0.022",
     "sim:slope=3.343,lapse=0.022,table=bench/data/velocity/observer_v_mkgp.csv"},
    {"virsu/tolhurst73, sdt k 1.30/0.059",
     "sim:decision=sdt,k=1.305,lapse=0.059,table=bench/data/velocity/observer_v_virsu.csv"},
    {"mesopic/robson66, Weibull 4.27/0.028",
     "sim:slope=4.269,lapse=0.028,table=bench/data/velocity/observer_v_mesopic.csv"},
    {"dog/tolhurst73, sdt k 1.96/0.038",
     "sim:decision=sdt,k=1.958,lapse=0.038,table=bench/data/velocity/observer_v_dog.csv"},
    {"mansak/robson66, Weibull 4.36/0.061",
     "sim:slope=4.362,lapse=0.061,table=bench/data/velocity/observer_v_mansak.csv"},
};
enum { N_OBS = sizeof VEL_OBSERVERS / sizeof VEL_OBSERVERS[0] };

typedef struct {
    int n_seeds, first_seed, n_budgets, budgets[MAX_BUDGETS], use_obs[N_OBS], use_method[N_METHODS];
    double refresh_hz;
} bench_opts;

/* One (observer, seed) run: RMS per method, budget (and sd, for QUEST); bayes's person time. */
typedef struct {
    double rms[N_METHODS][3][MAX_BUDGETS];
    double person_s[MAX_BUDGETS], session_wall_s[MAX_BUDGETS];
    int bayes_failed[MAX_BUDGETS];
} run_result;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* The grid's cells a station at refresh_hz can show (temporal frequency below refresh / 2). */
static int showable_cells(double refresh_hz, csf_cell *cells)
{
    int n = 0;
    for (int v = 0; v < N_V; v++)
        for (int e = 0; e < N_E; e++)
            for (int f = 0; f < N_F; f++)
                if (csf_velocity_temporal_hz(FREQS[f], VELS[v]) < refresh_hz / 2.0)
                    cells[n++] =
                        (csf_cell){.freq_cpd = FREQS[f], .ecc_deg = ECCS[e], .velocity_dps = VELS[v]};
    return n;
}

/* RMS of log10 error over the cells the person sees (est INFINITY counts as log10 CMAX). */
static double rms_error(const csf_observer_sim *o, const csf_cell *cells, int n, const double *est_log10)
{
    double se = 0.0;
    int k = 0;
    for (int c = 0; c < n; c++) {
        double th =
            csf_observer_sim_threshold_v(o, cells[c].freq_cpd, cells[c].ecc_deg, cells[c].velocity_dps);
        if (!(th < CMAX)) continue;
        double e = isfinite(est_log10[c]) ? fmin(est_log10[c], log10(CMAX)) : log10(CMAX);
        se += (e - log10(th)) * (e - log10(th)), k++;
    }
    return k ? sqrt(se / k) : NAN;
}

/* ---- bayes: a whole session ------------------------------------------------------------------ */

static int read_table(const char *path, const csf_cell *cells, int n, double *est_log10)
{
    csflut_table *t = NULL;
    if (csflut_open_file(path, &t) != CSFLUT_OK) return -1;
    if (csflut_axis_size(t, CSFLUT_AXIS_VEL) < N_V) {
        fprintf(stderr,
                "bench_velocity: the session wrote %s without a velocity axis (%d velocity nodes): this "
                "build's sessions do not drift the gratings; run with --methods bayesproc,quest,qplus\n",
                path, csflut_axis_size(t, CSFLUT_AXIS_VEL));
        csflut_close(t);
        return -1;
    }
    csflut_set_conservative(t, 0);
    for (int c = 0; c < n; c++) {
        double th = csflut_threshold4(t, cells[c].freq_cpd, cells[c].ecc_deg, cells[c].velocity_dps, NAN);
        est_log10[c] = isfinite(th) && th < CMAX ? log10(th) : INFINITY;
    }
    csflut_close(t);
    return 0;
}

/* Runs one session; est_log10 = the table at the cells (all INFINITY when the session wrote no
 * table). Returns 0, 1 = no table (CSF_E_INSUFFICIENT), -1 = the session failed. */
static int run_bayes(const char *spec, uint64_t seed, int trials, double refresh_hz, const csf_cell *cells,
                     int n, double *est_log10, double *person_s, double *wall_s)
{
    char dir[] = "/tmp/bench_velocity_XXXXXX", out[256], store[256];
    if (!mkdtemp(dir)) return -1;
    snprintf(out, sizeof out, "%s/t.csflut", dir);
    snprintf(store, sizeof store, "%s/s.sqlite", dir);
    csf_config cfg;
    csf_config_defaults(&cfg);
    cfg.refresh_hz = refresh_hz;
    csf_obs_options opt;
    csf_obs_options_defaults(&opt);
    opt.cfg = &cfg, opt.observer_spec = spec, opt.method = "bayes", opt.out_path = out,
    opt.store_path = store;
    memcpy(opt.freqs_cpd, FREQS, sizeof FREQS), opt.n_freqs = N_F;
    memcpy(opt.eccs_deg, ECCS, sizeof ECCS), opt.n_eccs = N_E;
    memcpy(opt.vels_dps, VELS, sizeof VELS), opt.n_vels = N_V;
    opt.trials = trials, opt.seed = seed, opt.headless = 1, opt.quiet = 1;
    csf_obs_result res;
    csf_error err = {0};
    csf_status st = csf_observer_calibrate(&opt, &res, &err);
    int rc = st == CSF_OK ? 0 : st == CSF_E_INSUFFICIENT ? 1 : -1;
    if (rc < 0)
        fprintf(stderr, "bench_velocity: bayes session (%s, seed %llu): %s\n", spec, (unsigned long long)seed,
                err.msg);
    for (int c = 0; c < n; c++) est_log10[c] = INFINITY;
    if (rc == 0 && read_table(out, cells, n, est_log10)) rc = -1;
    *person_s = rc >= 0 ? res.person_s : NAN; /* the session's clock, first trial to last */
    *wall_s = res.wall_s;
    remove(out), remove(store);
    char side[300];
    snprintf(side, sizeof side, "%s-wal", store), remove(side);
    snprintf(side, sizeof side, "%s-shm", store), remove(side);
    rmdir(dir);
    return rc;
}

/* ---- bayes through the procedure interface (what a session drives), the whole grid ---------- */

/* The bayes method on the full 6 x 4 x 3 grid, the unshowable cells marked not shown (a session
 * does the same), set up as a session sets it up (slope 3.5, lapse 0.02); answers from the
 * person's _v trial functions; est_log10 at the showable cells. */
static int run_bayes_proc(const csf_observer_sim *o, uint64_t seed, int budget, double refresh_hz,
                          const csf_cell *cells, int n, double *est_log10)
{
    csf_cell all[MAX_CELLS];
    unsigned char not_shown[MAX_CELLS];
    int n_alt[MAX_CELLS], n_all = 0;
    for (int v = 0; v < N_V; v++)
        for (int e = 0; e < N_E; e++)
            for (int f = 0; f < N_F; f++) {
                all[n_all] = (csf_cell){.freq_cpd = FREQS[f], .ecc_deg = ECCS[e], .velocity_dps = VELS[v]};
                not_shown[n_all++] = csf_velocity_temporal_hz(FREQS[f], VELS[v]) >= refresh_hz / 2.0;
            }
    if (sim2afc_default_layouts(all, n_all, 4, n_alt)) return -1;
    const csf_procedure_ops *ops = csf_procedure_find("bayes");
    csf_procedure_setup setup = {.cells = all,
                                 .n_cells = n_all,
                                 .trial_budget = budget,
                                 .seed = seed,
                                 .max_contrast = CMAX,
                                 .min_contrast = CMIN,
                                 .slope_beta = 3.5,
                                 .lapse = 0.02,
                                 .guess = 0.5,
                                 .n_alternatives = n_alt,
                                 .not_shown = not_shown};
    csf_error err = {0};
    void *st = NULL;
    if (!ops || ops->create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "bench_velocity: bayes: %s\n", ops ? err.msg : "not in this build");
        return -1;
    }
    for (int k = 0; k < budget; k++) {
        csf_trial_plan plan;
        if (ops->next(st, k, &plan) != CSF_OK) break;
        const csf_cell *c = &all[plan.cell];
        int m = plan.n_alternatives == 4 ? 4 : 2;
        double shown[4] = {0, 0, 0, 0}, rt;
        shown[plan.signal_interval] = plan.contrast;
        csf_trial_outcome out = {.rt_s = 0.6, .contrast_at_response = plan.contrast, .valid = 1};
        out.response = m == 4 ? csf_observer_sim_afc_v(o, (uint64_t)k, c->freq_cpd, c->ecc_deg,
                                                       c->velocity_dps, shown, 4, &rt)
                              : csf_observer_sim_2afc_v(o, (uint64_t)k, c->freq_cpd, c->ecc_deg,
                                                        c->velocity_dps, shown, &rt);
        ops->update(st, k, &plan, &out);
    }
    csf_cell_estimate est[MAX_CELLS];
    csf_status rc = ops->estimate(st, est, &err);
    ops->destroy(st);
    if (rc != CSF_OK) return fprintf(stderr, "bench_velocity: bayes estimate: %s\n", err.msg), -1;
    for (int c = 0, a = 0; c < n; c++) {
        while (a < n_all && (all[a].freq_cpd != cells[c].freq_cpd || all[a].ecc_deg != cells[c].ecc_deg ||
                             all[a].velocity_dps != cells[c].velocity_dps))
            a++;
        est_log10[c] = a < n_all && isfinite(est[a].threshold) && est[a].threshold < CMAX
                           ? log10(est[a].threshold)
                           : INFINITY;
    }
    return 0;
}

/* ---- the anchors ----------------------------------------------------------------------------- */

/* Population knowledge QUEST starts from: the bayes prior's mean static surface (as
 * bench_observer) times the published Kelly-Daly gain. */
static double guess_log10(const csf_cell *c)
{
    csf_model_params p = {.smax = pow(10.0, 2.25),
                          .fmax_cpd = pow(10.0, 0.45),
                          .beta_oct = 3.0,
                          .delta_log10 = 0.5,
                          .ecc_a = 0.03,
                          .ecc_b = 0.02};
    csf_velocity_params vp = csf_velocity_default();
    double t = -csf_model_log10_sensitivity(&p, c->freq_cpd, c->ecc_deg) -
               csf_velocity_log10_gain(&vp, c->freq_cpd, c->velocity_dps);
    return t > 0.0 ? 0.0 : t;
}

/* Scores a run at each of the bench's budgets (anchor_check_fn): RMS into rms[budget index]. */
typedef struct {
    const csf_observer_sim *o;
    const csf_cell *cells;
    int n, bi;
    double *rms;
} budget_scores;

static int score_budget(void *ctx, int trials, const double *est_log10)
{
    budget_scores *sc = ctx;
    (void)trials;
    sc->rms[sc->bi++] = rms_error(sc->o, sc->cells, sc->n, est_log10);
    return 0;
}

/* Per-cell QUEST (bench/anchor_run.h) with prior sd `sd`, scored at every budget on the way to the
 * largest. */
static void run_quest(const csf_observer_sim *o, uint64_t seed, const csf_cell *cells, int n,
                      const int *n_alt, double sd, const bench_opts *b, double *rms)
{
    double slope, lapse, guess[MAX_CELLS], est[MAX_CELLS];
    anchor_psychometric(o, &slope, &lapse);
    for (int c = 0; c < n; c++) guess[c] = guess_log10(&cells[c]);
    anchor_person person = {o, seed, cells, n_alt};
    budget_scores sc = {o, cells, n, 0, rms};
    anchor_run r = {cells,   n,          n_alt,        log10(CMIN),  log10(CMAX), seed, anchor_person_answer,
                    &person, b->budgets, b->n_budgets, score_budget, &sc};
    anchor_quest_cells(&r, guess, sd, slope, lapse, est, NULL);
}

/* Joint QUEST+ over the spatio-velocity family, scored at every budget. */
static int run_qplus(const csf_observer_sim *o, uint64_t seed, const csf_cell *cells, int n, const int *n_alt,
                     const bench_opts *b, double *rms)
{
    double slope, lapse, est[MAX_CELLS];
    anchor_psychometric(o, &slope, &lapse); /* the slope is QUEST+'s own parameter; lapse given */
    questplus *q = questplus_v_create(cells, n, n_alt, lapse, log10(CMIN), log10(CMAX));
    if (!q) return -1;
    anchor_person person = {o, seed, cells, n_alt};
    budget_scores sc = {o, cells, n, 0, rms};
    anchor_run r = {cells,   n,          n_alt,        log10(CMIN),  log10(CMAX), seed, anchor_person_answer,
                    &person, b->budgets, b->n_budgets, score_budget, &sc};
    anchor_questplus(&r, q, est);
    questplus_free(q);
    return 0;
}

/* The best the QUEST+ family can fit this person (its floor at any budget). */
static double qplus_floor(const csf_observer_sim *o, const csf_cell *cells, int n, const int *n_alt)
{
    double truth[MAX_CELLS];
    questplus *q = questplus_v_create(cells, n, n_alt, 0.02, log10(CMIN), log10(CMAX));
    if (!q) return NAN;
    for (int c = 0; c < n; c++) {
        double th =
            csf_observer_sim_threshold_v(o, cells[c].freq_cpd, cells[c].ecc_deg, cells[c].velocity_dps);
        truth[c] = th < CMAX ? log10(th) : INFINITY;
    }
    double r = questplus_best_fit_rms(q, truth);
    questplus_free(q);
    return r;
}

/* Diagnosis (CSF_BENCH_CELLS=1): every scored cell's truth and estimate (log10), on stderr. */
static void print_cells(const csf_observer_sim *o, const csf_cell *cells, int n, const double *est_log10,
                        const char *method, int trials)
{
    const char *env = getenv("CSF_BENCH_CELLS");
    if (!env || *env != '1') return;
    for (int c = 0; c < n; c++) {
        double th =
            csf_observer_sim_threshold_v(o, cells[c].freq_cpd, cells[c].ecc_deg, cells[c].velocity_dps);
        fprintf(stderr, "cell %s %d: %5.2f cpd %4.1f deg %4.1f deg/s truth %+.3f est %+.3f\n", method, trials,
                cells[c].freq_cpd, cells[c].ecc_deg, cells[c].velocity_dps, th < CMAX ? log10(th) : INFINITY,
                est_log10[c]);
    }
}

/* ---- one person, one seed; the tables --------------------------------------------------------- */

static int run_one(int ob, int s, const bench_opts *b, const csf_cell *cells, int n, const int *n_alt,
                   run_result *r)
{
    csf_observer_sim *o;
    csf_error err;
    if (csf_observer_sim_create(VEL_OBSERVERS[ob].spec, (uint64_t)s, &o, &err) != CSF_OK) {
        fprintf(stderr, "bench_velocity: %s: %s\n", VEL_OBSERVERS[ob].spec, err.msg);
        return -1;
    }
    uint64_t pseed = 1000 + (uint64_t)s;
    int rc = 0;
    for (int bi = 0; bi < b->n_budgets && b->use_method[M_BAYES] && rc >= 0; bi++) {
        double est[MAX_CELLS];
        rc = run_bayes(VEL_OBSERVERS[ob].spec, pseed, b->budgets[bi], b->refresh_hz, cells, n, est,
                       &r->person_s[bi], &r->session_wall_s[bi]);
        r->bayes_failed[bi] = rc != 0;
        r->rms[M_BAYES][0][bi] = rms_error(o, cells, n, est);
        print_cells(o, cells, n, est, "bayes", b->budgets[bi]);
    }
    for (int bi = 0; bi < b->n_budgets && b->use_method[M_BAYESP] && rc >= 0; bi++) {
        double est[MAX_CELLS];
        rc = run_bayes_proc(o, pseed, b->budgets[bi], b->refresh_hz, cells, n, est);
        r->rms[M_BAYESP][0][bi] = rms_error(o, cells, n, est);
        print_cells(o, cells, n, est, "bayesproc", b->budgets[bi]);
    }
    for (int k = 0; k < 3 && b->use_method[M_QUEST]; k++)
        run_quest(o, pseed, cells, n, n_alt, QUEST_SDS[k], b, r->rms[M_QUEST][k]);
    if (rc >= 0 && b->use_method[M_QPLUS]) rc = run_qplus(o, pseed, cells, n, n_alt, b, r->rms[M_QPLUS][0]);
    csf_observer_sim_free(o);
    /* one line per figure on stderr, so that runs split over processes can be pooled (none from a
     * run that failed or was interrupted: its figures are not measurements) */
    for (int m = 0; m < N_METHODS && rc >= 0; m++)
        for (int k = 0; k < (m == M_QUEST ? 3 : 1) && b->use_method[m]; k++)
            for (int bi = 0; bi < b->n_budgets; bi++)
                fprintf(stderr, "raw observer %d seed %d method %d sd %d trials %d rms %.5f person_s %.1f\n",
                        ob, s, m, k, b->budgets[bi], r->rms[m][k][bi], m == M_BAYES ? r->person_s[bi] : NAN);
    return rc < 0 ? -1 : 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Per budget: the QUEST prior sd with the smallest RMS over every person and seed (favours QUEST). */
static void best_quest_sd(const run_result (*res)[MAX_SEEDS], const bench_opts *b, int *best)
{
    for (int bi = 0; bi < b->n_budgets; bi++) {
        double best_ss = INFINITY;
        for (int k = 0; k < 3; k++) {
            double ss = 0.0;
            for (int ob = 0; ob < N_OBS; ob++)
                for (int s = 0; s < b->n_seeds && b->use_obs[ob]; s++)
                    ss += pow(res[ob][s].rms[M_QUEST][k][bi], 2);
            if (ss < best_ss) best_ss = ss, best[bi] = k;
        }
    }
}

/* RMS over people x seeds and median of the per-person medians, per method and budget. */
static void group_figures(const run_result (*res)[MAX_SEEDS], const bench_opts *b, const int *qsd,
                          double g[N_METHODS][MAX_BUDGETS], double gmed[N_METHODS][MAX_BUDGETS])
{
    for (int m = 0; m < N_METHODS; m++)
        for (int bi = 0; bi < b->n_budgets; bi++) {
            double ss = 0.0, meds[N_OBS], v[MAX_SEEDS];
            int k = m == M_QUEST ? qsd[bi] : 0, n = 0, nm = 0;
            for (int ob = 0; ob < N_OBS; ob++) {
                if (!b->use_obs[ob]) continue;
                for (int s = 0; s < b->n_seeds; s++) v[s] = res[ob][s].rms[m][k][bi], ss += v[s] * v[s], n++;
                meds[nm++] = median(v, b->n_seeds);
            }
            g[m][bi] = n ? sqrt(ss / n) : NAN;
            gmed[m][bi] = nm ? median(meds, nm) : NAN;
        }
}

static const char *const METHOD_NAMES[N_METHODS] = {"bayes (session)", "bayes (procedure)", "QUEST per cell",
                                                    "QUEST+ static x Kelly-Daly(c2, steepness)"};

/* The bayes row the target is judged on: the session when it ran, else the procedure. */
static int judged_bayes(const bench_opts *b)
{
    return b->use_method[M_BAYES] ? M_BAYES : M_BAYESP;
}

static void print_person_table(const run_result (*res)[MAX_SEEDS], const bench_opts *b, const int *qsd,
                               const double *floor_rms)
{
    int mb = judged_bayes(b);
    printf("| person (static / motion shape, psychometric) | QUEST+ floor |");
    for (int bi = 0; bi < b->n_budgets; bi++)
        printf(" %s / QUEST / QUEST+ %d | bayes person s %d |", METHOD_NAMES[mb], b->budgets[bi],
               b->budgets[bi]);
    printf("\n|---|---|");
    for (int bi = 0; bi < b->n_budgets; bi++) printf("---|---|");
    printf("\n");
    for (int ob = 0; ob < N_OBS; ob++) {
        if (!b->use_obs[ob]) continue;
        printf("| %s | %.3f |", VEL_OBSERVERS[ob].name, floor_rms[ob]);
        for (int bi = 0; bi < b->n_budgets; bi++) {
            double v[N_METHODS][MAX_SEEDS], ps[MAX_SEEDS];
            int fails = 0;
            for (int s = 0; s < b->n_seeds; s++) {
                for (int m = 0; m < N_METHODS; m++)
                    v[m][s] = res[ob][s].rms[m][m == M_QUEST ? qsd[bi] : 0][bi];
                ps[s] = res[ob][s].person_s[bi];
                fails += res[ob][s].bayes_failed[bi];
            }
            int shown[3] = {mb, M_QUEST, M_QPLUS};
            for (int k = 0; k < 3; k++) {
                if (b->use_method[shown[k]])
                    printf("%s%.3f", k ? " / " : " ", median(v[shown[k]], b->n_seeds));
                else printf("%s-", k ? " / " : " ");
            }
            printf("%s | ", fails ? " (bayes: no table on some seeds)" : "");
            if (b->use_method[M_BAYES]) printf("%.0f |", median(ps, b->n_seeds));
            else printf("- |");
        }
        printf("\n");
    }
}

static void print_summary(const run_result (*res)[MAX_SEEDS], const bench_opts *b, const double *floor_rms)
{
    int qsd[MAX_BUDGETS], mb = judged_bayes(b);
    double g[N_METHODS][MAX_BUDGETS], gmed[N_METHODS][MAX_BUDGETS];
    static const char *const sd_name[3] = {", sd 0.3", ", sd 0.5", ", sd 1"};
    best_quest_sd(res, b, qsd);
    group_figures(res, b, qsd, g, gmed);
    printf(
        "\nper person: median over seeds %d-%d of the RMS log10 error over the visible, showable cells; "
        "QUEST at its best prior sd per budget; person s = the bayes session's own clock from first trial to "
        "last (simulated answer times included; - when no session ran)\n\n",
        b->first_seed, b->first_seed + b->n_seeds - 1);
    print_person_table(res, b, qsd, floor_rms);
    printf("\n| method | trials | RMS over people x seeds | median of per-person medians "
           "|\n|---|---|---|---|\n");
    for (int m = 0; m < N_METHODS; m++)
        for (int bi = 0; bi < b->n_budgets && b->use_method[m]; bi++)
            printf("| %s%s | %d | %.3f | %.3f |\n", METHOD_NAMES[m], m == M_QUEST ? sd_name[qsd[bi]] : "",
                   b->budgets[bi], g[m][bi], gmed[m][bi]);
    if (!b->use_method[M_QUEST] || !b->use_method[M_QPLUS] ||
        !(b->use_method[M_BAYES] || b->use_method[M_BAYESP])) {
        printf("summary: bayes and both anchors were not all run; no comparison (pool the raw lines of the "
               "runs)\n");
        return;
    }
    for (int bi = 0; bi < b->n_budgets; bi++) {
        int ahead = g[mb][bi] < g[M_QUEST][bi] && g[mb][bi] < g[M_QPLUS][bi];
        printf("summary %d trials: %s %.3f, QUEST %.3f, QUEST+ %.3f (bayes %s both anchors)", b->budgets[bi],
               METHOD_NAMES[mb], g[mb][bi], g[M_QUEST][bi], g[M_QPLUS][bi],
               ahead ? "ahead of" : "NOT ahead of");
        if (b->budgets[bi] == 360)
            printf("; target (<= 0.12 and ahead) %s", g[mb][bi] <= 0.12 && ahead ? "met" : "NOT met");
        printf("\n");
    }
}

/* ---- options ----------------------------------------------------------------------------------- */

static int parse_list(const char *s, int *out, int max, int lo, int hi)
{
    int n = 0;
    while (*s) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < lo || v > hi || n == max) return -1;
        out[n++] = (int)v;
        if (*end && *end != ',') return -1;
        s = *end ? end + 1 : end;
    }
    return n;
}

/* "bayes" = whole sessions, "bayesproc" = the method through its procedure interface. */
static int parse_methods(const char *list, int *use)
{
    static const char *const keys[N_METHODS] = {"bayes", "bayesproc", "quest", "qplus"};
    char buf[128];
    snprintf(buf, sizeof buf, "%s", list);
    for (int m = 0; m < N_METHODS; m++) use[m] = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int m = 0;
        while (m < N_METHODS && strcmp(tok, keys[m])) m++;
        if (m == N_METHODS) {
            fprintf(stderr, "bench_velocity: --methods takes bayes, bayesproc, quest, qplus (got '%s')\n",
                    tok);
            return -1;
        }
        use[m] = 1;
    }
    return 0;
}

static int parse_args(int argc, char **argv, bench_opts *b)
{
    *b = (bench_opts){
        .n_seeds = 5, .first_seed = 1, .n_budgets = 3, .budgets = {240, 360, 480}, .refresh_hz = 120.0};
    for (int ob = 0; ob < N_OBS; ob++) b->use_obs[ob] = 1;
    for (int m = 0; m < N_METHODS; m++) b->use_method[m] = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int list[N_OBS], n;
        if (!strcmp(a, "--seeds") && v && (b->n_seeds = atoi(v)) >= 1 && b->n_seeds <= MAX_SEEDS) i++;
        else if (!strcmp(a, "--first-seed") && v && (b->first_seed = atoi(v)) >= 1 &&
                 b->first_seed <= 1000000)
            i++;
        else if (!strcmp(a, "--refresh") && v && (b->refresh_hz = atof(v)) >= 30 && b->refresh_hz <= 1000)
            i++;
        else if (!strcmp(a, "--budgets") && v &&
                 (b->n_budgets = parse_list(v, b->budgets, MAX_BUDGETS, 1, 5000)) >= 1) {
            i++;
            for (int k = 1; k < b->n_budgets; k++)
                if (b->budgets[k] <= b->budgets[k - 1])
                    return fprintf(stderr, "bench_velocity: --budgets must rise\n"), -1;
        } else if (!strcmp(a, "--observers") && v && (n = parse_list(v, list, N_OBS, 0, N_OBS - 1)) >= 1) {
            i++;
            for (int ob = 0; ob < N_OBS; ob++) b->use_obs[ob] = 0;
            for (int k = 0; k < n; k++) b->use_obs[list[k]] = 1;
        } else if (!strcmp(a, "--methods") && v) {
            i++;
            if (parse_methods(v, b->use_method)) return -1;
        } else {
            fprintf(stderr,
                    "usage: bench_velocity [--seeds 1-%d] [--first-seed N] [--budgets 240,360,480 (up to %d, "
                    "rising)] "
                    "[--observers 0-%d,...] [--methods bayes,bayesproc,quest,qplus] [--refresh 30-1000 Hz]\n",
                    MAX_SEEDS, MAX_BUDGETS, N_OBS - 1);
            return -1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    bench_opts b;
    if (parse_args(argc, argv, &b)) return 1;
    csf_cell cells[MAX_CELLS];
    int n_alt[MAX_CELLS], n = showable_cells(b.refresh_hz, cells);
    if (sim2afc_default_layouts(cells, n, 4, n_alt)) return 1;
    static run_result res[N_OBS][MAX_SEEDS];
    double floor_rms[N_OBS], t0 = now_s();
    for (int ob = 0; ob < N_OBS; ob++) {
        if (!b.use_obs[ob]) continue;
        for (int s = 0; s < b.n_seeds; s++)
            if (run_one(ob, b.first_seed + s, &b, cells, n, n_alt, &res[ob][s])) return 1;
        csf_observer_sim *o;
        csf_error err;
        if (csf_observer_sim_create(VEL_OBSERVERS[ob].spec, 1, &o, &err) != CSF_OK) return 1;
        floor_rms[ob] = qplus_floor(o, cells, n, n_alt);
        csf_observer_sim_free(o);
        fprintf(stderr, "  %s done (%.0f s)\n", VEL_OBSERVERS[ob].name, now_s() - t0);
    }
    printf(
        "velocity calibration: %d showable cells of %d (refresh %.0f Hz: f v < %.0f Hz), max contrast %.1f; "
        "bayes set up as a session (not told slope or lapse); QUEST told slope and lapse, QUEST+ the lapse\n",
        n, MAX_CELLS, b.refresh_hz, b.refresh_hz / 2.0, CMAX);
    print_summary(res, &b, floor_rms);
    return 0;
}
