/* Trials to a precision: how many trials each method needs before its table is good to 0.15 and
 * to 0.10 log10 RMS, on the held-out people of bench/data/README.md, both layouts.
 *   - bayes as `observer calibrate --precision SE` runs it (bench/precision_run.h): not told the
 *     person's slope or lapse, stopped by its own predicted RMS (checked after every trial from the
 *     10th), one session serving both levels; the achieved RMS against the truth at that stop;
 *   - per-cell QUEST (told the person's slope and lapse) at each prior sd, and joint QUEST+ (told
 *     the lapse), both bench/anchor_run.h, stopped by an ORACLE: the first checkpoint (every K
 *     trials) at which their achieved RMS against the truth reaches the level, or (matched) reaches
 *     what bayes achieved at its own stop on the same person and seed: the tables compared are then
 *     equally good. No session can know either; it flatters them, as does picking QUEST's best
 *     prior sd on the same people.
 * An anchor that has not reached a level at the cap (960 trials, --precision's cap) counts as the
 * cap and is marked. Achieved RMS: over the truly visible cells, a visible cell called never
 * visible counting with the max contrast as its estimate (bench_observer's score). Per set, at each
 * level, bayes's stated errors (bench_coverage's scores): coverage of the 95 % interval,
 * predicted/achieved RMS and the conservative view's fail-open rate at the shift its tables
 * recommend. Targets (four places, pooled over the sets): bayes's median trials <= 0.6 x QUEST+'s
 * and <= 0.35 x the best per-cell QUEST's, at both levels.
 *
 * Usage: bench_efficiency [--sets 1,2,...] [--layouts 4,2] [--seeds N] [--first-seed S] [--every K]
 *                         [--cap N] [--people N] [--check]
 * --sets: default every seen set (1 to N_SEEN_SETS, honest_sets.h); an unseen one only when named.
 * Person seed s, method seed 1000 + s, as bench_observer. --people: the first N held-out people of
 * each set (reduced runs); --check: exit 1 if a stop breaks the benchmark's own rules (an anchor
 * stopped above its level or off a checkpoint, a level reached later than a lower one...). Run
 * from the source root. Figures: BENCHMARKS.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "anchor_run.h"
#include "honest_sets.h"
#include "precision_run.h"
#include "tests/bayes/sim_2afc.h"

enum { N_LEVELS = 2, N_SDS = 3, MAX_SEEDS = 8, MAX_SAMPLES = MAX_HONEST_OBS * MAX_SEEDS, MAX_SETS = 19 };
enum { MAX_CHECKPOINTS = PR_CAP_PER_CELL * PR_CELLS };
static const double LEVELS[N_LEVELS] = {0.15, 0.10};
static const double QUEST_SDS[N_SDS] = {0.3, 0.5, 1.0};
/* The conservative shift bayes's tables recommend (recommended_shift_se, calib/observer_table.c) */
#define RECOMMENDED_SHIFT 2.0
#define CMIN 0.0005

typedef struct {
    int trials, capped; /* capped: the level not reached by the cap (trials = the cap) */
    double ach;         /* achieved RMS at the stop */
} stop_at;

/* The stops: bayes's own; each anchor's first oracle stop and its settled one (from the first
 * checkpoint after which its RMS never again rises above the level, up to the cap); and its matched
 * one: the first checkpoint at which its achieved RMS is no worse than what bayes achieved at its own
 * stop for that level, on the same person and seed (the two tables then equally good: bayes's stop
 * is on its predicted RMS, so what it achieves there lies on either side of the level). */
enum {
    M_BAYES,
    M_QUEST,
    M_QPLUS,
    M_QUEST_SETTLED,
    M_QPLUS_SETTLED,
    M_QUEST_MATCHED,
    M_QPLUS_MATCHED,
    N_METHODS
};

typedef struct {                                         /* one (set, layout): every person x seed */
    stop_at at[N_METHODS][N_SDS][MAX_SAMPLES][N_LEVELS]; /* sd index 0 but for QUEST */
    int n, cap_seen;                                     /* cap_seen: the cap the stops ran under */
    coverage_tally cov[N_LEVELS];
} group;

typedef struct {
    int sets[MAX_SETS], n_sets, layouts[2], n_layouts;
    int seeds, first_seed, every, cap, people, check;
} options;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- the oracle stop ----------------------------------------------------------------------- */

