/* Konica Minolta LS-100 / LS-110 / CS-100A emulator behind a pseudo-terminal: speaks the
 * instrument's serial protocol (MDS, MES; OKnn / ERnn replies, CR LF) and measures the simulated
 * display showing what csfcal shows (screen mirror, emu_screen.h). Options: emu_serial.h, with
 * --model LS-100|LS-110|CS-100A (CS-100A answers Y,x,y). Faults map to the instrument's own
 * answers: over -> ER10 (measuring range over), battery -> ER30, error -> ER20 (EEPROM), dark ->
 * a reading of 0.000 (below the measuring range). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tests/emu/emu_serial.h"

/* The instrument's display resolution: 4 significant digits, at most 3 decimals. */
static void fmt_lum(char *out, size_t cap, double Y)
{
    int dec = Y > 0 ? 3 - (int)floor(log10(Y)) : 3;
    if (dec > 3) dec = 3;
    if (dec < 0) dec = 0;
    snprintf(out, cap, "%9.*f", dec, Y);
}

int main(int argc, char **argv)
{
    emu_serial e;
    emu_serial_init(&e, argc, argv, "LS-100");
    int chroma = strcmp(e.model, "CS-100A") == 0;
    char cmd[256];
    for (;;) {
        int n = emu_serial_read_cmd(&e, cmd, sizeof cmd, '\n', NULL);
        if (n < 0) return 0;
        emu_serial_log("<- %s", cmd);
        if (strncmp(cmd, "MDS,", 4) == 0) {
            emu_serial_send(&e, strcmp(cmd + 4, "04") == 0 || strcmp(cmd + 4, "08") == 0 ||
                                        strcmp(cmd + 4, "09") == 0 ? "OK00\r\n" : "ER01\r\n");
        } else if (strcmp(cmd, "MES") == 0) {
            int f = emu_serial_begin_measure(&e);
            double xyz[3];
            char why[256], reply[160], lum[32];
            if (emu_light_measure(&e.light, xyz, why, sizeof why)) {
                fprintf(stderr, "emu_minolta: %s\n", why);
                emu_serial_send(&e, "ER20\r\n");
                continue;
            }
            if (f == EMU_F_OVER) snprintf(reply, sizeof reply, "ER10\r\n");
            else if (f == EMU_F_BATTERY) snprintf(reply, sizeof reply, "ER30\r\n");
            else if (f == EMU_F_ERROR) snprintf(reply, sizeof reply, "ER20\r\n");
            else {
                double Y = f == EMU_F_DARK ? 0 : xyz[1];
                fmt_lum(lum, sizeof lum, Y);
                double s = xyz[0] + xyz[1] + xyz[2];
                if (chroma && s > 0)
                    snprintf(reply, sizeof reply, "OK00,%s,%.4f,%.4f\r\n", lum, xyz[0] / s, xyz[1] / s);
                else if (chroma)
                    snprintf(reply, sizeof reply, "OK00,%s,0.0000,0.0000\r\n", lum);
                else
                    snprintf(reply, sizeof reply, "OK00,%s\r\n", lum);
            }
            if (!emu_serial_fault_reply(&e, f, reply)) emu_serial_send(&e, reply);
        } else if (strcmp(cmd, "CLE") == 0) {
            emu_serial_send(&e, "OK00\r\n");
        } else {
            emu_serial_send(&e, "ER00\r\n");
        }
    }
}
