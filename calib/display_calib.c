/* Photometric calibration procedure (see calib/display_calib.h for the contract).
 *
 * Grey: a coarse grid, then one step at a time while the curve's stated error (see "the stated
 * error" below: the knots' noise plus the model's own error, as a maximum over the range) is above
 * its aim. Where the model part dominates, the interval with the largest leave-one-out estimate
 * is split (where its neighbours' secants cross: at a kink that is the break); where the noise
 * part does, the noisiest level above 10 % of peak is read again. Where the curve is nearly a
 * power law the model already fits and readings go to averaging; where it bends (an LCD toe, a
 * kink) they go to new levels.
 *
 * Channels: fitted through the grey curve (a smooth channel-to-grey ratio with two to four
 * parameters, see fit_ratio), so a handful of readings per channel average their noise instead
 * of each becoming a knot; the channel's own adaptive curve is the fallback.
 *
 * Drift: the white (grey at full drive) is re-read between sweeps; a warm-up curve A + B e^(-t/tau)
 * fitted to every white reading scales each reading to the latest white, so a display still
 * warming up does not bend the curve (references interpolated in time when the curve does not
 * fit). */
#include "calib/display_calib.h"
#include "calib/curve_error.h"
#include "calib/meter_check.h"
#include "calib/warmup_model.h"
#include "core/json_read.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

/* ROLE_DARK_REJECTED: a dark reading of a series found contradictory (see dark_series), or taken
 * while the sensor was off the patch (see set_aside); ROLE_REJECTED: a sweep reading taken
 * between a good white reference and one that showed the sensor had moved or the display had
 * changed. Both are kept in the store and replayed, used for nothing. ROLE_CHECK: a spot check
 * between the sweep's levels (see spot_checks), stored under its channel like a sweep reading but
 * never part of the profile it tests. */
enum { ROLE_WARMUP, ROLE_DARK, ROLE_REF, ROLE_SWEEP, ROLE_DARK_REJECTED, ROLE_REJECTED, ROLE_CHECK };

typedef struct {
    int role, ch;
    double drive;
    double lum;       /* measured; NAN when too dark */
    double xyz[3];
    int has_xyz;
    double t_s;
} rd;

typedef struct {
    csf_photometer *ph;
    csf_store *store;
    int64_t sid;
    const csf_display_calib_opts *o;
    rd *r;
    size_t n, cap;
    csf_reading *replay;
    size_t n_replay, replay_pos;
    int seq;              /* next store sequence number (every attempt, failed ones too) */
    int live_started;
    double t_last;
    /* The instrument's reading number and clock as an uninterrupted session would have them: a
     * failed attempt ends the run, so after a resume it is retried under its own number and from
     * the time of the last reading that counted (neither the number nor the clock of the failed
     * attempt carries over: a faulted and resumed session reads what an unfaulted one read). */
    uint64_t inst_index;
    double t_accepted;
    double pending_wait_s; /* wait before the next live reading (warm-up); nothing while replaying */
    int dark_unconfirmed;  /* the dark series answered only "too dark": confirm after white */
    int suspect;           /* replay met a stored white reference that failed a check which puts
                              the readings since the white before it in doubt (set_aside) */
    int dark_live_series;  /* dark series taken live in this run (the re-measure limit) */
    int n_sweep, n_warmup, n_check;
    double noise_rel, noise_abs;
    double black;
    int progress_shown;
    /* smooth drift model fitted to every white reading (warm-up and references):
     * w(t) = A + B exp(-t/tau); refitted whenever a white reading is added */
    int drift_ok;
    double drift_A, drift_B, drift_tau, drift_tref;
    double drift_rms; /* relative rms of the white readings about the drift curve: the
                         instrument's noise with more degrees of freedom than one reference */
    csf_warm_judgement warm; /* the warm-up judgement after the latest warm-up reading */
    /* The quantile of the worst knot's noise a statement takes: the median for the error the
     * profile states, MET_QUANTILE for every "is the target met" decision (see the stated error). */
    double noise_quantile;
} ctx;

static const char *ch_name_store(int role, int ch)
{
    if (role == ROLE_WARMUP) return "white";
    if (role == ROLE_DARK) return "dark";
    static const char *n[4] = {"r", "g", "b", "grey"};
    return n[ch];
}

static csf_reading_status reading_status(csf_status st)
{
    switch (st) {
    case CSF_OK: return CSF_READING_OK;
    case CSF_E_TOO_DARK: return CSF_READING_TOO_DARK;
    case CSF_E_SATURATED: return CSF_READING_SATURATED;
    case CSF_E_TIMEOUT: return CSF_READING_TIMEOUT;
    default: return CSF_READING_ERROR;
    }
}

void csf_display_calib_defaults(csf_display_calib_opts *o)
{
    memset(o, 0, sizeof *o);
    o->target_rel = 0.0025;
    o->budget = 48;
    o->checks = 4;
    o->channels = 1;
    o->warmup_wait_s = 5;
    o->warmup_max = 40;
    o->drive_levels = 0; /* csfcal dithers, so fractional drives are real on screen */
}

static void progress(ctx *c)
{
    if (!c->o->progress) return;
    int total = c->o->budget > 0 ? c->o->budget : 1;
    int done = c->n_sweep > total ? total : c->n_sweep;
    if (c->n && c->r[c->n - 1].role == ROLE_WARMUP) {
        if (c->warm.model_significant && !isfinite(c->warm.wait_s))
            fprintf(stderr, "\rwarming up: white reading %d (%.0f s): white still drifting, not settling   ",
                    c->n_warmup, c->t_last);
        else if (c->warm.model_significant && c->warm.wait_s > 0)
            fprintf(stderr,
                    "\rwarming up: white reading %d (%.0f s): %.2f %% of drift left over the session, "
                    "about %.0f s more   ",
                    c->n_warmup, c->t_last, 100 * c->warm.remaining_rel, c->warm.wait_s);
        else
            fprintf(stderr, "\rwarming up: white reading %d (%.0f s)                       ", c->n_warmup,
                    c->t_last);
        c->progress_shown = 1;
        return;
    }
    if (c->n && c->r[c->n - 1].role == ROLE_CHECK) {
        fprintf(stderr, "\rspot checks between the sweep's levels: %d taken                          ",
                c->n_check);
        c->progress_shown = 1;
        return;
    }
    /* time per reading since the warm-up ended (its waits would inflate the estimate) */
    size_t first = 0;
    while (first < c->n && c->r[first].role == ROLE_WARMUP) first++;
    double t0 = first > 0 ? c->r[first - 1].t_s : 0;
    double per = c->n > first + 1 ? (c->t_last - t0) / (double)(c->n - first) : 1.0;
    int width = 30, fill = done * width / total;
    char bar[32];
    for (int i = 0; i < width; i++) bar[i] = i < fill ? '#' : '.';
    bar[width] = 0;
    fprintf(stderr, "\r[%s] %2d/%d sweep readings, about %.0f s left  ", bar, done, total,
            per * (total - done));
    c->progress_shown = 1;
}

static csf_status push(ctx *c, const rd *x, csf_error *err)
{
    if (c->n == c->cap) {
        size_t nc = c->cap ? c->cap * 2 : 128;
        rd *a = realloc(c->r, nc * sizeof *a);
        if (!a) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
        c->r = a;
        c->cap = nc;
    }
    c->r[c->n++] = *x;
    return CSF_OK;
}

static void fit_drift(ctx *c);

static void patch_rgb(int ch, double drive, double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = drive;
    if (ch < 3) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        rgb[ch] = drive;
    }
}

/* The last white reading that counted (warm-up or reference): NAN when none. */
static const rd *last_white(const ctx *c)
{
    for (size_t i = c->n; i-- > 0;)
        if ((c->r[i].role == ROLE_WARMUP || c->r[i].role == ROLE_REF) && isfinite(c->r[i].lum)) return &c->r[i];
    return NULL;
}

/* Mean of the dark readings that count; NAN when there are none or all said "too dark". */
static double dark_mean(const ctx *c)
{
    double s = 0;
    int k = 0;
    for (size_t i = 0; i < c->n; i++)
        if (c->r[i].role == ROLE_DARK && isfinite(c->r[i].lum)) {
            s += c->r[i].lum;
            k++;
        }
    return k ? s / k : NAN;
}

/* Plausibility of a live reading that the instrument reported as fine (calib/meter_check.h):
 * the failures a real meter shows without saying so. A reading that fails is stored with status
 * "error" and its values, ends the run, and is retried under its own number on --resume. */
static csf_status sanity(const ctx *c, int role, const double rgb[3], const csf_photometer_reading *pr,
                         csf_error *e, int *span)
{
    *span = 0;
    csf_meter_limits l;
    csf_meter_limits_default(&l);
    if (c->o->max_lum_cdm2 > 0) l.max_lum_cdm2 = c->o->max_lum_cdm2;
    char why[400];
    if (csf_meter_absurd(pr, &l, why, sizeof why)) return csf_error_set(e, CSF_E_PROTOCOL, "%s", why);
    if (c->n > 0) {
        const rd *p = &c->r[c->n - 1];
        csf_photometer_reading prev = {.lum_cdm2 = p->lum, .has_xyz = p->has_xyz};
        memcpy(prev.xyz, p->xyz, sizeof prev.xyz);
        double prgb[3];
        patch_rgb(p->ch, p->drive, prgb);
        if (csf_meter_frozen(&prev, prgb, pr, rgb, &l, why, sizeof why)) return csf_error_set(e, CSF_E_DEVICE, "%s", why);
    }
    const rd *w = last_white(c);
    int is_white = rgb[0] == 1 && rgb[1] == 1 && rgb[2] == 1;
    int is_black = rgb[0] == 0 && rgb[1] == 0 && rgb[2] == 0;
    if (w && is_black && csf_meter_no_contrast(w->lum, pr->lum_cdm2, &l, why, sizeof why))
        return csf_error_set(e, CSF_E_DEVICE, "%s", why);
    if (is_white && role == ROLE_REF && csf_meter_no_contrast(pr->lum_cdm2, dark_mean(c), &l, why, sizeof why)) {
        *span = 1;
        return csf_error_set(e, CSF_E_DEVICE, "%s; the readings since the last white are measured again on --resume", why);
    }
    if (w && is_white && role == ROLE_REF) {
        double ratio = 1;
        if (c->drift_ok) {
            double a = c->drift_A + c->drift_B * exp(-w->t_s / c->drift_tau);
            double b = c->drift_A + c->drift_B * exp(-pr->t_s / c->drift_tau);
            if (a > 0 && b > 0) ratio = b / a;
        }
        if (csf_meter_white_step(w->lum, pr->lum_cdm2, ratio, c->noise_rel, &l, why, sizeof why)) {
            *span = 1;
            return csf_error_set(e, CSF_E_DEVICE, "%s; the readings since the last white are measured again on --resume", why);
        }
    }
    if (w && !is_white && csf_meter_above_white(pr->lum_cdm2, w->lum, c->noise_abs, why, sizeof why))
        return csf_error_set(e, CSF_E_DEVICE, "%s", why);
    return CSF_OK;
}

static const char *fault_hint(csf_status st, int is_white)
{
    switch (st) {
    case CSF_E_TOO_DARK:
        return is_white ? "white is below the instrument's floor: is the cap on, is the sensor on the patch?"
                        : "below the instrument's floor where the display shows light: is the sensor still on the patch?";
    case CSF_E_SATURATED:
        return "over the instrument's range: choose its higher range, add a neutral density filter, or lower "
               "the display's brightness";
    case CSF_E_TIMEOUT: return "the instrument fell silent: check its cable and power";
    case CSF_E_GONE: return "the instrument is gone: reconnect it";
    case CSF_E_PROTOCOL: return "the instrument's answer cannot be a reading";
    default: return "";
    }
}

/* The message a fault ends the calibration with: which instrument, which reading, the problem. */
static csf_status meter_fault(const ctx *c, csf_status st, int role, int ch, double drive, const csf_error *m,
                              csf_error *err)
{
    static const char *what[] = {
        [ROLE_WARMUP] = "warm-up white", [ROLE_DARK] = "dark",          [ROLE_REF] = "white reference",
        [ROLE_SWEEP] = "sweep",          [ROLE_DARK_REJECTED] = "dark", [ROLE_REJECTED] = "sweep",
        [ROLE_CHECK] = "spot check"};
    _Static_assert(sizeof what / sizeof what[0] == ROLE_CHECK + 1, "a name for every role");
    static const char *chn[4] = {"red", "green", "blue", "grey"};
    double rgb[3];
    patch_rgb(ch, drive, rgb);
    const char *hint = fault_hint(st, rgb[0] == 1 && rgb[1] == 1 && rgb[2] == 1);
    return csf_error_set(err, st, "photometer %.120s, reading %llu (%s, %s at drive %.4g): %.260s%s%s",
                         csf_photometer_spec(c->ph), (unsigned long long)c->inst_index, what[role], chn[ch],
                         drive, m->msg, *hint ? "; " : "", hint);
}

/* The next stored reading of a session being resumed, which must be the one the procedure
 * asks for: a failed attempt there is passed over, as the live run went on to retry it.
 * *replayed is 0 when the stored readings have run out: the reading is then taken live. */
