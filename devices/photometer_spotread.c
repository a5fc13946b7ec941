/* ArgyllCMS spotread bridge (see devices/photometer_spotread.h): the process on a pseudo-terminal
 * is the transport; the text it prints is the protocol, scanned by csf_spotread_scan. */
#include "devices/photometer_spotread.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "devices/photometer_driver.h"
#include "devices/transport_serial.h"

#define MAX_ARGS 32

typedef struct {
    char *argv[MAX_ARGS + 4];
    int argc;
    char argbuf[512];
    char who[600];
    double timeout_s, start_timeout_s;
    pid_t pid;
    int master;          /* -1: not running */
    char buf[8192];
    size_t n;
    unsigned long readings;
} spot_state;

/* ---- protocol: scanning spotread's output ---- */

static int has(const char *line, const char *s) { return strstr(line, s) != NULL; }

static void fail(csf_spotread_event *ev, csf_status st, const char *line)
{
    ev->kind = CSF_SPOT_FAIL;
    ev->status = st;
    snprintf(ev->reason, sizeof ev->reason, "%s", line);
}

static csf_status misread_status(const char *reason)
{
    if (has(reason, "attery")) return CSF_E_DEVICE; /* "Battery too low" is not about the light */
    if (has(reason, "too low") || has(reason, "too dark") || has(reason, "Too dark") || has(reason, "Too low"))
        return CSF_E_TOO_DARK;
    if (has(reason, "aturat") || has(reason, "Too bright") || has(reason, "too bright") || has(reason, "too high"))
        return CSF_E_SATURATED;
    return CSF_E_DEVICE;
}

/* One complete line: 1 when it is an event. */
static int scan_line(const char *line, csf_spotread_event *ev)
{
    const char *r = strstr(line, "Result is XYZ:");
    if (r) {
        const char *p = r + 14;
        for (int k = 0; k < 3; k++) {
            char *end;
            errno = 0;
            double x = strtod(p, &end);
            if (end == p || errno == ERANGE || !isfinite(x)) {
                fail(ev, CSF_E_PROTOCOL, line);
                return 1;
            }
            ev->xyz[k] = x;
            p = end;
        }
        if (*p != ',' && *p != 0 && *p != ' ') {
            fail(ev, CSF_E_PROTOCOL, line);
            return 1;
        }
        ev->kind = CSF_SPOT_RESULT;
        return 1;
    }
    if (has(line, "Result is Y:")) { fail(ev, CSF_E_PROTOCOL, line); return 1; } /* ambient mode */
    if (has(line, "no instrument detected") || has(line, "No ports found")) { fail(ev, CSF_E_NOT_FOUND, line); return 1; }
    if (has(line, "Instrument initialisation failed")) { fail(ev, CSF_E_DEVICE, line); return 1; }
    if (has(line, "communication problem")) { fail(ev, CSF_E_GONE, line); return 1; }
    const char *m = strstr(line, "misread (");
    if (m) { fail(ev, misread_status(m), line); return 1; }
    if (has(line, "Spot read failed") || has(line, "Spot read needs a calibration") || has(line, "Spot read got abort")) {
        fail(ev, CSF_E_DEVICE, line);
        return 1;
    }
    if (has(line, "Diagnostic:") && !has(line, "Usage requested")) { fail(ev, CSF_E_INVALID_ARG, line); return 1; }
    if (has(line, "calibration position") || has(line, "white reference") || has(line, "hit any key to continue")) {
        ev->kind = CSF_SPOT_ASK;
        snprintf(ev->reason, sizeof ev->reason, "%s", line);
        return 1;
    }
    if (has(line, "to take a reading")) { ev->kind = CSF_SPOT_PROMPT; return 1; }
    return 0;
}

void csf_spotread_scan(const char *buf, size_t len, csf_spotread_event *ev)
{
    memset(ev, 0, sizeof *ev);
    size_t pos = 0;
    char line[512];
    while (pos < len) {
        const char *nl = memchr(buf + pos, '\n', len - pos);
        size_t end = nl ? (size_t)(nl - buf) : len;
        size_t ll = end - pos;
        /* control bytes (terminal sequences) and NULs out; over-long lines keep their start */
        size_t o = 0;
        for (size_t k = 0; k < ll && o + 1 < sizeof line; k++) {
            unsigned char c = (unsigned char)buf[pos + k];
            if (c >= 0x20 && c != 0x7f) line[o++] = (char)c;
        }
        line[o] = 0;
        if (!nl) {
            /* the prompt has no line ending; anything else unfinished waits for more */
            if (has(line, "to take a reading:") || has(line, "hit any key to continue")) {
                scan_line(line, ev);
                ev->consumed = len;
            }
            return;
        }
        pos = end + 1;
        if (scan_line(line, ev)) {
            ev->consumed = pos;
            return;
        }
    }
}

