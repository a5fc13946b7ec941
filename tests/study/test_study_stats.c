/* Study statistics (studies/study_stats.h) against values computed independently: exact
 * binomial sums in Python's integer arithmetic (math.comb; the interval ends by bisection on the
 * tail sums, as binom.test defines them), Macmillan & Creelman's d' definitions, and Weibull fits
 * of data drawn from known psychometric functions. */
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/rng.h"
#include "studies/study_plot.h"
#include "studies/study_stats.h"
#include "tests/check.h"

static void test_normal(void)
{
    CHECK_NEAR(csf_stats_norm_cdf(1.959963984540054), 0.975, 1e-12);
    CHECK_NEAR(csf_stats_norm_quantile(0.975), 1.959963984540054, 1e-9);
    CHECK_NEAR(csf_stats_norm_quantile(1e-10), -6.361340902404056, 1e-7);
    CHECK_NEAR(csf_stats_norm_quantile(0.5), 0, 1e-12);
}

static void test_clopper_pearson(void)
{
    double lo, hi;
    /* 5 of 10: 0.1870860, 0.8129140 */
    csf_stats_clopper_pearson(5, 10, 0.95, &lo, &hi);
    CHECK_NEAR(lo, 0.1870860, 1e-6);
    CHECK_NEAR(hi, 0.8129140, 1e-6);
    /* 0 of 20: 0, 0.1684335 */
    csf_stats_clopper_pearson(0, 20, 0.95, &lo, &hi);
    CHECK(lo == 0);
    CHECK_NEAR(hi, 0.1684335, 1e-6);
    /* 38 of 40: 0.83080314, 0.99388635 */
    csf_stats_clopper_pearson(38, 40, 0.95, &lo, &hi);
    CHECK_NEAR(lo, 0.83080314, 1e-7);
    CHECK_NEAR(hi, 0.99388635, 1e-7);
    csf_stats_clopper_pearson(40, 40, 0.95, &lo, &hi);
    CHECK(hi == 1);
    /* exact coverage: for n = 30 and p = 0.3 the interval covers p with probability >= 0.95 */
    double cover = 0;
    for (int k = 0; k <= 30; k++) {
        csf_stats_clopper_pearson(k, 30, 0.95, &lo, &hi);
        double pk = exp(lgamma(31) - lgamma(k + 1) - lgamma(31 - k) + k * log(0.3) + (30 - k) * log(0.7));
        if (lo <= 0.3 && 0.3 <= hi) cover += pk;
    }
    CHECK_MSG(cover >= 0.95, "coverage %g", cover);
}

static void test_binomial(void)
{
    /* P(X >= 8 | 10, 0.5) = 56/1024 */
    CHECK_NEAR(csf_stats_binom_p_greater(8, 10, 0.5), 0.0546875, 1e-12);
    /* two-sided: 112/1024 */
    CHECK_NEAR(csf_stats_binom_p_two_sided(8, 10, 0.5), 0.109375, 1e-12);
    /* 3 of 20 against 0.3: the outcomes no likelier than 3 sum to 0.22041827 */
    CHECK_NEAR(csf_stats_binom_p_two_sided(3, 20, 0.3), 0.22041827, 1e-7);
    CHECK_NEAR(csf_stats_binom_p_greater(0, 10, 0.5), 1, 0);
}

static void test_dprime(void)
{
    /* yes/no: H = 0.84134, F = 0.15866 -> d' = 2 */
    CHECK_NEAR(csf_stats_dprime_yesno(csf_stats_norm_cdf(1), csf_stats_norm_cdf(-1)), 2, 1e-9);
    /* differencing model: build H and F from d' = 2 and criterion k = 1.5, then invert */
    double k = 1.5, d = 2;
    double f = 2 * csf_stats_norm_cdf(-k / M_SQRT2);
    double h = csf_stats_norm_cdf((d - k) / M_SQRT2) + csf_stats_norm_cdf((-d - k) / M_SQRT2);
    CHECK_NEAR(csf_stats_dprime_sd_differencing(h, f), 2, 1e-6);
    /* independent observations, unbiased: p(c) = Phi(d/2)^2 + Phi(-d/2)^2; with H = p(c) and
     * F = 1 - p(c) the model gives d back */
    double pc = pow(csf_stats_norm_cdf(1), 2) + pow(csf_stats_norm_cdf(-1), 2);
    CHECK_NEAR(csf_stats_dprime_sd_independent(pc, 1 - pc), 2, 1e-6);
    /* same/different needs more hits than false alarms */
    CHECK(isnan(csf_stats_dprime_sd_differencing(0.3, 0.4)));
    /* the same rates mean a larger d' under differencing than under IO (M&C ch. 9) */
    CHECK(csf_stats_dprime_sd_differencing(0.7, 0.2) > csf_stats_dprime_sd_independent(0.7, 0.2));
}

