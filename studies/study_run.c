/* Running a user study (see study_run.h). */
#include "studies/study_run.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "calib/procedure.h"
#include "studies/study_plan.h"
#include "studies/study_sessions.h"
#include "calib/trial_io.h"
#include "model/observer_images.h"
#include "model/observer_sim.h"
#include "devices/responder.h"
#include "results/display_profile.h"
#include "core/json_read.h"
#include "core/rng.h"
#include "results/store/store.h"
#include "stimuli/geometry.h"
#include "stimuli/image.h"

#define CUE_FRACTION (2.0 / 3.0) /* place cues on for this share of the fixation period */
#define PRACTICE_MIN_CONTRAST 0.1

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

typedef struct {
    const csf_study *study;
    csf_presenter *pres;
    csf_trial_io io;
    csf_observer_sim *sim;
    uint64_t sim_seed;
    csf_image **img_a, **img_b; /* per condition (image conditions), normalised (normalise_image) */
    double *dev_a, *dev_b;      /* the contrasts that draw them faithfully */
    double *pair_r;             /* per condition: the simulated observer's detectability */
    double max_contrast;
    double period_s;
    double sim_answer_s; /* simulated answers' times, which no frame clock counts */
    double t0_s;         /* the presenter's time when this run's trials began */
    double clock_base_s; /* the session's clock then: the time its earlier runs took */
} study_ctx;

typedef struct {
    int choice;                 /* -1 none */
    double rt_s;
    int valid;
    char flags[64];
    double shown_target;        /* mean contrast shown in the target interval/place */
    double shown_max;
    int frames_planned, frames_shown, frames_missed;
    csf_trial_record rec;       /* the last stimulus interval's frames */
    int have_rec;
    double onset_s; /* the first interval's onset on the session's clock; NaN before */
} study_outcome;

static void add_flag(char *flags, const char *f)
{
    size_t n = strlen(flags);
    if (n + strlen(f) + 2 < 64) snprintf(flags + n, 64 - n, "%s%s", n ? "," : "", f);
}

int csf_study_places(const csf_study *s, const csf_study_condition *c, double polar_deg[2])
{
    if (s->design == CSF_DESIGN_2AFC) {
        polar_deg[0] = fmod(c->polar_deg + 180.0 + 720.0, 360.0);
        polar_deg[1] = fmod(c->polar_deg + 720.0, 360.0);
        return 2;
    }
    polar_deg[0] = polar_deg[1] = fmod(c->polar_deg + 720.0, 360.0);
    return 1;
}

static void cond_stimulus(const csf_study_condition *c, double polar, double contrast,
                          const csf_image *img, csf_stimulus *s)
{
    memset(s, 0, sizeof *s);
    s->ecc_deg = c->ecc_deg;
    s->polar_deg = polar;
    s->mean_lum_cdm2 = c->mean_lum_cdm2;
    if (c->kind == CSF_COND_IMAGE) {
        s->kind = CSF_STIM_IMAGE;
        s->image = img;
        s->radius_deg = 0.5 * c->size_deg;
        s->contrast = contrast;
        return;
    }
    s->kind = c->kind == CSF_COND_GABOR ? CSF_STIM_GABOR : CSF_STIM_GRATING;
    s->freq_cpd = c->freq_cpd;
    s->orientation_deg = c->orientation_deg;
    s->phase_deg = c->phase_deg;
    s->sigma_deg = c->sigma_deg;
    s->radius_deg = c->radius_deg;
    s->drift_hz = c->drift_hz;
    s->velocity_dps = c->velocity_dps;
    s->motion_dir_deg = c->motion_dir_deg;
    s->contrast = contrast;
}

static double patch_radius(const csf_study_condition *c, const csf_image *img)
{
    if (c->kind == CSF_COND_GABOR) return 3 * c->sigma_deg;
    if (c->kind == CSF_COND_GRATING) return c->radius_deg + 0.25;
    double r = 0.5 * c->size_deg;
    return img && img->width > 0 ? hypot(r, r * img->height / (double)img->width) : r;
}

/* The presenter draws an image as L = mean (1 + contrast (v - m) / m), m the image's mean, and
 * checks the luminance range as mean (1 +- contrast). To draw the image faithfully and have that
 * check test its real range, its values are rescaled about m by 1 / dev, dev = the largest
 * relative deviation |v - m| / m, and it is drawn at contrast dev: the same luminances, and the
 * check's range is the image's own. Returns dev (0 for a flat image). */
static double normalise_image(csf_image *img)
{
    double m = img->mean_lum, dev = 0;
    size_t n = (size_t)img->width * img->height;
    if (!(m > 0)) return 0;
    for (size_t i = 0; i < n; i++) dev = fmax(dev, fabs(img->lum[i] - m) / m);
    if (dev > 0)
        for (size_t i = 0; i < n; i++) img->lum[i] = (float)(m + (img->lum[i] - m) / dev);
    return dev;
}

/* ---- checks before the first trial ------------------------------------------------------------ */

static csf_status check_durations(const csf_study *s, double refresh_hz, csf_error *err)
{
    const struct { const char *name; double v; int may_be_zero; } d[] = {
        {"stimulus_s", s->stimulus_s, 0}, {"isi_s", s->isi_s, 1}, {"iti_s", s->iti_s, 1},
        {"fixation_s", s->fixation_s, 1}, {"feedback_s", s->feedback_s, 1}};
    double frame = 1.0 / refresh_hz;
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) {
        if (d[i].may_be_zero && d[i].v == 0) continue;
        if (d[i].v < 0.5 * frame)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = %g s is shorter than one frame at %g Hz "
                                 "(%.4g s): the display cannot show it", s->path, d[i].name, d[i].v,
                                 refresh_hz, frame);
    }
    return CSF_OK;
}

static csf_status check_condition(const csf_study *s, const csf_study_condition *c, csf_presenter *pres,
                                  const csf_image *img, double img_dev, csf_error *err)
{
    double polar[2];
    int n = csf_study_places(s, c, polar);
    double contrast = c->kind == CSF_COND_IMAGE ? img_dev : c->adaptive ? s->adaptive_max_contrast : c->contrast;
    for (int k = 0; k < n; k++) {
        csf_stimulus st;
        cond_stimulus(c, polar[k], contrast, img, &st);
        csf_error e;
        if (csf_presenter_validate(pres, &st, &e) != CSF_OK)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): at %g deg eccentricity, polar %g deg: "
                                 "%s", s->conditions_path, c->line, c->label, c->ecc_deg, polar[k], e.msg);
        if (c->kind == CSF_COND_IMAGE) {
            /* the image's finest detail (0.5 cycle per image pixel) must be displayable there */
            double f_img = 0.5 * img->width / c->size_deg;
            double nyq = csf_geometry_nyquist_cpd_any(csf_presenter_geometry(pres), c->ecc_deg, polar[k]);
            if (f_img > nyq)
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): a %d px wide image drawn %g deg wide "
                                     "holds detail up to %.3g cpd, above the display's Nyquist limit of "
                                     "%.3g cpd there: draw it at least %.3g deg wide or use a smaller image",
                                     s->conditions_path, c->line, c->label, img->width, c->size_deg, f_img,
                                     nyq, 0.5 * img->width / nyq);
        }
    }
    if (s->design == CSF_DESIGN_2AFC && c->kind == CSF_COND_IMAGE)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): image pairs are shown one image at a time: "
                             "use design = 2ifc or same_different", s->conditions_path, c->line, c->label);
    if (s->design == CSF_DESIGN_2AFC && c->ecc_deg < patch_radius(c, img))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): the two 2afc places overlap",
                             s->conditions_path, c->line, c->label);
    return CSF_OK;
}

