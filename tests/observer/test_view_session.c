/* Whole sessions with the simulated person who looks at the rendered frames (`--observer
 * sim:view=frame`):
 *  (a) with the right profile its table equals the table of the same person told the planned
 *      contrast: over seeds, mean signed log10 difference and the difference in RMS error
 *      against the truth both within 0.02, and most seeds' tables identical;
 *  (b) a profile of one display used on another shifts the table by the contrast ratio the two
 *      displays predict at the background: ratio = (d ln L_true / d v) / (d ln L_profile / d v) at
 *      the drive v of the mean luminance (small-signal: the presenter draws L0 (1 + C) through the
 *      profile's inverse, the true display turns the drive into light);
 *  (c) a grating drawn at the wrong place is not found: four-place proportion correct near chance
 *      and the thresholds far higher (or never visible);
 *  (d) a flat frame (nothing drawn) gives chance.
 * Every session is headless (EGL surfaceless, Mesa llvmpipe). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/config.h"
#include "calib/observer_calib.h"
#include "model/display_model.h"
#include "model/observer_sim.h"
#include "results/csflut/csflut.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "tests/check.h"

static char dir[] = "/tmp/csfcal-viewtest-XXXXXX";
static const double freqs[6] = {0.5, 1, 2, 4, 8, 16};
static const double eccs[4] = {0, 5, 10, 20};
#define NF 6
#define NE 4

/* What reached the person, trial by trial (csf_obs_options.seen_hook): log10(seen / reported)
 * at the place or interval with the grating, and the most seen where nothing was drawn. */
typedef struct {
    int n;
    double sum, sum_abs, max_abs, empty_max_rel;
} seen_stats;

static void on_seen(void *ctx, int n, const double *seen, const double *reported)
{
    seen_stats *s = ctx;
    int sig = -1;
    for (int k = 0; k < n; k++)
        if (reported[k] > 0) sig = k;
    if (sig < 0) return;
    double d = log10(seen[sig] / reported[sig]);
    s->n++;
    s->sum += d;
    s->sum_abs += fabs(d);
    if (fabs(d) > s->max_abs) s->max_abs = fabs(d);
    for (int k = 0; k < n; k++)
        if (k != sig && seen[k] / reported[sig] > s->empty_max_rel) s->empty_max_rel = seen[k] / reported[sig];
}

typedef struct {
    seen_stats seen;
    double log10_th[NE][NF]; /* +INFINITY: never visible */
    int have_table;
    int afc4_correct, afc4_n;   /* main four-place trials */
    int afc2_correct, afc2_n;   /* main two-interval trials */
    double wall_s;
} outcome;

static int run(const char *observer, int afc, uint64_t seed, int trials, double fault_polar, int fault_blank,
               const char *name, outcome *o)
{
    memset(o, 0, sizeof *o);
    char out[512], store[512];
    snprintf(out, sizeof out, "%s/%s.csflut", dir, name);
    snprintf(store, sizeof store, "%s/%s.sqlite", dir, name);
    csf_config cfg;
    csf_config_defaults(&cfg);
    csf_obs_options opt;
    csf_obs_options_defaults(&opt);
    opt.cfg = &cfg;
    opt.observer_spec = observer;
    opt.method = "bayes";
    opt.out_path = out;
    opt.store_path = store;
    memcpy(opt.freqs_cpd, freqs, sizeof freqs);
    opt.n_freqs = NF;
    memcpy(opt.eccs_deg, eccs, sizeof eccs);
    opt.n_eccs = NE;
    opt.trials = trials;
    opt.seed = seed;
    opt.headless = 1;
    opt.quiet = 1;
    opt.afc = afc;
    opt.fault_polar_offset_deg = fault_polar;
    opt.fault_blank = fault_blank;
    opt.seen_hook = on_seen;
    opt.seen_hook_ctx = &o->seen;
    csf_obs_result res;
    csf_error err;
    csf_status st = csf_observer_calibrate(&opt, &res, &err);
    o->wall_s = res.wall_s;
    if (st != CSF_OK && st != CSF_E_INSUFFICIENT) {
        fprintf(stderr, "%s: session failed: %s\n", name, err.msg);
        return -1;
    }
    if (st == CSF_OK) {
        csflut_table *t = NULL;
        if (csflut_open_file(out, &t) != CSFLUT_OK) return -1;
        csflut_set_conservative(t, 0);
        for (int e = 0; e < NE; e++)
            for (int f = 0; f < NF; f++) {
                double th = csflut_threshold(t, freqs[f], eccs[e]);
                o->log10_th[e][f] = isfinite(th) && th < 1 ? log10(th) : INFINITY;
            }
        csflut_close(t);
        o->have_table = 1;
    }
    csf_store *s = NULL;
    if (csf_store_open(store, &s, &err) != CSF_OK) return -1;
    csf_trial *tr = NULL;
    size_t n = 0;
    if (csf_store_get_trials(s, res.session_id, &tr, &n, &err) != CSF_OK) {
        csf_store_close(s);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        if (tr[i].is_practice || tr[i].signal_interval <= 0) continue;
        int ok = tr[i].response == tr[i].signal_interval;
        if (tr[i].n_alternatives == 4) o->afc4_correct += ok, o->afc4_n++;
        else o->afc2_correct += ok, o->afc2_n++;
    }
    free(tr);
    csf_store_close(s);
    return 0;
}

