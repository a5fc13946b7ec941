/* Weibull psychometric function, inverse, fade hazard, grid posterior and ML fit. */
#include <math.h>

#include "model/psychometric.h"
#include "core/rng.h"
#include "tests/check.h"

int main(void)
{
    csf_weibull w = {-2.0, 3.5, 0.5, 0.0};
    /* The Weibull's t: at x = t with lapse 0, 2AFC gives 1 - e^-1/2 = 81.6 %. */
    CHECK_NEAR(csf_psy_p(&w, -2.0), 0.816, 0.001);
    CHECK_NEAR(csf_psy_p(&w, -10.0), 0.5, 1e-9);
    CHECK_NEAR(csf_psy_p(&w, 1.0), 1.0, 1e-9);
    w.lapse = 0.04;
    CHECK_NEAR(csf_psy_p(&w, 1.0), 0.96, 1e-9);
    for (double p = 0.55; p < 0.95; p += 0.1) CHECK_NEAR(csf_psy_p(&w, csf_psy_inverse(&w, p)), p, 1e-9);
    CHECK(isnan(csf_psy_inverse(&w, 0.97)));
    CHECK(isnan(csf_psy_inverse(&w, 0.4)));
    CHECK(isfinite(csf_psy_loglik(&w, 5.0, 0)));
    CHECK(isfinite(csf_psy_loglik(&w, -9.0, 1)));

    /* The product of survivals over a ramp equals the survival at its top. */
    double s = 1, prev = -INFINITY;
    for (double x = -3; x <= -1.5; x += 0.01) {
        s *= 1 - csf_psy_fade_hazard(prev, x, -2, 3.5);
        prev = x;
    }
    CHECK_NEAR(1 - s, csf_psy_core(prev, -2, 3.5), 1e-9);
    CHECK(csf_psy_fade_hazard(-2.0, -2.1, -2, 3.5) == 0);

    /* Grid posterior concentrates on the true threshold with simulated 2AFC data. */
    csf_psy_grid g;
    CHECK(csf_psy_grid_init(&g, 101, -4, 0, -2, 2, 3.5, 0.5, 0.02) == 0);
    csf_weibull truth = {-2.3, 3.5, 0.5, 0.02};
    csf_psy_obs obs[400];
    for (int i = 0; i < 400; i++) {
        double x = csf_psy_grid_best_x(&g, -4, 0, 41);
        int r = csf_rng_uniform(5, 1, (uint64_t)i) < csf_psy_p(&truth, x);
        csf_psy_grid_update(&g, x, r);
        obs[i] = (csf_psy_obs){x, r};
    }
    double m, sd;
    csf_psy_grid_moments(&g, &m, &sd);
    CHECK_NEAR(m, -2.3, 3 * sd + 0.01);
    CHECK(sd < 0.06);
    CHECK(csf_psy_grid_prob_above(&g, -1.0) < 0.01);
    double t_hat, se;
    CHECK(csf_psy_fit_t(obs, 400, 3.5, 0.5, 0.02, -4, 0, &t_hat, &se) == 0);
    CHECK_NEAR(t_hat, -2.3, 3 * se + 0.01);
    CHECK(se > 0.01 && se < 0.08);
    CHECK_NEAR(t_hat, m, 0.05);
    csf_psy_grid_free(&g);
    CHECK(csf_psy_grid_init(&g, 1, -4, 0, 0, 1, 3.5, 0.5, 0.02) == -1);

    /* One threshold, whatever the task (model/psychometric.h). */
    double d_t = CSF_PSY_DPRIME_CRITERION;
    CHECK_NEAR(csf_psy_sdt_pc_mafc(d_t, 2), 1 - exp(-1) / 2, 1e-9);   /* 81.6 % at t */
    CHECK_NEAR(csf_psy_sdt_pc_mafc(0, 4), 0.25, 1e-9);
    /* m = 2 is the two-interval Weibull; m = 4 the max rule of the same d': 63.7 % at t (no lapse) */
    CHECK(csf_psy_p_afc(-2.1, -2.3, 3.1, 0.02, 2) == csf_psy_p4(-2.1, -2.3, 3.1, 0.5, 0.02));
    CHECK_NEAR(csf_psy_p_afc(-2.3, -2.3, 3.1, 0, 4), csf_psy_sdt_pc_mafc(d_t, 4), 1e-6);
    CHECK_NEAR(csf_psy_sdt_pc_mafc(d_t, 4), 0.637, 0.001);
    /* the table agrees with the integral everywhere (interpolation error < 1e-6) */
    double worst = 0;
    for (int i = 0; i < 400; i++) {
        double x = -3.5 + i * 0.005, k = 3.1 / CSF_PSY_WEIBULL_PER_K;
        double d = d_t * pow(10.0, k * (x + 2.3));
        double direct = 0.04 * 4 / 3 / 4 + (1 - 0.04 * 4 / 3) * csf_psy_sdt_pc_mafc(d, 4);
        worst = fmax(worst, fabs(csf_psy_p_afc(x, -2.3, 3.1, 0.04, 4) - direct));
    }
    CHECK(worst < 1e-6);
    /* upper asymptote 1 - lapse, lower 1/4; monotone */
    CHECK_NEAR(csf_psy_p_afc(0, -2.3, 3.1, 0.04, 4), 0.96, 1e-9);
    CHECK_NEAR(csf_psy_p_afc(-INFINITY, -2.3, 3.1, 0.04, 4), 0.25, 1e-9);
    CHECK(isnan(csf_psy_p_afc(-2, -2, 3, 0.02, 9)));
    /* the four-place 72.4 % point (where a Weibull with guess 1/4 puts t) is 0.094/k above t */
    double k = 3.1 / CSF_PSY_WEIBULL_PER_K, lo = -3, hi = -1;
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi);
        if (csf_psy_p_afc(mid, -2.3, 3.1, 0, 4) < 0.25 + 0.75 * (1 - exp(-1))) lo = mid;
        else hi = mid;
    }
    CHECK_NEAR(lo - -2.3, 0.0943 / k, 0.001);
    /* a grid set to four places uses it */
    CHECK(csf_psy_grid_init(&g, 11, -3, -1, -2, 1, 3.1, 0.25, 0.02) == 0);
    g.n_alt = 4;
    CHECK(csf_psy_grid_p(&g, -2.2, -2.3) == csf_psy_p_afc(-2.2, -2.3, 3.1, 0.02, 4));
    csf_psy_grid_free(&g);
    CHECK(csf_psy_fit_t(obs, 0, 3.5, 0.5, 0.02, -4, 0, &t_hat, &se) == -1);
    return CHECK_RESULT();
}