/* Runs to the cap: the settled stop needs the whole path (an anchor's RMS wanders as its posterior
 * moves between surfaces, so its first passage can be luck). */
typedef struct {
    const double *truth;
    int next;                   /* the next level to reach first */
    double last;                /* achieved RMS at the latest checkpoint */
    stop_at *first, *settled;   /* [N_LEVELS] */
    int settled_from[N_LEVELS]; /* checkpoint since which the RMS stays at or below the level; 0: above now */
    double settled_ach[N_LEVELS];
    const stop_at *bayes; /* [N_LEVELS]: bayes's stops on this person and seed */
    stop_at *matched;     /* [N_LEVELS] */
    int matched_done[N_LEVELS];
} oracle;

static int oracle_check(void *ctx, int trials, const double *est_log10)
{
    oracle *ora = ctx;
    ora->last = precision_achieved_rms(ora->truth, est_log10, PR_CELLS);
    const char *trace = getenv("CSF_BENCH_TRACE"); /* diagnosis: every checkpoint's achieved RMS */
    if (trace && *trace == '1') fprintf(stderr, "trace: %d %.4f\n", trials, ora->last);
    for (; ora->next < N_LEVELS && ora->last <= LEVELS[ora->next]; ora->next++)
        ora->first[ora->next] = (stop_at){trials, 0, ora->last};
    for (int l = 0; l < N_LEVELS; l++) {
        if (!(ora->last <= LEVELS[l])) ora->settled_from[l] = 0;
        else if (!ora->settled_from[l]) ora->settled_from[l] = trials, ora->settled_ach[l] = ora->last;
        if (!ora->matched_done[l] && ora->last <= ora->bayes[l].ach)
            ora->matched[l] = (stop_at){trials, 0, ora->last}, ora->matched_done[l] = 1;
    }
    return 0;
}

static void oracle_start(oracle *ora, const double *truth, const stop_at *bayes, stop_at *first,
                         stop_at *settled, stop_at *matched)
{
    *ora = (oracle){
        .truth = truth, .last = NAN, .first = first, .settled = settled, .bayes = bayes, .matched = matched};
}

/* The levels never reached count as the cap. */
static void oracle_finish(const oracle *ora, int cap)
{
    for (int l = ora->next; l < N_LEVELS; l++) ora->first[l] = (stop_at){cap, 1, ora->last};
    for (int l = 0; l < N_LEVELS; l++) {
        ora->settled[l] = ora->settled_from[l] ? (stop_at){ora->settled_from[l], 0, ora->settled_ach[l]}
                                               : (stop_at){cap, 1, ora->last};
        if (!ora->matched_done[l]) ora->matched[l] = (stop_at){cap, 1, ora->last};
    }
}

/* ---- one person, one seed ------------------------------------------------------------------ */

static int run_bayes(const options *op, const char *spec, int seed, const csf_cell *cells, const int *n_alt,
                     group *g)
{
    const csf_procedure_ops *bayes = csf_procedure_find("bayes");
    session_out so[N_LEVELS];
    if (!bayes || precision_session(bayes, spec, seed, cells, n_alt, op->cap, LEVELS, N_LEVELS, so))
        return -1;
    for (int l = 0; l < N_LEVELS; l++) {
        g->at[M_BAYES][0][g->n][l] =
            (stop_at){so[l].trials, !so[l].reached, precision_achieved_rms(so[l].truth, so[l].est, PR_CELLS)};
        coverage_tally_add(&g->cov[l], &so[l], 0);
    }
    return 0;
}

