/* Are the stated errors honest? For each method (bayes, 2afc, fade) on simulated people, per
 * held-out set: the coverage of the 95 % interval (estimate +- 1.96 stderr_log10) over the truly
 * visible cells, the session's predicted RMS error (sqrt of the mean stated variance over the
 * cells it reports visible, what `observer calibrate --precision` stops on) against the achieved
 * one, the conservative view's fail-open rate (csflut: each node lowered by K stated errors, then
 * the minimum over higher-or-equal frequency and eccentricity; fail-open = a truly visible cell whose
 * conservative threshold is above the truth), and the cells called never visible that are visible.
 *
 * Usage: bench_coverage [--sets 1,2,...] [--sim SPEC ...] [--methods bayes,2afc,fade] [--seeds N]
 *                       [--first-seed S] [--trials N] [--precision SE] [--layout 4|2] [--shift K]
 *                       [--cells]
 * --sets: held-out sets of bench/data/README.md (their held-out people only); --sim: people given
 * by spec instead (for tuning on the tuned-on truths: "sim:slope=2,lapse=0.06,table=..."). Person
 * seed s, method seed 1000 + s, as bench_observer. pred/ach: the session's predicted RMS (every
 * cell it reports visible) over the achieved RMS (the truly visible cells among them), as root
 * mean squares over the sessions; in brackets the stated RMS over the same cells as the achieved
 * one (a cell truly invisible but written finite has a stated error and no error to compare). Default: 120 trials; --precision stops a session
 * when its predicted RMS reaches SE (checked after every trial from the 10th, as the session does;
 * cap 40 trials per cell). Run from the source root. Figures: BENCHMARKS.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/procedure.h"
#include "honest_sets.h"
#include "model/observer_sim.h"
#include "tests/bayes/sim_2afc.h"

enum { N_CELLS = 24, MAX_SPECS = 16, MAX_SETS = 16, N_SHIFTS = 9 };
static const double SHIFTS[N_SHIFTS] = {0, 0.5, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0};
#define CMAX 1.0
#define PRECISION_MIN_TRIALS 10 /* as calib/observer_calib.c */
#define PRECISION_CAP_PER_CELL 40

typedef struct {
    double truth[N_CELLS], est[N_CELLS], se[N_CELLS]; /* log10; est INFINITY = never visible */
    int trials;
} session_out;

typedef struct {
    long n_vis, covered, called_inv, inv_wrong, vis_nan;
    long fail_open[N_SHIFTS];
    double pred_sq, ach_sq, ratio_sum; /* sums over sessions */
    double matched_sq;                 /* stated variance over the cells in ach_sq, summed RMS^2 */
    int n_sess, n_ratio;
    long trials;
    double cell_err_sq[N_CELLS], cell_se_sq[N_CELLS];
    int cell_cov[N_CELLS], cell_n[N_CELLS];
} tally;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* One fade trial against the simulated person, frame by frame at 60 Hz on the planned ramp
 * (tests/observer/sim_loop.h does the same; here a trial at a time, for the precision stop). */
static void fade_trial(csf_observer_sim *o, int i, const csf_cell *c, const csf_trial_plan *plan,
                       double *clock_s, csf_trial_outcome *out)
{
    const double dt = 1.0 / 60;
    csf_sim_fade_trial tr;
    double window = plan->ramp_s + 1.5;
    csf_observer_sim_fade_begin(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, plan->polar_deg, *clock_s, window,
                                &tr);
    double xe = log10(plan->contrast), rate = (xe - plan->ramp_start_log10) / plan->ramp_s;
    double shown = 0;
    int nf = (int)ceil(window / dt);
    for (int k = 0; k < nf; k++) {
        double t = k * dt;
        double x = t <= plan->ramp_s ? plan->ramp_start_log10 + rate * t : -INFINITY;
        double cs = plan->is_catch ? 0 : (isfinite(x) ? pow(10.0, x) : 0);
        if (cs > 0) shown = cs;
        double press;
        if (csf_observer_sim_fade_frame(o, &tr, *clock_s + t, cs, &press)) {
            out->response = 1;
            out->rt_s = press - *clock_s;
            out->contrast_at_response = shown;
            double cx, cy, a = plan->polar_deg * M_PI / 180;
            csf_observer_sim_click(o, &tr, &cx, &cy);
            double dx = cx - c->ecc_deg * cos(a), dy = cy - c->ecc_deg * sin(a);
            if (plan->is_catch || hypot(dx, dy) > 2.0 + 0.3 * c->ecc_deg || out->rt_s < 0.15) out->valid = 0;
            break;
        }
    }
    *clock_s += window + 1;
}