static csf_status take_replayed(ctx *c, int role, double drive, int accept_dark, const char *want, rd *out,
                                int *replayed, csf_error *err)
{
    *replayed = 1;
    while (c->replay_pos < c->n_replay) {
        const csf_reading *s = &c->replay[c->replay_pos++];
        if (strcmp(s->channel, want) != 0 || fabs(s->drive01 - drive) > 1e-12)
            return csf_error_set(err, CSF_E_FORMAT,
                                 "stored reading %d of session %lld is %s at %.6g where the procedure "
                                 "expects %s at %.6g: the session was made by a different procedure "
                                 "or settings and cannot be resumed", s->seq, (long long)c->sid,
                                 s->channel, s->drive01, want, drive);
        if (s->status == CSF_READING_STATUS_UNKNOWN) {
            /* A status a newer csfcal (or a hand) wrote: neither a good reading nor a failed
             * attempt for this one to decide on. */
            char shown[64];
            csf_store_printable(s->status_text, shown, sizeof shown);
            return csf_error_set(err, CSF_E_FORMAT,
                                 "stored reading %d of session %lld has status '%s', which this "
                                 "csfcal does not know (allowed ok, too_dark, saturated, timeout, "
                                 "error): the session cannot be resumed by it",
                                 s->seq, (long long)c->sid, shown);
        }
        c->t_last = s->t_s;
        int ok = s->status == CSF_READING_OK;
        int dark = s->status == CSF_READING_TOO_DARK;
        if (!ok && !(dark && accept_dark)) {
            /* a failed attempt: the live run stopped there and a resume retries it. A white
             * reference that failed because the sensor had moved or the display had changed
             * also puts the readings before it in doubt: the caller sets them aside (the same
             * check on the same state, so every resume decides alike) */
            if (role == ROLE_REF && isfinite(s->lum_cdm2)) {
                csf_photometer_reading sp = {.lum_cdm2 = s->lum_cdm2, .xyz = {s->X, s->Y, s->Z},
                                             .has_xyz = s->has_xyz, .t_s = s->t_s};
                double rgb[3] = {1, 1, 1};
                int span = 0;
                csf_error tmp;
                if (sanity(c, role, rgb, &sp, &tmp, &span) && span) {
                    c->suspect = 1;
                    return csf_error_set(err, CSF_E_INSUFFICIENT, "stored reading %d: %s", s->seq, tmp.msg);
                }
            }
            continue;
        }
        c->inst_index++;
        c->t_accepted = s->t_s;
        c->pending_wait_s = 0; /* the stored reading already includes any wait before it */
        out->lum = ok ? s->lum_cdm2 : NAN;
        out->xyz[0] = s->X;
        out->xyz[1] = s->Y;
        out->xyz[2] = s->Z;
        out->has_xyz = ok && s->has_xyz;
        out->t_s = s->t_s;
        if (role == ROLE_SWEEP) c->n_sweep++;
        if (role == ROLE_WARMUP) c->n_warmup++;
        if (role == ROLE_CHECK) c->n_check++;
        csf_status rst = push(c, out, err);
        if (!rst && (role == ROLE_WARMUP || role == ROLE_REF)) fit_drift(c);
        return rst;
    }
    *replayed = 0;
    return CSF_OK;
}

/* Every live attempt goes into the store at once, failed ones too; keep: its values are stored
 * (a reading, or an implausible one), else NAN. */
static csf_status store_live_reading(const ctx *c, const char *want, double drive, int keep,
                                     const csf_photometer_reading *pr, csf_status st, csf_error *err)
{
    csf_reading sr;
    memset(&sr, 0, sizeof sr);
    sr.session_id = c->sid;
    sr.seq = c->seq;
    snprintf(sr.channel, sizeof sr.channel, "%s", want);
    sr.drive01 = drive;
    sr.lum_cdm2 = keep ? pr->lum_cdm2 : NAN;
    sr.X = keep ? pr->xyz[0] : NAN;
    sr.Y = keep ? pr->xyz[1] : NAN;
    sr.Z = keep ? pr->xyz[2] : NAN;
    sr.has_xyz = keep && pr->has_xyz;
    sr.t_s = pr->t_s;
    sr.status = reading_status(st);
    return csf_store_add_reading(c->store, &sr, err);
}

/* A reading from the instrument: the patch shown, measured, checked, stored. */
static csf_status take_live(ctx *c, int role, int ch, double drive, int accept_dark, const char *want,
                            rd *out, csf_error *err)
{
    if (!c->live_started) {
        csf_photometer_resume_at(c->ph, c->inst_index, c->t_accepted);
        c->live_started = 1;
    }
    if (c->pending_wait_s > 0) csf_photometer_wait(c->ph, c->pending_wait_s);
    c->pending_wait_s = 0;
    double rgb[3];
    patch_rgb(ch, drive, rgb);
    /* the instrument is told the patch first (the built-in uniform source), then the hook draws
     * it and may install a screen source of its own (the rendered frame, csfcal display --render) */
    csf_photometer_show_patch(c->ph, rgb[0], rgb[1], rgb[2]);
    if (c->o->show_patch && c->o->show_patch(c->o->show_patch_user, rgb, c->inst_index) != 0)
        return csf_error_set(err, CSF_E_ABORTED, "the patch could not be drawn; readings so far are kept");
    csf_photometer_reading pr;
    csf_error merr;
    csf_error_clear(&merr);
    csf_status st = csf_photometer_measure(c->ph, &pr, &merr);
    int implausible = 0, span = 0;
    if (!st) implausible = (st = sanity(c, role, rgb, &pr, &merr, &span)) != CSF_OK;
    int keep = !st || implausible; /* an implausible reading is stored with its values */
    if (c->store) {
        csf_status sst = store_live_reading(c, want, drive, keep, &pr, st, err);
        if (sst) return sst;
    }
    c->seq++;
    c->t_last = pr.t_s;
    if (st && !(st == CSF_E_TOO_DARK && accept_dark)) return meter_fault(c, st, role, ch, drive, &merr, err);
    c->inst_index++;
    c->t_accepted = pr.t_s;
    out->lum = st ? NAN : pr.lum_cdm2;
    memcpy(out->xyz, pr.xyz, sizeof pr.xyz);
    out->has_xyz = !st && pr.has_xyz;
    out->t_s = pr.t_s;
    if (role == ROLE_SWEEP) c->n_sweep++;
    if (role == ROLE_WARMUP) c->n_warmup++;
    if (role == ROLE_CHECK) c->n_check++;
    csf_status pst = push(c, out, err);
    if (!pst && (role == ROLE_WARMUP || role == ROLE_REF)) fit_drift(c);
    progress(c);
    return pst;
}

/* Takes one reading: from the stored session while replaying, else from the instrument (and
 * stores it at once). accept_dark: a too-dark answer is a valid result here (black of an OLED). */
static csf_status take(ctx *c, int role, int ch, double drive, int accept_dark, rd *out, csf_error *err)
{
    memset(out, 0, sizeof *out);
    out->role = role;
    out->ch = ch;
    out->drive = drive;
    const char *want = ch_name_store(role, ch);
    int replayed;
    csf_status rst = take_replayed(c, role, drive, accept_dark, want, out, &replayed, err);
    if (replayed) return rst;
    return take_live(c, role, ch, drive, accept_dark, want, out, err);
}

/* White reference events: consecutive reference readings averaged (time and luminance). */
static size_t ref_events(const ctx *c, double *t, double *w, size_t max)
{
    size_t ne = 0;
    int open = 0;
    double st = 0, sw = 0;
    int k = 0;
    for (size_t i = 0; i <= c->n; i++) {
        const rd *x = i < c->n ? &c->r[i] : NULL;
        int is_ref = x && x->role == ROLE_REF && !isnan(x->lum);
        if (is_ref) {
            st += x->t_s;
            sw += x->lum;
            k++;
            open = 1;
        } else if (open) {
            if (ne < max) {
                t[ne] = st / k;
                w[ne] = sw / k;
                ne++;
            }
            st = sw = 0;
            k = 0;
            open = 0;
        }
    }
    return ne;
}

/* Warm-up drift as a smooth function of time, fitted to every white reading taken so far (the
 * warm-up series and all references): w(t) = A + B exp(-t/tau), tau searched on a log grid, A and
 * B by least squares. A display settling after power-on follows such a curve; fitting it to ~20
 * white readings gives the white at any moment to a fraction of one reading's noise, where the
 * ratio of two single references (the fallback) carries the noise of both into every reading.
 * The model is used only when it explains the white readings to within the instrument noise. */
static void fit_drift(ctx *c)
{
    c->drift_ok = 0;
    size_t nw = 0;
    double tlast = 0;
    int nref = 0;
    for (size_t i = 0; i < c->n; i++)
        if ((c->r[i].role == ROLE_WARMUP || c->r[i].role == ROLE_REF) && isfinite(c->r[i].lum)) {
            nw++;
            tlast = c->r[i].t_s;
            nref += c->r[i].role == ROLE_REF;
        }
    if (nw < 8 || nref < 1) return;
    double best_sse = INFINITY, bA = 0, bB = 0, btau = 0;
    for (int k = 0; k <= 64; k++) {
        double tau = 1.0 * pow(1.15, k);
        double s0 = 0, s1 = 0, s11 = 0, sy = 0, s1y = 0, syy = 0;
        for (size_t i = 0; i < c->n; i++) {
            const rd *x = &c->r[i];
            if (!((x->role == ROLE_WARMUP || x->role == ROLE_REF) && isfinite(x->lum))) continue;
            double e = exp(-x->t_s / tau);
            s0 += 1; s1 += e; s11 += e * e; sy += x->lum; s1y += e * x->lum; syy += x->lum * x->lum;
        }
        double det = s0 * s11 - s1 * s1;
        if (!(det > 1e-12 * s0 * s11)) continue;
        double A = (s11 * sy - s1 * s1y) / det, B = (s0 * s1y - s1 * sy) / det;
        double sse = syy - 2 * A * sy - 2 * B * s1y + A * A * s0 + 2 * A * B * s1 + B * B * s11;
        if (sse < best_sse) {
            best_sse = sse;
            bA = A; bB = B; btau = tau;
        }
    }
    if (!(bA > 0) || !isfinite(best_sse)) return;
    double rms = sqrt(fmax(best_sse, 0) / (double)(nw > 3 ? nw - 3 : 1)) / bA;
    double w_end = bA + bB * exp(-tlast / btau);
    if (!(w_end > 0)) return;
    /* the model must explain the white readings to within the noise the first references show
     * (2x, and at least 0.1 %); otherwise the drift is something else: interpolate references */
    double allow = fmax(2 * c->noise_rel, 0.001);
    if (c->noise_rel > 0 && rms > allow) return;
    c->drift_ok = 1;
    c->drift_rms = rms;
    c->drift_A = bA;
    c->drift_B = bB;
    c->drift_tau = btau;
    c->drift_tref = tlast;
}

/* Drift factor at time t: white at the latest white reading over the white at t (1 without
 * references). */
static double drift_factor(const ctx *c, double t)
{
    if (c->drift_ok) {
        double w_ref = c->drift_A + c->drift_B * exp(-c->drift_tref / c->drift_tau);
        double w_t = c->drift_A + c->drift_B * exp(-t / c->drift_tau);
        if (w_t > 0) return w_ref / w_t;
    }
    double et[64], ew[64];
    size_t ne = ref_events(c, et, ew, 64);
    if (ne == 0) return 1.0;
    double w;
    if (t <= et[0]) w = ew[0];
    else if (t >= et[ne - 1]) w = ew[ne - 1];
    else {
        size_t k = 0;
        while (k + 1 < ne && et[k + 1] < t) k++;
        w = ew[k] + (ew[k + 1] - ew[k]) * (t - et[k]) / (et[k + 1] - et[k]);
    }
    return ew[ne - 1] / w;
}

static double corrected(const ctx *c, const rd *x)
{
    return x->lum * drift_factor(c, x->t_s);
}

static void update_black(ctx *c)
{
    double s = 0;
    int k = 0;
    for (size_t i = 0; i < c->n; i++)
        if (c->r[i].role == ROLE_DARK) {
            s += isnan(c->r[i].lum) ? 0 : corrected(c, &c->r[i]);
            k++;
        }
    c->black = k ? s / k : 0;
}

/* Points (drive, lum) of one curve from the readings so far; channel curves exclude black.
 * Returns count; arrays malloc'd. */
static size_t curve_points(const ctx *c, int ch, double **v, double **L)
{
    *v = malloc((c->n + 1) * sizeof(double));
    *L = malloc((c->n + 1) * sizeof(double));
    size_t k = 0;
    if (!*v || !*L) return 0;
    if (ch < 3) {
        (*v)[k] = 0;
        (*L)[k++] = 0;
    }
    for (size_t i = 0; i < c->n; i++) {
        const rd *x = &c->r[i];
        if (ch == CSF_CH_GREY && x->role == ROLE_DARK) {
            (*v)[k] = 0;
            (*L)[k++] = isnan(x->lum) ? 0 : corrected(c, x);
        } else if (ch == CSF_CH_GREY && x->role == ROLE_REF) {
            (*v)[k] = 1;
            (*L)[k++] = corrected(c, x);
        } else if (x->role == ROLE_SWEEP && x->ch == ch) {
            (*v)[k] = x->drive;
            double l = isnan(x->lum) ? 0 : corrected(c, x);
            (*L)[k++] = ch < 3 ? l - c->black : l;
        }
    }
    return k;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Distinct sorted drives and mean luminance per drive. */
static size_t distinct(const double *v, const double *L, size_t n, double *dv, double *dl, int *cnt)
{
    double *pairs = malloc(2 * (n ? n : 1) * sizeof(double));
    if (!pairs) return 0;
    for (size_t i = 0; i < n; i++) {
        pairs[2 * i] = v[i];
        pairs[2 * i + 1] = L[i];
    }
    qsort(pairs, n, 2 * sizeof(double), cmp_dbl);
    size_t m = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i;
        double s = 0;
        while (j < n && pairs[2 * j] == pairs[2 * i]) s += pairs[2 * j++ + 1];
        dv[m] = pairs[2 * i];
        if (cnt) cnt[m] = (int)(j - i);
        dl[m++] = s / (double)(j - i);
        i = j;
    }
    free(pairs);
    return m;
}

/* Readings to average at a level of luminance lum (relative noise plus absolute noise). */
static int repeats_for(const ctx *c, double lum, double peak)
{
    if (!(lum >= 0.1 * peak) || !(lum > 0)) return 1;
    double s = sqrt(c->noise_rel * c->noise_rel + (c->noise_abs / lum) * (c->noise_abs / lum));
    double q = s / (c->o->target_rel / 2.5);
    double reads = q * q + 0.5; /* rounded: a noise estimate just above the limit is no reason to double */
    /* capped before the cast: replayed readings from a damaged store can make the noise estimate
     * huge or NaN (fuzz_resume found it), and the most averaging is the safe answer then */
    if (!(reads < 4.0)) return 4;
    return reads < 1.0 ? 1 : (int)reads;
}

