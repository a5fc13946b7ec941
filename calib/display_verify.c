/* Verification of a display profile (see calib/display_verify.h). */
#include "calib/display_verify.h"

#include "calib/meter_check.h"
#include "calib/warmup_model.h"

#include <math.h>
#include <string.h>

void csf_display_verify_defaults(csf_display_verify_opts *o)
{
    memset(o, 0, sizeof *o);
    o->n_levels = 5;
    o->target_rel = 0.0025;
    o->warmup_wait_s = 5;
    o->warmup_max = 40;
}

typedef struct {
    csf_photometer *ph;
    const csf_display_verify_opts *o;
    uint64_t index;
} vctx;

/* Tells the instrument the patch, lets the hook draw it (as take() does), reads it. */
static csf_status verify_read(vctx *v, const double rgb[3], csf_photometer_reading *r, csf_error *err)
{
    csf_photometer_show_patch(v->ph, rgb[0], rgb[1], rgb[2]);
    if (v->o->show_patch && v->o->show_patch(v->o->show_patch_user, rgb, v->index) != 0)
        return csf_error_set(err, CSF_E_ABORTED, "the verification patch could not be drawn");
    v->index++;
    csf_status st = csf_photometer_measure(v->ph, r, err);
    if (st) return st;
    /* an answer that cannot be light is not a deviation of the display */
    csf_meter_limits l;
    csf_meter_limits_default(&l);
    char why[400];
    if (csf_meter_absurd(r, &l, why, sizeof why))
        return csf_error_set(err, CSF_E_PROTOCOL, "photometer %.120s, verification reading %llu: %s",
                             csf_photometer_spec(v->ph), (unsigned long long)(v->index - 1), why);
    return CSF_OK;
}

/* Does the deviation verify saw agree with the error the profile states? A verification reading
 * differs from the profile by the profile's own error plus that reading's noise, so a profile as
 * good as stated shows at most about stated + 3 sd of one reading (sd from the settled warm-up
 * whites: the last six, or all when fewer). */
static void verify_against_statement(const csf_display_profile *p, const csf_display_verify_opts *o,
                                     const double *w, int n, csf_display_verify_result *res)
{
    double target, stated[CSF_CH_COUNT];
    res->profile_target_met = csf_profile_statement(p, &target, stated);
    res->profile_stated_rel = NAN;
    res->allowed_dev_rel = NAN;
    res->within_stated = -1;
    int k = n < 6 ? n : 6;
    res->reading_noise_rel = k >= 2 ? csf_sample_sd(w + n - k, k) / w[n - 1] : NAN;
    if (res->profile_target_met < 0) return;
    double worst = 0;
    for (int c = o->channels ? 0 : CSF_CH_GREY; c < CSF_CH_COUNT; c++)
        if (!isnan(stated[c])) worst = fmax(worst, stated[c]);
    res->profile_stated_rel = worst;
    res->allowed_dev_rel = worst + 3 * (isfinite(res->reading_noise_rel) ? res->reading_noise_rel : 0);
    res->within_stated = res->max_dev_rel <= res->allowed_dev_rel;
}

/* verify's warm-up: white until the judgement of calibrate (calib/warmup_model.h) calls the
 * display warm or warmup_max readings are taken, against the profile's own target when it states
 * one. The white readings go to w (256). */
static csf_status verify_warmup(vctx *v, const csf_display_profile *p, double *w,
                                csf_display_verify_result *res, csf_error *err)
{
    const csf_display_verify_opts *o = v->o;
    const double white_rgb[3] = {1, 1, 1};
    double tw[256], t0 = NAN;
    int maxn = o->warmup_max < 6 ? 6 : (o->warmup_max > 256 ? 256 : o->warmup_max);
    double stated[CSF_CH_COUNT], target = NAN;
    if (!(csf_profile_statement(p, &target, stated) >= 0 && target > 0)) target = o->target_rel;
    csf_warm_judgement j;
    memset(&j, 0, sizeof j);
    while (res->n_warmup < maxn) {
        if (res->n_warmup > 0) csf_photometer_wait(v->ph, o->warmup_wait_s);
        csf_photometer_reading r;
        csf_status st = verify_read(v, white_rgb, &r, err);
        if (st) return st;
        if (isnan(t0)) t0 = r.t_s - r.integration_s;
        tw[res->n_warmup] = r.t_s;
        w[res->n_warmup++] = r.lum_cdm2;
        res->warmup_s = r.t_s - t0;
        res->warm = csf_display_warm_judge(tw, w, res->n_warmup, target, CSF_WARM_SESSION_S, &j);
        res->warmup_change_rel = j.change_rel;
        if (res->warm) break;
    }
    res->warmup_remaining_rel = j.remaining_rel;
    res->warmup_settled_gap_rel = j.settled_gap_rel;
    res->warmup_wait_s = j.wait_s;
    return CSF_OK;
}