/* Mean and max |log10 b - log10 a| over cells visible in both (and the count). */
static double table_diff(const outcome *a, const outcome *b, double *max_abs, double *mean_signed, int *n)
{
    double sum = 0, ssum = 0, mx = 0;
    int k = 0;
    for (int e = 0; e < NE; e++)
        for (int f = 0; f < NF; f++) {
            double x = a->log10_th[e][f], y = b->log10_th[e][f];
            if (!isfinite(x) || !isfinite(y)) continue;
            sum += fabs(y - x);
            ssum += y - x;
            if (fabs(y - x) > mx) mx = fabs(y - x);
            k++;
        }
    *max_abs = mx;
    *mean_signed = k ? ssum / k : NAN;
    *n = k;
    return k ? sum / k : NAN;
}

/* Seeds per comparison (CSF_VIEW_SEEDS overrides, for the benchmark's longer runs). */
static int n_seeds(void)
{
    const char *v = getenv("CSF_VIEW_SEEDS");
    int n = v ? atoi(v) : 6;
    return n < 2 ? 2 : n > 64 ? 64 : n;
}

/* RMS over cells of log10(table / truth), cells finite in both; truth from the same spec. */
static double rms_vs_truth(const outcome *o, const char *spec, uint64_t seed)
{
    csf_observer_sim *sim = NULL;
    csf_error e;
    if (csf_observer_sim_create(spec, seed, &sim, &e) != CSF_OK) return NAN;
    double ss = 0;
    int k = 0;
    for (int ei = 0; ei < NE; ei++)
        for (int f = 0; f < NF; f++) {
            double t = csf_observer_sim_threshold(sim, freqs[f], eccs[ei]);
            if (!isfinite(t) || t >= 1 || !isfinite(o->log10_th[ei][f])) continue;
            ss += pow(o->log10_th[ei][f] - log10(t), 2);
            k++;
        }
    csf_observer_sim_free(sim);
    return k ? sqrt(ss / k) : NAN;
}

/* (a) the right profile: rendered-frame person == planned-contrast person, over seeds. With the
 * same seed both people draw the same numbers, so their answers agree trial for trial unless a
 * draw falls between the probability of the contrast seen (a fraction of a percent off, from
 * quantisation and dithering) and that of the contrast planned. After such a flip the adaptive
 * method takes another path and that session's table differs by the method's own noise (mean
 * |d| ~0.1 log10), which says nothing about what reached the eye. So "equal within 0.02" is
 * checked as a statement about the expected table: over seeds, no bias (mean signed difference
 * over every cell of every session) and no loss of accuracy against the truth; and most sessions'
 * tables are identical, which a frame that showed anything but the planned contrast would not
 * give. */
