/* termios transport (see devices/transport_serial.h). */
#include "devices/transport_serial.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    csf_transport t; /* first: the transport hands itself to its functions */
    int fd;
    char who[160];
} serial_port;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int poll_ms(double left_s)
{
    if (left_s <= 0) return 0;
    double ms = left_s * 1000 + 0.999;
    return ms > 2e9 ? 2000000000 : (int)ms;
}

static csf_status gone(serial_port *s, csf_error *err, int e)
{
    return csf_error_set(err, CSF_E_GONE, "%s: the instrument disconnected (%s); reconnect it and resume "
                         "the session", s->who, e ? strerror(e) : "port hung up");
}

static csf_status ser_write(csf_transport *t, const uint8_t *buf, size_t len, double timeout_s, csf_error *err)
{
    serial_port *s = (serial_port *)t;
    double end = now_s() + timeout_s;
    size_t done = 0;
    while (done < len) {
        struct pollfd pf = {s->fd, POLLOUT, 0};
        int r = poll(&pf, 1, poll_ms(end - now_s()));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return csf_error_set(err, CSF_E_DEVICE, "%s: poll: %s", s->who, strerror(errno));
        if (r == 0) return csf_error_set(err, CSF_E_TIMEOUT, "%s: could not send a command within %.1f s "
                                         "(flow control holding it?)", s->who, timeout_s);
        if (pf.revents & (POLLHUP | POLLERR | POLLNVAL)) return gone(s, err, 0);
        ssize_t w = write(s->fd, buf + done, len - done);
        if (w < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (w < 0) return errno == EIO || errno == ENXIO ? gone(s, err, errno)
                                                         : csf_error_set(err, CSF_E_DEVICE, "%s: write: %s", s->who, strerror(errno));
        done += (size_t)w;
    }
    return CSF_OK;
}

static csf_status ser_read(csf_transport *t, uint8_t *buf, size_t cap, size_t *got, double timeout_s, csf_error *err)
{
    serial_port *s = (serial_port *)t;
    *got = 0;
    double end = now_s() + timeout_s;
    for (;;) {
        struct pollfd pf = {s->fd, POLLIN, 0};
        int r = poll(&pf, 1, poll_ms(end - now_s()));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return csf_error_set(err, CSF_E_DEVICE, "%s: poll: %s", s->who, strerror(errno));
        if (r == 0) return CSF_OK; /* nothing before the timeout: *got = 0 */
        if (!(pf.revents & POLLIN) && (pf.revents & (POLLHUP | POLLERR | POLLNVAL))) return gone(s, err, 0);
        ssize_t n = read(s->fd, buf, cap);
        if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (n < 0) return errno == EIO || errno == ENXIO ? gone(s, err, errno)
                                                         : csf_error_set(err, CSF_E_DEVICE, "%s: read: %s", s->who, strerror(errno));
        if (n == 0) return gone(s, err, 0);
        *got = (size_t)n;
        return CSF_OK;
    }
}

static void ser_close(csf_transport *t)
{
    serial_port *s = (serial_port *)t;
    if (!s) return;
    if (s->fd >= 0) close(s->fd);
    free(s);
}

static speed_t baud_const(int baud)
{
    switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    default: return 0;
    }
}

csf_status csf_serial_open(const char *path, const csf_serial_params *p, const char *who, csf_transport **out,
                           csf_error *err)
{
    *out = NULL;
    speed_t sp = baud_const(p->baud);
    if (!sp || (p->data_bits != 7 && p->data_bits != 8) || (p->stop_bits != 1 && p->stop_bits != 2) ||
        (p->parity != 'N' && p->parity != 'E' && p->parity != 'O'))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: serial settings %d %d%c%d not supported", who, p->baud,
                             p->data_bits, p->parity, p->stop_bits);
    int fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        if (e == ENOENT || e == ENXIO || e == ENODEV)
            return csf_error_set(err, CSF_E_NOT_FOUND, "%s: no such serial port (%s): is the instrument plugged "
                                 "in? (ls /dev/ttyUSB* /dev/ttyACM* /dev/ttyS*)", who, strerror(e));
        if (e == EACCES || e == EPERM)
            return csf_error_set(err, CSF_E_UNSUPPORTED, "%s: %s: serial ports belong to the group 'dialout'; "
                                 "add yourself (sudo usermod -aG dialout $USER) and log in again", who, strerror(e));
        return csf_error_set(err, CSF_E_DEVICE, "%s: cannot open the port: %s", who, strerror(e));
    }
    if (!isatty(fd)) {
        close(fd);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "%s: not a serial port (not a terminal device)", who);
    }
    if (ioctl(fd, TIOCEXCL) != 0) {
        int e = errno;
        close(fd);
        return csf_error_set(err, CSF_E_DEVICE, "%s: cannot take the port for itself: %s", who, strerror(e));
    }
    struct termios tio;
    if (tcgetattr(fd, &tio) != 0) {
        int e = errno;
        close(fd);
        return csf_error_set(err, CSF_E_DEVICE, "%s: cannot read the port settings: %s", who, strerror(e));
    }
    cfmakeraw(&tio);
    tio.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    tio.c_cflag |= (p->data_bits == 7 ? CS7 : CS8) | CLOCAL | CREAD;
    if (p->parity != 'N') tio.c_cflag |= PARENB;
    if (p->parity == 'O') tio.c_cflag |= PARODD;
    if (p->stop_bits == 2) tio.c_cflag |= CSTOPB;
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    int bad = cfsetispeed(&tio, sp) != 0 || cfsetospeed(&tio, sp) != 0 || tcsetattr(fd, TCSANOW, &tio) != 0;
    int e = errno;
    /* A pseudo-terminal (the emulators in tests) always carries 8-bit characters without parity;
     * Linux keeps CS8 and glibc may then answer EINVAL. Only there, the rest of the settings is enough. */
    struct stat sb;
    if (bad && e == EINVAL && fstat(fd, &sb) == 0 && major(sb.st_rdev) >= 136 && major(sb.st_rdev) <= 143) {
        struct termios now;
        bad = tcgetattr(fd, &now) != 0 || cfgetospeed(&now) != sp || (now.c_lflag & (ICANON | ECHO));
    }
    if (bad) {
        close(fd);
        return csf_error_set(err, CSF_E_DEVICE, "%s: the port refused %d baud %d%c%d: %s", who, p->baud,
                             p->data_bits, p->parity, p->stop_bits, strerror(e));
    }
    tcflush(fd, TCIOFLUSH);
    serial_port *s = calloc(1, sizeof *s);
    if (!s) {
        close(fd);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    s->fd = fd;
    snprintf(s->who, sizeof s->who, "%s", who);
    s->t.write = ser_write;
    s->t.read = ser_read;
    s->t.close = ser_close;
    s->t.user = s;
    *out = &s->t;
    return CSF_OK;
}

