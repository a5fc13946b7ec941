/* Registry of the adaptive procedures behind calib/procedure.h. */
#include "calib/procedure.h"

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