/* ---- the process ---- */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void stop(spot_state *s)
{
    if (s->master < 0) return;
    if (write(s->master, "q", 1) < 0) { /* spotread's own way out */
    }
    close(s->master);
    s->master = -1;
    int status;
    for (int i = 0; i < 100; i++) {
        if (waitpid(s->pid, &status, WNOHANG) != 0) return;
        if (i == 20) kill(s->pid, SIGTERM);
        struct timespec ts = {0, 20000000};
        nanosleep(&ts, NULL);
    }
    kill(s->pid, SIGKILL);
    waitpid(s->pid, &status, 0);
}

/* Why the child is gone, for a message. */
static void exit_text(spot_state *s, char *out, size_t cap)
{
    int status = 0;
    pid_t r = waitpid(s->pid, &status, 0);
    if (r != s->pid) snprintf(out, cap, "ended");
    else if (WIFEXITED(status)) snprintf(out, cap, "exited with status %d", WEXITSTATUS(status));
    else if (WIFSIGNALED(status)) snprintf(out, cap, "was killed by signal %d", WTERMSIG(status));
    else snprintf(out, cap, "ended");
}

/* Reads spotread's output until an event other than `skip` (or any event when skip is 0). */
static csf_status next_event(spot_state *s, int skip, double timeout_s, const char *what, csf_spotread_event *ev,
                             csf_error *err)
{
    double end = now_s() + timeout_s;
    for (;;) {
        csf_spotread_event e;
        csf_spotread_scan(s->buf, s->n, &e);
        if (e.consumed) {
            memmove(s->buf, s->buf + e.consumed, s->n - e.consumed);
            s->n -= e.consumed;
            if (e.kind == skip) continue;
            *ev = e;
            return CSF_OK;
        }
        if (s->n == sizeof s->buf) { /* a flood of unknown text: keep the last half */
            memmove(s->buf, s->buf + sizeof s->buf / 2, sizeof s->buf / 2);
            s->n = sizeof s->buf / 2;
        }
        double left = end - now_s();
        if (left <= 0) {
            char q[160];
            csf_quote_bytes(s->buf, s->n > 60 ? 60 : s->n, q, sizeof q);
            stop(s);
            if (s->n) return csf_error_set(err, CSF_E_PROTOCOL, "%s: %s: output cut short or not understood "
                                           "within %.1f s ('%s')", s->who, what, timeout_s, q);
            return csf_error_set(err, CSF_E_TIMEOUT, "%s: no answer to %s within %.1f s (instrument busy, "
                                 "disconnected, or waiting for something?)", s->who, what, timeout_s);
        }
        struct pollfd pf = {s->master, POLLIN, 0};
        int pr = poll(&pf, 1, (int)(left * 1000) + 1);
        if (pr < 0 && errno == EINTR) continue;
        if (pr == 0) continue;
        ssize_t got = read(s->master, s->buf + s->n, sizeof s->buf - s->n);
        if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (got <= 0) {
            /* the child closed its terminal: whatever it said last may explain why */
            csf_spotread_scan(s->buf, s->n, &e);
            char why[64];
            close(s->master);
            s->master = -1;
            exit_text(s, why, sizeof why);
            if (e.kind == CSF_SPOT_FAIL)
                return csf_error_set(err, e.status, "%s: %s (spotread %s)", s->who, e.reason, why);
            return csf_error_set(err, CSF_E_GONE, "%s: spotread %s during %s (instrument unplugged?); "
                                 "reconnect it and resume the session", s->who, why, what);
        }
        s->n += (size_t)got;
    }
}

