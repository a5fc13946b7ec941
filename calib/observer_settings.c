#include "calib/observer_settings.h"

#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "core/json_read.h"

int csf_obs_settings_to_json(const csf_obs_settings *s, double sigma_deg, char *buf, size_t len)
{
    json_t *freqs = json_array(), *eccs = json_array();
    for (int i = 0; i < s->n_freqs; i++) json_array_append_new(freqs, json_real(s->freqs[i]));
    for (int i = 0; i < s->n_eccs; i++) json_array_append_new(eccs, json_real(s->eccs[i]));
    /* The anchor share means something to fade sessions only; a report of another session would
     * show it as if it had been used. */
    json_t *share = strcmp(s->method, "fade") == 0 ? json_real(s->fade_anchors) : NULL;
    json_t *o = json_pack("{s:s,s:s,s:i,s:i,s:i,s:i,s:o*,s:f,s:o,s:o,s:s}", "method", s->method, "observer",
                          s->observer, "trials", s->trials, "practice", s->practice, "break_every",
                          s->break_every, "afc", s->afc, "fade_anchors", share, "gabor_sigma_deg", sigma_deg,
                          "freqs_cpd", freqs, "eccs_deg", eccs, "profile_id", s->profile_id);
    /* Static sessions store what they always stored, so their records read as before. */
    if (o && s->n_vels > 0) {
        json_t *vels = json_array();
        for (int i = 0; i < s->n_vels; i++) json_array_append_new(vels, json_real(s->vels[i]));
        json_object_set_new(o, "vels_dps", vels);
        json_object_set_new(o, "drift_direction", json_integer(s->drift_direction));
    }
    if (o && s->precision > 0) json_object_set_new(o, "precision_log10", json_real(s->precision));
    char *text = o ? json_dumps(o, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17)) : NULL;
    json_decref(o);
    int rc = text && strlen(text) < len ? 0 : -1;
    if (rc == 0) memcpy(buf, text, strlen(text) + 1);
    else if (len) buf[0] = '\0';
    free(text);
    return rc;
}

/* A damaged store is refused at resume, never cast. */
int csf_obs_settings_from_json(const char *json, csf_obs_settings *s)
{
    memset(s, 0, sizeof *s);
    csf_json_doc *d;
    csf_error err;
    if (csf_json_parse_object(json, "stored observer settings", &d, &err) != CSF_OK) return -1;
    int ok = csf_json_get_string(d, "method", s->method, sizeof s->method, &err) == 1 &&
             csf_json_get_string(d, "observer", s->observer, sizeof s->observer, &err) == 1 &&
             csf_json_get_int(d, "trials", -1, 1000000, &s->trials, &err) == 1 &&
             csf_json_get_int(d, "practice", -1, 1000000, &s->practice, &err) == 1 &&
             csf_json_get_int(d, "break_every", -1, 1000000, &s->break_every, &err) == 1 &&
             csf_json_get_numbers(d, "freqs_cpd", s->freqs, CSF_OBS_MAX_AXIS, &s->n_freqs, &err) == 1 &&
             csf_json_get_numbers(d, "eccs_deg", s->eccs, CSF_OBS_MAX_AXIS, &s->n_eccs, &err) == 1;
    /* Sessions stored before four-place trials existed were two-interval throughout. */
    s->afc = 2;
    if (ok) ok = csf_json_get_int(d, "afc", 2, 4, &s->afc, &err) >= 0 && (s->afc == 2 || s->afc == 4);
    if (ok) ok = csf_json_get_string(d, "profile_id", s->profile_id, sizeof s->profile_id, &err) >= 0;
    /* Fade sessions stored before the anchors were pure yes/no sessions. */
    s->fade_anchors = 0;
    if (ok) ok = csf_json_get_number(d, "fade_anchors", 0, 0.5, &s->fade_anchors, &err) >= 0;
    /* No anchors outside fade sessions; a fade session's anchors are two-interval (those stored
     * before that was written down kept the --afc they were given and ignored). */
    if (strcmp(s->method, "fade") != 0) s->fade_anchors = 0;
    /* Sessions without a velocity axis stored neither key: static gratings. */
    if (ok) ok = csf_json_get_numbers(d, "vels_dps", s->vels, CSF_OBS_MAX_AXIS, &s->n_vels, &err) >= 0;
    if (ok) ok = csf_json_get_int(d, "drift_direction", -1, 1, &s->drift_direction, &err) >= 0;
    /* Sessions without it ran a fixed budget. */
    if (ok) ok = csf_json_get_number(d, "precision_log10", 0.001, 2.0, &s->precision, &err) >= 0;
    else s->afc = 2;
    csf_json_free(d);
    return ok ? 0 : -1;
}