static int run_anchors(const options *op, const char *spec, int seed, const csf_cell *cells, const int *n_alt,
                       group *g)
{
    csf_observer_sim *o;
    csf_error err = {0};
    if (csf_observer_sim_create(spec, (uint64_t)seed, &o, &err) != CSF_OK) {
        fprintf(stderr, "bench_efficiency: %s: %s\n", spec, err.msg);
        return -1;
    }
    double truth[PR_CELLS], guess[PR_CELLS], est[PR_CELLS], slope, lapse;
    for (int c = 0; c < PR_CELLS; c++) {
        truth[c] = log10(csf_observer_sim_threshold(o, cells[c].freq_cpd, cells[c].ecc_deg));
        guess[c] = anchor_static_guess_log10(&cells[c]);
    }
    static int checkpoints[MAX_CHECKPOINTS];
    int n_cp = 0;
    for (int k = op->every; k < op->cap + op->every; k += op->every)
        checkpoints[n_cp++] = k < op->cap ? k : op->cap;
    uint64_t pseed = 1000 + (uint64_t)seed;
    anchor_person person = {o, pseed, cells, n_alt};
    oracle ora;
    anchor_run r = {.cells = cells,
                    .n_cells = PR_CELLS,
                    .n_alt = n_alt,
                    .log10_cmin = log10(CMIN),
                    .log10_cmax = log10(PR_CMAX),
                    .seed = pseed,
                    .answer = anchor_person_answer,
                    .answer_ctx = &person,
                    .checkpoints = checkpoints,
                    .n_checkpoints = n_cp,
                    .check = oracle_check,
                    .check_ctx = &ora};
    anchor_psychometric(o, &slope, &lapse);
    const stop_at *bayes = g->at[M_BAYES][0][g->n]; /* run_bayes ran first */
    for (int k = 0; k < N_SDS; k++) {
        oracle_start(&ora, truth, bayes, g->at[M_QUEST][k][g->n], g->at[M_QUEST_SETTLED][k][g->n],
                     g->at[M_QUEST_MATCHED][k][g->n]);
        anchor_quest_cells(&r, guess, QUEST_SDS[k], slope, lapse, est, NULL);
        oracle_finish(&ora, op->cap);
    }
    questplus *q = questplus_create(cells, PR_CELLS, n_alt, lapse, log10(CMIN), log10(PR_CMAX));
    if (q) {
        oracle_start(&ora, truth, bayes, g->at[M_QPLUS][0][g->n], g->at[M_QPLUS_SETTLED][0][g->n],
                     g->at[M_QPLUS_MATCHED][0][g->n]);
        anchor_questplus(&r, q, est);
        oracle_finish(&ora, op->cap);
        questplus_free(q);
    }
    csf_observer_sim_free(o);
    return q ? 0 : -1;
}

/* The benchmark's own rules for one method's stops; a message on stderr for each one broken.
 * target: the RMS each oracle stop must have reached (the levels, or bayes's achieved for a matched
 * stop, which need not fall from one level to the next). */
static int check_stops(const options *op, const stop_at *at, const double *target, const char *method,
                       int oracle_stop, const char *spec, int seed)
{
    int bad = 0;
    for (int l = 0; l < N_LEVELS; l++) {
        const stop_at *s = &at[l];
        const char *why = NULL;
        if (s->capped && s->trials != op->cap) why = "marked capped below the cap";
        else if (l && s->trials < at[l - 1].trials && target[l] <= target[l - 1])
            why = "the lower level reached first";
        else if (!s->capped && oracle_stop && !(s->ach <= target[l])) why = "stopped above its level";
        else if (!s->capped && oracle_stop && s->trials % op->every && s->trials != op->cap)
            why = "stopped off a checkpoint";
        else if (!s->capped && !oracle_stop && s->trials < PR_MIN_TRIALS) why = "stopped before trial 10";
        if (why)
            fprintf(stderr, "bench_efficiency: check: %s, %s seed %d, level %.2f: %s (%d trials, RMS %.3f)\n",
                    method, spec, seed, LEVELS[l], why, s->trials, s->ach);
        bad += why != NULL;
    }
    return bad;
}

/* A settled stop comes no earlier than the first passage. */
static int check_settled(const stop_at *first, const stop_at *settled, const char *spec, int seed)
{
    int bad = 0;
    for (int l = 0; l < N_LEVELS; l++)
        if (settled[l].trials < first[l].trials) {
            fprintf(stderr,
                    "bench_efficiency: check: %s seed %d, level %.2f: settled at %d before the first "
                    "passage at %d\n",
                    spec, seed, LEVELS[l], settled[l].trials, first[l].trials);
            bad++;
        }
    return bad;
}

