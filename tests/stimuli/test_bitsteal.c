/* Bit-stealing (pseudo-grey across channels) with noise dither between sub-levels: the mean is
 * as exact as the plain noise dither (>= 12 bits), the per-pixel dither noise is much smaller,
 * channels really differ, and a profile without channel curves is refused. Truth: the profile's
 * channel curves, additively (black + r + g + b). */
#include <math.h>
#include <string.h>

#include "results/display_profile.h"
#include "stim_test.h"
#include "tests/check.h"

static double additive_lum(void *ctx, double r, double g, double b)
{
    const csf_display_profile *p = ctx;
    return csf_profile_lum_black(p) + csf_profile_channel_lum(p, 0, r) + csf_profile_channel_lum(p, 1, g) +
           csf_profile_channel_lum(p, 2, b);
}

/* sd of pixel luminance (cd/m2) over a uniform field in one frame; counts non-grey pixels */
static double field_sd(csf_presenter *p, csf_display_profile *prof, double lum, int *mixed)
{
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_DISC;
    s.mean_lum_cdm2 = lum;
    s.radius_deg = 0.5;
    csf_frame_info fi;
    csf_error e;
    CHECK_INT_EQ(csf_presenter_draw(p, &s, 0, &fi, &e), CSF_OK);
    int w, h;
    csf_presenter_render_size(p, &w, &h);
    uint16_t *lv = malloc(sizeof(uint16_t) * 3 * w * h);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, lv, &e), CSF_OK);
    double s1 = 0, s2 = 0;
    int n = w * h;
    *mixed = 0;
    for (int i = 0; i < n; i++) {
        const uint16_t *px = lv + 3 * i;
        double L = additive_lum(prof, px[0] / 255.0, px[1] / 255.0, px[2] / 255.0);
        s1 += L;
        s2 += L * L;
        if (px[0] != px[1] || px[1] != px[2]) (*mixed)++;
    }
    free(lv);
    return sqrt(fmax(0, s2 / n - (s1 / n) * (s1 / n)));
}

int main(void)
{
    csf_display_profile *prof = csf_profile_default();
    CHECK(prof && csf_profile_has_channels(prof));
    /* the default profile's channels add up to its grey curve (else the truth would differ) */
    for (int k = 0; k <= 255; k += 15) {
        double d = k / 255.0, grey = csf_profile_grey_lum(prof, d);
        CHECK_NEAR(additive_lum(prof, d, d, d), grey, 1e-6 * fmax(1, grey));
    }
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    csf_geometry_init(&cfg.geometry, 120, 120, 128, 128, 570, 0, 0, &e);
    cfg.profile = prof;
    cfg.dither = CSF_DITHER_BITSTEAL;
    csf_presenter *p = stim_test_open(&cfg);
    csf_selfcheck_resolution r;
    CHECK_INT_EQ(csf_selfcheck_resolution_run(p, 30, 8, 64, 7, additive_lum, prof, &r, &e), CSF_OK);
    printf("bit-stealing: max err %.3g of range (%.2f bits)\n", r.max_err_frac, r.effective_bits);
    CHECK(r.effective_bits >= 12.0);
    int mixed_bs, mixed_noise;
    double sd_bs = field_sd(p, prof, 37.3, &mixed_bs);
    csf_presenter_close(p);
    cfg.dither = CSF_DITHER_NOISE;
    p = stim_test_open(&cfg);
    double sd_noise = field_sd(p, prof, 37.3, &mixed_noise);
    csf_presenter_close(p);
    printf("dither noise sd at 37.3 cd/m2: bit-stealing %.4f, grey noise %.4f cd/m2\n", sd_bs, sd_noise);
    CHECK(mixed_bs > 1000);
    CHECK_INT_EQ(mixed_noise, 0);
    CHECK(sd_bs < 0.5 * sd_noise); /* sub-levels are uneven (B small, G large) */
    /* no channel curves: refused */
    cfg.dither = CSF_DITHER_BITSTEAL;
    cfg.profile = NULL;
    cfg.grey_lum_fn = NULL;
    csf_display_model *m = stim_test_model("lcd");
    cfg.grey_lum_fn = stim_test_model_grey;
    cfg.grey_lum_ctx = m;
    CHECK_INT_EQ(csf_presenter_open(&cfg, &p, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "per-channel");
    csf_display_model_free(m);
    csf_profile_free(prof);
    return CHECK_RESULT();
}