/* Data drawn from a known Weibull; the ML fit must recover it, and the bootstrap interval must
 * hold the truth in about 95 % of repeated experiments. */
static void test_fit(void)
{
    const double t = -2.0, beta = 3.5, lapse = 0.02;
    csf_psy_level lv[7];
    int covered = 0, runs = 40;
    double sum_t = 0;
    for (int r = 0; r < runs; r++) {
        csf_rng g;
        csf_rng_init(&g, 100 + (uint64_t)r, 3);
        for (int i = 0; i < 7; i++) {
            lv[i].x_log10 = t - 0.45 + 0.15 * i;
            lv[i].n = 60;
            double p = 0.5 + (0.5 - lapse) * (1 - exp(-pow(10, beta * (lv[i].x_log10 - t))));
            lv[i].k = 0;
            for (int j = 0; j < lv[i].n; j++) lv[i].k += csf_rng_next_uniform(&g) < p;
        }
        csf_weibull_fit f;
        CHECK(csf_weibull_fit_ml(lv, 7, 0.5, 0.06, &f) == 0);
        sum_t += f.t_log10;
        double tl, th, bl, bh;
        int ok = csf_weibull_bootstrap(lv, 7, &f, 0.06, 100, 7 + (uint64_t)r, 0.95, &tl, &th, &bl, &bh);
        CHECK(ok >= 95);
        CHECK(tl <= f.t_log10 && f.t_log10 <= th);
        covered += tl <= t && t <= th;
    }
    CHECK_NEAR(sum_t / runs, t, 0.02);
    /* 40 runs at 95 %: fewer than 33 covered has probability < 0.2 % */
    CHECK_MSG(covered >= 33, "bootstrap covered the truth in %d of %d runs", covered, runs);
    /* nothing to fit */
    csf_weibull_fit f;
    lv[0].n = 10;
    CHECK(csf_weibull_fit_ml(lv, 1, 0.5, 0.06, &f) == -1);
}

/* 2AFC log likelihood and its brute-force reference computations (plain loops over fine grids,
 * independent of the library's simplex and grids). */
static double ll2afc(const csf_psy_level *lv, int n, double t, double beta, double lapse)
{
    double s = 0;
    for (int i = 0; i < n; i++) {
        double p = 0.5 + (0.5 - lapse) * (1 - exp(-pow(10, beta * (lv[i].x_log10 - t))));
        if (p > 1 - 1e-12) p = 1 - 1e-12;
        s += lv[i].k * log(p) + (lv[i].n - lv[i].k) * log1p(-p);
    }
    return s;
}

static double brute_profile_t(const csf_psy_level *lv, int n, double t)
{
    double best = -INFINITY;
    for (int i = 0; i <= 400; i++)
        for (int j = 0; j <= 60; j++) {
            double v = ll2afc(lv, n, t, 0.5 * pow(40.0, i / 400.0), 0.001 * j);
            if (v > best) best = v;
        }
    return best;
}

/* The report's interval (marginal posterior, flat in t, width 1/beta and lapse) against a brute
 * force posterior on a finer, differently laid out grid (t by 0.002, beta uniform in 1/beta, lapse
 * by 0.0025); the profile interval's ends against the brute-force profile deviance (3.84 there);
 * coverage of both over repeated experiments. */