static void answer(csf_observer_sim *o, int i, const csf_cell *c, const csf_trial_plan *plan, double *clock_s,
                   csf_trial_outcome *out)
{
    *out = (csf_trial_outcome){0, NAN, NAN, 1};
    if (plan->task == CSF_TASK_FADE) {
        fade_trial(o, i, c, plan, clock_s, out);
        return;
    }
    int m = plan->n_alternatives == 4 ? 4 : 2;
    double cs[4] = {0, 0, 0, 0}, rt;
    cs[plan->signal_interval] = plan->contrast;
    out->response = m == 4 ? csf_observer_sim_afc(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, 4, &rt)
                           : csf_observer_sim_2afc(o, (uint64_t)i, c->freq_cpd, c->ecc_deg, cs, &rt);
    out->rt_s = rt;
    out->contrast_at_response = plan->contrast;
}

/* The session's predicted RMS (calib/observer_calib.c predicted_rms): over cells reported visible
 * with a stated error. */
static double predicted_rms(const csf_cell_estimate *e, int n)
{
    double sum = 0;
    int k = 0;
    for (int c = 0; c < n; c++)
        if (isfinite(e[c].threshold) && isfinite(e[c].stderr_log10))
            sum += e[c].stderr_log10 * e[c].stderr_log10, k++;
    return k ? sqrt(sum / k) : NAN;
}

static int run_session(const csf_procedure_ops *ops, const char *spec, int seed, const csf_cell *cells,
                       const int *n_alt, int trials, double precision, session_out *so)
{
    csf_observer_sim *o;
    csf_error err = {0};
    if (csf_observer_sim_create(spec, (uint64_t)seed, &o, &err) != CSF_OK) {
        fprintf(stderr, "bench_coverage: %s: %s\n", spec, err.msg);
        return -1;
    }
    int fade = ops->task == CSF_TASK_FADE;
    int cap = precision > 0 ? PRECISION_CAP_PER_CELL * N_CELLS : trials;
    csf_procedure_setup s = {.cells = cells,
                             .n_cells = N_CELLS,
                             .trial_budget = cap,
                             .seed = 1000 + (uint64_t)seed,
                             .max_contrast = CMAX,
                             .min_contrast = 0.0005,
                             .slope_beta = 3.5,
                             .lapse = 0.02,
                             .guess = fade ? 0.02 : 0.5,
                             .ramp_start_log10 = -3.0,
                             .ramp_end_log10 = 0.0,
                             .ramp_s = 6.0,
                             .reaction_latency_s = 0.37,
                             .n_alternatives = fade ? NULL : n_alt};
    void *st = NULL;
    csf_cell_estimate est[N_CELLS];
    if (ops->create(&s, &st, &err) != CSF_OK) {
        fprintf(stderr, "bench_coverage: %s: %s\n", ops->name, err.msg);
        csf_observer_sim_free(o);
        return -1;
    }
    double clock_s = 0;
    int k = 0;
    for (; k < cap; k++) {
        csf_trial_plan plan;
        if (ops->next(st, k, &plan) != CSF_OK) break;
        csf_trial_outcome out;
        answer(o, k, &cells[plan.cell], &plan, &clock_s, &out);
        ops->update(st, k, &plan, &out);
        if (precision > 0 && k + 1 >= PRECISION_MIN_TRIALS && ops->estimate(st, est, &err) == CSF_OK &&
            predicted_rms(est, N_CELLS) <= precision) {
            k++;
            break;
        }
    }
    ops->estimate(st, est, &err);
    ops->destroy(st);
    so->trials = k;
    for (int c = 0; c < N_CELLS; c++) {
        so->truth[c] = log10(csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg));
        so->est[c] = log10(est[c].threshold);
        so->se[c] = est[c].stderr_log10;
    }
    csf_observer_sim_free(o);
    return 0;
}

/* csflut's conservative view at shift k (results/csflut/csflut.c compute_conservative) on the
 * 6 x 4 grid (frequency fastest), into cons (log10). */
static void conservative(const session_out *so, double k, double *cons)
{
    for (int c = 0; c < N_CELLS; c++)
        cons[c] = so->est[c] - (isfinite(so->est[c]) && isfinite(so->se[c]) ? k * so->se[c] : 0);
    for (int e = 3; e >= 0; e--)
        for (int f = 5; f >= 0; f--) {
            double *v = &cons[e * 6 + f];
            if (f < 5 && cons[e * 6 + f + 1] < *v) *v = cons[e * 6 + f + 1];
            if (e < 3 && cons[(e + 1) * 6 + f] < *v) *v = cons[(e + 1) * 6 + f];
        }
}