csf_status csf_study_check_display(const csf_study *s, csf_presenter *pres, csf_error *err)
{
    csf_status st = check_durations(s, csf_presenter_refresh_hz(pres), err);
    for (int i = 0; st == CSF_OK && i < s->n_conds; i++) {
        const csf_study_condition *c = &s->conds[i];
        if (c->kind != CSF_COND_IMAGE) {
            st = check_condition(s, c, pres, NULL, 0, err);
            continue;
        }
        const char *paths[2] = {c->image_a, c->image_b};
        for (int k = 0; k < 2 && st == CSF_OK; k++) {
            csf_image *img = NULL;
            csf_error e;
            if (csf_image_load_png(paths[k], &img, &e) != CSF_OK)
                return csf_error_set(err, CSF_E_NOT_FOUND, "%s:%d (%s): %s: %s", s->conditions_path, c->line,
                                     c->label, k ? "image_b" : "image_a", e.msg);
            double dev = normalise_image(img);
            st = check_condition(s, c, pres, img, dev, err);
            csf_image_free(img);
        }
    }
    return st;
}

/* ---- one trial ------------------------------------------------------------------------------ */

static void take_record(study_outcome *o, int is_target)
{
    if (o->have_rec && o->rec.frames_drawn > 0) {
        /* keep only the newest interval's frame timing; counts add up over intervals */
    }
    o->frames_planned += o->rec.frames_planned;
    o->frames_shown += o->rec.frames_shown;
    o->frames_missed += o->rec.frames_missed;
    if (o->rec.flags[0]) add_flag(o->flags, o->rec.flags);
    if (is_target) {
        o->shown_target = csf_round9(o->rec.contrast_shown_mean);
        o->shown_max = csf_round9(o->rec.contrast_shown_max);
    }
}

/* A presenter time on the session's clock: the earlier runs' time, then this run's, the
 * simulated answers included (the virtual frame clock does not run while they are given), so
 * onsets keep rising over a resumed session as person time does. */
static double session_clock_s(const study_ctx *x, double presenter_s)
{
    return csf_round9(fmax(0.0, x->clock_base_s + (presenter_s - x->t0_s) + x->sim_answer_s));
}

/* One interval: the stimulus for stimulus_s (NULL: blank with fixation). The trial's onset is its
 * first interval's: the stimulus's first frame, or the start of the blank that stands for it. */
static csf_status show_interval(study_ctx *x, const csf_stimulus *s, int is_target, study_outcome *o,
                                csf_error *err)
{
    if (!s) {
        if (isnan(o->onset_s)) o->onset_s = session_clock_s(x, csf_presenter_time(x->pres));
        return csf_trial_io_blank(&x->io, x->study->stimulus_s, 1, err);
    }
    if (o->have_rec) csf_trial_record_free(&o->rec);
    o->have_rec = 0;
    csf_envelope env = {CSF_ENV_FIXED, x->study->stimulus_s, 0, 0};
    csf_status st = csf_presenter_run_trial(x->pres, s, &env, 1, NULL, NULL, &o->rec, err);
    if (st != CSF_OK) return st;
    o->have_rec = 1;
    if (isnan(o->onset_s)) o->onset_s = session_clock_s(x, o->rec.t_onset_s);
    take_record(o, is_target);
    return CSF_OK;
}

/* Inter-trial interval, then fixation with the places cued for its first part. */
static csf_status lead_in(study_ctx *x, const csf_study_condition *c, const csf_image *img, csf_error *err)
{
    const csf_study *s = x->study;
    csf_status st = csf_trial_io_blank(&x->io, s->iti_s, 0, err);
    if (st != CSF_OK || x->io.paused || s->fixation_s <= 0) return st;
    double polar[2], ecc[2] = {c->ecc_deg, c->ecc_deg};
    int n = csf_study_places(s, c, polar);
    double rad = patch_radius(c, img);
    int cue = c->ecc_deg > 0 && rad <= CSF_MARK_MAX_RADIUS_DEG;
    csf_error e;
    if (cue && csf_presenter_set_marks(x->pres, n, ecc, polar, rad, &e) != CSF_OK) cue = 0;
    st = csf_trial_io_blank(&x->io, s->fixation_s * (cue ? CUE_FRACTION : 1.0), 1, err);
    if (cue) csf_presenter_set_marks(x->pres, 0, NULL, NULL, 0, &e);
    if (st != CSF_OK || x->io.paused || !cue) return st;
    return csf_trial_io_blank(&x->io, s->fixation_s * (1 - CUE_FRACTION), 1, err);
}

/* The two stimuli of a two-interval or two-place trial (NULL = blank). */
static void pair_stimuli(study_ctx *x, const csf_study_condition *c, int cond, const csf_study_trial *t,
                         double level, csf_stimulus st[2], int have[2])
{
    const csf_study *s = x->study;
    double polar[2];
    csf_study_places(s, c, polar);
    have[0] = have[1] = 0;
    if (c->kind == CSF_COND_IMAGE) {
        /* which image goes first: 0 = a, 1 = b */
        int first, second;
        if (s->design == CSF_DESIGN_SAME_DIFF) {
            first = t->order;
            second = t->target ? !t->order : t->order;
        } else { /* 2ifc: the altered image (b) in the target interval */
            first = t->target == 0;
            second = t->target == 1;
        }
        const csf_image *im[2] = {x->img_a[cond], x->img_b[cond]};
        double dev[2] = {x->dev_a[cond], x->dev_b[cond]};
        cond_stimulus(c, polar[0], dev[first], im[first], &st[0]);
        cond_stimulus(c, polar[1], dev[second], im[second], &st[1]);
        have[0] = have[1] = 1;
        return;
    }
    int k = s->design == CSF_DESIGN_YES_NO ? 0 : t->target;
    if (s->design == CSF_DESIGN_YES_NO && !t->target) return;
    cond_stimulus(c, polar[k], level, NULL, &st[k]);
    have[k] = 1;
}

/* The speed at which a condition's carrier moves on the retina, with the eyes on the fixation mark:
 * its drift (drift_hz / f) plus the part of the patch's own motion across the bars (motion along
 * the bars does not move a grating's phase anywhere: the aperture problem, Wallach 1935). */