static void test_intervals(void)
{
    const double t = -2.0, beta = 3.5, lapse = 0.02;
    csf_psy_level lv[6];
    int cov_m = 0, cov_p = 0, runs = 40;
    for (int r = 0; r < runs; r++) {
        csf_rng g;
        csf_rng_init(&g, 500 + (uint64_t)r, 3);
        for (int i = 0; i < 6; i++) {
            lv[i].x_log10 = t - 0.45 + 0.15 * i;
            lv[i].n = 40;
            double p = 0.5 + (0.5 - lapse) * (1 - exp(-pow(10, beta * (lv[i].x_log10 - t))));
            lv[i].k = 0;
            for (int j = 0; j < lv[i].n; j++) lv[i].k += csf_rng_next_uniform(&g) < p;
        }
        csf_weibull_fit f;
        CHECK(csf_weibull_fit_ml(lv, 6, 0.5, 0.06, &f) == 0);
        double tl, th, bl, bh, pl, ph, x0, x1;
        CHECK(csf_weibull_marginal_ci(lv, 6, &f, 0.06, 0.95, &tl, &th, &bl, &bh) == 0);
        CHECK(tl < th && bl < bh && bl >= 0.5 && bh <= 20);
        CHECK(csf_weibull_profile_ci(lv, 6, &f, 0.06, 0.95, &pl, &ph, &x0, &x1) >= 0);
        CHECK(pl <= f.t_log10 && f.t_log10 <= ph);
        cov_m += tl <= t && t <= th;
        cov_p += pl <= t && t <= ph;
        if (r < 2) {
            /* brute-force posterior of t: t over the estimate +- 0.4 by 0.002 (the mass beyond is
             * below 1e-6 here), w = 1/beta uniform over [1/20, 2] (flat in the width) in 300
             * cells, lapse over [0, 0.06] by 0.005 */
            enum { NT = 401 };
            double mt[NT], t0 = f.t_log10 - 0.4, tot = 0;
            for (int i = 0; i < NT; i++) {
                double tt = t0 + 0.002 * i, m = 0;
                for (int j = 0; j < 300; j++) {
                    double b = 1 / (0.05 + (2 - 0.05) * (j + 0.5) / 300);
                    for (int l = 0; l <= 12; l++) m += exp(ll2afc(lv, 6, tt, b, 0.005 * l) - f.loglik);
                }
                mt[i] = m;
                tot += m;
            }
            double c = 0, q_lo = NAN, q_hi = NAN;
            for (int i = 0; i < NT; i++) {
                c += mt[i] / tot;
                if (isnan(q_lo) && c >= 0.025) q_lo = t0 + 0.002 * i;
                if (isnan(q_hi) && c >= 0.975) q_hi = t0 + 0.002 * i;
            }
            CHECK_MSG(fabs(tl - q_lo) < 0.006 && fabs(th - q_hi) < 0.006, "run %d: marginal [%.4f, %.4f], brute "
                      "force [%.4f, %.4f]", r, tl, th, q_lo, q_hi);
            printf("run %d: marginal [%.4f, %.4f], brute force [%.4f, %.4f]\n", r, tl, th, q_lo, q_hi);
            double top = brute_profile_t(lv, 6, f.t_log10);
            CHECK_NEAR(2 * (top - brute_profile_t(lv, 6, pl)), 3.8415, 0.05);
            CHECK_NEAR(2 * (top - brute_profile_t(lv, 6, ph)), 3.8415, 0.05);
        }
    }
    /* 40 runs at 95 %: fewer than 33 covered has probability < 0.2 % */
    CHECK_MSG(cov_m >= 33, "marginal interval covered the truth in %d of %d runs", cov_m, runs);
    CHECK_MSG(cov_p >= 33, "profile interval covered the truth in %d of %d runs", cov_p, runs);
    double a, b, c, d;
    csf_weibull_fit f = {.t_log10 = -2, .beta = 3, .lapse = 0, .guess = 0.5};
    CHECK(csf_weibull_marginal_ci(lv, 1, &f, 0.06, 0.95, &a, &b, &c, &d) == -1 && isnan(a));
    CHECK(csf_weibull_marginal_ci(lv, 6, &f, 0.06, 1.5, &a, &b, &c, &d) == -1);
}

/* Fisher's exact test of hits against false alarms, against exact hypergeometric sums (Python,
 * fractions and math.comb; the two-sided rule as R's fisher.test). */
static void test_fisher(void)
{
    CHECK_NEAR(csf_stats_fisher_greater(15, 20, 5, 20), 0.0019237636541887641, 1e-12);
    CHECK_NEAR(csf_stats_fisher_two_sided(15, 20, 5, 20), 0.0038475273083775283, 1e-12);
    CHECK_NEAR(csf_stats_fisher_greater(3, 10, 8, 10), 0.9972612526792093, 1e-12);
    CHECK_NEAR(csf_stats_fisher_two_sided(3, 10, 8, 10), 0.06977851869492736, 1e-12);
    CHECK_NEAR(csf_stats_fisher_greater(40, 60, 12, 20), 0.3886752524910985, 1e-12);
    CHECK_NEAR(csf_stats_fisher_two_sided(40, 60, 12, 20), 0.5988132945627055, 1e-12);
    CHECK_NEAR(csf_stats_fisher_greater(0, 5, 0, 5), 1.0, 1e-12);
    CHECK_NEAR(csf_stats_fisher_greater(5, 5, 0, 5), 0.003968253968253968, 1e-12);
    CHECK_NEAR(csf_stats_fisher_greater(3, 0, 1, 5), 1.0, 0); /* no signal trials: nothing to test */
}