/* Predicted luminance of a curve at drive v from the current points. */
static double predict(const ctx *c, int ch, double v)
{
    double *pv, *pl;
    size_t k = curve_points(c, ch, &pv, &pl);
    double out = NAN;
    csf_error e;
    if (k >= 2 && csf_profile_fit_curve(pv, pl, k, ch < 3, &v, &out, 1, &e)) out = NAN;
    free(pv);
    free(pl);
    return out;
}

/* Drive values the framebuffer can show: multiples of 1/drive_levels (8 bit: 1/255); 0 means
 * continuous (a dithered or high-depth output). */
static double snap(const ctx *c, double v)
{
    if (c->o->drive_levels <= 0) return v;
    return floor(v * c->o->drive_levels + 0.5) / c->o->drive_levels;
}

/* ---- channels through grey ----
 * A channel alone and the grey curve share the panel's transfer shape (toe, kinks, the
 * driver's LUT); what differs is a slowly varying ratio: a few tenths in gamma, and a load
 * effect (LCD crosstalk, OLED power limiting) that grows with how much light the whole grey
 * patch gives. So a channel is modelled as
 *     Lc(v) = Lc1 * x * exp(c0 + a u [+ b u^2] [+ d x^2]),   u = ln v,  x = G(v)/G(1),
 * G the grey curve less black (measured with more readings), Lc1 the mean of the channel's
 * full-drive readings; the coefficients are fitted by weighted least squares to the channel's
 * readings. The few channel readings then average their noise through two to four parameters
 * instead of each becoming a knot, and the channel inherits the grey curve's corners. The
 * simplest basis that explains the readings within their noise is used; when none does, the
 * channel keeps its own Hermite curve through its readings. */
enum { RB_ONE, RB_U, RB_U2, RB_X2 };
typedef struct {
    int ok;    /* explains the readings within their noise */
    int valid; /* a sane fit, though maybe not within noise */
    int nb, basis[4];
    double coef[4];
    double lc1, umin, chi2_dof;
    int n;
} ratio_model;

/* Grey luminance less black, from the grey readings so far, at drives v[0..n-1]. */
static int grey_incr(const ctx *c, const double *v, double *out, size_t n)
{
    double *pv, *pl;
    size_t k = curve_points(c, CSF_CH_GREY, &pv, &pl);
    double *ev = malloc((n + 1) * sizeof(double)), *el = malloc((n + 1) * sizeof(double));
    int rc = -1;
    csf_error e;
    if (ev && el && k >= 2) {
        ev[0] = 0;
        memcpy(ev + 1, v, n * sizeof(double));
        if (csf_profile_fit_curve(pv, pl, k, 0, ev, el, n + 1, &e) == CSF_OK) {
            for (size_t i = 0; i < n; i++) out[i] = el[i + 1] - el[0];
            rc = 0;
        }
    }
    free(pv); free(pl); free(ev); free(el);
    return rc;
}

static double basis_val(int b, double u, double x)
{
    switch (b) {
    case RB_ONE: return 1;
    case RB_U: return u;
    case RB_U2: return u * u;
    default: return x * x;
    }
}

/* ratio channel/grey (both normalised at full drive) at drive v where x = G(v)/G(1) */
static double ratio_eval(const ratio_model *rm, double v, double x)
{
    double u = v > 0 ? log(v) : rm->umin - 50;
    /* below the fitted range the ratio goes on as the power of the drive it has at the range's
     * low end (a quadratic in ln v would run away) */
    double ue = u < rm->umin ? rm->umin : u, r = 0, slope = 0;
    for (int j = 0; j < rm->nb; j++) {
        r += rm->coef[j] * basis_val(rm->basis[j], ue, x);
        if (rm->basis[j] == RB_U) slope += rm->coef[j];
        if (rm->basis[j] == RB_U2) slope += 2 * rm->coef[j] * ue;
    }
    if (u < ue) r += slope * (u - ue);
    return exp(r);
}

#define RATIO_GREY_VAR 4.9e-7 /* the grey curve's own error at a level (about 0.07 %), relative^2 */

/* Level i as a point of the ratio fit: its log ratio *r, weight *w (1 / variance) and basis values
 * f[nb], with lc1 the channel's and g1 grey's full-drive luminance. Returns 0 for a level the fit
 * leaves out (at drive 0, under 5 % of the channel's peak, or where grey is dark). */
static int ratio_point(const ctx *c, const double *dv, const double *dl, const int *cnt, const double *g,
                       size_t i, double lc1, double g1, const int *basis, int nb, double *r, double *w,
                       double *f)
{
    if (!(dv[i] > 0) || !(dl[i] >= 0.05 * lc1) || !(g[i] > 0)) return 0;
    /* the noise of one reading: the larger of the reference estimate (5 degrees of freedom)
     * and the scatter of the white readings about the drift curve (more) */
    double nr = fmax(c->noise_rel, c->drift_ok ? c->drift_rms : 0);
    double u = log(dv[i]), x = g[i] / g1;
    double var = (nr * nr + pow(c->noise_abs / dl[i], 2)) / (cnt[i] > 0 ? cnt[i] : 1) + RATIO_GREY_VAR;
    *r = log((dl[i] / lc1) / x);
    *w = 1 / var;
    for (int j = 0; j < nb; j++) f[j] = basis_val(basis[j], u, x);
    return 1;
}

/* Solves the nb x nb system in a (its right-hand side in column nb) in place, by Gauss-Jordan
 * elimination with partial pivoting, into z. Returns 0 when it is singular. */
static int solve_small(double a[4][5], int nb, double *z)
{
    for (int col = 0; col < nb; col++) {
        int piv = col;
        for (int r = col + 1; r < nb; r++)
            if (fabs(a[r][col]) > fabs(a[piv][col])) piv = r;
        if (!(fabs(a[piv][col]) > 1e-300)) return 0;
        for (int j = 0; j <= nb; j++) {
            double t = a[col][j];
            a[col][j] = a[piv][j];
            a[piv][j] = t;
        }
        for (int r = 0; r < nb; r++)
            if (r != col) {
                double f = a[r][col] / a[col][col];
                for (int j = col; j <= nb; j++) a[r][j] -= f * a[col][j];
            }
    }
    for (int j = 0; j < nb; j++) z[j] = a[j][nb] / a[j][j];
    return 1;
}

static void fit_ratio_basis(const ctx *c, const double *dv, const double *dl, const int *cnt, const double *g,
                            size_t m, const int *basis, int nb, ratio_model *rm)
{
    memset(rm, 0, sizeof *rm);
    rm->nb = nb;
    memcpy(rm->basis, basis, (size_t)nb * sizeof *basis);
    rm->lc1 = dl[m - 1];
    double g1 = g[m - 1];
    double A[4][5] = {{0}};
    int n = 0;
    double umin = 0;
    for (int pass = 0; pass < 2; pass++) {
        double chi2 = 0;
        for (size_t i = 0; i < m; i++) {
            double r, w, f[4];
            if (!ratio_point(c, dv, dl, cnt, g, i, rm->lc1, g1, basis, nb, &r, &w, f)) continue;
            if (pass == 0) {
                for (int j = 0; j < nb; j++) {
                    for (int k = 0; k < nb; k++) A[j][k] += w * f[j] * f[k];
                    A[j][nb] += w * f[j] * r;
                }
                if (log(dv[i]) < umin) umin = log(dv[i]);
                n++;
            } else {
                double d = r - log(ratio_eval(rm, dv[i], g[i] / g1));
                chi2 += d * d * w;
            }
        }
        if (pass == 0) {
            if (n < nb + 2) return; /* at least two degrees of freedom to judge the fit */
            if (!solve_small(A, nb, rm->coef)) return;
            rm->umin = umin;
            rm->n = n;
        } else {
            rm->chi2_dof = chi2 / (n - nb);
        }
    }
    int sane = 1;
    for (int j = 0; j < nb; j++) sane &= isfinite(rm->coef[j]) && fabs(rm->coef[j]) < (j == 0 ? 0.05 : 1);
    rm->valid = sane && isfinite(rm->chi2_dof);
    rm->ok = rm->valid && rm->chi2_dof < 6;
}

/* Tries bases from the simplest (a gamma difference) up; the first whose reduced chi-square is
 * below 2.5 wins, else the best (rm->ok when below 6; rm->valid for any sane fit). */
static void fit_ratio(const ctx *c, int ch, ratio_model *rm)
{
    memset(rm, 0, sizeof *rm);
    double *pv, *pl;
    size_t k = curve_points(c, ch, &pv, &pl);
    double *dv = malloc((k + 1) * sizeof(double)), *dl = malloc((k + 1) * sizeof(double)),
           *g = malloc((k + 2) * sizeof(double));
    int *cnt = calloc(k + 1, sizeof(int));
    size_t m = (dv && dl && g && cnt) ? distinct(pv, pl, k, dv, dl, cnt) : 0;
    free(pv);
    free(pl);
    if (m >= 4 && dv[m - 1] == 1.0 && dl[m - 1] > 0 && !grey_incr(c, dv, g, m) && g[m - 1] > 0) {
        static const int bases[4][4] = {{RB_ONE, RB_U}, {RB_ONE, RB_U, RB_X2}, {RB_ONE, RB_U, RB_U2},
                                        {RB_ONE, RB_U, RB_U2, RB_X2}};
        static const int nbs[4] = {2, 3, 3, 4};
        ratio_model best;
        memset(&best, 0, sizeof best);
        for (int t = 0; t < 4; t++) {
            ratio_model r;
            fit_ratio_basis(c, dv, dl, cnt, g, m, bases[t], nbs[t], &r);
            if (r.ok && r.chi2_dof < 2.5) {
                best = r;
                break;
            }
            if (r.valid && (!best.valid || r.chi2_dof < best.chi2_dof)) best = r;
        }
        *rm = best;
    }
    free(dv); free(dl); free(g); free(cnt);
}

/* Channel knots from the ratio model: at the grey curve's knots (so its corners carry over)
 * and the middles of wide grey intervals. */
