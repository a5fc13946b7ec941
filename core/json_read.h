/* Reading JSON that csfcal stored earlier (session settings in the store), through jansson. The
 * store is outside input once it has been on disk: a value may be missing (an older session), of
 * the wrong type, or absurd (a damaged or hostile file). Each getter says which, and the message
 * names the key, the value and the allowed range, so a resume can refuse instead of casting. */
#ifndef CSF_JSON_READ_H
#define CSF_JSON_READ_H

#include <stddef.h>

#include "core/csf_status.h"

typedef struct csf_json_doc csf_json_doc;

/* Parses text (NUL-terminated) that must hold one JSON object. `what` names it in messages. */
csf_status csf_json_parse_object(const char *text, const char *what, csf_json_doc **out, csf_error *err);
void csf_json_free(csf_json_doc *d);

/* Each getter returns 1 when the key is present and valid (*out set), 0 when it is absent (*out
 * untouched), and -1 when it is present but of the wrong type or outside [lo, hi] (err set). */
int csf_json_get_number(const csf_json_doc *d, const char *key, double lo, double hi, double *out,
                        csf_error *err);
int csf_json_get_int(const csf_json_doc *d, const char *key, long lo, long hi, int *out, csf_error *err);
/* A string that fits in len bytes including its NUL and holds no NUL of its own. */
int csf_json_get_string(const csf_json_doc *d, const char *key, char *out, size_t len, csf_error *err);
/* An array of 1..max numbers, each finite; *n is their count. */
int csf_json_get_numbers(const csf_json_doc *d, const char *key, double *out, int max, int *n,
                         csf_error *err);

#endif