/* Observers who cannot see the stimulus, with any bias (a "yes" rate from 0.02 to 0.98, as an
 * observer who always says yes has 0.9): 1000 yes/no sessions of 60 signal and 20 catch trials.
 * Hits against false alarms calls at most 5 % of them able to see at p < 0.05; hits against 0.5,
 * the test a yes/no report must not use, calls far more. */
static void test_yesno_blind(void)
{
    csf_rng rng;
    csf_rng_init(&rng, 2024, 7);
    int fisher_pos = 0, binom_pos = 0;
    for (int i = 0; i < 1000; i++) {
        double p_yes = 0.02 + 0.96 * csf_rng_next_uniform(&rng);
        int hits = 0, fa = 0;
        for (int j = 0; j < 60; j++) hits += csf_rng_next_uniform(&rng) < p_yes;
        for (int j = 0; j < 20; j++) fa += csf_rng_next_uniform(&rng) < p_yes;
        fisher_pos += csf_stats_fisher_greater(hits, 60, fa, 20) < 0.05;
        binom_pos += csf_stats_binom_p_greater(hits, 60, 0.5) < 0.05;
    }
    CHECK_MSG(fisher_pos <= 50, "%d of 1000 blind observers called able to see", fisher_pos);
    CHECK_MSG(binom_pos > 300, "the binomial test against 0.5 called only %d of 1000", binom_pos);
}

/* d' interval: the Gourevitch & Galanter variance, computed here from its definition. */
static void test_dprime_ci(void)
{
    double lo, hi, h = 0.8, f = 0.2;
    csf_stats_dprime_yesno_ci(h, f, 50, 40, 0.95, &lo, &hi);
    double zh = csf_stats_norm_quantile(h), zf = csf_stats_norm_quantile(f);
    double ph = exp(-zh * zh / 2) / sqrt(2 * M_PI), pf = exp(-zf * zf / 2) / sqrt(2 * M_PI);
    double se = sqrt(h * (1 - h) / (50 * ph * ph) + f * (1 - f) / (40 * pf * pf));
    CHECK_NEAR(0.5 * (lo + hi), zh - zf, 1e-12);
    CHECK_NEAR(0.5 * (hi - lo), 1.959963984540054 * se, 1e-9);
    csf_stats_dprime_yesno_ci(1.0, 0.2, 50, 40, 0.95, &lo, &hi);
    CHECK(isnan(lo) && isnan(hi));
}

static double corrected(int k, int n)
{
    return k == 0 ? 0.5 / n : k == n ? 1 - 0.5 / n : (double)k / n;
}

/* Same/different d' intervals. Differencing: data drawn from the model itself (written out here:
 * F = 2 Phi(-k/sqrt 2), H = Phi((d-k)/sqrt 2) + Phi((-d-k)/sqrt 2)) at d' = 1.5 and at d' = 0
 * must be covered at about the nominal 95 % (1000 simulated participants each, 60 + 60 trials;
 * the binomial band of 1000 draws at 95 % is 93.6-96.4 %, the bounds allow a little more for the
 * discreteness of 60 trials); the interval holds the point estimate; swapped rates give it mirrored.
 * Independent: the ends are that model's d' at the rates whose z(H) - z(F) is the yes/no
 * interval's ends. */
