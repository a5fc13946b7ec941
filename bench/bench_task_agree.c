/* Across observers: does the table's threshold stay the same whatever the task?
 * For every simulated person below, the same 8 cells off the fovea (1-8 cpd at 5 and 10 deg) are
 * measured three ways: the fade method (yes/no on a rising ramp, 12 trials a cell, latency probes
 * included), two-interval forced choice and four-place forced choice (per-cell Psi, `2afc`,
 * 60 trials a cell). Every method runs as a session runs it: slope, lapse and the reaction latency
 * are the person's unknowns, never passed in. Printed per person: the mean signed log10 error of
 * each table against the person's truth (the d' = 1.27 two-interval threshold the truth table
 * holds), fade - two intervals (item 4 asks <= 0.1) and four places - two intervals (<= 0.02 for
 * a signal-detection person; a high-threshold Weibull person reads lower with four places by
 * construction, see docs/observer-calibration.md). The error is taken against the truth per
 * (seed, cell), so the difference of two tables is not swamped by their independent noise.
 *
 * People: the psychometric functions of the three held-out sets of bench_observer --honest
 * (slopes 1.4-6, lapses 0-0.08, both decision models), slower reaction near threshold (Pieron),
 * criterion drift (yes/no) and runs of inattention (fatigue is left out: it moves the truth with
 * the trial count, which differs between the methods), on the default parametric truth and on the
 * tuned-on mscaled table.
 * Usage: bench_task_agree [--seeds N] [--first-seed S] [--quick] [--only SUBSTRING] [--person SPEC]...
 * (run from the source root). --only keeps the people whose spec contains SUBSTRING; --person
 * (repeatable, up to 32) replaces the list with the given observer specs, and --first-seed moves
 * the seeds: together they check the method on people and seeds its constants were not chosen on. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/procedure.h"
#include "model/observer_sim.h"
#include "tests/observer/sim_loop.h"

static const csf_cell CELLS[] = {{1.0, 5, 0},  {2.0, 5, 0},  {4.0, 5, 0},  {8.0, 5, 0},
                                 {1.0, 10, 0}, {2.0, 10, 0}, {4.0, 10, 0}, {8.0, 10, 0}};
enum { N_CELLS = sizeof CELLS / sizeof CELLS[0] };
static const int FOUR[N_CELLS] = {4, 4, 4, 4, 4, 4, 4, 4};

static const char *const PEOPLE[] = {
    "sim:decision=sdt",
    "sim:decision=sdt,k=2,lapse=0.05",
    "sim:decision=sdt,k=3.012,lapse=0.008",
    "sim:decision=sdt,k=1.769,lapse=0.021",
    "sim:decision=sdt,k=1.418,lapse=0.060",
    "sim:decision=sdt,k=4.744,lapse=0.079",
    "sim:decision=sdt,k=3.957,lapse=0.013",
    "sim:decision=sdt,k=1.705,lapse=0.046",
    "sim:decision=sdt,pieron_k=0.15",
    "sim:decision=sdt,pieron_k=0.3",
    "sim:decision=sdt,drift=0.01",
    "sim:decision=sdt,lapse_runs=0.05",
    "sim:decision=sdt,k=2.18,lapse=0.042,table=bench/data/observer_mscaled.csv",
    "sim",
    "sim:slope=2.2,lapse=0.05",
    "sim:slope=5,lapse=0",
    "sim:slope=1.549,lapse=0.074",
    "sim:slope=5.741,lapse=0.052",
    "sim:slope=3.994,lapse=0.045,pieron_k=0.15",
    "sim:slope=2.331,lapse=0.020,table=bench/data/observer_mscaled.csv",
};
enum { N_PEOPLE = sizeof PEOPLE / sizeof PEOPLE[0] };

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* Mean signed log10 error over seeds and cells of one method and layout; -1 on a failure. */
static int mean_error(const char *spec, const char *method, const int *layout, int per_cell, int first_seed,
                      int n_seeds, double *mean_out, double *rms_out, int *n_unfinite)
{
    const csf_procedure_ops *ops = csf_procedure_find(method);
    double sum = 0, sum2 = 0;
    int n = 0;
    *n_unfinite = 0;
    for (int seed = first_seed; seed < first_seed + n_seeds; seed++) {
        double err_log10[N_CELLS];
        if (sim_loop_errors(ops, spec, CELLS, N_CELLS, per_cell * N_CELLS, (uint64_t)seed, layout, 0, err_log10))
            return -1;
        for (int i = 0; i < N_CELLS; i++) {
            double e = err_log10[i];
            if (!isfinite(e)) {
                (*n_unfinite)++;
                continue;
            }
            sum += e;
            sum2 += e * e;
            n++;
        }
    }
    *mean_out = n ? sum / n : NAN;
    *rms_out = n ? sqrt(sum2 / n) : NAN;
    return 0;
}