static csf_status channel_from_grey(ctx *c, int ch, const ratio_model *rm, csf_display_profile *p,
                                    csf_error *err)
{
    const double *gv;
    size_t gn = csf_profile_knots(p, CSF_CH_GREY, &gv, NULL);
    double *v = malloc((2 * gn + 2) * sizeof(double)), *L = malloc((2 * gn + 2) * sizeof(double)),
           *g = malloc((2 * gn + 2) * sizeof(double));
    if (!v || !L || !g) {
        free(v); free(L); free(g);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    size_t n = 0;
    for (size_t i = 0; i < gn; i++) {
        if (i > 0 && gv[i] - gv[i - 1] > 1.0 / 64) v[n++] = 0.5 * (gv[i] + gv[i - 1]);
        v[n++] = gv[i];
    }
    double black = csf_profile_lum_black(p), g1 = csf_profile_lum_max(p) - black;
    for (size_t i = 0; i < n; i++) g[i] = csf_profile_grey_lum(p, v[i]) - black;
    for (size_t i = 0; i < n; i++) {
        double x = (g[i] > 0 ? g[i] : 0) / g1;
        double l = v[i] <= 0 ? 0 : rm->lc1 * x * ratio_eval(rm, v[i], x);
        if (i && l < L[i - 1]) l = L[i - 1];
        L[i] = l;
    }
    (void)c;
    csf_status st = csf_profile_set_channel_knots(p, ch, v, L, n, err);
    free(v); free(L); free(g);
    return st;
}

static csf_status measure_level(ctx *c, int ch, double v, double peak, int left, csf_error *err)
{
    double guess = predict(c, ch, v);
    if (isnan(guess)) guess = peak * pow(v, 2.2);
    int reps = repeats_for(c, guess, peak);
    if (reps > left) reps = left > 1 ? left : 1; /* never past the budget */
    for (int k = 0; k < reps; k++) {
        rd x;
        /* near black a too-dark answer is a fact about the display, not a fault */
        int accept_dark = guess < 0.02 * peak;
        csf_status st = take(c, ROLE_SWEEP, ch, v, accept_dark, &x, err);
        if (st) return st;
    }
    return CSF_OK;
}

/* Sets aside every reading since the last white that counted (sweep readings, darks): they were
 * taken while the sensor was off the patch or the display had changed. Returns how many. */
static int set_aside(ctx *c)
{
    size_t i = c->n;
    while (i > 0 && !((c->r[i - 1].role == ROLE_WARMUP || c->r[i - 1].role == ROLE_REF) && isfinite(c->r[i - 1].lum)))
        i--;
    int k = 0;
    for (; i < c->n; i++) {
        if (c->r[i].role == ROLE_SWEEP || c->r[i].role == ROLE_CHECK) {
            c->n_sweep -= c->r[i].role == ROLE_SWEEP;
            c->n_check -= c->r[i].role == ROLE_CHECK;
            c->r[i].role = ROLE_REJECTED;
            k++;
        } else if (c->r[i].role == ROLE_DARK) {
            c->r[i].role = ROLE_DARK_REJECTED;
            k++;
        }
    }
    return k;
}

/* A reference reading that replay found suspect (c->suspect): clears the flag, sets the readings
 * before it aside. *redo = 1 when there were any (the caller measures them again), 2 when there
 * were none (only the reference is taken again); no reading was taken either way. */
static csf_status suspect_white(ctx *c, csf_status st, int *redo)
{
    if (st != CSF_E_INSUFFICIENT || !c->suspect) return st;
    c->suspect = 0;
    *redo = set_aside(c) > 0 ? 1 : 2;
    return CSF_OK;
}

static csf_status sweep(ctx *c, int ch, int budget, const double *extra, int n_extra, double *est_out,
                        csf_error *err);

/* White reference: read as often as the noise requires, like a sweep level. *redo = 1: the
 * readings since the white before were set aside (see set_aside) and must be measured again. */
static csf_status reference(ctx *c, int *redo, csf_error *err)
{
    rd x;
    *redo = 0;
    double peak = predict(c, CSF_CH_GREY, 1.0);
    /* before the first reference the white level is unknown: relative noise alone decides */
    int reps = isnan(peak) ? repeats_for(c, 1e9, 1e9) : repeats_for(c, peak, peak);
    for (int k = 0; k < reps; k++) {
        csf_status st = suspect_white(c, take(c, ROLE_REF, CSF_CH_GREY, 1.0, 0, &x, err), redo);
        if (st) return st;
        if (*redo == 1) return CSF_OK;
        if (*redo == 2) {
            *redo = 0;
            k--;
        }
    }
    return CSF_OK;
}

/* A sweep followed by its white reference, swept again while the reference sets it aside. */
static csf_status sweep_ref(ctx *c, int ch, int budget, const double *extra, int n_extra, double *est_out,
                            csf_error *err)
{
    for (;;) {
        csf_status st = sweep(c, ch, budget, extra, n_extra, est_out, err);
        if (st) return st;
        int redo = 0;
        if ((st = reference(c, &redo, err))) return st;
        if (!redo) return CSF_OK;
    }
}

/* A curve's distinct drive levels so far: drive, mean luminance, readings per level. */
typedef struct {
    double *v, *lum;
    int *cnt;
    size_t m;
} levels;

static void levels_read(const ctx *c, int ch, levels *L)
{
    double *pv, *pl;
    size_t k = curve_points(c, ch, &pv, &pl);
    L->v = malloc((k + 1) * sizeof(double));
    L->lum = malloc((k + 1) * sizeof(double));
    L->cnt = calloc(k + 1, sizeof(int));
    L->m = L->v && L->lum && L->cnt ? distinct(pv, pl, k, L->v, L->lum, L->cnt) : 0;
    free(pv);
    free(pl);
}

static void levels_free(levels *L)
{
    free(L->v);
    free(L->lum);
    free(L->cnt);
}

/* The drive where the grey curve (less black) reaches frac of its peak, by bisection (1 when the
 * grey curve cannot be evaluated). */
static double grey_drive_at(const ctx *c, double frac)
{
    double v1 = 1, g1;
    if (grey_incr(c, &v1, &g1, 1) || !(g1 > 0)) return 1;
    double lo = 0, hi = 1;
    for (int it = 0; it < 30; it++) {
        double mid = 0.5 * (lo + hi), g;
        if (grey_incr(c, &mid, &g, 1)) return 1;
        if (g < frac * g1) lo = mid;
        else hi = mid;
    }
    return hi;
}

/* Where channel ch starts the range the target covers (10 % of its peak), from its levels so far: on
 * the line in ln L against ln v through the two levels around that point, or the lowest two above
 * it (a display curve is nearly a power law piece by piece). NAN when the levels cannot say. */
static double channel_range_start(const ctx *c, int ch)
{
    levels L;
    levels_read(c, ch, &L);
    double out = NAN;
    size_t i = 0;
    while (i < L.m && !(L.v[i] > 0 && L.lum[i] > 0)) i++;
    size_t j = i;
    while (j + 1 < L.m && L.lum[j] < 0.1 * L.lum[L.m - 1]) j++;
    size_t p = j > i ? j - 1 : j, q = p + 1;
    if (L.m >= 2 && q < L.m && L.v[p] > 0 && L.lum[p] > 0 && L.lum[q] > L.lum[p]) {
        double g = log(L.lum[q] / L.lum[p]) / log(L.v[q] / L.v[p]);
        out = L.v[p] * pow(0.1 * L.lum[L.m - 1] / L.lum[p], 1 / g);
    }
    levels_free(&L);
    return out;
}

/* The lowest drive above 0 that curve ch has a level at (1 when none). */
static double lowest_level(const ctx *c, int ch)
{
    levels L;
    levels_read(c, ch, &L);
    double out = 1;
    for (size_t i = 0; i < L.m; i++)
        if (L.v[i] > 0) {
            out = L.v[i];
            break;
        }
    levels_free(&L);
    return out;
}

/* The fixed levels of a sweep after full drive: a channel's full drive again when its share
 * allows (it scales the channel's whole curve; the ratio fit needs the four grid levels more),
 * the grid, then the corners the caller asks for. */
static csf_status sweep_fixed_levels(ctx *c, int ch, int budget, int start, const double *extra, int n_extra,
                                     double peak, csf_error *err)
{
    static const double grid_grey[] = {0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875};
    /* channels: spread over the range the target covers, for the fit of the channel-to-grey
     * ratio (see fit_ratio); the most informative first in case the budget is short */
    static const double grid_ch[] = {0.5, 0.75, 0.35, 0.9};
    const double *grid = ch == CSF_CH_GREY ? grid_grey : grid_ch;
    int ng = ch == CSF_CH_GREY ? 7 : 4;
    csf_status st;
    if (ch < 3 && budget >= 7 && c->n_sweep - start == 1) {
        st = measure_level(c, ch, 1.0, INFINITY, budget - (c->n_sweep - start), err);
        if (st) return st;
    }
    for (int i = 0; i < ng && c->n_sweep - start < budget; i++) {
        /* at most two readings each here: with a noisy instrument the grid's spread (what the
         * model and its stated error need) comes before averaging, which the refinement does */
        int left = budget - (c->n_sweep - start);
        double v = grid[i];
        /* a channel's lowest grid level goes where its range starts when the levels above say
         * where that is: a channel that clips or bends away from grey starts elsewhere (a clipped
         * green lower, a steeper red higher), and an interval the range starts inside is modelled
         * there from the side below the range, where the curve's relative error is largest and no
         * knot can witness it. Only between half the grid's level and the next grid level: the line
         * from the levels above is an extrapolation, worth trusting that far */
        if (ch < 3 && v < 0.5) {
            double s10 = channel_range_start(c, ch);
            if (s10 > 0.5 * v && s10 < 0.5) v = s10;
        }
        st = measure_level(c, ch, snap(c, v), peak, ch < 3 && left > 2 ? 2 : left, err);
        if (st) return st;
    }
    for (int i = 0; i < n_extra && c->n_sweep - start < budget; i++) {
        /* a grey corner may be one the model inferred between two levels: snap it to what the
         * framebuffer can show. After the grid and, like it, at most two readings: a corner read
         * four times by a noisy instrument before the grid could take a channel's whole share,
         * leaving a curve of three knots across the range */
        double q = snap(c, extra[i]);
        if (!(q > 0 && q < 1)) continue;
        int left = budget - (c->n_sweep - start);
        st = measure_level(c, ch, q, peak, left > 2 ? 2 : left, err);
        if (st) return st;
    }
    /* the low end of the range the target covers: where grey is at 10 % of its peak, unless the
     * grid reaches it; without it a channel's model there would be extrapolated, and neither
     * its readings nor its stated error could see how wrong */
    double d10 = ch < 3 ? grey_drive_at(c, 0.1) : 1;
    if (d10 < 0.3 && c->n_sweep - start < budget) {
        st = measure_level(c, ch, snap(c, d10), peak, budget - (c->n_sweep - start), err);
        if (st) return st;
    }
    return CSF_OK;
}

/* The drive level that splits interval wi of L: where the secant lines of the two neighbouring
 * intervals cross inside it (at a kink that is where the break is, found in a few readings like
 * regula falsi; on a smooth curve it is near the middle anyway), else the middle. */
static double split_point(const ctx *c, const levels *L, size_t wi)
{
    const double *dv = L->v, *dl = L->lum;
    size_t m = L->m;
    double width = dv[wi + 1] - dv[wi];
    double cand = 0.5 * (dv[wi] + dv[wi + 1]);
    if (m >= 4 && wi >= 1 && wi + 2 < m) {
        size_t l0 = wi - 1, r1 = wi + 2;
        while (l0 > 0 && dv[wi] - dv[l0] < 0.03) l0--;
        while (r1 + 1 < m && dv[r1] - dv[wi + 1] < 0.03) r1++;
        double s1 = (dl[wi] - dl[l0]) / (dv[wi] - dv[l0]);
        double s2 = (dl[r1] - dl[wi + 1]) / (dv[r1] - dv[wi + 1]);
        if (fabs(s2 - s1) > 1e-12 * (fabs(s1) + fabs(s2))) {
            double xi = (dl[wi + 1] - dl[wi] + s1 * dv[wi] - s2 * dv[wi + 1]) / (s1 - s2);
            double lo = dv[wi] + 0.05 * width, hi = dv[wi + 1] - 0.05 * width;
            if (xi > lo && xi < hi) cand = xi;
        }
    }
    double q = snap(c, cand);
    if (!(q > dv[wi] && q < dv[wi + 1])) q = snap(c, 0.5 * (dv[wi] + dv[wi + 1]));
    return q;
}

/* ---- the stated error ----
 * What the profile says about itself is the maximum relative error above 10 % of the curve's
 * peak, the quantity the target is stated for (docs/display-profile.md, "How wrong the profile
 * is"). Two parts, added in quadrature:
 *  - noise: the profile runs through the means of the readings, so each knot is off by its mean's
 *    own error, e_k ~ N(0, s_k^2), s_k from the instrument's repeatability (pooled_noise_rel) and
 *    the repeat count. The worst of K independent knots is what a max-error measure sees: the
 *    median of max_k |e_k| solves prod_k (2 Phi(m / s_k) - 1) = 1/2, about 2.0 s for 15 knots.
 *  - model: the interpolant's own error between knots, from leave-one-out at the scale of the gaps
 *    (csf_curve_interval_errors): the miss of a left-out knot, its noise removed in quadrature, scaled from
 *    the merged interval to each half. The largest over the intervals above 10 % of peak.
 * Leave-one-out alone understated the error by 2-7x at ordinary noise: it took the noise off and
 * never added it back, and an RMS-like miss is not the worst case over the range.
 * The profile states the median; whether the target is met (the sweep's stop, the top-up, the
 * target_met it reports) is judged at MET_QUANTILE of the noise part instead: a median just under
 * the target leaves the truth above it half the time, and a profile that says "target met" should
 * be right far more often than that. */
#define MET_QUANTILE 0.9

/* Sum of squared relative deviations from their level's mean, and degrees of freedom, over every
 * level above 10 % of its curve's peak read more than once; with_white: grey's drive 1 too. */
static void pool_scatter(const ctx *c, int with_white, double *ss, int *dof)
{
    for (int ch = 0; ch < CSF_CH_COUNT; ch++) {
        double *pv, *pl;
        size_t k = curve_points(c, ch, &pv, &pl);
        double top = 0;
        for (size_t i = 0; i < k; i++) top = fmax(top, pl[i]);
        for (size_t i = 0; i < k; i++) {
            if (!(pv[i] > 0) || !(pl[i] >= 0.1 * top)) continue;
            if (!with_white && ch == CSF_CH_GREY && pv[i] == 1) continue;
            int first = 1, n = 0;
            double mean = 0;
            for (size_t j = 0; j < k; j++)
                if (pv[j] == pv[i]) {
                    if (j < i) first = 0;
                    mean += pl[j];
                    n++;
                }
            if (!first || n < 2) continue;
            mean /= n;
            for (size_t j = 0; j < k; j++)
                if (pv[j] == pv[i]) *ss += pow(pl[j] / mean - 1, 2) - pow(c->noise_abs / mean, 2);
            *dof += n - 1;
        }
        free(pv);
        free(pl);
    }
}

/* Relative sd of one reading above 10 % of a curve's peak, pooled over every level read more than
 * once: the instrument's repeatability with many more degrees of freedom than the first six
 * references alone (their absolute noise part taken off). The white references at drive 1 count
 * only when the sweep levels give fewer than 5 degrees of freedom: after drift correction their
 * scatter also holds what the drift curve misses over the session, not only a reading's noise. */
static double pooled_noise_rel(const ctx *c)
{
    double ss = 0;
    int dof = 0;
    pool_scatter(c, 0, &ss, &dof);
    if (dof < 5) {
        ss = 0;
        dof = 0;
        pool_scatter(c, 1, &ss, &dof);
    }
    if (dof < 5 || !(ss > 0)) return fmax(c->noise_rel, c->drift_ok ? c->drift_rms : 0);
    return sqrt(ss / dof);
}

/* The q-quantile of max_k |e_k| for independent e_k ~ N(0, sd_k^2) (see above): the m with
 * prod_k (2 Phi(m / s_k) - 1) = q. */
static double max_noise_quantile(const double *sd, size_t n, double q)
{
    double hi = 0;
    for (size_t i = 0; i < n; i++) hi = fmax(hi, sd[i]);
    if (!(hi > 0)) return 0;
    double lo = 0;
    hi *= 10;
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi), f = 0;
        for (size_t i = 0; i < n; i++)
            if (sd[i] > 0) f += log(erf(mid / (sd[i] * sqrt(2.0))));
        if (f < log(q)) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

typedef struct {
    double noise, model, total; /* the two parts and sqrt(noise^2 + model^2), relative */
} statement;

/* Relative sd of each level's mean (sd[] has L->m entries). */
static void level_sds(const ctx *c, const levels *L, double nr, double *sd)
{
    for (size_t i = 0; i < L->m; i++) {
        double lum = fmax(L->lum[i], 1e-12);
        sd[i] = sqrt((nr * nr + pow(c->noise_abs / lum, 2)) / (L->cnt[i] > 0 ? L->cnt[i] : 1));
    }
}

/* Whether level i of L is in the range a statement covers: at or above 10 % of the curve's peak, or,
 * with a drive floor v_lo (not NaN), at or above that drive. */
static int in_range(const levels *L, size_t i, double peak, double v_lo)
{
    return isnan(v_lo) ? L->lum[i] >= 0.1 * peak : L->v[i] >= v_lo;
}

static statement curve_statement_over(const ctx *c, int ch, const levels *L, double *est, double v_lo);

/* The share of interval i's error (estimated for its middle) in the part from drive v_lo up, when
 * v_lo is inside it: a smooth interpolant's error goes as t^2 (1 - t)^2 across an interval, so over
 * [t0, 1] its largest is 16 t0^2 (1 - t0)^2 of the middle's when t0 > 1/2. A channel through grey
 * whose range starts late in one of grey's dark intervals inherits that much of it. */
static double covered_share(const levels *L, size_t i, double v_lo)
{
    double t0 = (v_lo - L->v[i]) / (L->v[i + 1] - L->v[i]);
    if (!(t0 > 0.5)) return 1;
    if (t0 > 1) t0 = 1;
    return 16 * t0 * t0 * (1 - t0) * (1 - t0);
}

/* The stated error of a curve modelled through its own levels; est (L->m entries, may be NULL)
 * gets the per-interval model error for placing levels. */
static statement curve_statement(const ctx *c, int ch, const levels *L, double *est)
{
    return curve_statement_over(c, ch, L, est, NAN);
}

/* The same over the drives from v_lo up (NaN: above 10 % of the curve's peak). */
static statement curve_statement_over(const ctx *c, int ch, const levels *L, double *est, double v_lo)
{
    statement out = {INFINITY, INFINITY, INFINITY};
    size_t m = L->m;
    if (m < 3) return out;
    double *sd = malloc(m * sizeof(double)), *e = est ? est : malloc(m * sizeof(double)),
           *top = malloc(m * sizeof(double)), *emin = calloc(m, sizeof(double));
    if (!sd || !e || !top || !emin) goto done;
    level_sds(c, L, pooled_noise_rel(c), sd);
    /* a "met" decision does not lean on a measured order above the usual 2: the measurement is
     * noisy, and a false "met" costs the user more than a reading */
    double p_max = c->noise_quantile > 0.5 ? 2 : 3;
    csf_curve_interval_errors(L->v, L->lum, m, ch < 3, sd, p_max, e, emin);
    double peak = L->lum[m - 1];
    size_t k = 0;
    out.model = 0;
    for (size_t i = 0; i < m; i++) {
        if (i + 1 < m && in_range(L, i + 1, peak, v_lo))
            out.model =
                fmax(out.model,
                     emin[i] * (isnan(v_lo) || in_range(L, i, peak, v_lo) ? 1 : covered_share(L, i, v_lo)));
        /* the knots in the range, and the one below its low end: the interval across the 10 %
         * line carries that knot's error into the range */
        if (L->v[i] > 0 && (in_range(L, i, peak, v_lo) || (i + 1 < m && in_range(L, i + 1, peak, v_lo))))
            top[k++] = sd[i];
    }
    out.noise = max_noise_quantile(top, k, c->noise_quantile > 0 ? c->noise_quantile : 0.5);
    /* leave-one-out needs two levels inside the range besides full drive to say anything about
     * the model there: with fewer the model's error is unknown, and so is the statement */
    if (k < 3) out.model = INFINITY;
    out.total = sqrt(out.noise * out.noise + out.model * out.model);
done:
    free(sd);
    free(top);
    free(emin);
    if (!est) free(e);
    return out;
}

/* Grey's stated error over the drives from v_lo up: a channel modelled through grey inherits grey's
 * error over the channel's own range, which starts below grey's 10 % point when the channel rises
 * earlier (a red of gamma 2.0 beside a grey of 2.4 reaches 10 % of its peak at a drive where grey
 * is at 3 %, among grey's sparse dark knots). */
static double curve_statement_grey_from(const ctx *c, double v_lo)
{
    levels L;
    levels_read(c, CSF_CH_GREY, &L);
    double t = curve_statement_over(c, CSF_CH_GREY, &L, NULL, v_lo).total;
    levels_free(&L);
    return t;
}

/* Grey's stated error above 10 % of its peak. */
static double curve_statement_grey(const ctx *c)
{
    return curve_statement_grey_from(c, NAN);
}

/* The level to split next: the worst interval of est that still has a drive level inside it
 * (NAN when none has); *worst gets its estimate. */
static double pick_split(const ctx *c, const levels *L, double *est, double *worst)
{
    size_t m = L->m;
    for (;;) {
        size_t wi = 0;
        for (size_t i = 0; i + 1 < m; i++)
            if (est[i] > est[wi]) wi = i;
        if (m < 2 || !(est[wi] >= 0)) return NAN;
        double width = L->v[wi + 1] - L->v[wi];
        double q = split_point(c, L, wi);
        if (q > L->v[wi] && q < L->v[wi + 1] && width >= 1.0 / 4096) {
            *worst = est[wi];
            return q;
        }
        est[wi] = -1; /* no level left inside: the display cannot show anything between */
    }
}

/* The level whose mean is noisiest above lo_frac of the peak (among equals the one with the widest
 * neighbouring intervals: its error spreads furthest); NAN when none. */
static double noisiest_level(const ctx *c, const levels *L, double lo_frac)
{
    double nr = pooled_noise_rel(c), worst = 0, wid = 0, at = NAN, peak = L->lum[L->m - 1];
    for (size_t i = 0; i < L->m; i++) {
        int in = L->lum[i] >= lo_frac * peak || (i + 1 < L->m && L->lum[i + 1] >= lo_frac * peak);
        if (!(L->v[i] > 0) || !in) continue;
        double sd = sqrt((nr * nr + pow(c->noise_abs / L->lum[i], 2)) / L->cnt[i]);
        double w = (i + 1 < L->m ? L->v[i + 1] : 1) - (i > 0 ? L->v[i - 1] : 0);
        if (sd > worst * 1.000001 || (sd > worst * 0.999999 && w > wid)) {
            worst = sd;
            wid = w;
            at = L->v[i];
        }
    }
    return at;
}

/* Spends the curve's share until its stated error meets the target: where the model part
 * dominates a new level splits the worst interval, where the noise part does the noisiest level
 * above 10 % of peak is read again (the part each reading reduces most). */
static csf_status refine_curve(ctx *c, int ch, int budget, int start, double peak, csf_error *err)
{
    /* a channel modelled through grey inherits grey's error and adds its own fit's: with channels,
     * grey aims at target/sqrt(2) so that they can meet the target too */
    double aim = ch == CSF_CH_GREY && c->o->channels ? c->o->target_rel / sqrt(2.0) : c->o->target_rel;
    while (c->n_sweep - start < budget) {
        levels L;
        levels_read(c, ch, &L);
        double *est = calloc(L.m + 1, sizeof(double));
        if (!est) {
            levels_free(&L);
            return csf_error_set(err, CSF_E_NOMEM, "out of memory");
        }
        statement s = curve_statement(c, ch, &L, est);
        if (L.m < 3)
            for (size_t i = 0; i + 1 < L.m; i++) est[i] = INFINITY; /* too few levels to judge: split */
        double worst = 0, next = NAN;
        if (!(s.total <= aim)) {
            if (!(s.model < s.noise)) next = pick_split(c, &L, est, &worst);
            if (isnan(next)) next = noisiest_level(c, &L, 0.1);
        }
        levels_free(&L);
        free(est);
        if (isnan(next)) break;
        csf_status st = measure_level(c, ch, next, peak, budget - (c->n_sweep - start), err);
        if (st) return st;
    }
    return CSF_OK;
}

/* The p quantile of the largest of n squared standard normal deviates (n >= 1, 0 < p < 1): z^2 where
 * (Phi(z) - Phi(-z))^n is p. */
static double noise_max_chi2(int n, double p_max)
{
    if (n < 1) n = 1;
    double p = pow(p_max, 1.0 / n), lo = 0, hi = 10;
    for (int it = 0; it < 60; it++) {
        double z = 0.5 * (lo + hi);
        if (erf(z / sqrt(2.0)) < p) lo = z;
        else hi = z;
    }
    return lo * lo;
}

/* The ratio model's miss at level i of the channel, predicted by the same basis fitted without that
 * level (leave-one-out: a fit through a level cannot show how far it misses between levels); the
 * fit through all levels when too few are left to refit, and at full drive (the normaliser). */
static double ratio_loo_residual(const ctx *c, const levels *L, const double *g, const ratio_model *rm,
                                 size_t i)
{
    size_t m = L->m;
    double x = g[i] / g[m - 1], pred = rm->lc1 * x * ratio_eval(rm, L->v[i], x);
    double in_sample = L->lum[i] / pred - 1;
    if (i + 1 >= m) return in_sample;
    double *dv = malloc(m * sizeof(double)), *dl = malloc(m * sizeof(double)),
           *dg = malloc(m * sizeof(double));
    int *cnt = malloc(m * sizeof(int));
    double out = in_sample;
    if (dv && dl && dg && cnt) {
        size_t k = 0;
        for (size_t j = 0; j < m; j++)
            if (j != i) {
                dv[k] = L->v[j], dl[k] = L->lum[j], dg[k] = g[j], cnt[k] = L->cnt[j];
                k++;
            }
        ratio_model r;
        fit_ratio_basis(c, dv, dl, cnt, dg, k, rm->basis, rm->nb, &r);
        if (r.valid) out = L->lum[i] / (r.lc1 * x * ratio_eval(&r, L->v[i], x)) - 1;
    }
    free(dv);
    free(dl);
    free(dg);
    free(cnt);
    return out;
}

/* The leverage of each level in the ratio fit rm, into h[L->m]: its weight times f_i' (F' W F)^-1 f_i,
 * the share of its own reading that the fit through it follows. Left out, a level misses the refit
 * by noise of variance var_i / (1 - h) (the leave-one-out residual of least squares, Allen 1974): a
 * level at an end of the range, where the refit extrapolates, misses by more than one in the
 * middle. 0 for a level the fit leaves out, and for all when the fit is singular. */
static void ratio_leverages(const ctx *c, const levels *L, const double *g, const ratio_model *rm, double *h)
{
    size_t m = L->m;
    double A[4][5] = {{0}}, r, w, f[4];
    for (size_t j = 0; j < m; j++) {
        h[j] = 0;
        if (!ratio_point(c, L->v, L->lum, L->cnt, g, j, rm->lc1, g[m - 1], rm->basis, rm->nb, &r, &w, f))
            continue;
        for (int a = 0; a < rm->nb; a++)
            for (int b = 0; b < rm->nb; b++) A[a][b] += w * f[a] * f[b];
    }
    for (size_t i = 0; i < m; i++) {
        double S[4][5], z[4];
        if (!ratio_point(c, L->v, L->lum, L->cnt, g, i, rm->lc1, g[m - 1], rm->basis, rm->nb, &r, &w, f))
            continue;
        memcpy(S, A, sizeof S); /* solve_small works in place */
        for (int a = 0; a < rm->nb; a++) S[a][rm->nb] = f[a];
        if (!solve_small(S, rm->nb, z)) return;
        for (int a = 0; a < rm->nb; a++) h[i] += w * f[a] * z[a];
    }
}

/* The stated error of channel ch modelled through grey (ratio model rm): grey's own stated error over
 * the channel's range of drives (the channel inherits its shape and its knots' noise), the fit's
 * uncertainty at the levels (about sd * sqrt(parameters / levels), doubled for the worst level), and a
 * bias the model leaves: the largest leave-one-out miss of a level mean less its noise, in
 * quadrature. *grey_part and *range_lo (may be NULL; set when the statement is) get grey's part and
 * the drive where the channel's range starts. */
static statement channel_grey_statement(const ctx *c, int ch, const ratio_model *rm, double *grey_part,
                                        double *range_lo)
{
    statement out = {INFINITY, INFINITY, INFINITY};
    levels L;
    levels_read(c, ch, &L);
    double *g = malloc((L.m + 1) * sizeof(double)), *lev = malloc((L.m + 1) * sizeof(double));
    if (g && lev && L.m >= 2 && !grey_incr(c, L.v, g, L.m) && g[L.m - 1] > 0) {
        ratio_leverages(c, &L, g, rm, lev);
        double nr = pooled_noise_rel(c), peak = L.lum[L.m - 1], ss = 0, bias2 = 0, v_lo = NAN;
        int n = 0, n_in = 0;
        for (size_t i = 0; i < L.m; i++) n_in += L.v[i] > 0 && L.lum[i] >= 0.1 * peak;
        /* a leave-one-out miss carries the level's own noise and the refit's, together its variance
         * over 1 - h, h the level's leverage (ratio_leverages). The largest of n_in such misses, were
         * they pure noise, reaches noise_max_chi2 times its variance with probability 1 - q: what
         * exceeds that is the model's, at the statement's quantile q (the median, or the 90th
         * percentile the target is judged at) */
        double q = c->noise_quantile > 0 ? c->noise_quantile : 0.5;
        double max_chi2 = noise_max_chi2(n_in, 1 - q);
        for (size_t i = 0; i < L.m; i++) {
            if (!(L.v[i] > 0) || !(L.lum[i] >= 0.1 * peak)) continue;
            /* the range starts where the channel crosses 10 % of its peak, between this level
             * and the one below (linear in luminance) */
            if (isnan(v_lo))
                v_lo = i > 0 && L.lum[i] > L.lum[i - 1]
                           ? L.v[i - 1] + (L.v[i] - L.v[i - 1]) * (0.1 * peak - L.lum[i - 1]) /
                                              (L.lum[i] - L.lum[i - 1])
                           : L.v[i];
            double sd2 = (nr * nr + pow(c->noise_abs / L.lum[i], 2)) / L.cnt[i];
            double r = ratio_loo_residual(c, &L, g, rm, i);
            bias2 = fmax(bias2, r * r - max_chi2 / fmax(1 - lev[i], 0.05) * sd2);
            ss += sd2;
            n++;
        }
        if (n > 0) {
            double grey_total = curve_statement_grey_from(c, v_lo);
            if (grey_part) *grey_part = grey_total;
            if (range_lo) *range_lo = v_lo;
            double fit = 2 * sqrt(ss / n * fmin(1.0, (double)rm->nb / (double)L.m));
            out.noise = sqrt(grey_total * grey_total + fit * fit);
            out.model = sqrt(fmax(bias2, 0));
            out.total = sqrt(out.noise * out.noise + out.model * out.model);
        }
    }
    free(g);
    free(lev);
    levels_free(&L);
    return out;
}

/* A channel whose ratio to grey explains its readings: the rest of its share repeats its noisiest
 * level until the channel's stated error meets the target. */
static csf_status refine_channel_via_grey(ctx *c, int ch, int budget, int start, csf_error *err)
{
    while (c->n_sweep - start < budget) {
        ratio_model rm;
        fit_ratio(c, ch, &rm);
        if (!rm.ok) return CSF_OK; /* the caller goes on with levels of its own */
        /* grey's statement as it is now (the pooled noise moves as readings come) */
        statement s = channel_grey_statement(c, ch, &rm, NULL, NULL);
        if (s.total <= c->o->target_rel) return CSF_OK;
        levels L;
        levels_read(c, ch, &L);
        double at = L.m >= 2 ? noisiest_level(c, &L, 0.05) : NAN;
        levels_free(&L);
        if (isnan(at)) return CSF_OK;
        rd x;
        csf_status st = take(c, ROLE_SWEEP, ch, at, 0, &x, err);
        if (st) return st;
    }
    return CSF_OK;
}

static csf_status sweep(ctx *c, int ch, int budget, const double *extra, int n_extra, double *est_out,
                        csf_error *err)
{
    int start = c->n_sweep;
    csf_status st;
    /* full drive first: it sets the curve's peak */
    if (ch < 3) {
        /* at most two readings: a noisy instrument would otherwise spend a short channel share
         * on full drive alone and leave too few levels to model the channel or state its error */
        st = measure_level(c, ch, 1.0, INFINITY, budget > 2 ? 2 : budget, err);
        if (st) return st;
    }
    double peak = predict(c, ch, 1.0);
    if (!(peak > 0)) return csf_error_set(err, CSF_E_INSUFFICIENT,
                                          "%s at full drive is not brighter than black: is the sensor on the patch?",
                                          ch < 3 ? (const char *[]){"red", "green", "blue"}[ch] : "white");
    st = sweep_fixed_levels(c, ch, budget, start, extra, n_extra, peak, err);
    if (st) return st;
    if (ch < 3 && c->n_sweep - start < budget) {
        /* where the channel's range starts, again from its two lowest levels now: the grid's
         * first estimate came from levels far above it, and a curve whose exponent falls towards
         * black (a panel whose gamma is not one number) starts lower than that said, in an
         * interval no knot would witness */
        double range_start = snap(c, channel_range_start(c, ch)), lowest = lowest_level(c, ch);
        int left = budget - (c->n_sweep - start);
        if (range_start > 0 && range_start < lowest - 1.0 / 64 &&
            (st = measure_level(c, ch, range_start, peak, left > 2 ? 2 : left, err)))
            return st;
    }
    if (ch < 3) {
        ratio_model rm;
        fit_ratio(c, ch, &rm);
        if (rm.ok) {
            st = refine_channel_via_grey(c, ch, budget, start, err);
            if (st) return st;
            fit_ratio(c, ch, &rm);
            if (rm.ok) return CSF_OK;
        }
    }
    st = refine_curve(c, ch, budget, start, peak, err);
    if (st) return st;
    if (ch == CSF_CH_GREY) {
        levels L;
        levels_read(c, ch, &L);
        *est_out = curve_statement(c, ch, &L, NULL).total;
        levels_free(&L);
    }
    return CSF_OK;
}

int csf_display_warm_settled(const double *w, int n, double target_rel, double *change_rel)
{
    if (change_rel) *change_rel = NAN;
    if (n < 6) return 0;
    double m1 = (w[n - 1] + w[n - 2] + w[n - 3]) / 3, m0 = (w[n - 4] + w[n - 5] + w[n - 6]) / 3;
    double s = csf_sample_sd(&w[n - 3], 3) / m1;
    double tol = fmax(target_rel / 4, 2.5 * s * sqrt(2.0 / 3.0));
    double change = fabs(m1 - m0) / m1;
    if (change_rel) *change_rel = change;
    return change < tol;
}

/* White until the display is warm by the settling model (calib/warmup_model.h): the step test
 * and, where the readings show a drift, less than the target of it left over the session. */
static csf_status warmup(ctx *c, csf_display_calib_result *res, csf_error *err)
{
    double w[256], t[256];
    int n = 0;
    res->warmup_stable = 0;
    int maxn = c->o->warmup_max < 6 ? 6 : (c->o->warmup_max > 256 ? 256 : c->o->warmup_max);
    while (n < maxn) {
        c->pending_wait_s = n > 0 ? c->o->warmup_wait_s : 0;
        rd x;
        csf_status st = take(c, ROLE_WARMUP, CSF_CH_GREY, 1.0, 0, &x, err);
        if (st) return st;
        t[n] = x.t_s;
        w[n++] = x.lum;
        int warm = csf_display_warm_judge(t, w, n, c->o->target_rel, CSF_WARM_SESSION_S, &c->warm);
        progress(c);
        if (warm) {
            res->warmup_stable = 1;
            break;
        }
    }
    res->warmup_remaining_rel = c->warm.remaining_rel;
    res->warmup_wait_s = c->warm.wait_s;
    c->noise_rel = n >= 3 ? csf_sample_sd(&w[n - 3], 3) / w[n - 1] : 0.001;
    return CSF_OK;
}

/* Black level and absolute noise from the dark readings that count. */
static void dark_stats(ctx *c)
{
    double d[64];
    int k = 0;
    for (size_t i = 0; i < c->n && k < 64; i++)
        if (c->r[i].role == ROLE_DARK) d[k++] = isnan(c->r[i].lum) ? 0 : c->r[i].lum;
    c->noise_abs = k > 1 ? csf_sample_sd(d, k) : 0;
    update_black(c);
}

static void reject_darks(ctx *c)
{
    for (size_t i = 0; i < c->n; i++)
        if (c->r[i].role == ROLE_DARK) c->r[i].role = ROLE_DARK_REJECTED;
}

enum { DARK_N = 6, DARK_MAX_LIVE_SERIES = 3 };

/* The dark series: DARK_N readings at drive 0, the black level every channel curve is measured
 * from and the absolute noise that decides repeats for dim levels (5 degrees of freedom).
 * A "too dark" answer is a fact about an OLED's black, but it is also what a sensor that slipped
 * off the screen says. So:
 *  - a series that mixes "too dark" with real readings contradicts itself (a black level cannot
 *    be below the instrument's floor and above it within seconds): it is set aside and measured
 *    again; after DARK_MAX_LIVE_SERIES such series in one run the calibration stops (resumable);
 *  - a series of only "too dark" answers is confirmed by one more dark reading after the first
 *    white references (confirm_dark): a real reading there contradicts it and the series is
 *    measured again; a stored session whose sensor fell off during the darks (the white after them
 *    failed too) is therefore repaired when it is resumed, not kept as black = 0.
 * Every decision depends only on the readings, so a resumed session replays it identically. */
static csf_status dark_series(ctx *c, csf_error *err)
{
    for (;;) {
        int n_dark = 0, n_real = 0;
        double lo = INFINITY, hi = 0;
        for (int i = 0; i < DARK_N; i++) {
            rd x;
            csf_status st = take(c, ROLE_DARK, CSF_CH_GREY, 0.0, 1, &x, err);
            if (st) return st;
            if (isnan(x.lum)) {
                n_dark++;
            } else {
                n_real++;
                lo = fmin(lo, x.lum);
                hi = fmax(hi, x.lum);
            }
        }
        if (c->live_started) c->dark_live_series++;
        c->dark_unconfirmed = n_real == 0;
        if (n_dark == 0 || n_real == 0) break;
        reject_darks(c);
        if (c->dark_live_series >= DARK_MAX_LIVE_SERIES)
            return csf_error_set(err, CSF_E_INSUFFICIENT,
                                 "the dark readings (drive 0) mix 'too dark' answers with readings of "
                                 "%.4g to %.4g cd/m2 in %d series: the sensor is not steady on the patch, "
                                 "or stray light reaches it, or the black level sits at the instrument's "
                                 "floor; fix the cause and resume the session", lo, hi, c->dark_live_series);
    }
    dark_stats(c);
    return CSF_OK;
}

/* One dark reading after the first white references when the dark series answered only "too
 * dark" (see dark_series). */
static csf_status confirm_dark(ctx *c, csf_error *err)
{
    while (c->dark_unconfirmed) {
        rd x;
        csf_status st = take(c, ROLE_DARK, CSF_CH_GREY, 0.0, 1, &x, err);
        if (st) return st;
        if (isnan(x.lum)) {
            c->dark_unconfirmed = 0; /* black really is below the floor (OLED) */
            break;
        }
        /* the screen's black is measurable: the "too dark" series was the sensor, not the display */
        reject_darks(c);
        if (c->dark_live_series >= DARK_MAX_LIVE_SERIES)
            return csf_error_set(err, CSF_E_INSUFFICIENT,
                                 "the dark readings (drive 0) answered 'too dark' and then %.4g cd/m2 "
                                 "in %d series: the sensor is not steady on the patch; fix the cause and "
                                 "resume the session", x.lum, c->dark_live_series);
        if ((st = dark_series(c, err))) return st;
    }
    dark_stats(c);
    return CSF_OK;
}

/* Which model channel ch gets (1: through grey, rm filled), and its stated error: through grey when
 * the ratio explains the readings within their noise (the sweep then spends the channel's share
 * on repeats), else the channel's own levels (the sweep then adds levels), unless a sane ratio
 * fit still states less than they do (a short budget). */
static int channel_statement(const ctx *c, int ch, ratio_model *rm, statement *stated)
{
    fit_ratio(c, ch, rm);
    statement g =
        rm->valid ? channel_grey_statement(c, ch, rm, NULL, NULL) : (statement){INFINITY, INFINITY, INFINITY};
    levels L;
    levels_read(c, ch, &L);
    statement own = curve_statement(c, ch, &L, NULL);
    levels_free(&L);
    int use = rm->ok || (rm->valid && g.total < own.total);
    *stated = use ? g : own;
    return use;
}

/* The same, its total alone. */
static int channel_via_grey(const ctx *c, int ch, ratio_model *rm, double *stated)
{
    statement s;
    int use = channel_statement(c, ch, rm, &s);
    *stated = s.total;
    return use;
}

/* ---- spot checks ----
 * The statement above sees what the levels show: the knots' noise and how far the model bends
 * between them. Structure finer than the levels (a LUT's ripple, a 6-bit panel's dithered native
 * levels) or a corner inside an interval (a channel that clips) leaves no trace at the knots. A few
 * readings between the levels, never fitted, show it, as a verification set does (ArgyllCMS's
 * dispcal verifies with patches it did not fit): their scatter about the profile, less what the
 * check's own noise and the profile's knot noise explain, is the profile's systematic error there.
 * What they see is an rms over a few drives; the statement is a maximum over the range. The peak
 * of a systematic error is about sqrt(2) times its rms for one slow wobble and about 2.8 times for
 * some fifty independent level errors (sqrt(2 ln 50): a 6-bit panel's native levels above 10 % of
 * peak); CHECK_PEAK_PER_RMS, 2, is within 1.5x of both. */
#define CHECK_PEAK_PER_RMS 2.0

static csf_status build_profile(ctx *c, const char *display_name, const char *instrument, double additivity,
                                csf_display_profile **out, csf_error *err);

/* Drive where a curve of the profile reaches 10 % of its peak (grey: of white, black included). */
static double profile_range_low(const csf_display_profile *p, int ch)
{
    if (ch == CSF_CH_GREY) return csf_profile_grey_drive(p, 0.1 * csf_profile_lum_max(p));
    return csf_profile_channel_drive(p, ch, 0.1 * csf_profile_channel_lum(p, ch, 1.0));
}

/* The profile's luminance of curve ch at drive v (a channel less black, as its readings are kept). */
static double profile_lum(const csf_display_profile *p, int ch, double v)
{
    return ch == CSF_CH_GREY ? csf_profile_grey_lum(p, v) : csf_profile_channel_lum(p, ch, v);
}

/* The profile the readings so far give: every curve through its levels, then each channel the
 * statement takes through grey rebuilt from grey (via[ch], may be NULL, gets the choice). *p is
 * NULL when it fails. */
static csf_status profile_from_readings(ctx *c, const char *display_name, const char *instrument,
                                        double additivity, int via[3], csf_display_profile **p,
                                        csf_error *err)
{
    csf_status st = build_profile(c, display_name, instrument, additivity, p, err);
    for (int ch = 0; !st && c->o->channels && ch < 3; ch++) {
        ratio_model rm;
        double stated;
        int use = channel_via_grey(c, ch, &rm, &stated);
        if (via) via[ch] = use;
        if (use) st = channel_from_grey(c, ch, &rm, *p, err);
    }
    if (st) {
        csf_profile_free(*p);
        *p = NULL;
    }
    return st;
}

/* Where a check best tests the lowest interval of curve ch that reaches its range (above drive
 * lo): a third of the way up from its lower knot, where a wrong slope at that knot (the model takes
 * it partly from the secant to black) shows most (t (1 - t)^2 peaks at t = 1/3). NAN when none. */
static double lowest_interval_check(const ctx *c, int ch, double lo)
{
    levels L;
    levels_read(c, ch, &L);
    double at = NAN;
    for (size_t i = 0; i + 1 < L.m; i++)
        if (L.v[i] > 0 && L.v[i + 1] > lo) {
            at = fmax(lo, L.v[i] + (L.v[i + 1] - L.v[i]) / 3);
            break;
        }
    levels_free(&L);
    return at;
}

/* Where grey shows the most shape between channel ch's levels: the drive of the largest departure of
 * grey's curve from the same model through grey at the channel's drives alone, from the drive lo
 * where the channel's range starts (NaN when there is none, or a level of the channel is near).
 * A channel modelled through grey copies that shape with no reading of its own there, and a joint
 * or a zone's gain step that only some channels have shows in grey there, diluted by the others'
 * share. */
static double grey_shape_probe(const ctx *c, int ch, double lo)
{
    enum { N_FINE = 255 };
    levels L;
    levels_read(c, ch, &L);
    double fv[N_FINE], fine[N_FINE], coarse[N_FINE], at = NAN, worst = 0;
    double *g = malloc((L.m + 1) * sizeof(double));
    csf_error e;
    if (g && L.m >= 4 && !grey_incr(c, L.v, g, L.m) && g[L.m - 1] > 0) {
        for (int j = 0; j < N_FINE; j++) fv[j] = (j + 1) / (double)N_FINE;
        if (!grey_incr(c, fv, fine, N_FINE) &&
            csf_profile_fit_curve(L.v, g, L.m, 1, fv, coarse, N_FINE, &e) == CSF_OK)
            for (int j = 0; j < N_FINE; j++) {
                if (!(fv[j] >= lo) || !(fine[j] > 0)) continue;
                double d = fabs(fine[j] - coarse[j]) / fine[j];
                if (d > worst) worst = d, at = fv[j];
            }
        for (size_t i = 0; !isnan(at) && i < L.m; i++)
            if (fabs(L.v[i] - at) < 1.0 / 64) at = NAN;
    }
    free(g);
    levels_free(&L);
    return at;
}

/* Where grey's own levels disagree most about an interval: the middle of the interval in range whose
 * two witnesses (each end knot left out in turn, csf_curve_interval_errors) differ most, the one seeing a
 * miss the other does not (NaN when none does). A step or a joint inside an interval shows to the
 * witness beside it only, and the statement, which takes their geometric mean, cannot tell it from
 * noise; a check there measures it. The gap is ranked as it is, not as a ratio: it is the most
 * error that geometric mean may be leaving out. */
static double grey_witness_split(const ctx *c)
{
    levels L;
    levels_read(c, CSF_CH_GREY, &L);
    double at = NAN, worst = 0;
    double *sd = malloc((L.m + 1) * sizeof(double)), *est = malloc((L.m + 1) * sizeof(double)),
           *emin = calloc(L.m + 1, sizeof(double));
    if (sd && est && emin && L.m >= 4) {
        level_sds(c, &L, pooled_noise_rel(c), sd);
        csf_curve_interval_errors(L.v, L.lum, L.m, 0, sd, 3, est, emin);
        double peak = L.lum[L.m - 1];
        for (size_t i = 0; i + 1 < L.m; i++)
            if (in_range(&L, i + 1, peak, NAN) && est[i] - emin[i] > worst) {
                /* a middle that framebuffer codes would round onto a knot checks nothing */
                double mid = snap(c, 0.5 * (L.v[i] + L.v[i + 1]));
                if (!(mid > L.v[i] && mid < L.v[i + 1])) continue;
                worst = est[i] - emin[i];
                at = mid;
            }
    }
    free(sd);
    free(est);
    free(emin);
    levels_free(&L);
    return at;
}

/* The check drives of curve ch: one in each of o->checks equal strata of its range above 10 % of
 * peak, at a point within the stratum that moves from stratum to stratum and curve to curve (a
 * golden-ratio sequence), so that checks do not fall in step with a LUT's or the sweep's spacing. */
static int check_drives(const ctx *c, const csf_display_profile *p, int ch, double *v, int max)
{
    double lo = profile_range_low(p, ch);
    if (!(lo >= 0 && lo < 1)) return 0;
    int n = c->o->checks < max ? c->o->checks : max, k = 0;
    double w = (1 - lo) / (n > 0 ? n : 1), low = lowest_interval_check(c, ch, lo);
    double probe = ch < 3 ? grey_shape_probe(c, ch, lo) : grey_witness_split(c);
    for (int i = 0; i < n; i++) {
        double f = fmod(0.6180339887498949 * (i + 1) + 0.381966 * ch, 1.0);
        double d = snap(c, lo + w * (i + 0.15 + 0.7 * f));
        int holds_low = low >= lo + w * i && low < lo + w * (i + 1);
        /* the stratum that holds it checks the lowest interval: no level below can witness it */
        if (holds_low) d = snap(c, low);
        /* the stratum that holds it checks the shape least confirmed: for a channel, grey's
         * (grey_shape_probe); for grey, where its witnesses disagree (grey_witness_split) */
        else if (probe >= lo + w * i && probe < lo + w * (i + 1)) d = snap(c, probe);
        if (d > 0 && d < 1) v[k++] = d;
    }
    return k;
}

/* The spot checks after the sweep: each curve's check drives, then a white reference (the drift
 * correction needs one after them); read again while the reference sets them aside. */
static csf_status spot_checks(ctx *c, csf_error *err)
{
    if (c->o->checks <= 0) return CSF_OK;
    for (;;) {
        csf_display_profile *p = NULL;
        csf_status st = profile_from_readings(c, "provisional", "", NAN, NULL, &p, err);
        if (st) return st;
        for (int ch = CSF_CH_GREY; !st && ch >= 0; ch--) {
            if (ch < 3 && !c->o->channels) break;
            double v[64];
            int n = check_drives(c, p, ch, v, 64);
            for (int i = 0; !st && i < n; i++) {
                rd x;
                st = take(c, ROLE_CHECK, ch, v[i], 0, &x, err);
            }
        }
        csf_profile_free(p);
        if (st) return st;
        int redo = 0;
        if ((st = reference(c, &redo, err))) return st;
        if (!redo) return CSF_OK;
    }
}

/* The relative sd of the profile's curve at drive v from the knots' noise (levels L with their
 * relative sds sd, linear weights between the two levels around v), in cd/m2 first: a channel's
 * knot at black is exact (zero luminance, no relative sd to speak of). */
static double knot_sd_at(const levels *L, const double *sd, double v)
{
    if (L->m < 2 || !sd) return 0;
    size_t i = 0;
    while (i + 2 < L->m && L->v[i + 1] <= v) i++;
    double t = L->v[i + 1] > L->v[i] ? fmin(1, fmax(0, (v - L->v[i]) / (L->v[i + 1] - L->v[i]))) : 0;
    double a = L->lum[i] > 0 ? sd[i] * L->lum[i] : 0, b = L->lum[i + 1] > 0 ? sd[i + 1] * L->lum[i + 1] : 0;
    double lum = (1 - t) * L->lum[i] + t * L->lum[i + 1];
    return lum > 0 ? sqrt(pow((1 - t) * a, 2) + pow(t * b, 2)) / lum : 0;
}

/* The systematic error the spot checks of curve ch show in profile p, scaled to a maximum over the
 * range (see CHECK_PEAK_PER_RMS); via: the curve is modelled through grey (its knot noise is then
 * grey's). NAN when the curve has no checks. */
static double check_error(const ctx *c, int ch, int via, const csf_display_profile *p)
{
    levels L;
    levels_read(c, via || ch == CSF_CH_GREY ? CSF_CH_GREY : ch, &L);
    double nr = pooled_noise_rel(c), ss = 0, noise2 = 0, *sd = malloc((L.m + 1) * sizeof(double));
    if (sd) level_sds(c, &L, nr, sd);
    int n = 0;
    for (size_t i = 0; i < c->n; i++) {
        const rd *x = &c->r[i];
        if (x->role != ROLE_CHECK || x->ch != ch || isnan(x->lum)) continue;
        double meas = corrected(c, x) - (ch < 3 ? c->black : 0), pred = profile_lum(p, ch, x->drive);
        if (!(pred > 0) || !(meas > 0)) continue;
        double r = meas / pred - 1, ks = knot_sd_at(&L, sd, x->drive);
        ss += r * r;
        noise2 += nr * nr + pow(c->noise_abs / meas, 2) + ks * ks;
        n++;
    }
    free(sd);
    levels_free(&L);
    if (!n) return NAN;
    /* the noise's share is taken at the 90th percentile of its chi-square (Wilson and Hilferty's
     * approximation): with four checks an unbiased subtraction leaves pure noise a positive excess
     * half the time, which a square root then makes a systematic error of about the noise's size */
    double z = 1.2816, q = n * pow(1 - 2.0 / (9 * n) + z * sqrt(2.0 / (9 * n)), 3);
    return CHECK_PEAK_PER_RMS * sqrt(fmax(0, (ss - noise2 * q / n) / n));
}

/* A statement with what the checks show: the larger of the model's error and the checks'. */
static double with_checks(statement s, double check)
{
    if (!isfinite(check)) return s.total;
    return fmax(s.total, sqrt(s.noise * s.noise + check * check));
}

/* The grey level to read next for grey's statement over the drives from v_lo up: a new level in the
 * worst interval there when the model part is the larger, else the noisiest level there; NAN when
 * none is left. */
static double grey_level_from(const ctx *c, double v_lo)
{
    levels L;
    levels_read(c, CSF_CH_GREY, &L);
    double *est = calloc(L.m + 1, sizeof(double)), next = NAN, worst = 0;
    if (est && L.m >= 3) {
        statement s = curve_statement_over(c, CSF_CH_GREY, &L, est, v_lo);
        for (size_t i = 0; i + 1 < L.m; i++)
            if (!(L.v[i + 1] > v_lo)) est[i] = -1;
        if (!(s.model < s.noise)) next = pick_split(c, &L, est, &worst);
        double top = L.lum[L.m - 1], at = predict(c, CSF_CH_GREY, v_lo);
        if (isnan(next) && top > 0 && at > 0) next = noisiest_level(c, &L, at / top);
    }
    free(est);
    levels_free(&L);
    return next;
}

/* After the sweeps: while a curve's stated error is above the target and sweep readings are
 * left, one more step on the worst curve (its statement moves as readings come: the pooled noise,
 * grey's error that channels inherit), then a white reference. What is left unmet when the
 * budget ends is reported as such (target_met). */
static csf_status top_up(ctx *c, csf_error *err)
{
    while (c->n_sweep < c->o->budget) {
        int worst_ch = CSF_CH_GREY;
        double worst = curve_statement_grey(c), st_ch;
        for (int ch = 0; c->o->channels && ch < 3; ch++) {
            ratio_model rm;
            channel_via_grey(c, ch, &rm, &st_ch);
            if (st_ch > worst) {
                worst = st_ch;
                worst_ch = ch;
            }
        }
        if (!(worst > c->o->target_rel)) return CSF_OK;
        int before = c->n_sweep;
        ratio_model rm;
        csf_status st;
        double gp = NAN, v_lo = NAN, grey_next = NAN;
        if (worst_ch < 3 && channel_via_grey(c, worst_ch, &rm, &st_ch)) {
            /* a channel through grey inherits grey's error over its own range, which may start
             * among grey's sparse dark levels: when that part is the larger, the reading goes to
             * grey there (a channel reading would only average the channel's own noise) */
            statement sc = channel_grey_statement(c, worst_ch, &rm, &gp, &v_lo);
            if (gp * gp > sc.total * sc.total - gp * gp) grey_next = grey_level_from(c, v_lo);
        }
        if (!isnan(grey_next)) {
            double peak = predict(c, CSF_CH_GREY, 1.0);
            st = measure_level(c, CSF_CH_GREY, grey_next, peak, c->o->budget - c->n_sweep, err);
        } else if (worst_ch < 3 && channel_via_grey(c, worst_ch, &rm, &st_ch)) {
            levels L;
            levels_read(c, worst_ch, &L);
            double at = L.m >= 2 ? noisiest_level(c, &L, 0.05) : NAN;
            levels_free(&L);
            rd x;
            st = isnan(at) ? CSF_OK : take(c, ROLE_SWEEP, worst_ch, at, 0, &x, err);
        } else {
            double peak = predict(c, worst_ch, 1.0);
            st = refine_curve(c, worst_ch, 1, c->n_sweep, peak, err);
        }
        if (st) return st;
        if (c->n_sweep == before) return CSF_OK; /* nothing left to measure there */
        int redo = 0;
        if ((st = reference(c, &redo, err))) return st;
    }
    return CSF_OK;
}

static csf_status run(ctx *c, csf_display_calib_result *res, csf_error *err)
{
    csf_status st = warmup(c, res, err);
    if (st) return st;
    if ((st = dark_series(c, err))) return st;
    /* first white reference: 6 readings in a row (no drift to speak of over 3 s after the
     * warm-up) give the noise estimate, 5 degrees of freedom. One that shows the darks were not
     * the screen's (no contrast: the sensor was off the patch) sets them aside: measured again */
    double wv[6];
    for (int i = 0; i < 6; i++) {
        rd x;
        int redo = 0;
        st = suspect_white(c, take(c, ROLE_REF, CSF_CH_GREY, 1.0, 0, &x, err), &redo);
        if (st) return st;
        if (redo == 1 && (st = dark_series(c, err))) return st;
        if (redo) {
            i = -1; /* the six in a row again */
            continue;
        }
        wv[i] = x.lum;
    }
    c->noise_rel = csf_sample_sd(wv, 6) / wv[5];
    if ((st = confirm_dark(c, err))) return st;
    int budget = c->o->budget;
    /* channels are fitted through the grey curve (few parameters), so grey gets half */
    int grey_budget = c->o->channels ? (int)(budget * 0.5 + 0.5) : budget;
    st = sweep_ref(c, CSF_CH_GREY, grey_budget, NULL, 0, &res->est_error_rel[CSF_CH_GREY], err);
    if (st) return st;
    if (c->o->channels) {
        /* a kink the grey sweep found is usually the panel's (a driver or LUT step common to
         * the channels): each channel measures at the grey curve's corners from the start */
        double corners[3];
        int nc = 0;
        {
            double *pv, *pl;
            size_t k = curve_points(c, CSF_CH_GREY, &pv, &pl);
            csf_error cerr;
            nc = (int)csf_profile_fit_corners(pv, pl, k, 0, corners, 3, &cerr);
            free(pv);
            free(pl);
            /* a corner in the dark toe (noise on a steep bend, or a real one far below the
             * range the target covers) is not worth a channel reading */
            int kept = 0;
            double gpeak = predict(c, CSF_CH_GREY, 1.0);
            for (int i = 0; i < nc; i++)
                if (predict(c, CSF_CH_GREY, corners[i]) >= 0.05 * gpeak) corners[kept++] = corners[i];
            nc = kept;
        }
        for (int ch = 0; ch < 3; ch++) {
            int left = budget - c->n_sweep;
            int b = left / (3 - ch);
            if (b < 2) b = 2;
            double grey_total = res->est_error_rel[CSF_CH_GREY]; /* what a channel through grey inherits */
            st = sweep_ref(c, ch, b, corners, nc, &grey_total, err);
            if (st) return st;
        }
    }
    if ((st = top_up(c, err))) return st;
    update_black(c);
    if ((st = spot_checks(c, err))) return st;
    update_black(c);
    return CSF_OK;
}

static void checks(ctx *c, csf_display_calib_result *res)
{
    /* drift and noise from the references */
    double first = NAN, last = NAN;
    for (size_t i = 0; i < c->n; i++)
        if (c->r[i].role == ROLE_REF) {
            if (isnan(first)) first = c->r[i].lum;
            last = c->r[i].lum;
        }
    res->drift_rel = last / first - 1;
    res->noise_rel = c->noise_rel;
    /* additivity */
    res->additivity_error = NAN;
    if (c->o->channels) {
        double white = predict(c, CSF_CH_GREY, 1.0), sum = c->black;
        for (int ch = 0; ch < 3; ch++) sum += predict(c, ch, 1.0);
        res->additivity_error = sum / white - 1;
    }
    /* monotonicity of the raw (drift-corrected, averaged) readings */
    res->monotonic_violations = 0;
    res->monotonic_msg[0] = 0;
    for (int ch = 0; ch < CSF_CH_COUNT; ch++) {
        if (ch < 3 && !c->o->channels) continue;
        double *pv, *pl;
        size_t k = curve_points(c, ch, &pv, &pl);
        double *dv = malloc((k + 1) * sizeof(double)), *dl = malloc((k + 1) * sizeof(double));
        size_t m = distinct(pv, pl, k, dv, dl, NULL);
        for (size_t i = 0; i + 1 < m; i++) {
            double s = 3 * sqrt(pow(c->noise_rel * dl[i], 2) + pow(c->noise_abs, 2)) + 1e-9;
            if (dl[i + 1] < dl[i] - s) {
                if (!res->monotonic_violations)
                    snprintf(res->monotonic_msg, sizeof res->monotonic_msg,
                             "%s falls from %.4g to %.4g cd/m2 between drive %.4g and %.4g (more than the "
                             "instrument noise)", (const char *[]){"red", "green", "blue", "grey"}[ch],
                             dl[i], dl[i + 1], dv[i], dv[i + 1]);
                res->monotonic_violations++;
            }
        }
        free(pv); free(pl); free(dv); free(dl);
    }
}

static csf_status build_profile(ctx *c, const char *display_name, const char *instrument,
                                double additivity, csf_display_profile **out, csf_error *err)
{
    csf_profile_reading *pr = calloc(c->n + 1, sizeof *pr);
    if (!pr) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    size_t k = 0;
    for (size_t i = 0; i < c->n; i++) {
        const rd *x = &c->r[i];
        if (x->role == ROLE_WARMUP || x->role == ROLE_DARK_REJECTED || x->role == ROLE_REJECTED ||
            x->role == ROLE_CHECK)
            continue;
        double f = drift_factor(c, x->t_s);
        pr[k].channel = x->role == ROLE_SWEEP ? x->ch : CSF_CH_GREY;
        pr[k].drive01 = x->drive;
        pr[k].lum_cdm2 = isnan(x->lum) ? 0 : x->lum * f;
        pr[k].has_xyz = x->has_xyz;
        for (int j = 0; j < 3; j++) pr[k].xyz[j] = x->xyz[j] * f;
        k++;
    }
    csf_profile_meta meta = {display_name, instrument, NULL, NULL, additivity};
    csf_status st = csf_profile_build(pr, k, &meta, out, err);
    free(pr);
    return st;
}

static void settings_json(const csf_display_calib_opts *o, const char *spec, char *buf, size_t len)
{
    /* Through jansson, so the photometer spec is kept as given and the text is always JSON; a
     * spec jansson refuses (not UTF-8) is stored empty, as the settings do not depend on it. */
    json_t *sp = json_string(spec);
    json_t *doc = json_pack("{s:o,s:f,s:i,s:i,s:f,s:i,s:i,s:i}", "photometer", sp ? sp : json_string(""),
                            "target_rel", o->target_rel, "budget", o->budget, "channels", o->channels,
                            "warmup_wait_s", o->warmup_wait_s, "warmup_max", o->warmup_max, "drive_levels",
                            o->drive_levels, "checks", o->checks);
    char *text = doc ? json_dumps(doc, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17)) : NULL;
    json_decref(doc);
    snprintf(buf, len, "%s", text && strlen(text) < len ? text : "{}");
    free(text);
}

