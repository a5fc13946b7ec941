/* Serial port transport (termios) for instruments on RS-232, USB-serial adapters and USB CDC
 * devices (/dev/ttyS*, /dev/ttyUSB*, /dev/ttyACM*; a pseudo-terminal in tests). Raw mode, the
 * instrument's baud rate, data bits, parity and stop bits; the port is opened exclusively
 * (TIOCEXCL) so a second program cannot interleave commands. Reads and writes wait with poll()
 * up to their timeout; a port that hangs up (cable pulled, USB device gone, emulator closed)
 * answers CSF_E_GONE. Messages start with the `who` given at open ("LS-100 on /dev/ttyUSB0"). */
#ifndef CSF_TRANSPORT_SERIAL_H
#define CSF_TRANSPORT_SERIAL_H

#include <stddef.h>

#include "devices/photometer_driver.h"

typedef struct {
    int baud;       /* 1200 .. 115200 */
    int data_bits;  /* 7 or 8 */
    char parity;    /* 'N', 'E' or 'O' */
    int stop_bits;  /* 1 or 2 */
} csf_serial_params;

/* Opens path. Errors: CSF_E_NOT_FOUND (no such port), CSF_E_UNSUPPORTED (permission: names the
 * dialout group; not a terminal device), CSF_E_DEVICE (in use, settings refused). */
csf_status csf_serial_open(const char *path, const csf_serial_params *p, const char *who, csf_transport **out,
                           csf_error *err);

/* Reads one line ending in '\n' (a '\r' before it and any leading "\r\n" are dropped) within
 * timeout_s in all. *len gets its length without the ending. Errors: CSF_E_TIMEOUT when nothing
 * came, CSF_E_PROTOCOL when a line was begun but not finished in time (a truncated reply; the
 * bytes that came are quoted) or is longer than cap - 1, CSF_E_GONE. `what` names the command
 * the line answers, for messages. */
csf_status csf_transport_read_line(csf_transport *t, char *line, size_t cap, size_t *len, double timeout_s,
                                   const char *who, const char *what, csf_error *err);

/* Drops bytes already waiting (a late answer to an earlier, timed-out command). */
void csf_transport_drain(csf_transport *t);

/* One command of a line protocol (the serial meters'): drops what is waiting, writes cmd and its
 * ending, and reads the answer line as csf_transport_read_line does (cmd names it in messages). */
csf_status csf_transport_ask_line(csf_transport *t, const char *cmd, const char *ending,
                                  double write_timeout_s, double read_timeout_s, char *line, size_t cap,
                                  size_t *len, const char *who, csf_error *err);
/* CSF_E_PROTOCOL for an answer the protocol's parser refused (why), the answer quoted printably. */
csf_status csf_transport_unreadable(const char *line, size_t len, const char *who, const char *cmd,
                                    const char *why, csf_error *err);
/* The port of a serial meter's spec "PORT[,OPTIONS]" into path (cap bytes); *options gets what
 * follows the first comma, or NULL. Refuses an empty port (naming spec_name and example_port as
 * the example to give) and a port path that does not fit. */
csf_status csf_serial_spec_port(const char *spec, const char *name, const char *spec_name,
                                const char *example_port, char *path, size_t cap, const char **options,
                                csf_error *err);

/* csf_quote_bytes (core/csf_status.h) gives the printable form of a reply for messages. */

#endif
