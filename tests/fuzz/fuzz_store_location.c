/* A store location (--store, --to, `store =` in station.conf) is outside input that csfcal
 * echoes in every message: csf_store_redact must never read or write out of bounds and always
 * terminate its output; what it shows holds no secret libpq would read (parsed again by libpq:
 * no password or sslpassword option, and no secret value of the input as text); redacting what
 * it shows finds no password in it; and csf_store_check_location accepts no location with a
 * secret or with a byte that is not printable text, and its message never repeats a secret. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libpq-fe.h>

#include "results/store/store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A secret worth looking for in shown text: 8 or more letters and digits, with both, so it
 * cannot be a word of a message, a keyword or part of an escape that happens to match. */
static int distinctive(const char *v)
{
    int digit = 0, alpha = 0;
    size_t n = 0;
    for (; v[n]; n++) {
        if (v[n] >= '0' && v[n] <= '9') digit = 1;
        else if ((v[n] >= 'a' && v[n] <= 'z') || (v[n] >= 'A' && v[n] <= 'Z')) alpha = 1;
        else return 0;
    }
    return n >= 8 && digit && alpha;
}

/* Whether another option of the input shows v anyway (its value holds it): then finding v in
 * the shown text proves nothing. */
static int shown_elsewhere(const PQconninfoOption *opts, const PQconninfoOption *secret)
{
    char buf[4096 * 4 + 1];
    for (const PQconninfoOption *p = opts; p->keyword; p++) {
        if (p == secret || !p->val) continue;
        csf_store_printable(p->val, buf, sizeof buf);
        if (strstr(buf, secret->val) || strstr(p->val, secret->val)) return 1;
    }
    return 0;
}

/* No distinctive secret value of in (libpq marks them '*') appears in text. */
static void check_no_secret(const char *in, const char *text)
{
    if (!csf_store_is_server(in)) return;
    PQconninfoOption *opts = PQconninfoParse(in, NULL);
    for (PQconninfoOption *o = opts; o && o->keyword; o++) {
        if (!o->val || !o->dispchar || !strchr(o->dispchar, '*') || !distinctive(o->val)) continue;
        if (!shown_elsewhere(opts, o) && strstr(text, o->val)) abort();
    }
    PQconninfoFree(opts);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    char *in = malloc(size + 1);
    if (!in) return 0;
    memcpy(in, data, size);
    in[size] = '\0';
    char out[256];
    for (size_t cap = 1; cap <= sizeof out; cap *= 4) { /* small outputs: clipped, terminated */
        memset(out, 'x', sizeof out);
        csf_store_redact(in, out, cap);
        if (!memchr(out, '\0', cap)) abort();
    }
    size_t n = strlen(in), cap = 4 * n + 64;
    char *big = malloc(cap);
    if (big) {
        csf_store_redact(in, big, cap);
        if (csf_store_has_password(big)) abort();
        check_no_secret(in, big);
    }
    csf_error err;
    csf_error_clear(&err);
    csf_status cs = csf_store_check_location(in, "--store", &err);
    if (cs == CSF_OK && (csf_store_has_password(in) || !*in)) abort();
    if (cs != CSF_OK && !err.msg[0]) abort();
    check_no_secret(in, err.msg);
    free(big);
    free(in);
    return 0;
}
