/* Shared by the display calibration tests: how far a profile is from the simulated display it was
 * measured on, whether two profiles are the same model bit for bit, and one calibration run on the
 * simulated photometer. */
#ifndef CSF_TESTS_CALIB_TRUTH_H
#define CSF_TESTS_CALIB_TRUTH_H

#include <math.h>

#include "calib/display_calib.h"
#include "calib/display_verify.h"
#include "model/display_model.h"
#include "results/display_profile.h"
#include "tests/check.h"

/* Largest relative error above 10 % of peak per curve (r, g, b against their own peaks, grey)
 * against the simulated truth display_spec (a display model spec: "lcd", "crt", "file=..."). */
static inline void profile_errors(const csf_display_profile *p, const char *display_spec, double out[4])
{
    csf_display_model *m = NULL;
    csf_error err;
    if (csf_display_model_create(display_spec, &m, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return;
    }
    double black = csf_display_model_lum(m, 0, 0, 0);
    for (int ch = 0; ch < 4; ch++) {
        double peak = ch == 3 ? csf_display_model_lum(m, 1, 1, 1)
                              : csf_display_model_lum(m, ch == 0, ch == 1, ch == 2) - black;
        double worst = 0;
        for (int i = 0; i <= 1020; i++) {
            double v = i / 1020.0, t, got;
            if (ch == 3) {
                t = csf_display_model_lum(m, v, v, v);
                got = csf_profile_grey_lum(p, v);
            } else {
                t = csf_display_model_lum(m, ch == 0 ? v : 0, ch == 1 ? v : 0, ch == 2 ? v : 0) - black;
                got = csf_profile_channel_lum(p, ch, v);
            }
            if (t < 0.1 * peak) continue;
            double e = fabs(got / t - 1);
            if (e > worst) worst = e;
        }
        out[ch] = worst;
    }
    csf_display_model_free(m);
}

/* Two profiles with the same model: every knot of every curve and the black level, bit for bit. */
static inline int profile_same_model(const csf_display_profile *a, const csf_display_profile *b)
{
    if (csf_profile_lum_black(a) != csf_profile_lum_black(b)) return 0;
    for (int c = 0; c < CSF_CH_COUNT; c++) {
        const double *va, *la, *vb, *lb;
        size_t na = csf_profile_knots(a, c, &va, &la), nb = csf_profile_knots(b, c, &vb, &lb);
        if (na != nb) return 0;
        for (size_t i = 0; i < na; i++)
            if (va[i] != vb[i] || la[i] != lb[i]) return 0;
    }
    return 1;
}

/* The accuracy target of calib_sim_run when above 0 (else the default): a run stops as soon as its
 * stated error meets the target, so a test of what the model can reach asks for a tighter one. */
static double calib_target_override = 0;

/* One calibration with the default options (budget > 0 replaces the reading budget) on the
 * photometer `spec`; the profile, or NULL with *st_out (when given) and err saying why. */
static inline csf_display_profile *calib_sim_run(const char *spec, uint64_t seed, int budget, csf_store *store,
                                                 int64_t *sid, csf_display_calib_result *res,
                                                 csf_status *st_out, csf_error *err)
{
    csf_photometer *ph = NULL;
    csf_status st = csf_photometer_open(spec, seed, &ph, err);
    CHECK_MSG(st == CSF_OK, "%s", err->msg);
    if (st) return NULL;
    csf_display_calib_opts o;
    csf_display_calib_defaults(&o);
    if (budget > 0) o.budget = budget;
    if (calib_target_override > 0) o.target_rel = calib_target_override;
    csf_display_profile *p = NULL;
    st = csf_display_calibrate(ph, &o, store, sid, seed, &p, res, err);
    if (st_out) *st_out = st;
    csf_photometer_close(ph);
    return p;
}

#endif