static csf_status start(spot_state *s, csf_error *err)
{
    s->n = 0;
    int m = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (m < 0 || grantpt(m) || unlockpt(m) || !ptsname(m)) {
        if (m >= 0) close(m);
        return csf_error_set(err, CSF_E_DEVICE, "%s: cannot make a terminal for spotread: %s", s->who, strerror(errno));
    }
    char slave[128];
    snprintf(slave, sizeof slave, "%s", ptsname(m));
    int ep[2]; /* exec failure report: closes on a successful exec */
    if (pipe2(ep, O_CLOEXEC) != 0) {
        close(m);
        return csf_error_set(err, CSF_E_DEVICE, "%s: pipe: %s", s->who, strerror(errno));
    }
    pid_t pid = fork();
    if (pid < 0) {
        close(m);
        close(ep[0]);
        close(ep[1]);
        return csf_error_set(err, CSF_E_DEVICE, "%s: fork: %s", s->who, strerror(errno));
    }
    if (pid == 0) {
        setsid();
        int sl = open(slave, O_RDWR);
        if (sl < 0 || dup2(sl, 0) < 0 || dup2(sl, 1) < 0 || dup2(sl, 2) < 0) {
            int e = errno;
            if (write(ep[1], &e, sizeof e) < 0) _exit(127);
            _exit(127);
        }
        if (sl > 2) close(sl);
        execvp("spotread", s->argv);
        int e = errno;
        if (write(ep[1], &e, sizeof e) < 0) _exit(127);
        _exit(127);
    }
    close(ep[1]);
    int e = 0;
    ssize_t r;
    do r = read(ep[0], &e, sizeof e);
    while (r < 0 && errno == EINTR);
    close(ep[0]);
    s->pid = pid;
    s->master = m;
    if (r == (ssize_t)sizeof e) {
        char why[64];
        close(m);
        s->master = -1;
        exit_text(s, why, sizeof why);
        if (e == ENOENT)
            return csf_error_set(err, CSF_E_NOT_FOUND, "%s: no spotread on PATH: install ArgyllCMS (Debian: apt "
                                 "install argyll)", s->who);
        return csf_error_set(err, CSF_E_DEVICE, "%s: cannot run spotread: %s", s->who, strerror(e));
    }
    csf_spotread_event ev = {0}; /* next_event fills it whenever it returns CSF_OK */
    csf_status st = next_event(s, 0, s->start_timeout_s, "start-up (instrument detection and calibration)", &ev, err);
    if (st) return st;
    if (ev.kind == CSF_SPOT_PROMPT) return CSF_OK;
    stop(s);
    if (ev.kind == CSF_SPOT_ASK)
        return csf_error_set(err, CSF_E_DEVICE, "%s: spotread asks for an instrument calibration csfcal cannot "
                             "do ('%s'): run spotread once by hand, or give -N", s->who, ev.reason);
    if (ev.kind == CSF_SPOT_FAIL)
        return csf_error_set(err, ev.status, "%s: %s", s->who, ev.reason);
    return csf_error_set(err, CSF_E_PROTOCOL, "%s: a reading before any key was pressed", s->who);
}

static csf_status spot_open(const char *options, uint64_t seed, void **state, csf_error *err)
{
    (void)seed;
    spot_state *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    s->master = -1;
    s->timeout_s = 60;
    s->start_timeout_s = 60;
    if (strlen(options) >= sizeof s->argbuf) {
        free(s);
        return csf_error_set(err, CSF_E_INVALID_ARG, "spotread: arguments longer than %zu characters",
                             sizeof s->argbuf - 1);
    }
    snprintf(s->argbuf, sizeof s->argbuf, "%s", options);
    s->argv[s->argc++] = "spotread";
    s->argv[s->argc++] = "-e"; /* emissive: absolute cd/m2 */
    s->argv[s->argc++] = "-x"; /* XYZ and Yxy */
    int n = snprintf(s->who, sizeof s->who, "spotread (ArgyllCMS) -e -x");
    char *save = NULL;
    for (char *tok = strtok_r(s->argbuf, " \t", &save); tok; tok = strtok_r(NULL, " \t", &save)) {
        double *dst = strncmp(tok, "timeout_s=", 10) == 0 ? &s->timeout_s
                      : strncmp(tok, "start_timeout_s=", 16) == 0 ? &s->start_timeout_s : NULL;
        if (dst) {
            char *end;
            errno = 0;
            double x = strtod(strchr(tok, '=') + 1, &end);
            if (errno || *end || !(x >= 0.1 && x <= 3600)) {
                csf_error_set(err, CSF_E_INVALID_ARG, "spotread: %s out of range (0.1 to 3600 s)", tok);
                free(s);
                return CSF_E_INVALID_ARG;
            }
            *dst = x;
            continue;
        }
        /* options that change what spotread prints or make it stop after one reading */
        if (!strcmp(tok, "-O") || !strcmp(tok, "-S") || !strcmp(tok, "-s") || !strcmp(tok, "-h") ||
            !strcmp(tok, "-T") || !strcmp(tok, "-V") || !strcmp(tok, "-a") || !strcmp(tok, "-t") ||
            !strncmp(tok, "-r", 2)) {
            csf_error_set(err, CSF_E_INVALID_ARG, "spotread: option %s is not for csfcal's bridge (it changes the "
                          "output or the measuring mode; -e -x are given already)", tok);
            free(s);
            return CSF_E_INVALID_ARG;
        }
        if (s->argc >= MAX_ARGS) {
            free(s);
            return csf_error_set(err, CSF_E_INVALID_ARG, "spotread: more than %d arguments", MAX_ARGS - 3);
        }
        s->argv[s->argc++] = tok;
        if (n > 0 && (size_t)n < sizeof s->who) n += snprintf(s->who + n, sizeof s->who - (size_t)n, " %s", tok);
    }
    s->argv[s->argc] = NULL;
    signal(SIGPIPE, SIG_IGN);
    csf_status st = start(s, err);
    if (st) {
        free(s);
        return st;
    }
    *state = s;
    return CSF_OK;
}