static void test_right_profile(outcome *frame_afc4 /* [seeds] */)
{
    static const struct {
        const char *plan, *frame;
        int afc;
    } people[] = {
        {"sim", "sim:view=frame", 4},
        {"sim:decision=sdt,slope=2.2,lapse=0.05", "sim:decision=sdt,slope=2.2,lapse=0.05,view=frame", 2},
    };
    const int seeds = n_seeds();
    for (size_t i = 0; i < sizeof people / sizeof people[0]; i++) {
        int identical = 0, cells = 0;
        double signed_sum = 0, abs_mean_sum = 0, rms_plan = 0, rms_frame = 0, frame_s = 0, plan_s = 0;
        for (int s = 1; s <= seeds; s++) {
            outcome plan, frame;
            char n1[32], n2[32];
            snprintf(n1, sizeof n1, "plan%zu_%d", i, s);
            snprintf(n2, sizeof n2, "frame%zu_%d", i, s);
            CHECK(run(people[i].plan, people[i].afc, (uint64_t)s, 120, 0, 0, n1, &plan) == 0);
            CHECK(run(people[i].frame, people[i].afc, (uint64_t)s, 120, 0, 0, n2, &frame) == 0);
            CHECK(plan.have_table && frame.have_table);
            double mx, ms;
            int n;
            double mean = table_diff(&plan, &frame, &mx, &ms, &n);
            CHECK(n >= 12);
            identical += mx < 1e-9;
            cells += n;
            signed_sum += ms * n;
            abs_mean_sum += mean;
            double rp = rms_vs_truth(&plan, people[i].plan, (uint64_t)s);
            double rf = rms_vs_truth(&frame, people[i].plan, (uint64_t)s);
            rms_plan += rp;
            rms_frame += rf;
            frame_s += frame.wall_s;
            plan_s += plan.wall_s;
            const seen_stats *ss = &frame.seen;
            CHECK(ss->n >= 100);
            CHECK_MSG(ss->sum_abs / ss->n <= 0.01, "seed %d: seen differs from reported by %.4f log10 per trial", s,
                      ss->sum_abs / ss->n);
            CHECK_MSG(ss->empty_max_rel < 0.1, "seed %d: an empty place showed %.3f of the grating's contrast", s,
                      ss->empty_max_rel);
            printf("(a) %s, --afc %d, seed %d: %d cells, mean |d| %.4f, signed %+.4f, max %.4f log10; RMS vs "
                   "truth %.4f (frame) / %.4f (plan); seen vs reported %.4f log10 per trial over %d trials\n",
                   people[i].frame, people[i].afc, s, n, mean, ms, mx, rf, rp, ss->sum_abs / ss->n, ss->n);
            if (i == 0) frame_afc4[s - 1] = frame;
        }
        double bias = signed_sum / cells, d_rms = (rms_frame - rms_plan) / seeds;
        printf("(a) %s, --afc %d, %d seeds: identical tables %d; mean over seeds of mean |d| %.4f; mean signed d "
               "%+.4f over %d cells; RMS vs truth %.4f (frame) vs %.4f (plan); sessions %.2f s vs %.2f s\n",
               people[i].frame, people[i].afc, seeds, identical, abs_mean_sum / seeds, bias, cells,
               rms_frame / seeds, rms_plan / seeds, frame_s / seeds, plan_s / seeds);
        /* A diverged seed moves the mean signed d by ~±0.05 / seeds, the RMS by ~±0.02 / seeds. */
        CHECK_MSG(fabs(bias) <= 0.02, "rendered-frame tables sit %+.4f log10 from the planned ones", bias);
        CHECK_MSG(fabs(d_rms) <= 0.02, "rendered-frame tables' RMS error differs by %+.4f log10", d_rms);
        /* 15 % of two-interval seeds diverged over 20 (BENCHMARKS.md); half is far out. */
        CHECK_MSG(2 * identical >= seeds, "only %d of %d seeds gave identical tables", identical, seeds);
    }
}

/* d ln L / d v of a grey curve, numerically. */
static double log_slope(double (*lum)(const void *, double), const void *ctx, double v)
{
    const double h = 1e-4;
    return (log(lum(ctx, v + h)) - log(lum(ctx, v - h))) / (2 * h);
}
static double prof_grey(const void *ctx, double v) { return csf_profile_grey_lum(ctx, v); }
static double model_grey(const void *ctx, double v) { return csf_display_model_lum(ctx, v, v, v); }