static void tally_session(tally *t, const session_out *so, int per_cell)
{
    double lc = log10(CMAX), pred = 0, ach = 0, matched = 0;
    int np = 0, na = 0;
    for (int c = 0; c < N_CELLS; c++) {
        int vis = so->truth[c] < lc, est_vis = so->est[c] < INFINITY,
            ok = isfinite(so->est[c]) && isfinite(so->se[c]);
        if (so->est[c] == INFINITY) t->called_inv++, t->inv_wrong += vis;
        if (ok) pred += so->se[c] * so->se[c], np++;
        if (!vis) continue;
        t->n_vis++;
        if (!est_vis || isnan(so->est[c])) {
            t->vis_nan += isnan(so->est[c]);
            continue;
        }
        if (!ok) continue;
        double d = so->est[c] - so->truth[c];
        int cov = fabs(d) <= 1.96 * so->se[c];
        t->covered += cov;
        ach += d * d, matched += so->se[c] * so->se[c], na++;
        if (per_cell) {
            t->cell_err_sq[c] += d * d, t->cell_se_sq[c] += so->se[c] * so->se[c];
            t->cell_cov[c] += cov, t->cell_n[c]++;
        }
    }
    for (int j = 0; j < N_SHIFTS; j++) {
        double cons[N_CELLS];
        conservative(so, SHIFTS[j], cons);
        for (int c = 0; c < N_CELLS; c++)
            t->fail_open[j] += so->truth[c] < lc && cons[c] > so->truth[c] + 1e-12;
    }
    if (np && na) {
        pred = sqrt(pred / np), ach = sqrt(ach / na);
        t->pred_sq += pred * pred, t->ach_sq += ach * ach, t->matched_sq += matched / na;
        if (ach > 0) t->ratio_sum += pred / ach, t->n_ratio++;
    }
    t->n_sess++;
    t->trials += so->trials;
}

static void print_row(const char *set, const char *method, const tally *t)
{
    double nv = t->n_vis ? (double)t->n_vis : 1.0, ns = t->n_sess ? t->n_sess : 1;
    char kbest[16] = "> 3";
    for (int j = 0; j < N_SHIFTS; j++)
        if (t->fail_open[j] <= 0.025 * t->n_vis) {
            snprintf(kbest, sizeof kbest, "%.2f", SHIFTS[j]);
            break;
        }
    printf("| %s | %s | %d | %.0f | %.1f %% | %.3f | %.3f | %.2f (%.2f) | %.2f | %.1f %% | %.1f %% | %s | "
           "%ld/%ld | %ld "
           "|\n",
           set, method, t->n_sess, t->trials / ns, 100.0 * t->covered / nv, sqrt(t->pred_sq / ns),
           sqrt(t->ach_sq / ns), sqrt(t->pred_sq / (t->ach_sq > 0 ? t->ach_sq : 1)),
           sqrt(t->matched_sq / (t->ach_sq > 0 ? t->ach_sq : 1)),
           t->n_ratio ? t->ratio_sum / t->n_ratio : NAN, 100.0 * t->fail_open[0] / nv,
           100.0 * t->fail_open[6] / nv, kbest, t->inv_wrong, t->called_inv, t->vis_nan);
}

static void print_shifts(const char *set, const char *method, const tally *t)
{
    printf("fail-open by shift, %s, %s:", set, method);
    for (int j = 0; j < N_SHIFTS; j++)
        printf(" K=%.2f %.1f%%", SHIFTS[j], 100.0 * t->fail_open[j] / (t->n_vis ? (double)t->n_vis : 1.0));
    printf("\n");
}

static void print_cells(const tally *t, const csf_cell *cells)
{
    for (int c = 0; c < N_CELLS; c++)
        if (t->cell_n[c])
            printf("    cell %4.1f cpd %2.0f deg: n %d, coverage %.0f %%, RMS err %.3f, RMS stated %.3f\n",
                   cells[c].freq_cpd, cells[c].ecc_deg, t->cell_n[c], 100.0 * t->cell_cov[c] / t->cell_n[c],
                   sqrt(t->cell_err_sq[c] / t->cell_n[c]), sqrt(t->cell_se_sq[c] / t->cell_n[c]));
}

static int parse_list(const char *s, int *v, int max)
{
    int n = 0;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    for (char *tok = strtok(buf, ","); tok && n < max; tok = strtok(NULL, ",")) v[n++] = atoi(tok);
    return n;
}

typedef struct {
    int sets[MAX_SETS], n_sets;
    const char *specs[MAX_SPECS];
    int n_specs;
    const csf_procedure_ops *methods[3];
    int n_methods, seeds, first_seed, trials, layout, per_cell;
    double precision;
} options;

