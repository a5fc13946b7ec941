/* Study settings files (studies/study_file.h) are outside input: parsing must refuse garbage with
 * a message, never crash or read out of bounds. Accepted settings go on to a small conditions
 * table and a trial plan. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "studies/study_file.h"
#include "studies/study_plan.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_study s;
    memset(&s, 0, sizeof s);
    csf_error err;
    if (csf_study_parse_settings(&s, (const char *)data, size, "fuzz.conf", &err) != CSF_OK) return 0;
    /* grp: a column for blocked_by = grp */
    static const char csv[] = "label,freq_cpd,contrast,ecc_deg,grp\na,2,0.05,5,x\nb,4,0.05,5,y\n";
    if (s.trials_per_condition * 2 + s.practice_trials > 4000) return 0; /* keep the plan small */
    if (csf_study_parse_conditions(&s, csv, sizeof csv - 1, "fuzz.csv", "", &err) == CSF_OK) {
        csf_study_trial *t = NULL;
        int n = 0;
        if (csf_study_make_plan(&s, 1, 1, &t, &n, &err) == CSF_OK) free(t);
    }
    free(s.conds);
    return 0;
}
