/* A study session's settings JSON as a store holds it (outside input once a store is shared):
 * its "identity" member (studies/study_identity.h) is read back, and a read identity is compared
 * with itself and with an empty one, as study run does before it resumes a session. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "studies/study_identity.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    json_error_t je;
    json_t *j = json_loadb((const char *)data, size, 0, &je);
    if (!j) return 0;
    csf_study_identity id, none;
    memset(&none, 0, sizeof none);
    csf_error err;
    const json_t *member = json_object_get(j, "identity");
    if (csf_study_identity_from_json(member ? member : j, &id, &err) == CSF_OK) {
        char what[600];
        if (csf_study_identity_diff(&id, &id, what, sizeof what) != 0) abort();
        csf_study_identity_diff(&id, &none, what, sizeof what);
        csf_study_identity_diff(&none, &id, what, sizeof what);
        json_t *back = csf_study_identity_to_json(&id);
        csf_study_identity again;
        if (!back || csf_study_identity_from_json(back, &again, &err) != CSF_OK) abort();
        if (strcmp(again.sha256, id.sha256) || again.n_images != id.n_images ||
            strcmp(again.instructions_sha256, id.instructions_sha256))
            abort();
        csf_study_identity_free(&again);
        json_decref(back);
        csf_study_identity_free(&id);
    }
    json_decref(j);
    return 0;
}