/* The stored settings decide on resume, so the replay takes the same path. They are outside input
 * by then (a damaged or hostile store): every value is range-checked before it is used, with the
 * same limits a new session gets; keys an older session did not store keep today's defaults. */
static csf_status stored_settings(const char *json, int64_t sid, csf_display_calib_opts *o, csf_error *err)
{
    char what[64];
    snprintf(what, sizeof what, "stored settings of display session %lld", (long long)sid);
    csf_json_doc *d;
    csf_status st = csf_json_parse_object(json, what, &d, err);
    if (st) return st;
    int channels = o->channels;
    csf_display_calib_opts defaults;
    csf_display_calib_defaults(&defaults);
    o->checks = defaults.checks; /* a session stored before spot checks existed gets today's default */
    int bad = csf_json_get_number(d, "target_rel", 1e-5, 0.5, &o->target_rel, err) < 0 ||
              csf_json_get_int(d, "budget", 8, 4096, &o->budget, err) < 0 ||
              csf_json_get_int(d, "channels", 0, 1, &channels, err) < 0 ||
              csf_json_get_number(d, "warmup_wait_s", 0, 86400, &o->warmup_wait_s, err) < 0 ||
              csf_json_get_int(d, "warmup_max", 0, 4096, &o->warmup_max, err) < 0 ||
              csf_json_get_int(d, "drive_levels", 0, 65535, &o->drive_levels, err) < 0 ||
              csf_json_get_int(d, "checks", 0, CSF_DISPLAY_MAX_CHECKS, &o->checks, err) < 0;
    csf_json_free(d);
    if (bad) return CSF_E_FORMAT;
    o->channels = channels != 0;
    return CSF_OK;
}