static double condition_retinal_velocity(const csf_study_condition *c)
{
    if (!(c->freq_cpd > 0)) return 0.0;
    double across = c->velocity_dps * cos((c->motion_dir_deg - c->orientation_deg) * M_PI / 180.0);
    return fabs(c->drift_hz / c->freq_cpd + across);
}

/* The simulated person's yes/no answer: the fade-in observer fed the frames actually shown (a
 * constant-contrast interval is a ramp that does not rise), then blank frames for the response
 * window; a press is "yes". */
static int sim_yes_no(study_ctx *x, uint64_t key, const csf_study_condition *c, const study_outcome *o,
                      int shown, double *rt)
{
    const csf_study *s = x->study;
    double window = s->response_window_s > 0 ? s->response_window_s : 1.0;
    int n_stim = shown && o->have_rec ? o->rec.frames_shown : (int)lround(s->stimulus_s / x->period_s);
    int n_total = n_stim + (int)lround(window / x->period_s);
    csf_sim_fade_trial tr;
    csf_observer_sim_fade_begin_v(x->sim, key, c->freq_cpd, c->ecc_deg, condition_retinal_velocity(c),
                                  c->polar_deg, 0, n_total * x->period_s, &tr);
    for (int i = 0; i < n_total; i++) {
        double cs = shown && i < n_stim && o->have_rec ? o->rec.contrast_per_period[i] : 0;
        double press;
        if (csf_observer_sim_fade_frame(x->sim, &tr, i * x->period_s, csf_round9(cs), &press)) {
            double end = n_stim * x->period_s;
            *rt = csf_round9(press > end ? press - end : 0);
            return 1;
        }
    }
    *rt = NAN;
    return 0;
}

static csf_status respond(study_ctx *x, uint64_t key, int cond, const csf_study_trial *t,
                          study_outcome *o, csf_error *err)
{
    const csf_study *s = x->study;
    const csf_study_condition *c = &s->conds[cond];
    if (x->sim) {
        double rt = NAN;
        if (s->design == CSF_DESIGN_YES_NO) {
            o->choice = sim_yes_no(x, key, c, o, t->target, &rt);
        } else if (s->design == CSF_DESIGN_SAME_DIFF) {
            o->choice = csf_observer_sim_same_different(x->sim, x->sim_seed, key, t->target ? x->pair_r[cond] : 0, &rt);
        } else if (c->kind == CSF_COND_IMAGE) {
            o->choice = csf_observer_sim_image_afc(x->sim, x->sim_seed, key, x->pair_r[cond], t->target, &rt);
        } else {
            double shown[2] = {0, 0};
            shown[t->target] = o->shown_target;
            o->choice = csf_observer_sim_2afc_v(x->sim, key, c->freq_cpd, c->ecc_deg,
                                                condition_retinal_velocity(c), shown, &rt);
        }
        o->rt_s = csf_round9(rt);
        o->valid = 1;
        /* the simulated person's answer (a yes/no "no" waits out the window) is person time */
        x->sim_answer_s += isfinite(rt) ? rt
                           : s->design == CSF_DESIGN_YES_NO
                               ? (s->response_window_s > 0 ? s->response_window_s : 1.0)
                               : 0.0;
        return CSF_OK;
    }
    csf_status st = csf_trial_io_wait_choice(&x->io, csf_responder_now(), s->response_window_s, &o->choice,
                                             &o->rt_s, err);
    o->valid = o->choice >= 0;
    if (!o->valid && !x->io.paused) add_flag(o->flags, "no_response");
    return st;
}

static csf_status run_one(study_ctx *x, uint64_t key, const csf_study_trial *t, double level,
                          study_outcome *o, csf_error *err)
{
    memset(o, 0, sizeof *o);
    o->choice = -1;
    o->rt_s = o->shown_target = o->shown_max = o->onset_s = NAN;
    const csf_study *s = x->study;
    int cond = t->cond;
    const csf_study_condition *c = &s->conds[cond];
    csf_status st = lead_in(x, c, c->kind == CSF_COND_IMAGE ? x->img_a[cond] : NULL, err);
    if (st != CSF_OK || x->io.paused) return st;
    csf_stimulus stim[2];
    int have[2];
    pair_stimuli(x, c, cond, t, level, stim, have);
    if (s->design == CSF_DESIGN_2AFC || s->design == CSF_DESIGN_YES_NO) {
        /* one interval: the target at its place (2afc), or target / nothing (yes/no) */
        int k = s->design == CSF_DESIGN_2AFC ? t->target : 0;
        st = show_interval(x, have[k] ? &stim[k] : NULL, 1, o, err);
    } else {
        st = show_interval(x, have[0] ? &stim[0] : NULL, t->target == 0, o, err);
        if (st == CSF_OK && !x->io.paused) st = csf_trial_io_blank(&x->io, s->isi_s, 1, err);
        if (st == CSF_OK && !x->io.paused) st = show_interval(x, have[1] ? &stim[1] : NULL, t->target == 1, o, err);
    }
    if (st != CSF_OK || x->io.paused) return st;
    return respond(x, key, cond, t, o, err);
}

/* ---- session ---------------------------------------------------------------------------------- */

typedef struct {
    csf_study *study;
    csf_store *store;
    csf_display_profile *profile;
    csf_presenter *pres;
    csf_responder *resp;
    csf_observer_sim *sim;
    csf_study_trial *plan;
    csf_trial *stored;
    void **proc;                /* per condition: adaptive procedure state */
    const csf_procedure_ops **ops;
    csf_image **img_a, **img_b;
    double *dev_a, *dev_b;
    double *pair_r;
    csf_study_identity identity; /* the files as they are now, images' bytes kept to be stored */
    int participant_index;       /* the session's (new: counted from the version's sessions) */
} run_res;

static void run_res_free(run_res *R)
{
    int n = R->study ? R->study->n_conds : 0;
    for (int i = 0; i < n; i++) {
        if (R->proc && R->proc[i]) R->ops[i]->destroy(R->proc[i]);
        if (R->img_a) csf_image_free(R->img_a[i]);
        if (R->img_b) csf_image_free(R->img_b[i]);
    }
    free(R->proc);
    free(R->ops);
    free(R->img_a);
    free(R->img_b);
    free(R->pair_r);
    free(R->dev_a);
    free(R->dev_b);
    free(R->plan);
    free(R->stored);
    csf_responder_close(R->resp);
    csf_observer_sim_free(R->sim);
    csf_presenter_close(R->pres);
    csf_profile_free(R->profile);
    csf_store_close(R->store);
    csf_study_free(R->study);
    csf_study_identity_free(&R->identity);
}