/* (b) the default profile (a gamma-2.2 display) used on a CRT of gamma 2.8. */
static void test_wrong_profile(const outcome *right /* [seeds] */)
{
    csf_display_profile *prof = csf_profile_default();
    csf_display_model *crt = NULL;
    csf_error e;
    CHECK(prof && csf_display_model_create("crt,gamma=2.8", &crt, &e) == CSF_OK);
    if (!prof || !crt) return;
    double mean_lum = 0.5 * (csf_profile_lum_black(prof) + csf_profile_lum_max(prof));
    double v0 = csf_profile_grey_drive(prof, mean_lum);
    double ratio = log_slope(model_grey, crt, v0) / log_slope(prof_grey, prof, v0);
    /* the person sees ratio x the planned contrast, so the table holds threshold / ratio */
    double predicted = -log10(ratio);
    CHECK(fabs(predicted) > 0.1); /* a shift the test can see */
    /* The person behind the wrong profile answers like a person `ratio` times more sensitive
     * behind the right one (smax x ratio scales every threshold by 1 / ratio). Trial for trial
     * with the same seed the two sessions agree until one answer flips on a contrast seen a little
     * off ratio x reported; after that the paths differ by the method's own noise. So, over seeds:
     * what reaches the person is ratio x the reported contrast (to the small-signal approximation;
     * the sessions' contrasts are mostly below 10 %), the mean signed difference from the
     * equivalent person vanishes (a table that did not follow the physics would sit the whole
     * predicted shift, > 0.1, away), and the mean shift against the right-profile tables of (a)
     * is the predicted one to within the seed-to-seed noise of one session's mean (~0.07 log10
     * per diverged seed). */
    const int seeds = n_seeds();
    int cells = 0, shift_cells = 0;
    double seen_sum = 0, signed_sum = 0, shift_sum = 0;
    int seen_n = 0;
    for (int s = 1; s <= seeds; s++) {
        outcome wrong, equiv;
        char n1[32], n2[32], spec[128];
        snprintf(n1, sizeof n1, "wrong_%d", s);
        snprintf(n2, sizeof n2, "equiv_%d", s);
        CHECK(run("sim:view=frame,display=crt,display_gamma=2.8", 4, (uint64_t)s, 120, 0, 0, n1, &wrong) == 0);
        snprintf(spec, sizeof spec, "sim:view=frame,smax=%.6g", 250.0 * ratio);
        CHECK(run(spec, 4, (uint64_t)s, 120, 0, 0, n2, &equiv) == 0);
        seen_sum += wrong.seen.sum;
        seen_n += wrong.seen.n;
        CHECK(wrong.seen.n >= 100);
        double mx, ms;
        int n;
        double mean = table_diff(&equiv, &wrong, &mx, &ms, &n);
        CHECK(n >= 12);
        cells += n;
        signed_sum += ms * n;
        double smx, sms;
        int sn;
        table_diff(&right[s - 1], &wrong, &smx, &sms, &sn);
        shift_cells += sn;
        shift_sum += sms * sn;
        printf("(b) seed %d: seen/reported %+.4f log10 over %d trials; vs the equivalent person mean |d| %.4f, "
               "signed %+.4f, max %.4f over %d cells; shift against the right profile %+.4f\n", s,
               wrong.seen.sum / wrong.seen.n, wrong.seen.n, mean, ms, mx, n, sms);
    }
    double seen_log = seen_sum / seen_n, bias = signed_sum / cells, shift = shift_sum / shift_cells;
    printf("(b) default profile on a gamma-2.8 CRT, %d seeds: predicted contrast ratio %.4f (%+.4f log10), seen/"
           "reported %+.4f; vs the equivalent person mean signed %+.4f over %d cells; shift against the right "
           "profile %+.4f (predicted %+.4f)\n", seeds, ratio, log10(ratio), seen_log, bias, cells, shift, predicted);
    CHECK_MSG(fabs(seen_log - log10(ratio)) <= 0.01, "seen/reported %+.4f log10, predicted %+.4f", seen_log,
              log10(ratio));
    /* Per diverged seed the mean signed difference spreads with sd ~0.03 (12 seeds, -0.083 to
     * +0.030; BENCHMARKS.md), ~0.013 over six: 0.04 is three of those, a third of the shift a
     * table that ignored the display would show. */
    CHECK_MSG(fabs(bias) <= 0.04, "wrong-profile tables vs the equivalent person: mean signed %+.4f log10", bias);
    CHECK_MSG(fabs(shift - predicted) <= 0.5 * fabs(predicted), "shift %+.4f log10, predicted %+.4f", shift,
              predicted);
    csf_display_model_free(crt);
    csf_profile_free(prof);
}

