/* One checked number parser and one key=value list parser for every spec csfcal reads: the
 * simulated devices' options (`--observer sim:smax=250,fmax=3`, `--photometer sim:display=lcd`,
 * a display model's `lcd,gamma=2.4`) and the command line's numbers. The refusals every spec
 * shares (an empty item, a key given twice) live here once, so no parser can forget one. */
#ifndef CSF_SPEC_H
#define CSF_SPEC_H

#include "core/csf_status.h"

typedef enum {
    CSF_NUM_OK = 0,
    CSF_NUM_NOT_A_NUMBER, /* empty, trailing text, not finite, or beyond double's range */
    CSF_NUM_OUT_OF_RANGE, /* a number, outside [lo, hi]; *out holds it for the message */
} csf_num_result;

/* text as a finite double in [lo, hi]. Leading white space is allowed (as strtod allows it),
 * nothing may follow the number. On CSF_NUM_OUT_OF_RANGE *out holds the value read; on
 * CSF_NUM_NOT_A_NUMBER *out is untouched. */
csf_num_result csf_number_parse(const char *text, double lo, double hi, double *out);

/* text as a base-10 whole number in [lo, hi], with the same rules. */
csf_num_result csf_whole_parse(const char *text, long lo, long hi, long *out);

/* The longest spec text csf_spec_split takes, and enough items that the count is never what
 * refuses a spec of that length (an item takes at least two characters with its comma). */
#define CSF_SPEC_MAX_CHARS 2047
#define CSF_SPEC_MAX_ITEMS 1024

typedef struct {
    const char *key;   /* the item up to its first '=', or the whole item when it has none */
    const char *value; /* after the first '='; NULL when the item has no '=' */
} csf_spec_item;

typedef struct {
    char buf[CSF_SPEC_MAX_CHARS + 1];
    csf_spec_item item[CSF_SPEC_MAX_ITEMS];
    int n;
} csf_spec;

/* Splits "k=v,k2=v2,..." at every comma into items (in out->buf; out stays valid while it
 * lives). An empty text is zero items. Refuses with CSF_E_INVALID_ARG, the message starting
 * "<what>: " and naming the item by its position (1 = first): an empty item ("a=1,,b=2", a
 * leading or trailing comma), a key given twice ("smax=250,smax=300": which one was meant is
 * a guess), and a text over CSF_SPEC_MAX_CHARS characters. Items without '=' are kept for the
 * caller to judge (a display spec opens with its kind). */
csf_status csf_spec_split(const char *text, const char *what, csf_spec *out, csf_error *err);

#endif