/* A resume's check of the stored kind and state; a kind or state this build does not know is
 * refused, never taken for a known one. */
static csf_status resumable(const csf_session_info *si, int64_t session_id, csf_error *err)
{
    char kind[64], state[64];
    csf_store_printable(si->kind_text, kind, sizeof kind);
    csf_store_printable(si->state_text, state, sizeof state);
    if (si->kind != CSF_SESSION_DISPLAY)
        return csf_error_set(
            err, CSF_E_INVALID_ARG, "session %lld is a %s session%s, not a display calibration",
            (long long)session_id, kind, si->kind ? "" : " (a kind this csfcal does not know)");
    if (si->state == CSF_SESSION_FINISHED)
        return csf_error_set(err, CSF_E_INVALID_ARG, "session %lld is already finished; nothing to resume",
                             (long long)session_id);
    /* aborted is final, by `sessions abort` or because its settings could not be used: a resume
     * would take it back from whoever closed it */
    if (si->state == CSF_SESSION_ABORTED)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "session %lld was aborted; only running or paused display sessions can be "
                             "resumed (its readings stay in the store: csfcal sessions export %lld)",
                             (long long)session_id, (long long)session_id);
    if (si->state == CSF_SESSION_STATE_UNKNOWN)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "session %lld is in state '%s', which this csfcal does not know "
                             "(allowed running, paused, finished, aborted); it is not resumed",
                             (long long)session_id, state);
    return CSF_OK;
}

