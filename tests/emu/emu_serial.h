/* What the serial instrument emulators (emu_minolta, emu_pr) share: a pseudo-terminal the driver
 * opens as its serial port (so csfcal's real termios path runs), the light model of emu_screen.h,
 * and the faults every emulator can inject.
 *
 * Command line (both emulators):
 *   --path-file F      write the pty's slave path (/dev/pts/N) to F (atomically) once ready
 *   --display SPEC     simulated display (model/display_model.h spec; default lcd)
 *   --seed N --noise REL --abs-noise CDM2 --gain G   instrument model (defaults 1, 0.001, 0.0005, 1)
 *   --model NAME       instrument name it reports (emulator-specific)
 *   --slow S           every reply is sent S seconds late (a slow device)
 *   --fault KIND@N[+COUNT]  from measurement N (0-based, counted by this emulator), COUNT of them
 *                      (default 1; unplug is for good): unplug (closes the pty and exits),
 *                      timeout (no reply), garbage (random bytes and a line end), truncated (the
 *                      first half of the reply, no line end), dark, over (over range), battery
 *                      (low battery, where the instrument reports it), error (another instrument
 *                      error code)
 * The emulator keeps a slave descriptor of its own open, so one emulator serves several csfcal
 * runs one after another; SIGTERM ends it. */
#ifndef CSF_EMU_SERIAL_H
#define CSF_EMU_SERIAL_H

#include <stddef.h>

#include "tests/emu/emu_screen.h"

enum { EMU_F_NONE, EMU_F_UNPLUG, EMU_F_TIMEOUT, EMU_F_GARBAGE, EMU_F_TRUNCATED, EMU_F_DARK, EMU_F_OVER,
       EMU_F_BATTERY, EMU_F_ERROR };

typedef struct {
    int master, slave_keep;
    char slave_path[128];
    emu_light light;
    const char *model;
    double slow_s;
    int fault;
    long fault_at, fault_count;
    long n_meas;           /* measurements begun */
    unsigned long long garbage_state;
} emu_serial;

/* Parses the common options (unknown ones are left for the caller: returns their index in *rest,
 * or argc), opens the pty and the light model. Exits with a message on bad options. */
void emu_serial_init(emu_serial *e, int argc, char **argv, const char *default_model);
/* Reads one command: bytes up to `term` (dropped, with a '\r' before it), or up to the literal
 * `bare` when given (PR's PHOTO has no ending). Returns its length, -1 when the port is gone. */
int emu_serial_read_cmd(emu_serial *e, char *buf, size_t cap, char term, const char *bare);
/* Sends a reply (after the --slow delay). */
void emu_serial_send(emu_serial *e, const char *s);
/* Begins a measurement: returns the fault that applies to it (EMU_F_NONE when none). unplug exits
 * here; timeout/garbage/truncated are acted on by emu_serial_fault_reply. */
int emu_serial_begin_measure(emu_serial *e);
/* For timeout, garbage and truncated: sends what the fault sends (reply = the good reply, for
 * truncation). Returns 1 when the fault was handled (the caller sends nothing more). */
int emu_serial_fault_reply(emu_serial *e, int fault, const char *reply);
void emu_serial_log(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