static csf_status load_images(run_res *R, study_ctx *x, csf_error *err)
{
    const csf_study *s = R->study;
    /* arrays of pointers to images, one per condition */
    R->img_a = calloc((size_t)s->n_conds, sizeof *R->img_a); // NOLINT(bugprone-sizeof-expression)
    R->img_b = calloc((size_t)s->n_conds, sizeof *R->img_b); // NOLINT(bugprone-sizeof-expression)
    R->pair_r = calloc((size_t)s->n_conds, sizeof *R->pair_r);
    R->dev_a = calloc((size_t)s->n_conds, sizeof *R->dev_a);
    R->dev_b = calloc((size_t)s->n_conds, sizeof *R->dev_b);
    if (!R->img_a || !R->img_b || !R->pair_r || !R->dev_a || !R->dev_b) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int i = 0; i < s->n_conds; i++) {
        const csf_study_condition *c = &s->conds[i];
        if (c->kind != CSF_COND_IMAGE) continue;
        csf_error e;
        if (csf_image_load_png(c->image_a, &R->img_a[i], &e) != CSF_OK ||
            csf_image_load_png(c->image_b, &R->img_b[i], &e) != CSF_OK)
            return csf_error_set(err, CSF_E_NOT_FOUND, "%s:%d (%s): %s", s->conditions_path, c->line,
                                 c->label, e.msg);
        if (R->sim) {
            csf_image_pair_eval ev;
            /* a moving image is judged as moving: with fixation held, its retinal speed is its own */
            if (csf_image_pair_evaluate_v(R->sim, R->img_a[i]->lum, R->img_b[i]->lum, R->img_a[i]->width,
                                          R->img_a[i]->height, c->size_deg, c->ecc_deg, c->polar_deg,
                                          c->velocity_dps, &ev) != 0)
                return csf_error_set(err, CSF_E_NOMEM, "out of memory evaluating image pair %s", c->label);
            R->pair_r[i] = ev.r;
        }
        R->dev_a[i] = normalise_image(R->img_a[i]);
        R->dev_b[i] = normalise_image(R->img_b[i]);
    }
    x->dev_a = R->dev_a;
    x->dev_b = R->dev_b;
    x->img_a = R->img_a;
    x->img_b = R->img_b;
    x->pair_r = R->pair_r;
    return CSF_OK;
}

static csf_status make_procedures(run_res *R, uint64_t seed, double max_contrast, csf_cell *cells,
                                  csf_error *err)
{
    const csf_study *s = R->study;
    R->proc = calloc((size_t)s->n_conds, sizeof *R->proc);
    R->ops = calloc((size_t)s->n_conds, sizeof *R->ops); // NOLINT(bugprone-sizeof-expression): pointers
    if (!R->proc || !R->ops) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int i = 0; i < s->n_conds; i++) {
        const csf_study_condition *c = &s->conds[i];
        if (!c->adaptive) continue;
        R->ops[i] = csf_procedure_find(c->method);
        if (!R->ops[i])
            return csf_error_set(err, CSF_E_UNSUPPORTED, "%s:%d (%s): method %s is not in this build",
                                 s->conditions_path, c->line, c->label, c->method);
        cells[i] = (csf_cell){c->freq_cpd, c->ecc_deg, 0};
        csf_procedure_setup setup;
        memset(&setup, 0, sizeof setup);
        setup.cells = &cells[i];
        setup.n_cells = 1;
        setup.trial_budget = s->trials_per_condition;
        setup.seed = seed ^ (0x9e3779b97f4a7c15ULL * (uint64_t)(i + 1));
        setup.max_contrast = max_contrast;
        setup.min_contrast = 0.0005;
        setup.slope_beta = 3.5;
        setup.lapse = 0.02;
        setup.guess = 0.5;
        csf_status st = R->ops[i]->create(&setup, &R->proc[i], err);
        if (st != CSF_OK) return st;
    }
    return CSF_OK;
}

/* The level of a trial: the condition's fixed contrast, or the adaptive procedure's next one. */
static double trial_level(run_res *R, const csf_study_trial *t, double max_contrast, csf_trial_plan *plan)
{
    const csf_study_condition *c = &R->study->conds[t->cond];
    memset(plan, 0, sizeof *plan);
    double level = c->contrast;
    if (t->practice) {
        double base = c->adaptive ? max_contrast : 4 * c->contrast;
        level = fmin(max_contrast, fmax(base, PRACTICE_MIN_CONTRAST));
        if (c->kind == CSF_COND_IMAGE) level = 1;
        return level;
    }
    if (c->adaptive) {
        if (R->ops[t->cond]->next(R->proc[t->cond], t->cond_trial, plan) == CSF_OK) level = plan->contrast;
        else level = max_contrast; /* the procedure finished early: keep asking at the ceiling */
        plan->contrast = level;
        plan->signal_interval = t->target;
        plan->n_alternatives = 2;
        plan->task = CSF_TASK_2AFC;
    }
    if (c->kind != CSF_COND_IMAGE && level > max_contrast) level = max_contrast;
    return csf_round9(level);
}

static void fill_trial(csf_trial *tr, const run_res *R, int64_t sid, int seq, const csf_study_trial *t,
                       double level, const study_outcome *o)
{
    const csf_study *s = R->study;
    const csf_study_condition *c = &s->conds[t->cond];
    memset(tr, 0, sizeof *tr);
    tr->session_id = sid;
    tr->seq = seq;
    snprintf(tr->method, sizeof tr->method, "%s", csf_study_design_name(s->design));
    double polar[2];
    csf_study_places(s, c, polar);
    tr->freq_cpd = c->kind == CSF_COND_IMAGE ? 0 : c->freq_cpd;
    tr->ecc_deg = c->ecc_deg;
    tr->polar_deg = csf_round9(s->design == CSF_DESIGN_2AFC ? polar[t->target] : polar[0]);
    tr->orientation_deg = c->orientation_deg;
    tr->sigma_deg = c->kind == CSF_COND_GABOR ? c->sigma_deg : 0;
    tr->velocity_dps = c->velocity_dps;
    tr->mean_lum_cdm2 = c->mean_lum_cdm2;
    tr->is_practice = t->practice;
    int forced = s->design == CSF_DESIGN_2AFC || s->design == CSF_DESIGN_2IFC;
    tr->is_catch = !forced && !t->target;
    tr->contrast_requested = level;
    tr->contrast_shown_mean = o->shown_target;
    tr->contrast_shown_max = o->shown_max;
    tr->frames_planned = o->frames_planned;
    tr->frames_shown = o->frames_shown;
    tr->frames_missed = o->frames_missed;
    tr->signal_interval = forced ? t->target + 1 : 0;
    tr->n_alternatives = forced ? 2 : 0;
    tr->response = !o->valid ? 0 : forced ? o->choice + 1 : o->choice;
    tr->rt_s = o->rt_s;
    tr->click_x_deg = tr->click_y_deg = NAN;
    tr->valid = o->valid;
    snprintf(tr->flags, sizeof tr->flags, "%s", o->flags);
    tr->has_onset = isfinite(o->onset_s);
    tr->onset_s = tr->has_onset ? o->onset_s : 0.0;
}

/* What an adaptive procedure saw, from a stored trial (replay and live use this one function). */
static csf_trial_outcome outcome_of(const csf_trial *t)
{
    csf_trial_outcome o;
    memset(&o, 0, sizeof o);
    o.response = t->response - 1;
    o.rt_s = t->rt_s;
    o.contrast_at_response = t->contrast_shown_mean;
    o.valid = t->valid;
    return o;
}

