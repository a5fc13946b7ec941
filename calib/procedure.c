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

int csf_precision_planned_trials(const csf_procedure_ops *ops, int n_shown, double precision_log10, int cap)
{
    if (!ops || n_shown <= 0 || !(precision_log10 > 0)) return cap;
    double need = ceil(n_shown * pow(ops->reach_log10 / precision_log10, 2.0));
    return need < cap ? (int)need : cap;
}

double csf_precision_expected_rms(const csf_procedure_ops *ops, int n_shown, int trials)
{
    return ops && n_shown > 0 && trials > 0 ? ops->reach_log10 / sqrt((double)trials / n_shown) : INFINITY;
}
