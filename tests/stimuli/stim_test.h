/* Shared helpers for the stimulus tests: a simulated display (model/display_model.h) as both
 * the presenter's luminance model and the truth that turns read-back pixels into cd/m2. */
#ifndef CSF_TESTS_STIM_TEST_H
#define CSF_TESTS_STIM_TEST_H

#include <stdio.h>
#include <stdlib.h>

#include "model/display_model.h"
#include "stimuli/presenter.h"
#include "stimuli/selfcheck.h"

static inline double stim_test_model_lum(void *ctx, double r, double g, double b)
{
    return csf_display_model_lum((const csf_display_model *)ctx, r, g, b);
}

static inline double stim_test_model_grey(void *ctx, double d)
{
    return csf_display_model_lum((const csf_display_model *)ctx, d, d, d);
}

static inline csf_display_model *stim_test_model(const char *spec)
{
    csf_display_model *m = NULL;
    csf_error e;
    if (csf_display_model_create(spec, &m, &e) != CSF_OK) {
        fprintf(stderr, "display model '%s': %s\n", spec, e.msg);
        exit(1);
    }
    return m;
}

static inline csf_presenter *stim_test_open(csf_presenter_config *cfg)
{
    csf_presenter *p = NULL;
    csf_error e;
    if (csf_presenter_open(cfg, &p, &e) != CSF_OK) {
        fprintf(stderr, "presenter: %s\n", e.msg);
        exit(1);
    }
    return p;
}

#endif
