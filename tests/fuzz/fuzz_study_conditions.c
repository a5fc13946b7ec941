/* Study conditions tables (CSV, studies/study_file.h) are outside input. The first byte picks the
 * design (its value mod 4: 2afc, 2ifc, same_different, yes_no); the rest is the CSV text. An
 * accepted table goes on to a trial plan. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "studies/study_file.h"
#include "studies/study_plan.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    static const char *const designs[] = {"2afc", "2ifc", "same_different", "yes_no"};
    char settings[160];
    snprintf(settings, sizeof settings, "name = fuzz\ndesign = %s\nconditions = c.csv\ntrials_per_condition = 4\n"
             "blocks = 2\npractice_trials = 2\n", designs[data[0] % 4]);
    csf_study s;
    memset(&s, 0, sizeof s);
    csf_error err;
    if (csf_study_parse_settings(&s, settings, strlen(settings), "fuzz.conf", &err) != CSF_OK) abort();
    if (csf_study_parse_conditions(&s, (const char *)data + 1, size - 1, "fuzz.csv", "/nonexistent", &err) ==
        CSF_OK) {
        csf_study_trial *t = NULL;
        int n = 0;
        if (csf_study_make_plan(&s, 7, 3, &t, &n, &err) == CSF_OK) free(t);
        /* the export's view of the same text: every condition's cells, the user's columns too */
        char *text = malloc(size);
        if (!text) abort();
        memcpy(text, data + 1, size - 1);
        text[size - 1] = '\0';
        s.conditions_text = text;
        csf_study_table tab;
        if (csf_study_conditions_table(&s, &tab, &err) != CSF_OK) abort();
        csf_study_table_free(&tab);
        free(text);
    }
    free(s.conds);
    return 0;
}