static int run_person(const options *op, const char *spec, int seed, const csf_cell *cells, const int *n_alt,
                      group *g)
{
    if (g->n >= MAX_SAMPLES) return -1;
    g->cap_seen = op->cap;
    if (run_bayes(op, spec, seed, cells, n_alt, g) || run_anchors(op, spec, seed, cells, n_alt, g)) return -1;
    int bad = 0;
    if (op->check) {
        static const char *name[N_METHODS] = {
            "bayes", "QUEST", "QUEST+", "QUEST settled", "QUEST+ settled", "QUEST matched", "QUEST+ matched"};
        double matched[N_LEVELS];
        for (int l = 0; l < N_LEVELS; l++) matched[l] = g->at[M_BAYES][0][g->n][l].ach;
        for (int m = 0; m < N_METHODS; m++)
            for (int k = 0; k < (m == M_QUEST || m == M_QUEST_SETTLED || m == M_QUEST_MATCHED ? N_SDS : 1);
                 k++)
                bad += check_stops(op, g->at[m][k][g->n], m >= M_QUEST_MATCHED ? matched : LEVELS, name[m],
                                   m != M_BAYES, spec, seed);
        for (int k = 0; k < N_SDS; k++)
            bad += check_settled(g->at[M_QUEST][k][g->n], g->at[M_QUEST_SETTLED][k][g->n], spec, seed);
        bad += check_settled(g->at[M_QPLUS][0][g->n], g->at[M_QPLUS_SETTLED][0][g->n], spec, seed);
    }
    g->n++;
    return bad ? 1 : 0;
}

