/* The resources of an observer session (see observer_resources.h), and a whole session from the
 * options: the steps the command takes, for callers that want no say in them. */
#include "calib/observer_resources.h"

#include <stdio.h>
#include <string.h>

#include "calib/observer_trials.h"

/* The display profile: the configured one, or the default model with a word that it is a guess. */
static csf_status open_profile(const csf_obs_options *opt, csf_obs_resources *r, csf_error *err)
{
    if (opt->cfg->display_profile[0]) return csf_profile_load(opt->cfg->display_profile, &r->profile, err);
    r->profile = csf_profile_default();
    if (!r->profile) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    if (!opt->quiet && !opt->resume_id)
        fprintf(stderr,
                "csfcal: observer: no --profile given: using the default display model "
                "(%s); thresholds are only as good as this guess\n",
                csf_profile_id(r->profile));
    return CSF_OK;
}

/* The presenter: a window for a human; for a simulated person a small offscreen frame on the
 * virtual clock (or none with view=frame, whose person rasterises what it looks at itself). */
static csf_status open_presenter(const csf_obs_options *opt, const csf_obs_session *s, csf_obs_resources *r,
                                 csf_error *err)
{
    uint64_t seed;
    int is_sim;
    csf_obs_session_settings(s, &seed, &is_sim);
    const csf_config *cfg = opt->cfg;
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    pc.headless = is_sim ? 1 : 0;
    pc.geometry = *csf_obs_session_geometry(s);
    pc.refresh_hz = cfg->refresh_hz;
    pc.profile = r->profile;
    pc.framebuffer_bits = cfg->framebuffer_bits;
    pc.monitor = cfg->monitor[0] ? cfg->monitor : NULL;
    pc.seed = seed;
    if (is_sim) {
        pc.render_width_px = opt->render_w > 0 ? opt->render_w : 64;
        pc.render_height_px = opt->render_h > 0 ? opt->render_h : 36;
        pc.render_every = opt->render_every ? opt->render_every : 1;
        /* view=frame: the person's regions are rasterised at full resolution on their own; the
         * small session frame has no one to look at it unless --render-every asks for it */
        if (!opt->render_every && csf_observer_sim_params_get(r->sim)->view_frame) pc.render_every = -1;
        pc.fault_polar_offset_deg = opt->fault_polar_offset_deg;
        pc.fault_blank = opt->fault_blank;
    }
    return csf_presenter_open(&pc, &r->pres, err);
}

/* view=frame: the simulated person's eyes on the presenter's frames. */
static csf_status open_eyes(const csf_obs_options *opt, const csf_obs_settings *set, csf_obs_resources *r,
                            csf_error *err)
{
    const csf_observer_sim_params *sp = csf_observer_sim_params_get(r->sim);
    if (!sp->view_frame) return CSF_OK;
    /* Every frame when gratings drift: sampling every k-th frame would alias their temporal
     * frequency above refresh / 2k for the person as it would for a camera. */
    int step = set->n_vels > 0 ? 1 : (int)sp->frame_step;
    csf_status st = csf_obs_screen_open(r->pres, r->profile, sp->display, sp->display_gamma, GABOR_SIGMA_DEG,
                                        0.0, step, &r->eyes, err);
    if (st != CSF_OK) return st;
    csf_obs_screen_set_person(r->eyes, r->sim);
    if (!opt->quiet)
        fprintf(stderr,
                "csfcal: observer: the simulated person looks at the rendered frames through "
                "the display %s\n",
                csf_obs_screen_display(r->eyes));
    return CSF_OK;
}

csf_status csf_obs_resources_open(const csf_obs_options *opt, const csf_obs_session *s, csf_obs_resources *r,
                                  csf_error *err)
{
    uint64_t seed;
    int is_sim;
    const csf_obs_settings *set = csf_obs_session_settings(s, &seed, &is_sim);
    csf_status st = is_sim ? csf_observer_sim_create(set->observer, seed, &r->sim, err) : CSF_OK;
    if (st == CSF_OK) st = open_profile(opt, r, err);
    if (st == CSF_OK) st = open_presenter(opt, s, r, err);
    if (st == CSF_OK && is_sim) st = open_eyes(opt, set, r, err);
    if (st == CSF_OK && !is_sim) {
        const char *spec = opt->cfg->responder[0] ? opt->cfg->responder : "keyboard";
        st = csf_responder_open(spec, csf_presenter_window(r->pres), &r->resp, err);
    }
    return st;
}

void csf_obs_resources_close(csf_obs_resources *r)
{
    csf_responder_close(r->resp);
    csf_observer_sim_free(r->sim);
    csf_obs_screen_close(r->eyes);
    csf_presenter_close(r->pres);
    csf_profile_free(r->profile);
    csf_store_close(r->store);
    memset(r, 0, sizeof *r);
}

csf_status csf_observer_calibrate(const csf_obs_options *opt, csf_obs_result *res, csf_error *err)
{
    csf_obs_resources r;
    memset(&r, 0, sizeof r);
    csf_obs_session *s = NULL;
    /* A resumed session's settings are in the store; a new session opens it only once every check
     * has passed, so that nothing is written for a refused one. */
    csf_status st = opt->resume_id && !opt->demo ? csf_store_open(opt->store_path, &r.store, err) : CSF_OK;
    if (st == CSF_OK) st = csf_obs_session_begin(opt, r.store, res, &s, err);
    if (st == CSF_OK) st = csf_obs_resources_open(opt, s, &r, err);
    if (st == CSF_OK) st = csf_obs_session_check(s, &r, err);
    if (st == CSF_OK && opt->demo) st = csf_obs_session_demo(s, err);
    else if (st == CSF_OK) {
        if (!r.store) st = csf_store_open(opt->store_path, &r.store, err);
        if (st == CSF_OK) st = csf_obs_session_run(s, r.store, err);
    }
    csf_obs_session_free(s);
    csf_obs_resources_close(&r);
    return st;
}