static void feedback(study_ctx *x, const csf_trial *t)
{
    const csf_study *s = x->study;
    int shown = s->feedback == CSF_FEEDBACK_ALL || (s->feedback == CSF_FEEDBACK_PRACTICE && t->is_practice);
    if (!shown || x->sim || !t->valid || s->feedback_s <= 0) return;
    int correct = t->signal_interval ? t->response == t->signal_interval : t->response == !t->is_catch;
    int n = (int)lround(s->feedback_s / x->period_s);
    csf_error e;
    for (int i = 0; i < n; i++)
        if (csf_presenter_text_screen(x->pres, correct ? "Correct" : "Wrong", &e) != CSF_OK) break;
}

/* A session whose participant or study files could not be stored: marked aborted, and the
 * message says so (its number stays unused; a report leaves it out). */
static void abort_unstarted(csf_store *store, int64_t sid, csf_error *err)
{
    csf_error e2;
    char m[sizeof err->msg];
    snprintf(m, sizeof m, "%s", err->msg);
    if (csf_store_set_session_state(store, sid, CSF_SESSION_ABORTED, &e2) == CSF_OK)
        csf_error_set(err, err->code, "%s; session %lld marked aborted", m, (long long)sid);
}

/* doc (taken) as compact JSON text, keys in order; malloc'd, NULL when doc is NULL (jansson
 * refuses text that is not UTF-8) or memory ran out. Settings are written only this way, so a
 * name with a quote or a control character can never make them invalid. */
static char *to_json(json_t *doc)
{
    char *text = doc ? json_dumps(doc, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(doc);
    return text;
}

static csf_status not_json(const csf_study *s, csf_error *err)
{
    return csf_error_set(err, CSF_E_INVALID_ARG, "study %s: its settings cannot be written as JSON "
                         "(names, codes and the observer must be UTF-8 text)", s->name);
}

/* Whether this version's sessions ran the files as they are now: refused, naming what changed
 * and how to go on, when one did not. A participant's own session is checked first (resume). */
static csf_status check_version(const run_res *R, const csf_study_run_options *opt, int version,
                                const csf_study_session *list, int n, const csf_study_session *mine,
                                csf_error *err)
{
    const csf_study *s = R->study;
    const csf_study_session *ref = mine;
    for (int i = 0; !ref && i < n; i++)
        if (list[i].version == version) ref = &list[i];
    if (!ref || !strcmp(ref->key, R->identity.sha256)) return CSF_OK;
    char what[1500];
    if (ref->legacy) {
        char fnv[32];
        snprintf(fnv, sizeof fnv, "%016llx", (unsigned long long)s->hash);
        /* recorded before image hashes: its two files' hash is all there is to compare */
        if (!strcmp(fnv, ref->key) && !mine) return CSF_OK;
        snprintf(what, sizeof what, "%s",
                 strcmp(fnv, ref->key) ? "the settings or conditions file changed"
                                       : "its images were not recorded");
    } else {
        csf_study_identity_diff(&ref->identity, &R->identity, what, sizeof what);
    }
    char shown[300];
    csf_store_printable(opt->participant, shown, sizeof shown);
    int next = csf_study_versions_max(list, n) + 1;
    if (mine)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "study %s version %d: participant %s's session %lld began "
                             "with other files: %s. Resume it with the files it began with; to run these "
                             "files, start a new version (--version %d) or give the study a new name",
                             s->name, version, shown, (long long)mine->id, what, next);
    return csf_error_set(err, CSF_E_INVALID_ARG,
                         "study %s version %d was run with other files (session %lld, "
                         "participant %s): %s. Its participants are not pooled with other files: to run "
                         "these, start a new version (--version %d) or give the study a new name",
                         s->name, version, (long long)ref->id, ref->participant, what, next);
}

/* A participant's index in a version: the number of its sessions begun before, aborted starts
 * (which ran no trial) not counted. */
static int participant_index(const csf_study_session *list, int n, int version)
{
    int k = 0;
    for (int i = 0; i < n; i++) k += list[i].version == version && list[i].state != CSF_SESSION_ABORTED;
    return k;
}

/* Metadata given again on resume must be what the session began with (it is kept once). */
static csf_status same_meta(const char *key, const char *given, const char *stored, int64_t sid,
                            csf_error *err)
{
    if (!given || !strcmp(given, stored)) return CSF_OK;
    if (!*stored)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--set %s: session %lld began without %s; a session "
                             "keeps the metadata it began with: resume without --set %s",
                             key, (long long)sid, key, key);
    return csf_error_set(err, CSF_E_INVALID_ARG,
                         "--set %s: session %lld began with %s = '%s'; a session "
                         "keeps the metadata it began with: resume without --set %s or with the same "
                         "value",
                         key, (long long)sid, key, stored, key);
}

/* The participant's session of this version (newest), or NULL. */
static const csf_study_session *find_mine(const csf_study_session *list, int n, const char *participant,
                                          int version)
{
    const csf_study_session *m = NULL;
    for (int i = 0; i < n; i++)
        if (list[i].version == version && !strcmp(list[i].participant, participant)) m = &list[i];
    return m;
}

static csf_status resume_session(run_res *R, const csf_study_run_options *opt, int version,
                                 const csf_study_session *mine, int64_t *sid, int *resumed,
                                 csf_study_run_result *res, csf_error *err)
{
    const csf_study *s = R->study;
    char shown[300];
    csf_store_printable(opt->participant, shown, sizeof shown);
    *sid = mine->id;
    if (mine->state == CSF_SESSION_FINISHED)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "study %s version %d: participant %s has already "
                             "finished it (session %lld); use another participant code",
                             s->name, version, shown, (long long)*sid);
    if (mine->state == CSF_SESSION_ABORTED)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "study %s version %d: participant %s's session %lld was "
                             "aborted; use another participant code",
                             s->name, version, shown, (long long)*sid);
    if (!csf_session_state_open(mine->state)) {
        char state[64];
        csf_store_printable(mine->state_text, state, sizeof state);
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "study %s version %d: participant %s's session %lld is in state "
                             "'%s', which this csfcal does not know (it resumes running or "
                             "paused sessions); use another participant code",
                             s->name, version, shown, (long long)*sid, state);
    }
    csf_status st = same_meta("experimenter", opt->experimenter, mine->experimenter, *sid, err);
    if (st == CSF_OK) st = same_meta("notes", opt->notes, mine->notes, *sid, err);
    if (st != CSF_OK) return st;
    R->participant_index = mine->participant_index;
    *resumed = 1;
    char sname[160];
    csf_study_store_name(s->name, version, sname, sizeof sname);
    csf_store_find_study(R->store, sname, &res->study_id, NULL);
    return csf_store_set_session_state(R->store, *sid, CSF_SESSION_RUNNING, err);
}

/* The study files and every image, stored with the session so the store alone holds what the
 * participant saw (an image's bytes under the name the conditions file gives it). */
