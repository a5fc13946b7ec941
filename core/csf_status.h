/* Status codes and error reports shared by csfcal's modules (not by csflut, which stands alone).
 * Shape follows libusb: every code has a stable name and a human sentence; a csf_error carries the
 * code plus a message that names the problem and the limit that was broken. */
#ifndef CSF_STATUS_H
#define CSF_STATUS_H

#include <stddef.h>

typedef enum {
    CSF_OK = 0,
    CSF_E_INVALID_ARG,  /* a caller or user passed a value outside its allowed range */
    CSF_E_IO,           /* file system error */
    CSF_E_FORMAT,       /* malformed input file */
    CSF_E_NOMEM,
    CSF_E_UNSUPPORTED,  /* feature or device not available on this system */
    CSF_E_DEVICE,       /* generic device failure */
    CSF_E_TIMEOUT,      /* device did not answer in time */
    CSF_E_TOO_DARK,     /* photometer: below its measuring floor */
    CSF_E_SATURATED,    /* photometer: above its measuring range */
    CSF_E_GONE,         /* device unplugged / disappeared */
    CSF_E_PROTOCOL,     /* device answered with bytes we do not understand */
    CSF_E_STORE,        /* results store failure (disk full, read-only, corrupt) */
    CSF_E_NOT_FOUND,
    CSF_E_ABORTED,      /* user stopped, or a signal */
    CSF_E_INSUFFICIENT, /* data cannot support the requested result */
    CSF_STATUS_COUNT
} csf_status;

typedef struct {
    csf_status code;
    char msg[512];
} csf_error;

const char *csf_status_name(csf_status code);
const char *csf_status_message(csf_status code);

/* Sets e (if non-NULL) and returns code, so callers can `return csf_error_set(e, ...)`. */
csf_status csf_error_set(csf_error *e, csf_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
#if defined(__clang_analyzer__) && !defined(CSF_STATUS_DEFINING)
/* The static analyzer looks at one file at a time and cannot see that csf_error_set returns its
 * code; spelled out for it, `if (st) return st;` after a failed call is followed as the failure
 * it is, instead of going on with outputs the failed call never wrote. Compilers never see this. */
#define csf_error_set(e, code, ...) (csf_error_set((e), (code), __VA_ARGS__), (code))
#endif
void csf_error_clear(csf_error *e);

/* Bytes from outside (a file, an instrument's reply) for a message: printable ASCII as it is,
 * \r and \n as such and every other byte as \xNN, so a hostile input cannot put control codes
 * on a terminal. Writes at most cap bytes into out, NUL included. */
void csf_quote_bytes(const char *in, size_t n, char *out, size_t cap);

#endif