/* ---- the figures --------------------------------------------------------------------------- */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Quantile p of sorted v (linear between order statistics, as R's type 7). */
static double quantile(const double *v, int n, double p)
{
    if (n <= 0) return NAN;
    double h = (n - 1) * p;
    int i = (int)floor(h);
    return i + 1 < n ? v[i] + (h - i) * (v[i + 1] - v[i]) : v[n - 1];
}

typedef struct {
    double med, p90, ach_med;
    int n, n_capped;
} summary;

/* Trials (median, 90th percentile) and achieved RMS (median) of stops at[i * stride] over n. */
static summary summarise(const stop_at *at, int n, int stride)
{
    static int tr[MAX_SAMPLES * MAX_SETS];
    static double t[MAX_SAMPLES * MAX_SETS], a[MAX_SAMPLES * MAX_SETS];
    summary s = {NAN, NAN, NAN, n, 0};
    for (int i = 0; i < n; i++) {
        tr[i] = at[(size_t)i * stride].trials, a[i] = at[(size_t)i * stride].ach;
        s.n_capped += at[(size_t)i * stride].capped;
    }
    qsort(tr, (size_t)n, sizeof *tr, cmp_int);
    qsort(a, (size_t)n, sizeof *a, cmp_double);
    for (int i = 0; i < n; i++) t[i] = tr[i];
    s.med = quantile(t, n, 0.5), s.p90 = quantile(t, n, 0.9), s.ach_med = quantile(a, n, 0.5);
    return s;
}

/* Stops of one method at one level over groups g[0..n_g): gathered, then summarised. */
static summary pooled(const group *const *g, int n_g, int method, int sd, int level)
{
    static stop_at all[MAX_SAMPLES * MAX_SETS];
    int n = 0;
    for (int k = 0; k < n_g; k++)
        for (int i = 0; i < g[k]->n; i++) all[n++] = g[k]->at[method][sd][i][level];
    return summarise(all, n, 1);
}

/* The prior sd whose median (then 90th percentile) is least: QUEST's best, picked on these people. */
static int best_sd(const group *const *g, int n_g, int method, int level)
{
    int best = 0;
    summary sb = pooled(g, n_g, method, 0, level);
    for (int k = 1; k < N_SDS; k++) {
        summary s = pooled(g, n_g, method, k, level);
        if (s.med < sb.med || (s.med == sb.med && s.p90 < sb.p90)) best = k, sb = s;
    }
    return best;
}

/* "med / p90", a figure at the cap marked "+", and how many stops hit it. */
static void format_trials(const summary *s, int cap, char *buf, size_t len)
{
    char capped[32] = "";
    if (s->n_capped) snprintf(capped, sizeof capped, " [%d/%d capped]", s->n_capped, s->n);
    snprintf(buf, len, "%.0f%s / %.0f%s%s", s->med, s->med >= cap ? "+" : "", s->p90,
             s->p90 >= cap ? "+" : "", capped);
}

static int shift_index(void)
{
    for (int j = 0; j < PR_N_SHIFTS; j++)
        if (PR_SHIFTS[j] == RECOMMENDED_SHIFT) return j;
    return PR_N_SHIFTS - 1;
}

/* bayes's stated errors at a level: coverage, predicted/achieved, fail-open at the shift. */
static void format_stated(const group *const *g, int n_g, int level, char *buf, size_t len)
{
    coverage_tally t;
    memset(&t, 0, sizeof t);
    for (int k = 0; k < n_g; k++) {
        const coverage_tally *s = &g[k]->cov[level];
        t.n_vis += s->n_vis, t.covered += s->covered, t.pred_sq += s->pred_sq, t.ach_sq += s->ach_sq;
        t.fail_open[shift_index()] += s->fail_open[shift_index()];
    }
    double nv = t.n_vis ? (double)t.n_vis : 1.0;
    snprintf(buf, len, "%.1f %% | %.2f | %.1f %%", 100.0 * t.covered / nv,
             sqrt(t.pred_sq / (t.ach_sq > 0 ? t.ach_sq : 1)), 100.0 * t.fail_open[shift_index()] / nv);
}

/* An anchor at a level: first passage, settled, then matched ("med / p90 (sd)"); methods[3] are its
 * first, settled and matched stops. */
static void print_anchor(const options *op, const group *const *g, int n_g, const int methods[3], int level)
{
    static const char *const label[3] = {" ", "; settled ", "; matched "};
    for (int k = 0; k < 3; k++) {
        char b[96], sd[16] = "";
        int best = methods[0] == M_QUEST ? best_sd(g, n_g, methods[k], level) : 0;
        summary s = pooled(g, n_g, methods[k], best, level);
        format_trials(&s, op->cap, b, sizeof b);
        if (methods[0] == M_QUEST) snprintf(sd, sizeof sd, " (sd %.1f)", QUEST_SDS[best]);
        printf("%s%s%s", label[k], b, sd);
    }
    printf(" |");
}

static const int QUEST_STOPS[3] = {M_QUEST, M_QUEST_SETTLED, M_QUEST_MATCHED};
static const int QPLUS_STOPS[3] = {M_QPLUS, M_QPLUS_SETTLED, M_QPLUS_MATCHED};

/* One row of the table: the groups g[0..n_g) pooled (one set, or all of a layout's). */
static void print_row(const options *op, const char *label, int layout, const group *const *g, int n_g)
{
    int n = 0;
    for (int k = 0; k < n_g; k++) n += g[k]->n;
    printf("| %s | %d | %d |", label, layout, n);
    for (int l = 0; l < N_LEVELS; l++) {
        char b[96];
        summary s = pooled(g, n_g, M_BAYES, 0, l);
        format_trials(&s, op->cap, b, sizeof b);
        printf(" %s | %.3f |", b, s.ach_med);
    }
    for (int l = 0; l < N_LEVELS; l++) print_anchor(op, g, n_g, QUEST_STOPS, l);
    for (int l = 0; l < N_LEVELS; l++) print_anchor(op, g, n_g, QPLUS_STOPS, l);
    for (int l = 0; l < N_LEVELS; l++) {
        char b[96];
        format_stated(g, n_g, l, b, sizeof b);
        printf(" %s |", b);
    }
    printf("\n");
}

/* The efficiency targets over all sets of a layout: bayes's median against each anchor's, with the
 * anchors' first oracle stop at the level, their settled one, and the one matched to what bayes
 * achieved (the target asks for the anchors stopped "at the same achieved RMS"). */
static void print_targets(int layout, const group *const *g, int n_g)
{
    static const char *const stop_name[3] = {"first oracle", "settled", "matched"};
    for (int l = 0; l < N_LEVELS; l++) {
        summary b = pooled(g, n_g, M_BAYES, 0, l);
        for (int k = 0; k < 3; k++) {
            int mq = QUEST_STOPS[k], mp = QPLUS_STOPS[k];
            summary qp = pooled(g, n_g, mp, 0, l);
            int sd = best_sd(g, n_g, mq, l);
            summary qc = pooled(g, n_g, mq, sd, l);
            double r_qp = b.med / qp.med, r_qc = b.med / qc.med;
            printf("layout %d, to %.2f log10, all sets (%d sessions), anchors' %s stop: bayes median %.0f "
                   "trials; QUEST+ %.0f%s: %.2f x (target <= 0.6: %s); best QUEST (sd %.1f) %.0f%s: %.2f x "
                   "(target <= 0.35: %s)\n",
                   layout, LEVELS[l], b.n, stop_name[k], b.med, qp.med,
                   qp.med >= g[0]->cap_seen ? " (the cap)" : "", r_qp, r_qp <= 0.6 ? "met" : "NOT met",
                   QUEST_SDS[sd], qc.med, qc.med >= g[0]->cap_seen ? " (the cap)" : "", r_qc,
                   r_qc <= 0.35 ? "met" : "NOT met");
        }
    }
}

static void print_header(const options *op)
{
    printf(
        "Trials to a precision, held-out people (bench/data/README.md), seeds %d-%d (person s, method "
        "1000 + s), cap %d.\n"
        "bayes: stopped by its own predicted RMS (observer calibrate --precision), not told slope or lapse. "
        "QUEST (told slope and lapse; best prior sd picked on these people) and QUEST+ (told the lapse): "
        "stopped by an ORACLE, the first multiple of %d trials at which their achieved RMS against the "
        "truth reaches the level (first), the first from which it stays at or below the level up to "
        "the cap (settled), and the first at which it is no worse than what bayes achieved at its own "
        "stop on the same person and seed (matched). No session can know any of them: they flatter "
        "them. A figure at the cap is marked +.\n"
        "Trials: median / 90th percentile over people x seeds; ach: median achieved RMS at bayes's stop. "
        "Stated errors (bayes, at each level's stop): coverage of the 95 %% interval, predicted/achieved "
        "RMS, fail-open of the conservative view at the recommended shift K = %.1f.\n\n",
        op->first_seed, op->first_seed + op->seeds - 1, op->cap, op->every, RECOMMENDED_SHIFT);
    printf("| set | layout | sessions | bayes to 0.15 | ach | bayes to 0.10 | ach | QUEST to 0.15 (oracle) | "
           "QUEST to 0.10 (oracle) | QUEST+ to 0.15 (oracle) | QUEST+ to 0.10 (oracle) | coverage, 0.15 | "
           "pred/ach, 0.15 | fail-open, 0.15 | coverage, 0.10 | pred/ach, 0.10 | fail-open, 0.10 |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
}

/* A comma-separated list of integers lo..hi into v (at most max); the count, or -1. */
static int parse_list(const char *s, int lo, int hi, int *v, int max)
{
    int n = 0;
    while (*s) {
        char *end;
        long x = strtol(s, &end, 10);
        if (end == s || x < lo || x > hi || n == max || (*end && *end != ',')) return -1;
        v[n++] = (int)x;
        s = *end ? end + 1 : end;
    }
    return n;
}

/* An integer option lo..hi; 0, or -1 after saying what was wrong. */
static int parse_int(const char *name, const char *s, int lo, int hi, int *v)
{
    char *end;
    long x = strtol(s, &end, 10);
    if (end == s || *end || x < lo || x > hi) {
        fprintf(stderr, "bench_efficiency: %s '%s': expected a whole number from %d to %d\n", name, s, lo,
                hi);
        return -1;
    }
    *v = (int)x;
    return 0;
}

static int parse_args(int argc, char **argv, options *op)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--check")) {
            op->check = 1;
            continue;
        }
        if (!v) {
            fprintf(stderr, "bench_efficiency: unknown option or missing value: '%s'\n", a);
            return -1;
        }
        i++;
        int rc = 0;
        if (!strcmp(a, "--sets")) {
            op->n_sets = parse_list(v, 1, N_HONEST_SETS, op->sets, MAX_SETS);
            if (op->n_sets < 1)
                fprintf(stderr, "bench_efficiency: --sets '%s': expected set numbers 1-%d, comma-separated\n",
                        v, (int)N_HONEST_SETS);
            rc = op->n_sets < 1 ? -1 : 0;
        } else if (!strcmp(a, "--layouts")) {
            op->n_layouts = parse_list(v, 2, 4, op->layouts, 2);
            for (int k = 0; k < op->n_layouts; k++) rc |= op->layouts[k] == 3 ? -1 : 0;
            if (op->n_layouts < 1 || rc)
                fprintf(stderr, "bench_efficiency: --layouts '%s': expected 4, 2 or 4,2\n", v);
            rc = op->n_layouts < 1 || rc ? -1 : 0;
        } else if (!strcmp(a, "--seeds")) rc = parse_int(a, v, 1, MAX_SEEDS, &op->seeds);
        else if (!strcmp(a, "--first-seed")) rc = parse_int(a, v, 1, 1000000, &op->first_seed);
        else if (!strcmp(a, "--every")) rc = parse_int(a, v, 1, 100, &op->every);
        else if (!strcmp(a, "--cap")) rc = parse_int(a, v, PR_MIN_TRIALS, MAX_CHECKPOINTS, &op->cap);
        else if (!strcmp(a, "--people")) rc = parse_int(a, v, 1, MAX_HONEST_OBS, &op->people);
        else {
            fprintf(stderr, "bench_efficiency: unknown option '%s'\n", a);
            rc = -1;
        }
        if (rc) return -1;
    }
    return 0;
}

