/* The benchmark's anchors (bench/quest_cell.h, bench/questplus.h) recover a known observer: a
 * QUEST posterior starts at its guess and converges to the truth; QUEST+ fits a surface that is
 * on its grid exactly (best-fit RMS 0) and recovers it from simulated trials, reporting cells
 * beyond the display's reach as never visible. Seeded; core/rng.h only. */
#include <math.h>
#include <stdio.h>

#include "quest_cell.h"
#include "questplus.h"
#include "model/csf_model.h"
#include "core/rng.h"

static int fails;
#define CHECK(cond, ...)                                                                          \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            fails++;                                                                              \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                           \
            printf(__VA_ARGS__);                                                                  \
            printf("\n");                                                                         \
        }                                                                                         \
    } while (0)

static int weibull_answer(uint64_t seed, int k, double x, double t, double slope, double lapse, double g)
{
    double p = g + (1.0 - g - lapse) * (1.0 - exp(-pow(10.0, slope * (x - t))));
    return csf_rng_uniform(seed, 1, (uint64_t)k) < p;
}

static void test_quest_cell(void)
{
    quest_cell q;
    quest_cell_init(&q, -1.5, 0.5, 3.5, 0.02, 0.5);
    CHECK(fabs(quest_cell_mean(&q) + 1.5) < 0.01, "prior mean %.3f, want -1.5", quest_cell_mean(&q));
    CHECK(fabs(quest_cell_quantile(&q, 0.5) + 1.5) < 0.01, "prior median %.3f", quest_cell_quantile(&q, 0.5));
    CHECK(fabs(quest_cell_prob_below(&q, -1.5) - 0.5) < 0.02, "P(t < guess) %.3f", quest_cell_prob_below(&q, -1.5));
    double worst = 0.0;
    for (uint64_t seed = 1; seed <= 5; seed++) {
        quest_cell_init(&q, -1.5, 0.5, 3.5, 0.02, 0.5);
        for (int k = 0; k < 200; k++) {
            double x = quest_cell_quantile(&q, 0.5);
            quest_cell_update(&q, x, weibull_answer(seed, k, x, -2.0, 3.5, 0.02, 0.5));
        }
        double e = fabs(quest_cell_mean(&q) + 2.0);
        worst = e > worst ? e : worst;
    }
    CHECK(worst < 0.12, "QUEST after 200 trials is %.3f log10 off the truth -2.0", worst);
}

static void test_questplus(void)
{
    csf_cell cells[24];
    int n_alt[24], n = 0;
    static const double eccs[4] = {0, 5, 10, 20};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 6; i++) {
            cells[n] = (csf_cell){0.5 * pow(2.0, i), eccs[j], 0};
            n_alt[n++] = j ? 4 : 2;
        }
    /* a surface on the grid: log10 Smax 2.1, log10 fmax 0.35, 3 octaves, delta 0.25, a 0.02, b 0.025 */
    csf_model_params p = {.smax = pow(10.0, 2.1), .fmax_cpd = pow(10.0, 0.35), .beta_oct = 3.0,
                          .delta_log10 = 0.25, .ecc_a = 0.02, .ecc_b = 0.025};
    double truth[24];
    int n_invisible = 0;
    for (int c = 0; c < n; c++) {
        truth[c] = -csf_model_log10_sensitivity(&p, cells[c].freq_cpd, cells[c].ecc_deg);
        n_invisible += truth[c] >= 0.0;
    }
    CHECK(n_invisible > 0, "the test surface should have a cell beyond the display's reach");
    questplus *q = questplus_create(cells, n, n_alt, 0.02, log10(0.0005), 0.0);
    CHECK(q != NULL, "questplus_create");
    if (!q) return;
    CHECK(questplus_best_fit_rms(q, truth) < 1e-5, "on-grid surface: best fit %.4f", questplus_best_fit_rms(q, truth));
    for (int k = 0; k < 150; k++) {
        int c;
        double x;
        questplus_next(q, 7, k, &c, &x);
        CHECK(c >= 0 && c < n && x <= 0.0 && x >= log10(0.0005), "trial %d: cell %d x %.2f", k, c, x);
        questplus_update(q, c, x, weibull_answer(7, k, x, truth[c], 3.2, 0.02, n_alt[c] == 4 ? 0.25 : 0.5));
    }
    double est[24], se = 0.0;
    int nv = 0;
    questplus_estimate(q, est);
    for (int c = 0; c < n; c++) {
        if (truth[c] >= 0.0) {
            CHECK(!isfinite(est[c]), "cell %d (truth %.2f) should be never visible, got %.2f", c, truth[c], est[c]);
            continue;
        }
        double e = isfinite(est[c]) ? est[c] : 0.0;
        se += (e - truth[c]) * (e - truth[c]), nv++;
    }
    CHECK(sqrt(se / nv) < 0.08, "QUEST+ RMS %.3f after 150 trials on its own surface", sqrt(se / nv));
    questplus_free(q);
}

int main(void)
{
    test_quest_cell();
    test_questplus();
    if (!fails) printf("ok\n");
    return fails ? 1 : 0;
}