static void test_dprime_sd_ci(void)
{
    const double truth[2] = {1.5, 0};
    for (int c = 0; c < 2; c++) {
        double k = -M_SQRT2 * csf_stats_norm_quantile(0.1);
        double pf = 2 * csf_stats_norm_cdf(-k / M_SQRT2);
        double ph =
            csf_stats_norm_cdf((truth[c] - k) / M_SQRT2) + csf_stats_norm_cdf((-truth[c] - k) / M_SQRT2);
        csf_rng g;
        csf_rng_init(&g, 4242 + (uint64_t)c, 9);
        int covered = 0, n = 1000;
        for (int r = 0; r < n; r++) {
            int hits = 0, fas = 0;
            for (int j = 0; j < 60; j++) {
                hits += csf_rng_next_uniform(&g) < ph;
                fas += csf_rng_next_uniform(&g) < pf;
            }
            double lo, hi;
            csf_stats_dprime_sd_ci(corrected(hits, 60), corrected(fas, 60), 60, 60, 1, 0.95, &lo, &hi);
            covered += lo <= truth[c] && truth[c] <= hi;
        }
        CHECK_MSG(covered >= 0.93 * n && covered <= 0.975 * n,
                  "d' %g: differencing interval covered %d of %d", truth[c], covered, n);
        printf("same/different d' %g: the differencing interval covered %d of %d\n", truth[c], covered, n);
    }
    double lo, hi, lo2, hi2;
    csf_stats_dprime_sd_ci(0.7, 0.2, 50, 40, 1, 0.95, &lo, &hi);
    double d = csf_stats_dprime_sd_differencing(0.7, 0.2);
    CHECK_MSG(lo < d && d < hi && hi - lo < 3, "differencing: %g in [%g, %g]", d, lo, hi);
    csf_stats_dprime_sd_ci(0.2, 0.7, 40, 50, 1, 0.95, &lo2, &hi2);
    CHECK_NEAR(lo2, -hi, 1e-6);
    CHECK_NEAR(hi2, -lo, 1e-6);
    double yl, yh;
    csf_stats_dprime_yesno_ci(0.7, 0.2, 50, 40, 0.95, &yl, &yh);
    csf_stats_dprime_sd_ci(0.7, 0.2, 50, 40, 0, 0.95, &lo, &hi);
    double zf = csf_stats_norm_quantile(0.2);
    CHECK_NEAR(hi, csf_stats_dprime_sd_independent(csf_stats_norm_cdf(zf + yh), 0.2), 1e-6);
    CHECK(yl > 0);
    CHECK_NEAR(lo, csf_stats_dprime_sd_independent(csf_stats_norm_cdf(zf + yl), 0.2), 1e-6);
    csf_stats_dprime_sd_ci(1.0, 0.2, 50, 40, 1, 0.95, &lo, &hi);
    CHECK(isnan(lo) && isnan(hi));
}

/* Negative log-likelihood of the Weibull with guess g, written out here from its definition. */
static double nll(const csf_psy_level *lv, int n, double g, double t, double beta, double lapse)
{
    double s = 0;
    for (int i = 0; i < n; i++) {
        double p = g + (1 - g - lapse) * (1 - exp(-pow(10.0, beta * (lv[i].x_log10 - t))));
        p = fmin(fmax(p, 1e-12), 1 - 1e-12);
        s -= lv[i].k * log(p) + (lv[i].n - lv[i].k) * log(1 - p);
    }
    return s;
}

/* The fit reaches the global optimum on two-peak data: 2AFC sets of 6 levels x 12 trials where
 * a steep slope through one jump competes with a shallow slope through all the levels. These
 * seven came from seeded random observers; a simplex from a few starts settled on the worse peak
 * in each (by 0.06 to 1.2 in negative log-likelihood). Each fit is checked against a brute-force
 * search of this test's own likelihood (t in steps of 0.005 log10, beta 0.5-20 in 1 % steps,
 * lapse 0-0.06 in steps of 0.01). */
static void test_fit_global(void)
{
    static const int k[7][6] = {{4, 5, 11, 9, 11, 12}, {4, 11, 9, 12, 11, 12}, {4, 5, 11, 9, 10, 11},
                                {5, 7, 11, 10, 11, 12}, {4, 7, 7, 12, 8, 12},   {4, 3, 5, 11, 10, 12},
                                {7, 5, 5, 10, 10, 11}};
    for (int set = 0; set < 7; set++) {
        csf_psy_level lv[6];
        for (int i = 0; i < 6; i++) {
            lv[i].x_log10 = -2.5 + 0.2 * i;
            lv[i].n = 12;
            lv[i].k = k[set][i];
        }
        csf_weibull_fit fit;
        CHECK(csf_weibull_fit_ml(lv, 6, 0.5, 0.06, &fit) == 0);
        double best = INFINITY, bt = NAN, bb = NAN;
        for (double tt = -3.5; tt <= -0.5; tt += 0.005)
            for (double b = 0.5; b <= 20; b *= 1.01)
                for (int l = 0; l <= 6; l++) {
                    double f = nll(lv, 6, 0.5, tt, b, 0.01 * l);
                    if (f < best) {
                        best = f;
                        bt = tt;
                        bb = b;
                    }
                }
        double got = nll(lv, 6, 0.5, fit.t_log10, fit.beta, fit.lapse);
        CHECK_MSG(got <= best + 1e-3, "set %d: fit t %.3f beta %.2f (nll %.4f), brute force t %.3f beta %.2f (%.4f)",
                  set, fit.t_log10, fit.beta, got, bt, bb, best);
    }
}

