#define CSF_STATUS_DEFINING /* the function itself, not the analyzer's stand-in in csf_status.h */
#include "core/csf_status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const struct {
    const char *name;
    const char *message;
} status_table[CSF_STATUS_COUNT] = {
    [CSF_OK] = {"CSF_OK", "success"},
    [CSF_E_INVALID_ARG] = {"CSF_E_INVALID_ARG", "invalid argument"},
    [CSF_E_IO] = {"CSF_E_IO", "input/output error"},
    [CSF_E_FORMAT] = {"CSF_E_FORMAT", "malformed input"},
    [CSF_E_NOMEM] = {"CSF_E_NOMEM", "out of memory"},
    [CSF_E_UNSUPPORTED] = {"CSF_E_UNSUPPORTED", "not supported on this system"},
    [CSF_E_DEVICE] = {"CSF_E_DEVICE", "device failure"},
    [CSF_E_TIMEOUT] = {"CSF_E_TIMEOUT", "device timed out"},
    [CSF_E_TOO_DARK] = {"CSF_E_TOO_DARK", "too dark for the instrument"},
    [CSF_E_SATURATED] = {"CSF_E_SATURATED", "instrument saturated"},
    [CSF_E_GONE] = {"CSF_E_GONE", "device disconnected"},
    [CSF_E_PROTOCOL] = {"CSF_E_PROTOCOL", "device protocol error"},
    [CSF_E_STORE] = {"CSF_E_STORE", "results store error"},
    [CSF_E_NOT_FOUND] = {"CSF_E_NOT_FOUND", "not found"},
    [CSF_E_ABORTED] = {"CSF_E_ABORTED", "aborted"},
    [CSF_E_INSUFFICIENT] = {"CSF_E_INSUFFICIENT", "data insufficient"},
};

const char *csf_status_name(csf_status code)
{
    if ((int)code < 0 || code >= CSF_STATUS_COUNT) return "CSF_E_UNKNOWN";
    return status_table[code].name;
}

const char *csf_status_message(csf_status code)
{
    if ((int)code < 0 || code >= CSF_STATUS_COUNT) return "unknown error";
    return status_table[code].message;
}

csf_status csf_error_set(csf_error *e, csf_status code, const char *fmt, ...)
{
    if (e) {
        e->code = code;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(e->msg, sizeof e->msg, fmt, ap); // NOLINT(clang-analyzer-valist.Uninitialized): va_start(ap, fmt) is the line above
        va_end(ap);
    }
    return code;
}

void csf_error_clear(csf_error *e)
{
    if (e) {
        e->code = CSF_OK;
        e->msg[0] = '\0';
    }
}

void csf_quote_bytes(const char *in, size_t n, char *out, size_t cap)
{
    size_t o = 0;
    if (!cap) return;
    for (size_t i = 0; i < n && o + 5 < cap; i++) {
        unsigned char c = (unsigned char)in[i];
        if (c >= 0x20 && c < 0x7f && c != '\\') out[o++] = (char)c;
        else o += (size_t)snprintf(out + o, cap - o, c == '\r' ? "\\r" : c == '\n' ? "\\n" : "\\x%02x", c);
    }
    if (o >= cap) o = cap - 1;
    out[o] = 0;
}
