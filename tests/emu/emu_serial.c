/* Serial instrument emulators' shared part (see emu_serial.h). */
#include "tests/emu/emu_serial.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

static const char *const fault_names[] = {"none", "unplug", "timeout", "garbage", "truncated", "dark", "over",
                                          "battery", "error"};

void emu_serial_log(const char *fmt, ...)
{
    if (!getenv("CSF_EMU_VERBOSE")) return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "emu: ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

static void die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "emulator: ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    exit(2);
}

static double need_num(const char *v, const char *what)
{
    char *end;
    double x = strtod(v, &end);
    if (end == v || *end || !isfinite(x)) die("%s: '%s' is not a number", what, v);
    return x;
}

static void write_path_file(const char *file, const char *path)
{
    char tmp[1024];
    snprintf(tmp, sizeof tmp, "%s.tmp", file);
    FILE *f = fopen(tmp, "w");
    if (!f || fprintf(f, "%s\n", path) < 0 || fclose(f) != 0 || rename(tmp, file) != 0)
        die("cannot write %s: %s", file, strerror(errno));
}

void emu_serial_init(emu_serial *e, int argc, char **argv, const char *default_model)
{
    memset(e, 0, sizeof *e);
    e->model = default_model;
    const char *display = "lcd", *path_file = NULL;
    double seed = 1, noise = 0.001, abs_noise = 0.0005, gain = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) die("option %s needs a value", a);
        i++;
        if (!strcmp(a, "--path-file")) path_file = v;
        else if (!strcmp(a, "--display")) display = v;
        else if (!strcmp(a, "--seed")) seed = need_num(v, a);
        else if (!strcmp(a, "--noise")) noise = need_num(v, a);
        else if (!strcmp(a, "--abs-noise")) abs_noise = need_num(v, a);
        else if (!strcmp(a, "--gain")) gain = need_num(v, a);
        else if (!strcmp(a, "--model")) e->model = v;
        else if (!strcmp(a, "--slow")) e->slow_s = need_num(v, a);
        else if (!strcmp(a, "--fault")) {
            const char *at = strchr(v, '@');
            if (!at) die("--fault %s: KIND@N[+COUNT]", v);
            for (int k = 1; k < (int)(sizeof fault_names / sizeof fault_names[0]); k++)
                if (strlen(fault_names[k]) == (size_t)(at - v) && !strncmp(v, fault_names[k], (size_t)(at - v))) e->fault = k;
            if (!e->fault) die("--fault %s: unknown kind", v);
            char *end;
            e->fault_at = strtol(at + 1, &end, 10);
            e->fault_count = *end == '+' ? strtol(end + 1, &end, 10) : 1;
            if (*end || e->fault_at < 0 || e->fault_count < 1) die("--fault %s: KIND@N[+COUNT]", v);
        } else die("unknown option %s", a);
    }
    char why[256];
    if (emu_light_open(&e->light, display, why, sizeof why)) die("--display %s: %s", display, why);
    e->light.seed = (uint64_t)seed;
    e->light.noise_rel = noise;
    e->light.noise_abs = abs_noise;
    e->light.gain = gain;
    e->garbage_state = (unsigned long long)seed * 2654435761ull + 1;
    signal(SIGPIPE, SIG_IGN);
    e->master = posix_openpt(O_RDWR | O_NOCTTY);
    if (e->master < 0 || grantpt(e->master) || unlockpt(e->master)) die("posix_openpt: %s", strerror(errno));
    const char *sp = ptsname(e->master);
    if (!sp) die("ptsname: %s", strerror(errno));
    snprintf(e->slave_path, sizeof e->slave_path, "%s", sp);
    /* our own slave descriptor: raw from the start (no echo before the driver sets it up), and
     * the master does not see a hang-up between two csfcal runs */
    e->slave_keep = open(e->slave_path, O_RDWR | O_NOCTTY);
    if (e->slave_keep < 0) die("open %s: %s", e->slave_path, strerror(errno));
    struct termios t;
    tcgetattr(e->slave_keep, &t);
    cfmakeraw(&t);
    tcsetattr(e->slave_keep, TCSANOW, &t);
    if (path_file) write_path_file(path_file, e->slave_path);
    printf("%s\n", e->slave_path);
    fflush(stdout);
}

int emu_serial_read_cmd(emu_serial *e, char *buf, size_t cap, char term, const char *bare)
{
    size_t n = 0;
    for (;;) {
        char c;
        ssize_t r = read(e->master, &c, 1);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return -1;
        if (c == term) {
            if (n > 0 && buf[n - 1] == '\r') n--;
            buf[n] = 0;
            return (int)n;
        }
        if (n == 0 && (c == '\r' || c == '\n')) continue;
        if (n + 1 < cap) buf[n++] = c;
        buf[n] = 0;
        if (bare && strcmp(buf, bare) == 0) return (int)n;
    }
}

static void sleep_s(double s)
{
    if (!(s > 0)) return;
    struct timespec ts = {(time_t)s, (long)((s - floor(s)) * 1e9)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

void emu_serial_send(emu_serial *e, const char *s)
{
    sleep_s(e->slow_s);
    emu_serial_log("-> %s", s);
    size_t len = strlen(s), done = 0;
    while (done < len) {
        ssize_t w = write(e->master, s + done, len - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return;
        done += (size_t)w;
    }
}

int emu_serial_begin_measure(emu_serial *e)
{
    long i = e->n_meas++;
    if (!e->fault || i < e->fault_at) return EMU_F_NONE;
    if (e->fault != EMU_F_UNPLUG && i >= e->fault_at + e->fault_count) return EMU_F_NONE;
    if (e->fault == EMU_F_UNPLUG) {
        emu_serial_log("unplugged at measurement %ld", i);
        close(e->master);
        close(e->slave_keep);
        exit(0);
    }
    return e->fault;
}

int emu_serial_fault_reply(emu_serial *e, int fault, const char *reply)
{
    if (fault == EMU_F_TIMEOUT) return 1;
    if (fault == EMU_F_GARBAGE) {
        char g[24];
        for (int k = 0; k < 16; k++) {
            e->garbage_state = e->garbage_state * 6364136223846793005ull + 1442695040888963407ull;
            unsigned char c = (unsigned char)(e->garbage_state >> 56);
            g[k] = (char)(c == '\n' ? '#' : c == 0 ? 1 : c);
        }
        g[16] = '\r';
        g[17] = '\n';
        g[18] = 0;
        emu_serial_send(e, g);
        return 1;
    }
    if (fault == EMU_F_TRUNCATED) {
        char t[256];
        size_t n = strlen(reply) / 2;
        snprintf(t, sizeof t, "%.*s", (int)n, reply);
        emu_serial_send(e, t);
        return 1;
    }
    return 0;
}