static csf_status store_files(run_res *R, int64_t sid, csf_error *err)
{
    const csf_study *s = R->study;
    csf_status st = csf_store_add_artifact(R->store, sid, "study", s->path, s->settings_text,
                                           strlen(s->settings_text), err);
    if (st == CSF_OK)
        st = csf_store_add_artifact(R->store, sid, "conditions", s->conditions_path, s->conditions_text,
                                    strlen(s->conditions_text), err);
    if (st == CSF_OK && s->instructions_text)
        st = csf_store_add_artifact(R->store, sid, "instructions", s->instructions_file, s->instructions_text,
                                    strlen(s->instructions_text), err);
    for (int i = 0; st == CSF_OK && i < R->identity.n_images; i++) {
        const csf_study_image *im = &R->identity.images[i];
        st = csf_store_add_artifact(R->store, sid, "image", im->name, im->bytes, im->len, err);
    }
    return st;
}

/* The settings a new session starts with: who, which files (their identity) and version. */
static char *session_json(const run_res *R, const csf_study_run_options *opt, const char *observer,
                          uint64_t seed, int version)
{
    const csf_study *s = R->study;
    char fnv[32];
    snprintf(fnv, sizeof fnv, "%016llx", (unsigned long long)s->hash);
    /* Seeds are below 2^53 (csf_study_participant_seed; a study file's seed): JSON integers. */
    json_t *j = json_pack("{s:s,s:s,s:i,s:s,s:s,s:s,s:s,s:I,s:I,s:i,s:o}", "study", s->name, "participant",
                          opt->participant, "version", version, "sha256", R->identity.sha256, "hash", fnv,
                          "design", csf_study_design_name(s->design), "observer", observer, "study_seed",
                          (json_int_t)s->seed, "seed", (json_int_t)seed, "n_conditions", s->n_conds,
                          "identity", csf_study_identity_to_json(&R->identity));
    /* the plan is rebuilt from the participant's index: it is kept with the seed */
    if (j) json_object_set_new(j, "participant_index", json_integer(R->participant_index));
    if (j && s->latin != CSF_LATIN_NONE)
        json_object_set_new(j, "counterbalance_row",
                            json_integer(csf_study_latin_row(s, R->participant_index, NULL)));
    if (j && opt->experimenter) json_object_set_new(j, "experimenter", json_string(opt->experimenter));
    if (j && opt->notes) json_object_set_new(j, "notes", json_string(opt->notes));
    return to_json(j);
}

csf_status csf_study_check_meta(const char *key, const char *value, csf_error *err)
{
    char what[64];
    snprintf(what, sizeof what, "--set %s", key);
    if (strlen(value) >= CSF_STUDY_META_MAX)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--set %s: %zu bytes; at most %d", key, strlen(value),
                             CSF_STUDY_META_MAX - 1);
    if (!*value) return csf_error_set(err, CSF_E_INVALID_ARG, "--set %s: empty (leave it out instead)", key);
    return csf_store_check_text(value, what, err);
}

static csf_status open_session(run_res *R, const csf_study_run_options *opt, const char *observer,
                               uint64_t seed, int64_t *sid, int *resumed, csf_study_run_result *res,
                               csf_error *err)
{
    const csf_study *s = R->study;
    int version = opt->version > 0 ? opt->version : 1;
    csf_study_session *list = NULL;
    int n = 0;
    csf_status st = csf_study_sessions_list(R->store, s->name, &list, &n, err);
    const csf_study_session *mine = st == CSF_OK ? find_mine(list, n, opt->participant, version) : NULL;
    if (st == CSF_OK) st = check_version(R, opt, version, list, n, mine, err);
    if (st == CSF_OK && mine) st = resume_session(R, opt, version, mine, sid, resumed, res, err);
    if (st == CSF_OK && !mine) R->participant_index = participant_index(list, n, version);
    csf_study_sessions_free(list, n);
    if (st != CSF_OK || *resumed) return st;
    char sname[160];
    csf_study_store_name(s->name, version, sname, sizeof sname);
    if (csf_store_find_study(R->store, sname, &res->study_id, NULL) != CSF_OK) {
        char *design = to_json(json_pack("{s:s,s:s,s:i}", "design", csf_study_design_name(s->design),
                                         "sha256", R->identity.sha256, "version", version));
        st = design ? csf_store_create_study(R->store, sname, design, &res->study_id, err) : not_json(s, err);
        free(design);
        if (st != CSF_OK) return st;
    }
    char *json = session_json(R, opt, observer, seed, version);
    st = json ? csf_store_begin_session_profile(R->store, CSF_SESSION_STUDY, opt->participant,
                                                csf_profile_display(R->profile), csf_profile_id(R->profile),
                                                json, seed, sid, err)
              : not_json(s, err);
    free(json);
    if (st != CSF_OK) return st;
    /* The session comes first: on a server a station may add a participant only to a study
     * session of its own that has none yet (docs/store_roles.sql), so a code cannot be taken
     * without a session. find_mine above refuses a code another session of this version has; a
     * code taken any other way is refused here, and the session just begun is closed as aborted
     * so the lab never sees a running session without its participant and study files. */
    st = csf_store_add_participant(R->store, res->study_id, opt->participant, &res->participant_id, err);
    if (st == CSF_OK) st = csf_store_link_session_participant(R->store, *sid, res->participant_id, err);
    if (st == CSF_OK) st = store_files(R, *sid, err);
    if (st != CSF_OK) abort_unstarted(R->store, *sid, err);
    return st;
}

/* Where the session's clock stands when a run begins: the person time of its earlier runs, or,
 * after a run that was killed before it could add its time, the end of the last stored trial
 * (its onset, presentation and answer time: a lower bound, the rest of that run is lost). */
static double clock_base(run_res *R, int64_t sid, size_t n_stored)
{
    const csf_study *s = R->study;
    int two = s->design == CSF_DESIGN_2IFC || s->design == CSF_DESIGN_SAME_DIFF;
    double shown_s = two ? 2 * s->stimulus_s + s->isi_s : s->stimulus_s;
    double base = 0;
    csf_session_info info;
    memset(&info, 0, sizeof info);
    csf_error e;
    if (csf_store_get_session(R->store, sid, &info, &e) == CSF_OK && isfinite(info.person_s))
        base = info.person_s;
    csf_session_info_free(&info);
    for (size_t i = 0; i < n_stored; i++)
        if (R->stored[i].has_onset)
            base = fmax(base, R->stored[i].onset_s + shown_s +
                                  (isfinite(R->stored[i].rt_s) ? R->stored[i].rt_s : 0.0));
    return base;
}

/* Test aid (documented in docs/studies.md): CSFCAL_TEST_KILL_AFTER=N kills the process with
 * SIGKILL right after the N-th trial of this run is stored, as a crash would. */
static long kill_after(void)
{
    const char *v = getenv("CSFCAL_TEST_KILL_AFTER");
    return v && *v ? strtol(v, NULL, 10) : 0;
}