/* A PNG report holds its pages in one image, which cairo caps at 32767 px: more pages are refused
 * before anything is written, naming the formats that hold them. */
static void test_png_page_limit(void)
{
    static csf_study_plot_bar_page pages[60];
    char path[] = "/tmp/csf_png_limit_XXXXXX.png";
    int fd = mkstemps(path, 4);
    CHECK(fd >= 0);
    close(fd);
    unlink(path);
    csf_error err;
    CHECK(csf_study_plot_write(path, NULL, 0, pages, 60, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "at most 55 pages");
    CHECK_STR_CONTAINS(err.msg, ".pdf");
    CHECK(access(path, F_OK) != 0);
}

/* Labels come from the store, outside input: one that is not UTF-8, one with control characters
 * and one longer than a label is drawn (multi-byte, so a cut by bytes would split a character).
 * cairo refuses such text and then draws nothing more; the page must still be written whole. */
static void test_hostile_labels(void)
{
    static csf_study_plot_bar bars[3];
    snprintf(bars[0].label, sizeof bars[0].label, "%s", "bad \xff\xfe code");
    snprintf(bars[1].label, sizeof bars[1].label, "%s", "esc \x1b[31m red \x07");
    char long_title[320] = "";
    for (int i = 0; i < 150; i++) strcat(long_title, "\xc3\xa9"); /* 300 bytes of U+00E9 */
    snprintf(bars[2].label, sizeof bars[2].label, "%s", "ok");
    for (int b = 0; b < 3; b++) {
        bars[b].p = 0.5 + 0.1 * b, bars[b].lo = bars[b].p - 0.1, bars[b].hi = bars[b].p + 0.1;
        bars[b].chance = NAN;
        memcpy(bars[b].cells[0], bars[b].label, sizeof bars[b].label);
        snprintf(bars[b].cells[1], sizeof bars[b].cells[1], "%s", "\xe2\x82");
    }
    csf_study_plot_bar_page page = {
        .axis = "proportion \xc0\xaf", .legend = "legend \x1b", .n_columns = 2, .bars = bars, .n_bars = 3};
    snprintf(page.title, sizeof page.title, "%s", long_title);
    page.columns[0] = "condition", page.columns[1] = "n";
    char path[] = "/tmp/csf_hostile_XXXXXX.png";
    int fd = mkstemps(path, 4);
    CHECK(fd >= 0);
    close(fd);
    csf_error err;
    CHECK_INT_EQ(csf_study_plot_write(path, NULL, 0, &page, 1, &err), CSF_OK);
    cairo_surface_t *img = cairo_image_surface_create_from_png(path);
    CHECK_INT_EQ(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    unlink(path);
    if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS) return cairo_surface_destroy(img);
    /* every bar's marker drawn: dark pixels inside the plot frame at each of the three slots */
    cairo_surface_flush(img);
    int stride = cairo_image_surface_get_stride(img);
    const unsigned char *px = cairo_image_surface_get_data(img);
    long dark = 0;
    for (int y = (int)CSF_STUDY_PLOT_T; y < (int)CSF_STUDY_PLOT_B; y++)
        for (int x = (int)CSF_STUDY_PLOT_L + 2; x < (int)CSF_STUDY_PLOT_R - 2; x++) {
            const unsigned char *p = px + (size_t)y * (size_t)stride + 4 * (size_t)x;
            dark += p[0] + p[1] + p[2] < 3 * 128;
        }
    fprintf(stderr, "hostile labels: %ld dark pixels in the plot\n", dark);
    CHECK(dark > 60);
    cairo_surface_destroy(img);
}

int main(void)
{
    test_png_page_limit();
    test_hostile_labels();
    test_normal();
    test_clopper_pearson();
    test_binomial();
    test_dprime();
    test_fit();
    test_intervals();
    test_fisher();
    test_yesno_blind();
    test_dprime_ci();
    test_dprime_sd_ci();
    test_fit_global();
    return CHECK_RESULT();
}
