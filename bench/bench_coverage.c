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
#include "precision_run.h"
#include "tests/bayes/sim_2afc.h"

enum { N_CELLS = PR_CELLS, MAX_SPECS = 16, MAX_SETS = 19, N_SHIFTS = PR_N_SHIFTS };
#define SHIFTS PR_SHIFTS
#define CMAX PR_CMAX
typedef coverage_tally tally;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
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
            int cap = op->precision > 0 ? PR_CAP_PER_CELL * N_CELLS : op->trials;
            if (precision_session(ops, specs[p], s, cells, n_alt, cap, &op->precision, op->precision > 0,
                                  &so))
                return -1;
            coverage_tally_add(&t, &so, op->per_cell);
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
        printf("budget: --precision %.3f (cap %d)", op.precision, PR_CAP_PER_CELL * N_CELLS);
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