static void spot_close(void *state)
{
    spot_state *s = state;
    if (!s) return;
    stop(s);
    free(s);
}

static csf_status spot_identify(void *state, char *buf, size_t len, csf_error *err)
{
    spot_state *s = state;
    (void)err;
    snprintf(buf, len, "%s", s->who);
    return CSF_OK;
}

static csf_status spot_measure(void *state, const csf_screen_source *src, csf_photometer_reading *out,
                               csf_error *err)
{
    spot_state *s = state;
    (void)src;
    unsigned long i = s->readings++;
    csf_status st = CSF_OK;
    if (s->master < 0) st = start(s, err); /* after a failure: a fresh spotread */
    csf_spotread_event ev = {0}; /* next_event fills it whenever it returns CSF_OK */
    if (!st && write(s->master, " ", 1) != 1)
        st = csf_error_set(err, CSF_E_GONE, "%s: cannot send a key to spotread: %s", s->who, strerror(errno));
    if (!st) st = next_event(s, CSF_SPOT_PROMPT, s->timeout_s, "a reading", &ev, err);
    if (!st && ev.kind != CSF_SPOT_RESULT) {
        stop(s);
        st = ev.kind == CSF_SPOT_FAIL ? csf_error_set(err, ev.status, "%s: %s", s->who, ev.reason)
                                      : csf_error_set(err, CSF_E_DEVICE, "%s: spotread asks '%s'", s->who, ev.reason);
    }
    if (st) {
        stop(s);
        size_t l = strlen(err->msg);
        snprintf(err->msg + l, sizeof err->msg - l, " (reading %lu)", i);
        return st;
    }
    /* near black a colorimeter's zero offset can go below 0: too dark, not a garbled answer */
    if (!(ev.xyz[1] > 0))
        return csf_error_set(err, CSF_E_TOO_DARK, "%s: too dark: Y = %g (reading %lu)", s->who, ev.xyz[1], i);
    if (ev.xyz[0] < 0 || ev.xyz[2] < 0) {
        stop(s);
        return csf_error_set(err, CSF_E_PROTOCOL, "%s: negative XYZ %g %g %g in its result (reading %lu)", s->who,
                             ev.xyz[0], ev.xyz[1], ev.xyz[2], i);
    }
    memcpy(out->xyz, ev.xyz, sizeof ev.xyz);
    out->lum_cdm2 = ev.xyz[1];
    out->has_xyz = 1;
    return CSF_OK;
}

/* spotread drives whatever Argyll finds; on a display that is nearly always a contact colorimeter
 * (i1Display, Spyder, ColorMunki on the screen), so the patch is checked as for one: a 20 mm face,
 * our working figure (see devices/photometer_colorcal2.c). */
const csf_photometer_driver csf_photometer_spotread_driver = {
    .name = "spotread",
    .description = "ArgyllCMS spotread bridge (any instrument Argyll supports: spotread[:ARGS])",
    .caps = CSF_PHOT_CAP_XYZ,
    .open = spot_open,
    .identify = spot_identify,
    .measure = spot_measure,
    .close = spot_close,
    .field_mm = 20.0,
};
