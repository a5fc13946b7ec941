/* The simulated observer's image-pair model (model/observer_images.h) pools over space as the
 * thresholds it uses were measured (Gabors of sigma 1 deg):
 *   - a 1-deg Gabor difference at the observer's threshold pools to r near 1 (P(seen) 1 - 1/e);
 *   - the same band contrast spread over a 4x larger grating patch is more visible (summation);
 *   - one pixel whose local band contrast is well above the grating threshold is NOT seen: a
 *     difference confined to a pixel pools over far less area (this is what made Luebke &
 *     Hallen's "imperceptible" renders look different: one pixel one code value apart);
 *   - contrast is local (Peli): the same luminance step is less visible on a bright region of a
 *     dark image than on a dim one. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "model/observer_images.h"
#include "model/observer_sim.h"
#include "tests/check.h"

enum { W = 256, H = 256 };
static const double PPD = 32, FREQ_CPD = 4;

/* a: uniform lum0; b: a + lum0 * c * envelope * carrier, envelope a Gaussian of sigma_deg
 * (sigma_deg <= 0: a single pixel at the centre with amplitude c) */
static double pair_r(const csf_observer_sim *o, double lum0, double c, double sigma_deg)
{
    float *a = malloc(sizeof(float) * W * H), *b = malloc(sizeof(float) * W * H);
    if (!a || !b) abort();
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dx = (x + 0.5 - W / 2.0) / PPD, dy = (y + 0.5 - H / 2.0) / PPD;
            double m;
            if (sigma_deg > 0) m = exp(-(dx * dx + dy * dy) / (2 * sigma_deg * sigma_deg)) * sin(2 * M_PI * FREQ_CPD * dx);
            else m = (x == W / 2 && y == H / 2);
            a[y * W + x] = (float)lum0;
            b[y * W + x] = (float)(lum0 * (1 + c * m));
        }
    csf_image_pair_eval ev;
    CHECK(csf_image_pair_evaluate(o, a, b, W, H, W / PPD, 0, 0, &ev) == 0);
    free(a);
    free(b);
    return ev.r;
}

int main(void)
{
    csf_observer_sim *o = NULL;
    csf_error e;
    CHECK(csf_observer_sim_create("sim", 1, &o, &e) == CSF_OK);
    if (!o) return 1;
    double t = csf_observer_sim_threshold(o, FREQ_CPD, 0);
    double r_gabor = pair_r(o, 0.5, t, 1.0);
    double r_wide = pair_r(o, 0.5, t, 2.0);
    double r_pixel = pair_r(o, 0.5, 4 * t, 0);
    double r_pixel_max = pair_r(o, 0.5, 1.0, 0);
    fprintf(stderr, "threshold %.4f at %g cpd; r: Gabor sigma 1 deg at threshold %.3f, sigma 2 deg %.3f, "
            "one pixel at 4x threshold %.3f, one pixel at contrast 1 %.3f\n",
            t, FREQ_CPD, r_gabor, r_wide, r_pixel, r_pixel_max);
    CHECK_MSG(r_gabor > 0.7 && r_gabor < 1.4, "a 1-deg Gabor at threshold pools to %.3f", r_gabor);
    CHECK_MSG(r_wide > 1.2 * r_gabor, "a 4x larger patch %.3f, the Gabor %.3f", r_wide, r_gabor);
    CHECK_MSG(r_pixel < 0.5, "one pixel at 4x the grating threshold: r %.3f (P(seen) must be small)", r_pixel);
    CHECK_MSG(r_pixel_max > r_pixel, "more pixel contrast, more visible");
    /* Local contrast: a step on a bright patch of an otherwise dark image */
    float *a = malloc(sizeof(float) * W * H), *b = malloc(sizeof(float) * W * H);
    if (!a || !b) abort();
    double r_bright = 0, r_dim = 0;
    for (int pass = 0; pass < 2; pass++) {
        double patch = pass == 0 ? 0.9 : 0.1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                double dx = (x + 0.5 - W / 2.0) / PPD, dy = (y + 0.5 - H / 2.0) / PPD;
                int in = fabs(dx) < 3 && fabs(dy) < 3;
                a[y * W + x] = (float)(in ? patch : 0.02);
                b[y * W + x] = a[y * W + x] + (float)(in ? 0.01 * exp(-(dx * dx + dy * dy) / 2) * sin(2 * M_PI * FREQ_CPD * dx) : 0);
            }
        csf_image_pair_eval ev;
        CHECK(csf_image_pair_evaluate(o, a, b, W, H, W / PPD, 0, 0, &ev) == 0);
        if (pass == 0) r_bright = ev.r;
        else r_dim = ev.r;
    }
    fprintf(stderr, "same luminance difference on a bright patch: r %.3f, on a dim patch: %.3f\n", r_bright, r_dim);
    CHECK_MSG(r_dim > 4 * r_bright, "Weber: 9x less local luminance must make the step far more visible");
    free(a);
    free(b);
    csf_observer_sim_free(o);
    return CHECK_RESULT();
}