csf_status csf_display_verify_run(csf_photometer *ph, const csf_display_profile *p,
                                  const csf_display_verify_opts *o, csf_display_verify_result *res,
                                  csf_error *err)
{
    memset(res, 0, sizeof *res);
    for (int c = 0; c < CSF_CH_COUNT; c++) res->dev_rel[c] = NAN;
    res->warmup_change_rel = NAN;
    if (o->n_levels < 1 || o->n_levels > 64)
        return csf_error_set(err, CSF_E_INVALID_ARG, "verify levels %d out of range (1 to 64)", o->n_levels);
    if (o->channels && !csf_profile_has_channels(p))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "profile %s has no r, g, b curves (it was calibrated "
                             "with --no-channels): verify grey only, or calibrate again with channels",
                             csf_profile_id(p));
    vctx v = {ph, o, 0};
    csf_photometer_reading r;
    /* warm-up: the same readings and the same judgement as calibrate; a display still warming up
     * would be reported as drifted (or, worse, as fine) for a reason that goes away by itself */
    double w[256];
    csf_status wst = verify_warmup(&v, p, w, res, err);
    if (wst) return wst;
    /* white: the mean of the last three warm-up readings (the settled level) */
    int n = res->n_warmup, k = n < 3 ? n : 3;
    double wm = 0;
    for (int i = n - k; i < n; i++) wm += w[i];
    wm /= k;
    double peak = csf_profile_lum_max(p), black = csf_profile_lum_black(p);
    res->white_dev_rel = wm / peak - 1;
    res->dev_rel[CSF_CH_GREY] = fabs(res->white_dev_rel);
    res->n_checked[CSF_CH_GREY] = 1;
    for (int ch = o->channels ? 0 : CSF_CH_GREY; ch < CSF_CH_COUNT; ch++) {
        double cpeak = ch == CSF_CH_GREY ? peak : black + csf_profile_channel_lum(p, ch, 1.0);
        if (ch < 3) {
            res->dev_rel[ch] = 0;
            res->n_checked[ch] = 0;
        }
        /* channels are checked at full drive too (grey's full drive is the white above) */
        int top = ch == CSF_CH_GREY ? o->n_levels : o->n_levels + 1;
        for (int i = 1; i <= top; i++) {
            double d = i > o->n_levels ? 1.0 : (double)i / (o->n_levels + 1);
            double rgb[3] = {d, d, d};
            if (ch < 3) {
                rgb[0] = rgb[1] = rgb[2] = 0;
                rgb[ch] = d;
            }
            double want =
                ch == CSF_CH_GREY ? csf_profile_grey_lum(p, d) : black + csf_profile_channel_lum(p, ch, d);
            csf_status st = verify_read(&v, rgb, &r, err);
            if (st == CSF_E_TOO_DARK && want < 0.1 * cpeak) continue;
            if (st) return st;
            if (want < 0.1 * cpeak) continue;
            double dev = fabs(r.lum_cdm2 / want - 1);
            if (dev > res->dev_rel[ch]) res->dev_rel[ch] = dev;
            res->n_checked[ch]++;
        }
    }
    res->max_dev_rel = 0;
    for (int c = 0; c < CSF_CH_COUNT; c++)
        if (isfinite(res->dev_rel[c]) && res->dev_rel[c] > res->max_dev_rel)
            res->max_dev_rel = res->dev_rel[c];
    res->n_readings = (int)v.index;
    verify_against_statement(p, o, w, n, res);
    return CSF_OK;
}

csf_status csf_display_verify(csf_photometer *ph, const csf_display_profile *p, int n_levels,
                              double *max_dev_rel, double *white_dev_rel, csf_error *err)
{
    csf_display_verify_opts o;
    csf_display_verify_defaults(&o);
    o.n_levels = n_levels;
    csf_display_verify_result res;
    csf_status st = csf_display_verify_run(ph, p, &o, &res, err);
    if (st) return st;
    *max_dev_rel = res.max_dev_rel;
    *white_dev_rel = res.white_dev_rel;
    return CSF_OK;
}
