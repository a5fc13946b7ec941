#include <math.h>

#include "model/csf_model.h"
#include "model/csf_velocity.h"
#include "tests/check.h"

int main(void)
{
    csf_model_params p = csf_model_default();
    /* Peak at fmax in the fovea. */
    CHECK_NEAR(csf_model_sensitivity(&p, 3.0, 0), 250.0, 1e-9);
    /* Half height one half-bandwidth (1.5 octaves) above the peak. */
    CHECK_NEAR(csf_model_sensitivity(&p, 3.0 * pow(2, 1.5), 0), 125.0, 1e-6);
    /* Truncation below the peak: never more than delta below Smax. */
    CHECK_NEAR(csf_model_log10_sensitivity(&p, 0.05, 0), log10(250) - 0.5, 1e-12);
    /* Eccentricity factor 10^-(a + b f) e. */
    CHECK_NEAR(csf_model_log10_sensitivity(&p, 4.0, 10) - csf_model_log10_sensitivity(&p, 4.0, 0),
               -(0.0297 + 0.0190 * 4.0) * 10, 1e-12);
    /* Frequency scaling: at e the band is the foveal one at f (1 + s e), on top of the loss. */
    csf_model_params m = csf_model_default();
    m.ecc_scale_per_deg = 0.3;
    double plain_10 = csf_model_log10_sensitivity(&p, 1.0, 10) - csf_model_log10_sensitivity(&p, 1.0, 0);
    CHECK_NEAR(csf_model_log10_sensitivity(&m, 1.0, 10),
               csf_model_log10_sensitivity(&p, 4.0, 0) - (0.0297 + 0.0190 * 1.0) * 10, 1e-12);
    /* below the peak the magnified periphery gains, above it loses more than the plain model */
    CHECK(csf_model_log10_sensitivity(&m, 1.0, 10) - csf_model_log10_sensitivity(&m, 1.0, 0) > plain_10 + 0.1);
    CHECK(csf_model_log10_sensitivity(&m, 8.0, 10) < csf_model_log10_sensitivity(&p, 8.0, 10) - 0.3);
    CHECK_NEAR(csf_model_log10_sensitivity(&m, 8.0, 0), csf_model_log10_sensitivity(&p, 8.0, 0), 0);
    /* A foveal depression: all of it at the fovea, next to nothing by 5 deg, so the 5 deg ring can
     * be more sensitive than the fovea (which the outward-growing loss alone never allows). */
    csf_model_params d = csf_model_default();
    d.fovea_dip_log10 = 0.4;
    CHECK_NEAR(csf_model_log10_sensitivity(&d, 8.0, 0), csf_model_log10_sensitivity(&p, 8.0, 0) - 0.4, 1e-12);
    CHECK_NEAR(csf_model_log10_sensitivity(&d, 8.0, 5), csf_model_log10_sensitivity(&p, 8.0, 5), 0.001);
    CHECK(csf_model_log10_sensitivity(&d, 2.0, 5) > csf_model_log10_sensitivity(&d, 2.0, 0));
    CHECK(csf_model_log10_sensitivity(&p, 2.0, 5) < csf_model_log10_sensitivity(&p, 2.0, 0));
    csf_model_use_nasal_field(&p);
    CHECK_NEAR(p.ecc_a, 0.0114, 0);
    CHECK_NEAR(csf_model_threshold(&p, 3.0, 0) * csf_model_sensitivity(&p, 3.0, 0), 1.0, 1e-12);
    /* Kelly-Daly velocity gain: none at rest or within fixational drift, the sign of the
     * velocity ignored; low frequencies gain, high ones lose steeply (Kelly 1979, Fig. 9 shape). */
    csf_velocity_params vp = csf_velocity_default();
    CHECK_NEAR(csf_velocity_log10_gain(&vp, 4.0, 0.0), 0.0, 0);
    CHECK_NEAR(csf_velocity_log10_gain(&vp, 4.0, 0.1), 0.0, 0);
    CHECK_NEAR(csf_velocity_log10_gain(&vp, 4.0, -8.0), csf_velocity_log10_gain(&vp, 4.0, 8.0), 0);
    CHECK(csf_velocity_log10_gain(&vp, 0.5, 4.0) > 0.5);
    CHECK(csf_velocity_log10_gain(&vp, 8.0, 4.0) < -2.0);
    CHECK(csf_velocity_log10_gain(&vp, 8.0, 12.0) < csf_velocity_log10_gain(&vp, 8.0, 4.0));
    /* by hand from Daly's constants at 4 cpd, 8 deg/s: k(13.6) = 8.165, k(0.255) = 15.058 */
    double hand =
        (log(8.165 * 13.6 / (15.058 * 0.255)) - 0.67 * 4 * M_PI * 4 * (13.6 - 0.255) / 45.9) / M_LN10;
    CHECK_NEAR(csf_velocity_log10_gain(&vp, 4.0, 8.0), hand, 0.002);
    vp.steepness = 0.5;
    CHECK_NEAR(csf_velocity_log10_gain(&vp, 4.0, 8.0), 0.5 * hand, 0.001);
    CHECK(isnan(csf_velocity_log10_gain(&vp, NAN, 1.0)));
    CHECK_NEAR(csf_velocity_temporal_hz(4.0, -3.0), 12.0, 1e-12);
    CHECK_NEAR(csf_velocity_warp(0.0), log10(CSF_VELOCITY_WARP_V0_DPS), 1e-12);
    return CHECK_RESULT();
}
