/* Photo Research PR-655 / PR-670 emulator behind a pseudo-terminal: remote mode (PHOTO ... Q),
 * D110 / D111 (serial number, model), M0 (measure), D1 (Y, x, y) and D2 (X, Y, Z) of the last
 * measurement, replies "NNNN,..." CR LF; it measures the simulated display showing what csfcal
 * shows (screen mirror, emu_screen.h). Options: emu_serial.h, --model PR-655|PR-670. Faults: the
 * measurement's own codes on M0 (dark -> -008 weak light, over -> -002 light overload, error ->
 * -001 light source not constant; this instrument reports no battery state: battery acts as
 * error), timeout on M0 (no answer), garbage and truncated on the D2 answer. */
#include <stdio.h>
#include <string.h>

#include "tests/emu/emu_serial.h"

int main(int argc, char **argv)
{
    emu_serial e;
    emu_serial_init(&e, argc, argv, "PR-655");
    int remote = 0, have = 0, pending = 0; /* pending: fault waiting for the D2 answer */
    double xyz[3] = {0, 0, 0};
    char cmd[256], reply[256];
    for (;;) {
        int n = emu_serial_read_cmd(&e, cmd, sizeof cmd, '\r', remote ? "Q" : "PHOTO");
        if (n < 0) return 0;
        emu_serial_log("<- %s", cmd);
        if (!remote) {
            if (strcmp(cmd, "PHOTO") == 0) {
                remote = 1;
                emu_serial_send(&e, " REMOTE MODE\r\n");
            }
            continue; /* a local-mode instrument ignores everything else */
        }
        if (strcmp(cmd, "Q") == 0) { /* no line ending: back to local mode */
            remote = 0;
            continue;
        }
        if (strcmp(cmd, "D110") == 0) emu_serial_send(&e, "0000,60054321\r\n");
        else if (strcmp(cmd, "D111") == 0) {
            snprintf(reply, sizeof reply, "0000,%s\r\n", e.model);
            emu_serial_send(&e, reply);
        } else if (strcmp(cmd, "M0") == 0) {
            int f = emu_serial_begin_measure(&e);
            char why[256];
            have = 0;
            pending = 0;
            if (f == EMU_F_TIMEOUT) continue;
            if (emu_light_measure(&e.light, xyz, why, sizeof why)) {
                fprintf(stderr, "emu_pr: %s\n", why);
                emu_serial_send(&e, "-004\r\n");
                continue;
            }
            if (f == EMU_F_DARK || xyz[1] < 0.001) emu_serial_send(&e, "-008\r\n"); /* its floor */
            else if (f == EMU_F_OVER) emu_serial_send(&e, "-002\r\n");
            else if (f == EMU_F_ERROR || f == EMU_F_BATTERY) emu_serial_send(&e, "-001\r\n");
            else {
                have = 1;
                pending = f;
                emu_serial_send(&e, "0000\r\n");
            }
        } else if (strcmp(cmd, "D1") == 0 || strcmp(cmd, "D2") == 0) {
            if (!have) {
                emu_serial_send(&e, "-2000\r\n");
                continue;
            }
            double s = xyz[0] + xyz[1] + xyz[2];
            if (cmd[1] == '1')
                snprintf(reply, sizeof reply, "0000,111,%.4e,%.4f,%.4f\r\n", xyz[1], s > 0 ? xyz[0] / s : 0,
                         s > 0 ? xyz[1] / s : 0);
            else
                snprintf(reply, sizeof reply, "0000,111,%.4e,%.4e,%.4e\r\n", xyz[0], xyz[1], xyz[2]);
            int f = pending;
            pending = 0;
            if (!emu_serial_fault_reply(&e, f, reply)) emu_serial_send(&e, reply);
        } else {
            emu_serial_send(&e, "-1000\r\n");
        }
    }
}