/* A session being resumed: its kind and state checked, its stored settings into o (a session whose
 * settings cannot be used is marked aborted), its readings into c for the replay. */
static csf_status resume_session(ctx *c, csf_display_calib_opts *o, int64_t session_id, csf_error *err)
{
    csf_status st;
    csf_session_info si;
    memset(&si, 0, sizeof si);
    st = csf_store_get_session(c->store, session_id, &si, err);
    if (st) return st;
    st = resumable(&si, session_id, err);
    if (st) {
        csf_session_info_free(&si);
        return st;
    }
    st = stored_settings(si.settings_json, session_id, o, err);
    csf_session_info_free(&si);
    if (st) {
        /* Every later resume would fail the same way: take the session off the resumable
         * list, keep its readings. */
        char why[sizeof err->msg];
        snprintf(why, sizeof why, "%s", err ? err->msg : "stored settings are damaged");
        csf_store_set_session_state(c->store, session_id, CSF_SESSION_ABORTED, NULL);
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s; the session cannot be resumed and is now "
                             "marked aborted (its readings stay in the store: csfcal sessions export %lld)",
                             why, (long long)session_id);
    }
    c->sid = session_id;
    st = csf_store_get_readings(c->store, c->sid, &c->replay, &c->n_replay, err);
    if (st) return st;
    c->seq = (int)c->n_replay;
    for (size_t i = 0; i < c->n_replay; i++)
        if (c->replay[i].seq >= c->seq) c->seq = c->replay[i].seq + 1;
    if ((st = csf_store_set_session_state(c->store, c->sid, CSF_SESSION_RUNNING, err))) {
        free(c->replay);
        return st;
    }
    return CSF_OK;
}

