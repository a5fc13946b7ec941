/* Observer calibration accuracy (issue 6): RMS error of log10 threshold over the visible cells of
 * the default 6 x 4 grid against a simulated 2AFC observer's truth, for several trial budgets and
 * seeds, for every 2AFC method in the registry, and side by side with Psychtoolbox's QUEST (one
 * QUEST per cell, run by bench/quest/run_quest.m under octave-cli) with --quest.
 *
 * Observers: the parametric default (the model's own form) and two table-defined ones that are
 * not of the model's form: bench/data/observer_bumpy.csv (adversarial: notch and ripple) and
 * bench/data/observer_mscaled.csv (smooth and realistic: Barten fovea, Rovamo-Virsu frequency
 * scaling over eccentricity); the scripts next to them say how they were made.
 *
 * Layouts (--layouts): "2" = two intervals in every cell (classic 2IFC, guess 1/2); "4" = what a
 * session does by default on the default station (531 x 299 mm, 1920 x 1080, 570 mm): four places
 * (spatial 4AFC, guess 1/4) for every cell whose four Gabors (sigma 1 deg) fit apart on screen
 * (calib/afc_layout.h), two intervals for the foveal cells. QUEST gets the same layout per cell.
 *
 * usage: bench_observer [--seeds N] [--budgets 60,80,120,240,480] [--table CSV] [--table2 CSV]
 *                       [--quest] [--quest-sd 1.0] [--methods bayes,2afc] [--octave PATH]
 *                       [--first-seed 1] [--observers 0,1,2] [--layouts 4,2] [--cells]
 *                       [--sim SPEC ...]
 * --cells also prints, per observer, method and budget, each cell's truth, mean error (bias), RMS
 * error and mean number of trials over the seeds: where the error is.
 * --sim SPEC (repeatable, up to 8; issue 12 item 2): instead of the bench's own observer, answer
 * with the simulated observer of devices/observer_sim.h built from SPEC ("sim:key=value,...",
 * e.g. sim:slope=2.2,lapse=0.05 or sim:decision=sdt), seeded with the seed, on the same three
 * truths (",table=FILE" is appended for the table observers). The methods are set up as a
 * session sets them up (slope 3.5, lapse 0.02), NOT with the observer's values: these are
 * observers that are not the method's model, and the figure is what a session would get.
 * Printed per spec and truth: RMS, cells of the wrong visibility, and the mean signed error of
 * the two-interval and of the four-place cells (a task-dependent threshold shows there).
 * Run from the source root (default tables bench/data/observer_bumpy.csv and
 * bench/data/observer_mscaled.csv, script bench/quest/). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/afc_layout.h"
#include "calib/procedure.h"
#include "devices/observer_sim.h"
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

/* Prior-mean surface of the bayes method, used as QUEST's per-cell guess so QUEST starts from the
 * same population knowledge (and not from the parametric observer's exact truth). */
static double guess_log10(const csf_cell *c)
{
    csf_model_params p = {.smax = pow(10.0, 2.25), .fmax_cpd = pow(10.0, 0.45), .beta_oct = 3.0,
                          .delta_log10 = 0.5, .ecc_a = 0.03, .ecc_b = 0.02};
    double t = -csf_model_log10_sensitivity(&p, c->freq_cpd, c->ecc_deg);
    return t > 0.0 ? 0.0 : t;
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
    csf_error err = {0};
    void *st = NULL;
    if (ops->create(&setup, &st, &err) != CSF_OK) {
        fprintf(stderr, "%s: create: %s\n", ops->name, err.msg);
        return -1;
    }
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
    }
    csf_status rc = ops->estimate(st, est, &err);
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
                    double bias_sum[2] = {0, 0};
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
                        wrong_total += wrong;
                        csf_observer_sim_free(o);
                    }
                    char b2[16] = "-", b4[16] = "-";
                    if (bias_n[0]) snprintf(b2, sizeof b2, "%+.3f", bias_sum[0] / bias_n[0]);
                    if (bias_n[1]) snprintf(b4, sizeof b4, "%+.3f", bias_sum[1] / bias_n[1]);
                    printf("| %s | %s | %s | %d | %.3f | %d | %s | %s | %.1f |\n", specs[sp], truth_name[ob],
                           methods[m]->name, budgets[b], sqrt(sum_sq / n_seeds), wrong_total, b2, b4,
                           (now_s() - t0) * 1000.0 / n_seeds);
                    fflush(stdout);
                }
        }
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
    int per_cell = 0;
    const char *specs[MAX_SPECS];
    int n_specs = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seeds") && i + 1 < argc) {
            n_seeds = atoi(argv[++i]);
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
        } else if (!strcmp(argv[i], "--cells")) {
            per_cell = 1;
        } else if (!strcmp(argv[i], "--quest")) {
            quest = 1;
        } else {
            fprintf(stderr, "usage: bench_observer [--seeds N] [--budgets 60,80,120,240,480] "
                            "[--table CSV] [--table2 CSV] [--observers 0,1,2] [--quest] [--quest-sd SD] [--methods bayes,2afc] [--octave PATH] [--first-seed N] [--layouts 4,2] [--cells] [--sim SPEC ...]\n");
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

    /* the default station of a session (docs/observer-calibration.md) and its Gabor sigma */
    csf_geometry geom;
    csf_error gerr;
    if (csf_geometry_init(&geom, 531.0, 299.0, 1920, 1080, 570.0, 0.0, 0.0, &gerr) != CSF_OK) return 1;
    const char *layout_name[N_LAYOUTS] = {"four places off the fovea (session default on the default station), two intervals at the fovea",
                                          "two intervals in every cell (2IFC)"};
    for (int ly = 0; ly < N_LAYOUTS; ly++) {
        if (!use_layout[ly]) continue;
        int n_alt[24];
        for (int c = 0; c < n; c++) {
            csf_afc_layout lay;
            csf_afc_choose_layout(&geom, cells[c].ecc_deg, 1.0, ly == 0 ? 4 : 2, &lay);
            n_alt[c] = lay.n_alternatives;
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
                    fprintf(tf, "%d,%d,%.6f,%.6f,%d,%d\n", ob, c, t, guess_log10(&cells[c]), t < log10(cmax), n_alt[c]);
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
