/* Rendered Gabors read back through a simulated LCD: Michelson contrast within 2 % (relative) at
 * 1 % contrast and within 10 % at 0.2 %, averaged over 60 frames, at eccentricities 0, 10, 30 deg;
 * spatial frequency within 1 % (measured independently along the horizontal meridian with
 * atan(x/D), not through geometry.c); position; Nyquist and off-screen refusals with the limit. */
#include <math.h>
#include <string.h>

#include "stim_test.h"
#include "tests/check.h"

#define DEG (M_PI / 180.0)
#define D_MM 300.0

/* Frequency along the meridian row: maximise |sum (L - m) env e^{-i 2 pi f (theta - ecc)}|,
 * theta = atan(x / D) from pixel positions only. */
static double row_projection(const double *L, const double *theta, int n, double m, double ecc,
                             double sigma, double f)
{
    double re = 0, im = 0;
    for (int i = 0; i < n; i++) {
        double d = theta[i] - ecc, env = exp(-d * d / (2 * sigma * sigma));
        re += (L[i] - m) * env * cos(2 * M_PI * f * d);
        im += (L[i] - m) * env * sin(2 * M_PI * f * d);
    }
    return hypot(re, im);
}

static double row_frequency(const double *L, const double *theta, int n, double m, double ecc,
                            double sigma, double f0)
{
    double lo = 0.9 * f0, hi = 1.1 * f0;
    for (int it = 0; it < 3; it++) { /* coarse-to-fine scans */
        double best = lo, bv = -1, step = (hi - lo) / 40;
        for (int i = 0; i <= 40; i++) {
            double f = lo + step * i, v = row_projection(L, theta, n, m, ecc, sigma, f);
            if (v > bv) bv = v, best = f;
        }
        lo = best - step;
        hi = best + step;
    }
    return 0.5 * (lo + hi);
}

int main(void)
{
    csf_display_model *model = stim_test_model("lcd");
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    /* a wide, short screen at 300 mm so that 30 deg fits with modest pixel counts */
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&cfg.geometry, 440.0, 186 * 0.34375, 1280, 186, D_MM, 0, 0, &e), CSF_OK);
    cfg.grey_lum_fn = stim_test_model_grey;
    cfg.grey_lum_ctx = model;
    csf_presenter *p = stim_test_open(&cfg);
    double black, max;
    csf_presenter_lum_range(p, &black, &max);
    int rw, rh;
    csf_presenter_render_size(p, &rw, &rh);
    uint16_t *lv = malloc(sizeof(uint16_t) * 3 * rw * rh);
    double *row = malloc(sizeof(double) * rw), *theta = malloc(sizeof(double) * rw);

    const double eccs[3] = {0, 10, 30};
    const double contrasts[2] = {0.01, 0.002};
    for (int ie = 0; ie < 3; ie++) {
        for (int ic = 0; ic < 2; ic++) {
            csf_stimulus s;
            memset(&s, 0, sizeof s);
            s.kind = CSF_STIM_GABOR;
            s.freq_cpd = 4.0;
            s.sigma_deg = 0.75;
            s.ecc_deg = eccs[ie];
            s.polar_deg = 0;
            s.contrast = contrasts[ic];
            s.phase_deg = 30;
            s.mean_lum_cdm2 = 0.4 * max;
            csf_selfcheck_result r;
            int rc = csf_selfcheck_stimulus(p, &s, 60, stim_test_model_lum, model, &r, &e);
            CHECK_MSG(rc == CSF_OK, "%s", e.msg);
            double tol = ic == 0 ? 0.02 : 0.10;
            CHECK_MSG(fabs(r.contrast / s.contrast - 1) <= tol,
                      "ecc %g: contrast %.6f measured %.6f (rel err %.4f, allowed %.2f)", s.ecc_deg,
                      s.contrast, r.contrast, r.contrast / s.contrast - 1, tol);
            CHECK_MSG(fabs(r.mean_lum_cdm2 / s.mean_lum_cdm2 - 1) < 1e-3, "mean %g vs %g",
                      r.mean_lum_cdm2, s.mean_lum_cdm2);
            if (ic == 0) {
                CHECK_MSG(fabs(r.freq_cpd / s.freq_cpd - 1) <= 0.01, "ecc %g: freq %g measured %g",
                          s.ecc_deg, s.freq_cpd, r.freq_cpd);
                CHECK_NEAR(r.orientation_deg, 0.0, 1.0);
                CHECK_NEAR(r.ecc_deg, s.ecc_deg, 0.1);
                /* independent: a 1 % Gabor, one more frame, averaged along the meridian rows */
                csf_frame_info fi;
                memset(row, 0, sizeof(double) * rw);
                const int nf = 20;
                for (int f = 0; f < nf; f++) {
                    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
                    CHECK_INT_EQ(csf_presenter_readback_levels(p, lv, &e), CSF_OK);
                    for (int i = 0; i < rw; i++)
                        for (int j = rh / 2 - 1; j <= rh / 2; j++) {
                            const uint16_t *px = lv + 3 * ((size_t)j * rw + i);
                            row[i] += csf_display_model_lum(model, px[0] / 255.0, px[1] / 255.0,
                                                            px[2] / 255.0) / (2.0 * nf);
                        }
                }
                for (int i = 0; i < rw; i++) theta[i] = atan(((i + 0.5) / rw - 0.5) * 440.0 / D_MM) / DEG;
                double fr = row_frequency(row, theta, rw, s.mean_lum_cdm2, s.ecc_deg, s.sigma_deg, 4.0);
                CHECK_MSG(fabs(fr / 4.0 - 1) <= 0.01, "ecc %g: meridian frequency %g", s.ecc_deg, fr);
            }
            printf("ecc %4.1f  C %.4f -> %.5f (%+.2f %%)  f 4 -> %.4f  ecc -> %.3f  mean %.3f\n",
                   s.ecc_deg, s.contrast, r.contrast, 100 * (r.contrast / s.contrast - 1), r.freq_cpd,
                   r.ecc_deg, r.mean_lum_cdm2);
        }
    }

    /* refusals: Nyquist (the limit is local: 9 cpd is too fine at the centre, fine at 30 deg) */
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = 9.0;
    s.sigma_deg = 0.75;
    s.contrast = 0.1;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "Nyquist");
    char lim[32];
    snprintf(lim, sizeof lim, "%.4g cpd", csf_geometry_nyquist_cpd(csf_presenter_geometry(p), 0, 0, 0));
    CHECK_STR_CONTAINS(e.msg, lim);
    csf_frame_info fi;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_E_INVALID_ARG);
    s.ecc_deg = 30;
    CHECK_MSG(csf_presenter_validate(p, &s, &e) == CSF_OK, "%s", e.msg);
    s.freq_cpd = 12;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    /* off-screen: the screen reaches atan(220/300) = 36.3 deg horizontally */
    s.freq_cpd = 4;
    s.ecc_deg = 35;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "leaves the screen");
    CHECK_STR_CONTAINS(e.msg, "36.3 deg");
    s.ecc_deg = 10;
    s.polar_deg = 90; /* the screen is only ~6 deg tall */
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    s.polar_deg = 0;
    s.contrast = 1.5;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "0 to 1");
    s.contrast = 0.9;
    s.mean_lum_cdm2 = 0.9 * max; /* peak would exceed the display */
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "display's range");

    free(lv);
    free(row);
    free(theta);
    csf_presenter_close(p);
    csf_display_model_free(model);
    return CHECK_RESULT();
}