static csf_status run_trials(run_res *R, study_ctx *x, int64_t sid, int n_plan, size_t n_stored,
                             double max_contrast, csf_study_run_result *res, csf_error *err)
{
    const csf_study *s = R->study;
    long die = kill_after();
    for (int seq = (int)n_stored; seq < n_plan; seq++) {
        const csf_study_trial *t = &R->plan[seq];
        if (seq > 0 && t->block > 0 && t->block != R->plan[seq - 1].block && !x->sim) {
            char msg[400];
            snprintf(msg, sizeof msg, "%s\n(block %d of %d done)", s->break_text, t->block, s->blocks);
            csf_status st = csf_trial_io_screen(&x->io, msg, err);
            if (st != CSF_OK) return st;
        }
        if (x->io.paused || stop_requested) return CSF_E_ABORTED;
        csf_trial_plan plan;
        double level = trial_level(R, t, max_contrast, &plan);
        study_outcome o;
        uint64_t key = (t->practice ? CSF_SIM_PRACTICE_INDEX : 0) + (uint64_t)seq;
        csf_status st = run_one(x, key, t, level, &o, err);
        if (st != CSF_OK || x->io.paused) {
            if (o.have_rec) csf_trial_record_free(&o.rec);
            return st != CSF_OK ? st : CSF_E_ABORTED;
        }
        csf_trial tr;
        fill_trial(&tr, R, sid, seq, t, level, &o);
        st = csf_trial_io_store(R->store, &tr, &o.rec, o.have_rec, err);
        if (st != CSF_OK) return st;
        res->n_stored++;
        res->n_run_now++;
        if (die > 0 && res->n_run_now >= die) raise(SIGKILL);
        if (!t->practice && s->conds[t->cond].adaptive) {
            csf_trial_outcome oc = outcome_of(&tr);
            R->ops[t->cond]->update(R->proc[t->cond], t->cond_trial, &plan, &oc);
        }
        feedback(x, &tr);
    }
    return CSF_OK;
}

static csf_status open_display(run_res *R, const csf_study_run_options *opt, int is_sim, uint64_t seed,
                               csf_error *err)
{
    const csf_config *cfg = opt->cfg;
    csf_geometry geom;
    csf_status st = csf_geometry_init(&geom, CSF_GEOMETRY_FROM_CONFIG(*cfg), err);
    if (st != CSF_OK) return st;
    if (cfg->display_profile[0]) st = csf_profile_load(cfg->display_profile, &R->profile, err);
    else if (!(R->profile = csf_profile_default())) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    else if (!opt->quiet)
        /* contrast on the screen is only as right as the luminance model: say when it is a guess */
        fprintf(stderr, "csfcal: study run: no --profile given: using the default display model (%s); "
                        "the contrasts shown are only as good as this guess\n", csf_profile_id(R->profile));
    if (st != CSF_OK) return st;
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    pc.headless = is_sim;
    pc.geometry = geom;
    pc.refresh_hz = cfg->refresh_hz;
    pc.profile = R->profile;
    pc.framebuffer_bits = cfg->framebuffer_bits;
    pc.monitor = cfg->monitor[0] ? cfg->monitor : NULL;
    pc.seed = seed;
    if (is_sim) {
        /* bookkeeping only: the presenter still validates, times and records every frame */
        pc.render_width_px = 64;
        pc.render_height_px = 36;
        pc.render_every = -1;
    }
    st = csf_presenter_open(&pc, &R->pres, err);
    if (st == CSF_OK && !is_sim)
        st = csf_responder_open(cfg->responder[0] ? cfg->responder : "keyboard", csf_presenter_window(R->pres),
                                &R->resp, err);
    return st;
}

/* The participant code and the observer (sim or human, and whether it can run here), before
 * anything is loaded. */
