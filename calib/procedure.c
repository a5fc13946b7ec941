/* Registry of the adaptive procedures behind calib/procedure.h. */
#include "calib/procedure.h"

#include <math.h>
#include <string.h>

/* A strong reference (declared in procedure.h): a weak one does not pull method_bayes.o out of
 * the static calib library, which left `--method bayes` (the default) missing from csfcal. */

const csf_procedure_ops *csf_procedure_find(const char *name)
{
    if (!name) return NULL;
    if (strcmp(name, "fade") == 0) return &csf_procedure_fade;
    if (strcmp(name, "2afc") == 0) return &csf_procedure_2afc;
    if (strcmp(name, "bayes") == 0) {
        const csf_procedure_ops *b = &csf_procedure_bayes;
        return (b && b->create) ? b : NULL;
    }
    return NULL;
}

static double reach_log10(const char *name)
{
    if (name && strcmp(name, "bayes") == 0) return 0.27;
    if (name && strcmp(name, "2afc") == 0) return 0.45;
    return 0.32;
}

int csf_precision_planned_trials(const char *name, int n_shown, double precision_log10, int cap)
{
    if (n_shown <= 0 || !(precision_log10 > 0)) return cap;
    double need = ceil(n_shown * pow(reach_log10(name) / precision_log10, 2.0));
    return need < cap ? (int)need : cap;
}

double csf_precision_expected_rms(const char *name, int n_shown, int trials)
{
    return n_shown > 0 && trials > 0 ? reach_log10(name) / sqrt((double)trials / n_shown) : INFINITY;
}
