/* A store location (--store, --to, `store =` in station.conf) is outside input that csfcal
 * echoes in every message: csf_store_redact must never read or write out of bounds, always
 * terminate its output, never make it longer than the input, and leave no password behind:
 * redacting twice changes nothing (a password left in would be removed the second time), and
 * has_password agrees with whether redaction changed anything; a server URI keeps no
 * "user:secret@" in its authority; and a key=value string keeps no "password" key where libpq
 * would read one (a quote inside a bare value is an ordinary character there). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "results/store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A password in a URI's userinfo: a ':' before the last '@' of the authority. */
static int uri_userinfo_has_secret(const char *s)
{
    const char *auth = strstr(s, "://");
    if (!auth) return 0;
    auth += 3;
    size_t alen = strcspn(auth, "/?#");
    const char *at = NULL;
    for (const char *p = auth; p < auth + alen; p++)
        if (*p == '@') at = p;
    return at && memchr(auth, ':', (size_t)(at - auth)) != NULL;
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
    size_t n = strlen(in);
    char *big = malloc(n + 1), *big2 = malloc(n + 1);
    if (big && big2) {
        csf_store_redact(in, big, n + 1);
        if (strlen(big) > n) abort();
        csf_store_redact(big, big2, n + 1);
        if (strcmp(big, big2) != 0) abort(); /* nothing left to remove */
        if (csf_store_has_password(big) && n < 2048) abort();
        if (n < 2048 && csf_store_has_password(in) != (strcmp(in, big) != 0)) abort();
        if (csf_store_is_server(in) && strstr(in, "://") && uri_userinfo_has_secret(big)) abort();
    }
    free(big);
    free(big2);
    free(in);
    return 0;
}