static csf_status check_run_options(const csf_study_run_options *opt, const char **observer_out,
                                    int *is_sim_out, csf_error *err)
{
    if (!opt->participant || !csf_study_participant_ok(opt->participant)) {
        char shown[300]; /* the code as typed, escaped: it may hold terminal controls */
        csf_store_printable(opt->participant, shown, sizeof shown);
        return csf_error_set(err, CSF_E_INVALID_ARG, "--participant '%s': a letter or digit, then up to 62 "
                             "letters, digits, '_', '-' or '.' (no '..'): a pseudonymous code, not a name",
                             shown);
    }
    const char *observer = opt->observer_spec ? opt->observer_spec
                         : opt->cfg->observer[0] ? opt->cfg->observer : "sim";
    int is_sim = !strncmp(observer, "sim", 3) && (observer[3] == '\0' || observer[3] == ':');
    *observer_out = observer;
    *is_sim_out = is_sim;
    if (!is_sim && strcmp(observer, "human"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer %s: expected sim[:key=value,...] or human", observer);
    if (strpbrk(observer, "\"\\") || strpbrk(opt->study_path, "\"\\"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer and the study path may not hold quotes or "
                             "backslashes");
    if (!is_sim && opt->headless)
        return csf_error_set(err, CSF_E_UNSUPPORTED, "--observer human needs a display: no window can be "
                             "opened headless (use --observer sim)");
    csf_status st = opt->experimenter ? csf_study_check_meta("experimenter", opt->experimenter, err) : CSF_OK;
    if (st == CSF_OK && opt->notes) st = csf_study_check_meta("notes", opt->notes, err);
    return st;
}

/* Adaptive procedures: the stored answers replayed into them, so each goes on where it stopped. */
static void replay_stored(run_res *R, size_t n_stored, double max_contrast)
{
    const csf_study *s = R->study;
    for (size_t i = 0; i < n_stored; i++) {
        const csf_study_trial *t = &R->plan[i];
        if (t->practice || !s->conds[t->cond].adaptive) continue;
        csf_trial_plan plan;
        trial_level(R, t, max_contrast, &plan);
        csf_trial_outcome oc = outcome_of(&R->stored[i]);
        R->ops[t->cond]->update(R->proc[t->cond], t->cond_trial, &plan, &oc);
    }
}

/* Silent reading of instructions: 238 words a minute (Brysbaert 2019, non-fiction), varied
 * between people by a factor of about 1.3 (log-normal, keyed by the participant's seed). */
#define READING_WPM 238.0
#define READING_LOG_SD 0.25

static double reading_time_s(const char *text, uint64_t seed)
{
    int words = 0;
    for (const char *p = text; *p; p++)
        words += (p == text || p[-1] == ' ' || p[-1] == '\n') && *p != ' ' && *p != '\n';
    double wpm = READING_WPM * exp(READING_LOG_SD * csf_rng_normal(seed, 0x1257, 0));
    return 60.0 * words / wpm;
}

/* The instruction screen before practice: the study's instructions (settings text, then the
 * instructions file), or a default line. A person reads and presses a key; a simulated one
 * spends its reading time, counted as person time. */
static csf_status instructions(study_ctx *x, csf_error *err)
{
    const csf_study *s = x->study;
    if (!s->instructions[0] && !s->instructions_text) {
        if (x->sim) return CSF_OK;
        return csf_trial_io_screen(&x->io,
                                   "Fixate the central mark. After each trial answer with the keys for "
                                   "first/left or second/right.\nPress any key to begin.",
                                   err);
    }
    size_t cap = strlen(s->instructions) + (s->instructions_text ? strlen(s->instructions_text) : 0) + 64;
    char *text = malloc(cap);
    if (!text) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    snprintf(text, cap, "%s%s%s\nPress Space to begin.", s->instructions,
             s->instructions[0] && s->instructions_text ? "\n\n" : "",
             s->instructions_text ? s->instructions_text : "");
    csf_status st = CSF_OK;
    if (x->sim) x->sim_answer_s += reading_time_s(text, x->sim_seed);
    else st = csf_trial_io_screen(&x->io, text, err);
    free(text);
    return st;
}

/* The trials, with SIGINT and SIGTERM asking for a pause between them (their handlers as
 * before once the trials stop); a new human session starts with the instructions. */
static csf_status run_with_signals(run_res *R, study_ctx *x, int64_t sid, int n_plan, size_t n_stored,
                                   double max_contrast, csf_study_run_result *res, csf_error *err)
{
    csf_status st = CSF_OK;
    struct sigaction sa, old_int, old_term;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    stop_requested = 0;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    if (!res->resumed) st = instructions(x, err);
    if (st == CSF_OK) st = run_trials(R, x, sid, n_plan, n_stored, max_contrast, res, err);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    return st;
}

/* The session's state in the store once the trials stop: finished, or paused to be continued. */
static csf_status end_session(run_res *R, int64_t sid, int n_plan, csf_status st, csf_study_run_result *res,
                              csf_error *err)
{
    const csf_study *s = R->study;
    csf_error e2;
    if (st == CSF_OK) {
        res->finished = 1;
        st = csf_store_set_session_state(R->store, sid, CSF_SESSION_FINISHED, err);
    } else if (st == CSF_E_ABORTED) {
        csf_store_set_session_state(R->store, sid, CSF_SESSION_PAUSED, &e2);
        csf_error_set(err, CSF_E_ABORTED,
                      "study %s: paused after %d of %d trials (all stored); run the same "
                      "command again to continue",
                      s->name, res->n_stored, n_plan);
    } else {
        csf_store_set_session_state(R->store, sid, CSF_SESSION_PAUSED, &e2);
    }
    return st;
}

csf_status csf_study_run(const csf_study_run_options *opt, csf_study_run_result *res, csf_error *err)
{
    memset(res, 0, sizeof *res);
    run_res R;
    memset(&R, 0, sizeof R);
    const char *observer = NULL;
    int is_sim = 0;
    csf_status st = check_run_options(opt, &observer, &is_sim, err);
    if (st != CSF_OK) return st;
    st = csf_study_load(opt->study_path, &R.study, err);
    if (st != CSF_OK) return st;
    const csf_study *s = R.study;
    uint64_t seed = csf_study_participant_seed(s, opt->participant);
    res->seed = seed;
    res->hash = s->hash;
    res->version = opt->version > 0 ? opt->version : 1;
    if ((st = csf_study_identity_compute(s, 1, &R.identity, err)) != CSF_OK) goto out;
    memcpy(res->sha256, R.identity.sha256, sizeof res->sha256);
    if (is_sim && (st = csf_observer_sim_create(observer, seed, &R.sim, err)) != CSF_OK) goto out;
    if ((st = open_display(&R, opt, is_sim, seed, err)) != CSF_OK) goto out;
    if ((st = csf_study_check_display(s, R.pres, err)) != CSF_OK) goto out;
    int n_plan;
    /* the plan of the first row, to refuse an impossible one before anything is stored; the
     * participant's own row is planned once the session tells its index */
    if ((st = csf_study_make_plan(s, seed, 0, &R.plan, &n_plan, err)) != CSF_OK) goto out;
    res->n_planned = n_plan;
    double lb, lm;
    csf_presenter_lum_range(R.pres, &lb, &lm);
    double max_contrast = fmin(s->adaptive_max_contrast, floor(0.98 * (lm - lb) / (lm + lb) * 1000) / 1000);

    study_ctx x;
    memset(&x, 0, sizeof x);
    x.study = s;
    x.pres = R.pres;
    x.io = (csf_trial_io){R.pres, R.resp, &stop_requested, 0};
    x.sim = R.sim;
    x.sim_seed = seed;
    x.max_contrast = max_contrast;
    x.period_s = 1.0 / csf_presenter_refresh_hz(R.pres);
    if ((st = load_images(&R, &x, err)) != CSF_OK) goto out;
    csf_cell cells[CSF_STUDY_MAX_CONDITIONS];
    if ((st = make_procedures(&R, seed, max_contrast, cells, err)) != CSF_OK) goto out;

    /* everything is checked: only now is the store written */
    if ((st = csf_store_open(opt->store_path, &R.store, err)) != CSF_OK) goto out;
    int64_t sid = 0;
    if ((st = open_session(&R, opt, observer, seed, &sid, &res->resumed, res, err)) != CSF_OK) goto out;
    res->session_id = sid;
    res->participant_index = R.participant_index;
    res->latin_row = csf_study_latin_row(s, R.participant_index, NULL);
    free(R.plan);
    R.plan = NULL;
    if ((st = csf_study_make_plan(s, seed, R.participant_index, &R.plan, &n_plan, err)) != CSF_OK) goto out;
    size_t n_stored = 0;
    if ((st = csf_store_get_trials(R.store, sid, &R.stored, &n_stored, err)) != CSF_OK) goto out;
    if (n_stored > (size_t)n_plan) {
        st = csf_error_set(err, CSF_E_INVALID_ARG, "session %lld holds %zu trials, the study plans %d",
                           (long long)sid, n_stored, n_plan);
        goto out;
    }
    replay_stored(&R, n_stored, max_contrast);
    res->n_stored = (int)n_stored;
    if (!opt->quiet)
        fprintf(stderr, "csfcal: study %s: participant %s, session %lld, %s%d of %d trials stored\n", s->name,
                opt->participant, (long long)sid, res->resumed ? "resuming: " : "", (int)n_stored, n_plan);
    /* The participant's time in this run, on the session's clock (the presenter's: virtual
     * when simulated, plus the simulated answers), instructions and pauses included; added to
     * the session's before it ends. */
    double t0_s = csf_presenter_time(R.pres);
    x.t0_s = t0_s;
    x.clock_base_s = clock_base(&R, sid, n_stored);
    st = run_with_signals(&R, &x, sid, n_plan, n_stored, max_contrast, res, err);
    double person_s = csf_presenter_time(R.pres) - t0_s + x.sim_answer_s;
    csf_error pe;
    if (csf_store_add_person_time(R.store, sid, fmax(0.0, person_s), &pe) != CSF_OK && st == CSF_OK)
        st = csf_error_set(err, pe.code, "%s", pe.msg);
    st = end_session(&R, sid, n_plan, st, res, err);
out:
    run_res_free(&R);
    return st;
}