int main(int argc, char **argv)
{
    int n_seeds = 12, first_seed = 1, quick = 0, n_people = N_PEOPLE;
    const char *only = NULL;
    const char *people[32];
    int n_given = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seeds") && i + 1 < argc) n_seeds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--first-seed") && i + 1 < argc) first_seed = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
        else if (!strcmp(argv[i], "--person") && i + 1 < argc) {
            if (n_given == 32) {
                fprintf(stderr, "bench_task_agree: at most 32 --person specs\n");
                return 1;
            }
            people[n_given++] = argv[++i];
        } else {
            fprintf(stderr, "usage: bench_task_agree [--seeds N] [--first-seed S] [--quick] [--only SUBSTRING] "
                            "[--person SPEC]...\n");
            return 1;
        }
    }
    if (quick) n_seeds = 3;
    if (n_seeds < 1 || n_seeds > 1000) {
        fprintf(stderr, "bench_task_agree: --seeds takes 1-1000\n");
        return 1;
    }
    if (first_seed < 1 || first_seed > 1000000) {
        fprintf(stderr, "bench_task_agree: --first-seed takes 1-1000000\n");
        return 1;
    }
    if (n_given) n_people = n_given;
    else
        for (int p = 0; p < N_PEOPLE; p++) people[p] = PEOPLE[p];
    printf("8 cells (1-8 cpd at 5 and 10 deg), seeds %d-%d; mean signed log10 error against the truth; "
           "fade 12 trials a cell, forced choice (2afc) 60 a cell\n\n", first_seed, first_seed + n_seeds - 1);
    printf("| person | fade | two intervals | four places | fade - two intervals | four - two | fade RMS | not finite |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    double t0 = now_s(), worst_fade = 0, worst_sdt_layout = 0, fade_rms_sum = 0;
    int fade_within = 0, sdt_n = 0, sdt_within = 0, n_run = 0;
    for (int p = 0; p < n_people; p++) {
        if (only && !strstr(people[p], only)) continue;
        n_run++;
        double fade, two, four, fade_rms, two_rms, four_rms;
        int u1, u2, u3;
        if (mean_error(people[p], "fade", NULL, 12, first_seed, n_seeds, &fade, &fade_rms, &u1) ||
            mean_error(people[p], "2afc", NULL, 60, first_seed, n_seeds, &two, &two_rms, &u2) ||
            mean_error(people[p], "2afc", FOUR, 60, first_seed, n_seeds, &four, &four_rms, &u3))
            return 1;
        double d_fade = fade - two, d_layout = four - two;
        int sdt = strstr(people[p], "decision=sdt") != NULL;
        printf("| %s | %+.3f | %+.3f | %+.3f | %+.3f | %+.3f%s | %.3f | %d |\n", people[p], fade, two, four, d_fade,
               d_layout, sdt ? "" : " (Weibull)", fade_rms, u1 + u2 + u3);
        fade_rms_sum += fade_rms;
        fflush(stdout);
        if (fabs(d_fade) <= 0.1) fade_within++;
        if (fabs(d_fade) > fabs(worst_fade)) worst_fade = d_fade;
        if (sdt) {
            sdt_n++;
            if (fabs(d_layout) <= 0.02) sdt_within++;
            if (fabs(d_layout) > fabs(worst_sdt_layout)) worst_sdt_layout = d_layout;
        }
    }
    printf("\nfade vs two intervals within 0.1: %d of %d people (largest %+.3f); four places vs two intervals "
           "within 0.02 for signal-detection people: %d of %d (largest %+.3f); fade RMS against the truth, mean "
           "over people: %.3f; %.1f s\n",
           fade_within, n_run, worst_fade, sdt_within, sdt_n, worst_sdt_layout, n_run ? fade_rms_sum / n_run : NAN,
           now_s() - t0);
    return 0;
}