/* (c) every grating drawn 45 deg of polar angle from its place: between two of the four places,
 * at 3.8 deg from each at 5 deg eccentricity; off the single place of two-interval cells. */
static void test_wrong_place(const outcome *right)
{
    outcome o;
    CHECK(run("sim:view=frame", 4, 1, 120, 45, 0, "misplaced", &o) == 0);
    double pc = o.afc4_n ? (double)o.afc4_correct / o.afc4_n : NAN;
    printf("(c) misplaced gratings: four-place proportion correct %.3f (%d trials; chance 0.25, the "
           "right place %.3f)\n", pc, o.afc4_n, right->afc4_n ? (double)right->afc4_correct / right->afc4_n : NAN);
    CHECK(o.afc4_n >= 20); /* the method soon stops showing cells it finds invisible */
    CHECK_MSG(pc < 0.4, "proportion correct %.3f with the gratings drawn off their places", pc);
    int n = 0, higher = 0;
    for (int e = 1; e < NE; e++) /* at 0 deg a polar rotation does not move the grating */
        for (int f = 0; f < NF; f++) {
            if (!isfinite(right->log10_th[e][f])) continue;
            n++;
            double x = o.have_table ? o.log10_th[e][f] : INFINITY;
            higher += !isfinite(x) || x - right->log10_th[e][f] >= 0.5;
        }
    printf("(c) %d of %d visible peripheral cells never visible or >= 0.5 log10 higher\n", higher, n);
    CHECK(n >= 8);
    CHECK_MSG(higher >= n - 1, "only %d of %d cells far higher", higher, n);
}

/* (d) nothing drawn: chance in every forced choice. No cell may read a threshold a person could
 * have: a cell the table calls visible sits at 0.25 Michelson contrast or more (1.5 log10 or more
 * above a normal observer's threshold at 4 cpd). With about 5 chance answers a cell, one cell can
 * come out just under the reach: 16 cpd at the fovea at 0.40 before the surface's frequency
 * scaling, 4 cpd at the fovea at 0.29 with it (this seed). */
static void test_flat_frame(void)
{
    outcome o;
    CHECK(run("sim:view=frame", 4, 3, 120, 0, 1, "flat", &o) == 0);
    double expect = 0.25 * o.afc4_n + 0.5 * o.afc2_n, var = 0.1875 * o.afc4_n + 0.25 * o.afc2_n;
    int correct = o.afc4_correct + o.afc2_correct;
    printf("(d) flat frames: %d of %d correct, chance %.1f +- %.1f\n", correct, o.afc4_n + o.afc2_n, expect,
           sqrt(var));
    CHECK(o.afc4_n + o.afc2_n >= 100);
    CHECK_MSG(fabs(correct - expect) <= 3 * sqrt(var), "%d correct, chance %.1f", correct, expect);
    if (o.have_table)
        for (int e = 0; e < NE; e++)
            for (int f = 0; f < NF; f++)
                CHECK_MSG(!isfinite(o.log10_th[e][f]) || o.log10_th[e][f] > log10(0.25),
                          "flat frames: %g cpd at %g deg visible at %.3g", freqs[f], eccs[e],
                          pow(10, o.log10_th[e][f]));
}

int main(void)
{
    if (!mkdtemp(dir)) return 2;
    outcome *right = calloc((size_t)n_seeds(), sizeof *right);
    if (!right) return 2;
    test_right_profile(right);
    int all = 1;
    for (int s = 0; s < n_seeds(); s++) all &= right[s].have_table;
    if (all) {
        test_wrong_profile(right);
        test_wrong_place(&right[0]);
    }
    free(right);
    test_flat_frame();
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return CHECK_RESULT();
}