static int parse_args(int argc, char **argv, options *op)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--cells")) {
            op->per_cell = 1;
            continue;
        }
        if (!v) return -1;
        i++;
        if (!strcmp(a, "--sets")) op->n_sets = parse_list(v, op->sets, MAX_SETS);
        else if (!strcmp(a, "--sim") && op->n_specs < MAX_SPECS) op->specs[op->n_specs++] = v;
        else if (!strcmp(a, "--seeds")) op->seeds = atoi(v);
        else if (!strcmp(a, "--first-seed")) op->first_seed = atoi(v);
        else if (!strcmp(a, "--trials")) op->trials = atoi(v);
        else if (!strcmp(a, "--precision")) op->precision = atof(v);
        else if (!strcmp(a, "--layout")) op->layout = atoi(v);
        else if (!strcmp(a, "--methods")) {
            char buf[64];
            snprintf(buf, sizeof buf, "%s", v);
            op->n_methods = 0;
            for (char *tok = strtok(buf, ","); tok && op->n_methods < 3; tok = strtok(NULL, ","))
                if (!(op->methods[op->n_methods++] = csf_procedure_find(tok))) return -1;
        } else return -1;
    }
    for (int k = 0; k < op->n_sets; k++)
        if (op->sets[k] < 1 || op->sets[k] > N_HONEST_SETS) return -1;
    return op->seeds >= 1 && op->trials >= 1 && (op->layout == 2 || op->layout == 4) && op->precision >= 0
               ? 0
               : -1;
}

/* One group of people (a held-out set, or the --sim specs) through one method. */
static int run_group(const options *op, const csf_procedure_ops *ops, const char *const *specs, int n_specs,
                     const char *label, const csf_cell *cells, const int *n_alt)
{
    tally t;
    memset(&t, 0, sizeof t);
    double t0 = now_s();
    for (int p = 0; p < n_specs; p++)
        for (int s = op->first_seed; s < op->first_seed + op->seeds; s++) {
            session_out so;
            if (run_session(ops, specs[p], s, cells, n_alt, op->trials, op->precision, &so)) return -1;
            tally_session(&t, &so, op->per_cell);
            for (int c = 0; op->per_cell && c < N_CELLS; c++)
                if (so.est[c] == INFINITY && so.truth[c] < log10(CMAX))
                    printf("    never visible but visible: %s seed %d, %g cpd %g deg, truth %.3f log10\n",
                           specs[p], s, cells[c].freq_cpd, cells[c].ecc_deg, so.truth[c]);
        }
    print_row(label, ops->name, &t);
    print_shifts(label, ops->name, &t);
    if (op->per_cell) print_cells(&t, cells);
    fprintf(stderr, "  %s %s: %.1f s\n", label, ops->name, now_s() - t0);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    options op = {.seeds = 5, .first_seed = 1, .trials = 120, .layout = 4};
    op.methods[0] = csf_procedure_find("bayes"), op.methods[1] = &csf_procedure_2afc;
    op.methods[2] = &csf_procedure_fade, op.n_methods = op.methods[0] ? 3 : 2;
    if (!op.methods[0]) op.methods[0] = &csf_procedure_2afc, op.methods[1] = &csf_procedure_fade;
    if (parse_args(argc, argv, &op)) {
        fprintf(stderr,
                "usage: bench_coverage [--sets 1,2,...] [--sim SPEC ...] [--methods bayes,2afc,fade] "
                "[--seeds N] [--first-seed S] [--trials N] [--precision SE] [--layout 4|2] [--cells]\n");
        return 2;
    }
    csf_cell cells[N_CELLS];
    int n_alt[N_CELLS];
    if (sim2afc_default_grid(cells) != N_CELLS || sim2afc_default_layouts(cells, N_CELLS, op.layout, n_alt))
        return 1;
    if (op.precision > 0)
        printf("budget: --precision %.3f (cap %d)", op.precision, PRECISION_CAP_PER_CELL * N_CELLS);
    else printf("budget: %d trials", op.trials);
    printf(", layout %d, seeds %d-%d (person s, method 1000 + s)\n\n", op.layout, op.first_seed,
           op.first_seed + op.seeds - 1);
    printf(
        "| people | method | sessions | trials | coverage 95 %% | predicted RMS | achieved RMS | pred/ach "
        "(same cells) | pred/ach, mean per session | fail-open K=0 | K=2 | K for <= 2.5 %% | never-visible "
        "wrong/called | visible with no estimate "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int m = 0; m < op.n_methods; m++) {
        if (op.n_specs && run_group(&op, op.methods[m], op.specs, op.n_specs, "--sim", cells, n_alt))
            return 1;
        for (int k = 0; k < op.n_sets; k++) {
            const char *specs[MAX_HONEST_OBS];
            int n = 0;
            char label[32];
            for (int p = 0; p < HONEST_SETS[op.sets[k] - 1].n; p++)
                if (HONEST_SETS[op.sets[k] - 1].obs[p].held_out)
                    specs[n++] = HONEST_SETS[op.sets[k] - 1].obs[p].spec;
            snprintf(label, sizeof label, "set %d", op.sets[k]);
            if (run_group(&op, op.methods[m], specs, n, label, cells, n_alt)) return 1;
        }
    }
    return 0;
}
