/* An observer session's stored settings (sessions.settings) are read back on --resume from a
 * store that may come from another station, a backup or a damaged disk. The reader must refuse
 * anything out of range with -1 and never read out of bounds; what it accepts must be in range,
 * and writing it back and reading that again must give the same settings. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "calib/observer_settings.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int same(const csf_obs_settings *a, const csf_obs_settings *b)
{
    if (strcmp(a->method, b->method) || strcmp(a->observer, b->observer) || strcmp(a->profile_id, b->profile_id))
        return 0;
    if (a->trials != b->trials || a->practice != b->practice || a->break_every != b->break_every ||
        a->afc != b->afc || a->fade_anchors != b->fade_anchors || a->n_freqs != b->n_freqs || a->n_eccs != b->n_eccs)
        return 0;
    for (int i = 0; i < a->n_freqs; i++)
        if (a->freqs[i] != b->freqs[i]) return 0;
    for (int i = 0; i < a->n_eccs; i++)
        if (a->eccs[i] != b->eccs[i]) return 0;
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    csf_obs_settings s, back;
    if (csf_obs_settings_from_json(text, &s) == 0) {
        if (s.afc != 2 && s.afc != 4) abort();
        if (!(s.fade_anchors >= 0 && s.fade_anchors <= 0.5)) abort();
        if (s.n_freqs < 0 || s.n_freqs > CSF_OBS_MAX_AXIS || s.n_eccs < 0 || s.n_eccs > CSF_OBS_MAX_AXIS) abort();
        if (memchr(s.method, '\0', sizeof s.method) == NULL || memchr(s.observer, '\0', sizeof s.observer) == NULL)
            abort();
        for (int i = 0; i < s.n_freqs; i++)
            if (!isfinite(s.freqs[i])) abort();
        char json[8192];
        if (csf_obs_settings_to_json(&s, 1.0, json, sizeof json) != 0) abort();
        if (csf_obs_settings_from_json(json, &back) != 0 || !same(&s, &back)) abort();
    }
    free(text);
    return 0;
}