csf_status csf_transport_read_line(csf_transport *t, char *line, size_t cap, size_t *len, double timeout_s,
                                   const char *who, const char *what, csf_error *err)
{
    double end = now_s() + timeout_s;
    size_t n = 0;
    *len = 0;
    for (;;) {
        uint8_t c;
        size_t got = 0;
        double left = end - now_s();
        csf_status st = left > 0 ? t->read(t, &c, 1, &got, left, err) : CSF_OK;
        if (st) return st;
        if (got == 0) {
            if (n == 0)
                return csf_error_set(err, CSF_E_TIMEOUT, "%s: no answer to %s within %.1f s (switched off, "
                                     "not in remote mode, or a different port?)", who, what, timeout_s);
            char q[160];
            csf_quote_bytes(line, n, q, sizeof q);
            return csf_error_set(err, CSF_E_PROTOCOL, "%s: answer to %s cut short after %zu bytes ('%s'), nothing "
                                 "more within %.1f s", who, what, n, q, timeout_s);
        }
        if (c == '\n') {
            if (n > 0 && line[n - 1] == '\r') n--;
            if (n == 0) continue; /* an empty line (a stray line ending) */
            line[n] = 0;
            *len = n;
            return CSF_OK;
        }
        if (n + 1 >= cap) {
            char q[160];
            csf_quote_bytes(line, n, q, sizeof q);
            return csf_error_set(err, CSF_E_PROTOCOL, "%s: answer to %s longer than %zu bytes ('%s...')", who,
                                 what, cap - 1, q);
        }
        line[n++] = (char)c;
    }
}

csf_status csf_transport_ask_line(csf_transport *t, const char *cmd, const char *ending,
                                  double write_timeout_s, double read_timeout_s, char *line, size_t cap,
                                  size_t *len, const char *who, csf_error *err)
{
    char out[64];
    int n = snprintf(out, sizeof out, "%s%s", cmd, ending);
    if (n < 0 || (size_t)n >= sizeof out)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: command %.20s... longer than %zu bytes", who, cmd,
                             sizeof out - 1);
    csf_transport_drain(t); /* a late answer to an earlier, timed-out command */
    csf_status st = t->write(t, (const uint8_t *)out, (size_t)n, write_timeout_s, err);
    if (st) return st;
    return csf_transport_read_line(t, line, cap, len, read_timeout_s, who, cmd, err);
}

csf_status csf_transport_unreadable(const char *line, size_t len, const char *who, const char *cmd,
                                    const char *why, csf_error *err)
{
    char q[160];
    csf_quote_bytes(line, len, q, sizeof q);
    return csf_error_set(err, CSF_E_PROTOCOL, "%s: unreadable answer to %s ('%s'): %s", who, cmd, q, why);
}

csf_status csf_serial_spec_port(const char *spec, const char *name, const char *spec_name,
                                const char *example_port, char *path, size_t cap, const char **options,
                                csf_error *err)
{
    if (!spec[0])
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: give the serial port, e.g. --photometer %s:%s",
                             name, spec_name, example_port);
    const char *comma = strchr(spec, ',');
    size_t plen = comma ? (size_t)(comma - spec) : strlen(spec);
    if (plen >= cap)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: port path longer than %zu characters", name,
                             cap - 1);
    memcpy(path, spec, plen);
    path[plen] = 0;
    *options = comma ? comma + 1 : NULL;
    return CSF_OK;
}

void csf_transport_drain(csf_transport *t)
{
    uint8_t buf[256];
    size_t got;
    csf_error e;
    for (int i = 0; i < 64; i++)
        if (t->read(t, buf, sizeof buf, &got, 0.0, &e) || got == 0) break;
}
