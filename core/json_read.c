#include "core/json_read.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct csf_json_doc {
    json_t *root;
    const char *what;
};

csf_status csf_json_parse_object(const char *text, const char *what, csf_json_doc **out, csf_error *err)
{
    *out = NULL;
    if (!text) return csf_error_set(err, CSF_E_FORMAT, "%s: no JSON text", what);
    json_error_t je;
    json_t *root = json_loads(text, JSON_REJECT_DUPLICATES, &je);
    if (!root)
        return csf_error_set(err, CSF_E_FORMAT, "%s: not valid JSON at line %d, column %d: %s", what, je.line,
                             je.column, je.text);
    if (!json_is_object(root)) {
        json_decref(root);
        return csf_error_set(err, CSF_E_FORMAT, "%s: not a JSON object", what);
    }
    csf_json_doc *d = malloc(sizeof *d);
    if (!d) {
        json_decref(root);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    d->root = root;
    d->what = what;
    *out = d;
    return CSF_OK;
}

void csf_json_free(csf_json_doc *d)
{
    if (!d) return;
    json_decref(d->root);
    free(d);
}

int csf_json_get_number(const csf_json_doc *d, const char *key, double lo, double hi, double *out,
                        csf_error *err)
{
    json_t *v = json_object_get(d->root, key);
    if (!v) return 0;
    if (!json_is_number(v)) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s is not a number", d->what, key);
        return -1;
    }
    double x = json_number_value(v);
    if (!(x >= lo && x <= hi)) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s = %g is outside the allowed %g to %g", d->what, key, x, lo, hi);
        return -1;
    }
    *out = x;
    return 1;
}

int csf_json_get_int(const csf_json_doc *d, const char *key, long lo, long hi, int *out, csf_error *err)
{
    json_t *v = json_object_get(d->root, key);
    if (!v) return 0;
    if (!json_is_integer(v)) {
        if (json_is_number(v))
            csf_error_set(err, CSF_E_FORMAT, "%s: %s = %g is not a whole number from %ld to %ld", d->what, key,
                          json_number_value(v), lo, hi);
        else
            csf_error_set(err, CSF_E_FORMAT, "%s: %s is not a number", d->what, key);
        return -1;
    }
    json_int_t x = json_integer_value(v);
    if (x < lo || x > hi) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s = %lld is outside the allowed %ld to %ld", d->what, key,
                      (long long)x, lo, hi);
        return -1;
    }
    *out = (int)x;
    return 1;
}

int csf_json_get_string(const csf_json_doc *d, const char *key, char *out, size_t len, csf_error *err)
{
    json_t *v = json_object_get(d->root, key);
    if (!v) return 0;
    if (!json_is_string(v)) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s is not a string", d->what, key);
        return -1;
    }
    size_t n = json_string_length(v);
    const char *s = json_string_value(v);
    if (n >= len || memchr(s, '\0', n)) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s is longer than %zu bytes or holds a NUL", d->what, key,
                      len ? len - 1 : 0);
        return -1;
    }
    memcpy(out, s, n + 1);
    return 1;
}

int csf_json_get_numbers(const csf_json_doc *d, const char *key, double *out, int max, int *n,
                         csf_error *err)
{
    json_t *v = json_object_get(d->root, key);
    if (!v) return 0;
    size_t count = json_is_array(v) ? json_array_size(v) : 0;
    if (count < 1 || count > (size_t)max) {
        csf_error_set(err, CSF_E_FORMAT, "%s: %s must be an array of 1 to %d numbers", d->what, key, max);
        return -1;
    }
    for (size_t i = 0; i < count; i++) {
        json_t *e = json_array_get(v, i);
        double x = json_is_number(e) ? json_number_value(e) : NAN;
        if (!isfinite(x)) {
            csf_error_set(err, CSF_E_FORMAT, "%s: item %zu of %s is not a finite number", d->what, i + 1, key);
            return -1;
        }
        out[i] = x;
    }
    *n = (int)count;
    return 1;
}