/* Every held-out person of set `set` (the first op->people) x seed, into g. 0, 1 (a check failed)
 * or -1. */
static int run_set(const options *op, int set, const csf_cell *cells, const int *n_alt, group *g)
{
    int bad = 0, taken = 0;
    for (int p = 0; p < HONEST_SETS[set - 1].n && taken < op->people; p++) {
        const honest_observer *h = &HONEST_SETS[set - 1].obs[p];
        if (!h->held_out) continue;
        taken++;
        for (int s = op->first_seed; s < op->first_seed + op->seeds; s++) {
            double t0 = now_s();
            int rc = run_person(op, h->spec, s, cells, n_alt, g);
            if (rc < 0) return -1;
            bad |= rc;
            fprintf(stderr, "  set %d, %s, seed %d: %.1f s\n", set, h->name, s, now_s() - t0);
        }
    }
    return bad;
}

int main(int argc, char **argv)
{
    options op = {.n_layouts = 2,
                  .layouts = {4, 2},
                  .seeds = 1,
                  .first_seed = 1,
                  .every = 5,
                  .cap = PR_CAP_PER_CELL * PR_CELLS,
                  .people = MAX_HONEST_OBS};
    for (int k = 0; k < (int)N_SEEN_SETS; k++) op.sets[k] = k + 1;
    op.n_sets = N_SEEN_SETS;
    if (parse_args(argc, argv, &op)) {
        fprintf(stderr,
                "usage: bench_efficiency [--sets 1,2,...] [--layouts 4,2] [--seeds 1-%d] [--first-seed S] "
                "[--every K] [--cap N] [--people N] [--check]\n",
                MAX_SEEDS);
        return 2;
    }
    if (!csf_procedure_find("bayes")) {
        fprintf(stderr, "bench_efficiency: this build has no bayes method\n");
        return 1;
    }
    static group groups[2][MAX_SETS];
    csf_cell cells[PR_CELLS];
    int bad = 0;
    print_header(&op);
    if (sim2afc_default_grid(cells) != PR_CELLS) return 1;
    for (int ly = 0; ly < op.n_layouts; ly++) {
        int n_alt[PR_CELLS];
        const group *g[MAX_SETS];
        if (sim2afc_default_layouts(cells, PR_CELLS, op.layouts[ly], n_alt)) return 1;
        for (int k = 0; k < op.n_sets; k++) {
            int rc = run_set(&op, op.sets[k], cells, n_alt, &groups[ly][k]);
            if (rc < 0) return 1;
            bad |= rc;
            char label[16];
            snprintf(label, sizeof label, "%d", op.sets[k]);
            g[k] = &groups[ly][k];
            print_row(&op, label, op.layouts[ly], &g[k], 1);
            fflush(stdout);
        }
        print_row(&op, "all", op.layouts[ly], g, op.n_sets);
    }
    printf("\n");
    for (int ly = 0; ly < op.n_layouts; ly++) {
        const group *g[MAX_SETS];
        for (int k = 0; k < op.n_sets; k++) g[k] = &groups[ly][k];
        print_targets(op.layouts[ly], g, op.n_sets);
    }
    return bad;
}