/* Every curve's stated error from all the readings (the references after the last sweep
 * included), for the model the profile holds: grey and channels through their own levels, or a
 * channel through grey (channel_grey_statement). target_met: all at or below the target. */
static void stated_errors(const ctx *c, const csf_display_calib_opts *o, const csf_display_profile *p,
                          csf_display_calib_result *res)
{
    ctx median = *c; /* what the profile states: the median */
    median.noise_quantile = 0.5;
    for (int ch = 0; ch < CSF_CH_COUNT; ch++)
        res->est_error_rel[ch] = res->met_error_rel[ch] = res->check_error_rel[ch] = NAN;
    levels L;
    levels_read(c, CSF_CH_GREY, &L);
    double chk = p ? check_error(c, CSF_CH_GREY, 0, p) : NAN;
    res->check_error_rel[CSF_CH_GREY] = chk;
    statement sg = curve_statement(c, CSF_CH_GREY, &L, NULL);
    int met_without_checks = sg.total <= o->target_rel;
    res->est_error_rel[CSF_CH_GREY] = with_checks(curve_statement(&median, CSF_CH_GREY, &L, NULL), chk);
    res->met_error_rel[CSF_CH_GREY] = with_checks(sg, chk);
    levels_free(&L);
    for (int ch = 0; o->channels && ch < 3; ch++) {
        ratio_model rm;
        statement sm, sq;
        channel_statement(&median, ch, &rm, &sm);
        channel_statement(c, ch, &rm, &sq);
        /* the checks are judged against the model the profile holds */
        chk = p ? check_error(c, ch, res->channel_via_grey[ch], p) : NAN;
        res->check_error_rel[ch] = chk;
        res->est_error_rel[ch] = with_checks(sm, chk);
        res->met_error_rel[ch] = with_checks(sq, chk);
        met_without_checks &= sq.total <= o->target_rel;
    }
    res->target_met = 1;
    for (int ch = 0; ch < CSF_CH_COUNT; ch++)
        if (ch == CSF_CH_GREY || o->channels) res->target_met &= res->met_error_rel[ch] <= o->target_rel;
    res->checks_raised = met_without_checks && !res->target_met;
}

/* The profile from a run that ended well: the checks, the profile and the channels taken from the
 * grey curve where their own readings are too few. *out is NULL when it fails. */
static csf_status finish_profile(ctx *c, const csf_display_calib_opts *o, csf_display_profile **out,
                                 csf_display_calib_result *res, csf_error *err)
{
    csf_photometer *ph = c->ph;
    csf_status st;
    checks(c, res);
    char ident[256];
    csf_error ie;
    if (csf_photometer_identify(ph, ident, sizeof ident, &ie))
        snprintf(ident, sizeof ident, "%s", csf_photometer_spec(ph));
    const char *dn = o->display_name ? o->display_name : csf_photometer_spec(ph);
    st = profile_from_readings(c, dn, ident, res->additivity_error, res->channel_via_grey, out, err);
    stated_errors(c, o, *out, res);
    if (!st) csf_profile_set_statement(*out, o->target_rel, res->est_error_rel, res->target_met);
    return st;
}

/* The session's end in the store: finished with its profile, or paused to be resumed. */
static void close_session(const ctx *c, csf_status st, const csf_display_profile *out)
{
    csf_error e2;
    if (st == CSF_OK) {
        char *text = NULL;
        if (csf_profile_to_text(out, &text, &e2) == CSF_OK) {
            csf_store_add_artifact(c->store, c->sid, "profile", NULL, text, strlen(text), &e2);
            free(text);
        }
        csf_store_set_session_state(c->store, c->sid, CSF_SESSION_FINISHED, &e2);
    } else {
        csf_store_set_session_state(c->store, c->sid, CSF_SESSION_PAUSED, &e2);
    }
}

csf_status csf_display_calibrate(csf_photometer *ph, const csf_display_calib_opts *opts_in,
                                 csf_store *store, int64_t *session_id, uint64_t seed,
                                 csf_display_profile **out, csf_display_calib_result *res,
                                 csf_error *err)
{
    *out = NULL;
    csf_display_calib_result local;
    if (!res) res = &local;
    memset(res, 0, sizeof *res);
    csf_display_calib_opts o = *opts_in;
    if (o.drive_levels < 0 || o.drive_levels > 65535)
        return csf_error_set(err, CSF_E_INVALID_ARG, "drive levels %d out of range (0 = continuous, up to 65535)",
                             o.drive_levels);
    if (o.checks < 0 || o.checks > CSF_DISPLAY_MAX_CHECKS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "spot checks %d per curve out of range (0 to %d)",
                             o.checks, CSF_DISPLAY_MAX_CHECKS);
    if (!(o.target_rel >= 1e-5 && o.target_rel <= 0.5) || o.budget < 8 || o.budget > 4096)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "calibration target %g (allowed 1e-5 to 0.5) or budget %d (allowed 8 to 4096) out of range",
                             o.target_rel, o.budget);
    ctx c;
    memset(&c, 0, sizeof c);
    c.ph = ph;
    c.store = store;
    c.o = &o;
    c.noise_quantile = MET_QUANTILE;
    csf_status st = CSF_OK;
    char settings[1024];
    if (store && session_id && *session_id > 0) {
        st = resume_session(&c, &o, *session_id, err);
        if (st) return st;
    } else if (store) {
        settings_json(&o, csf_photometer_spec(ph), settings, sizeof settings);
        const char *dn = o.display_name ? o.display_name : csf_photometer_spec(ph);
        st = csf_store_begin_session(store, CSF_SESSION_DISPLAY, NULL, dn, settings, seed, &c.sid, err);
        if (st) return st;
        if (session_id) *session_id = c.sid;
    }
    st = run(&c, res, err);
    if (c.progress_shown) fputc('\n', stderr);
    res->n_readings = (int)c.n;
    res->n_sweep = c.n_sweep;
    res->n_warmup = c.n_warmup;
    res->n_check = c.n_check;
    res->n_profile = 0;
    for (size_t i = 0; i < c.n; i++) /* what build_profile takes */
        res->n_profile += c.r[i].role == ROLE_DARK || c.r[i].role == ROLE_REF || c.r[i].role == ROLE_SWEEP;

    if (!st) {
        st = finish_profile(&c, &o, out, res, err);
    }
    if (store && c.sid > 0) {
        close_session(&c, st, *out);
    }
    free(c.r);
    free(c.replay);
    return st;
}
