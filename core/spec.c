#include "core/spec.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

csf_num_result csf_number_parse(const char *text, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v)) return CSF_NUM_NOT_A_NUMBER;
    *out = v;
    return v < lo || v > hi ? CSF_NUM_OUT_OF_RANGE : CSF_NUM_OK;
}

csf_num_result csf_whole_parse(const char *text, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE) return CSF_NUM_NOT_A_NUMBER;
    *out = v;
    return v < lo || v > hi ? CSF_NUM_OUT_OF_RANGE : CSF_NUM_OK;
}

/* The first earlier item with the same key, or -1; items without '=' are not keys. */
static int earlier_same_key(const csf_spec *s, int i)
{
    if (!s->item[i].value) return -1;
    for (int j = 0; j < i; j++)
        if (s->item[j].value && strcmp(s->item[j].key, s->item[i].key) == 0) return j;
    return -1;
}

csf_status csf_spec_split(const char *text, const char *what, csf_spec *out, csf_error *err)
{
    out->n = 0;
    size_t len = strlen(text);
    char shown[200];
    csf_quote_bytes(text, len, shown, sizeof shown);
    if (len > CSF_SPEC_MAX_CHARS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: spec longer than %d characters", what,
                             CSF_SPEC_MAX_CHARS);
    memcpy(out->buf, text, len + 1);
    if (len == 0) return CSF_OK;
    /* Split by hand: strtok would skip an empty item, and "smax=250,,fmax=3" is a typing
     * mistake the user should hear about, not a separator to drop. */
    for (char *tok = out->buf;;) {
        char *comma = strchr(tok, ',');
        if (comma) *comma = '\0';
        int i = out->n;
        if (*tok == '\0')
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: item %d of '%s' is empty", what, i + 1, shown);
        char *eq = strchr(tok, '=');
        if (eq) *eq = '\0';
        out->item[i] = (csf_spec_item){tok, eq ? eq + 1 : NULL};
        out->n++;
        int j = earlier_same_key(out, i);
        if (j >= 0) {
            char key[100];
            csf_quote_bytes(tok, strlen(tok), key, sizeof key);
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s: key '%s' given twice (items %d and %d of '%s'); give it once", what,
                                 key, j + 1, i + 1, shown);
        }
        if (!comma) return CSF_OK;
        tok = comma + 1;
    }
}
