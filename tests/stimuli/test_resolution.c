/* Effective luminance resolution on an 8-bit framebuffer: the patch-mean luminance over N frames
 * must be within 2^-12 of the display's range of the request (random levels 20-80 % of peak),
 * through two different simulated displays. Without dithering the same check must fail (it is the
 * plain 8-bit quantisation), which shows the check can tell the difference. */
#include <math.h>
#include <string.h>

#include "stim_test.h"
#include "tests/check.h"

static csf_selfcheck_resolution run(const char *spec, int dither, int bits)
{
    csf_display_model *model = stim_test_model(spec);
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    CHECK_INT_EQ(csf_geometry_init(&cfg.geometry, 120, 120, 192, 192, 570, 0, 0, &e), CSF_OK);
    cfg.grey_lum_fn = stim_test_model_grey;
    cfg.grey_lum_ctx = model;
    cfg.dither = dither;
    cfg.framebuffer_bits = bits;
    cfg.seed = 11;
    csf_presenter *p = stim_test_open(&cfg);
    csf_selfcheck_resolution r;
    memset(&r, 0, sizeof r);
    int rc = csf_selfcheck_resolution_run(p, 40, 8, 64, 2026, stim_test_model_lum, model, &r, &e);
    CHECK_MSG(rc == CSF_OK, "%s", e.msg);
    printf("%-4s dither=%d bits=%d: max err %.3g of range (%.2f bits), rms %.3g\n", spec, dither,
           bits, r.max_err_frac, r.effective_bits, r.rms_err_frac);
    csf_presenter_close(p);
    csf_display_model_free(model);
    return r;
}

int main(void)
{
    csf_selfcheck_resolution a = run("lcd", CSF_DITHER_NOISE, 8);
    CHECK_MSG(a.max_err_frac <= ldexp(1.0, -12), "lcd: %.3g > 2^-12", a.max_err_frac);
    CHECK(a.effective_bits >= 12.0);
    csf_selfcheck_resolution b = run("crt,gamma=2.6", CSF_DITHER_NOISE, 8);
    CHECK_MSG(b.max_err_frac <= ldexp(1.0, -12), "crt: %.3g > 2^-12", b.max_err_frac);
    /* plain rounding to 8 bits: errors up to half a step, far above 2^-12 */
    csf_selfcheck_resolution c = run("lcd", CSF_DITHER_NONE, 8);
    CHECK(c.max_err_frac > ldexp(1.0, -11));
    CHECK(c.effective_bits < 11.0);
    /* a 10-bit framebuffer without dithering lands between the two */
    csf_selfcheck_resolution d = run("lcd", CSF_DITHER_NONE, 10);
    CHECK(d.max_err_frac < c.max_err_frac);
    CHECK(d.max_err_frac > a.max_err_frac);
    /* argument checks */
    csf_display_model *model = stim_test_model("lcd");
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    csf_geometry_init(&cfg.geometry, 120, 120, 64, 64, 570, 0, 0, &e);
    csf_presenter *p = stim_test_open(&cfg);
    csf_selfcheck_resolution r;
    CHECK_INT_EQ(csf_selfcheck_resolution_run(p, 4, 2, 65, 1, stim_test_model_lum, model, &r, &e),
                 CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "1..64 px");
    csf_presenter_close(p);
    /* presenter configuration checks */
    cfg.framebuffer_bits = 12;
    CHECK_INT_EQ(csf_presenter_open(&cfg, &p, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "only 8 or 10");
    cfg.framebuffer_bits = 8;
    cfg.refresh_hz = 5;
    CHECK_INT_EQ(csf_presenter_open(&cfg, &p, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "20 to 1000 Hz");
    csf_display_model_free(model);
    return CHECK_RESULT();
}
