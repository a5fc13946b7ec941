/* Stand-in for ArgyllCMS spotread, built as an executable named `spotread` and put first on PATH
 * by the tests. It behaves as spotread does on a console: takes single key presses (raw terminal),
 * prints the documented prompt "... any other key to take a reading: " and, per key, the result
 * line " Result is XYZ: X Y Z, Yxy: Y x y" measured on the simulated display showing what csfcal
 * shows (screen mirror, emu_screen.h); q, Q or Esc end it. It insists on -e and -x (what the bridge
 * gives) and accepts any other option.
 * Settings from the environment, CSF_FAKE_SPOTREAD="key=value,...": display=SPEC (lcd), seed=N,
 * gain=G, noise=REL, slow=S (seconds before each result), fault=KIND@N (from reading N of this
 * process, once; noinst and initfail apply at start): noinst ("no instrument detected", exit 1),
 * initfail (instrument initialisation failed), unplug ("communication problem", exit 1), timeout
 * (no answer), garbage (an unreadable result line), truncated (half a result line, then silence),
 * dark (misread: light level too low), over (misread: too bright), battery (misread: battery too
 * low), crash (exits without a word). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "tests/emu/emu_screen.h"

static const char prompt[] =
    "\nPlace instrument on spot to be measured,\n"
    "and hit [A-Z] to read white and setup FWA compensation (keyed to letter)\n"
    "[a-z] to read and make FWA compensated reading from keyed reference\n"
    "'r' to set reference, 's' to save spectrum,\n"
    "'h' to toggle high res., 'k' to do a calibration\n"
    "Hit ESC or Q to exit, any other key to take a reading: ";

static void out(const char *s)
{
    fputs(s, stdout);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    int e = 0, x = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-e")) e = 1;
        if (!strcmp(argv[i], "-x")) x = 1;
    }
    if (!e || !x) {
        out("Diagnostic: the csfcal stand-in wants -e -x\n");
        return 1;
    }
    char conf[512] = "";
    const char *env = getenv("CSF_FAKE_SPOTREAD");
    if (env) snprintf(conf, sizeof conf, "%s", env);
    char display[256] = "lcd", fault[32] = "";
    double seed = 1, gain = 1, noise = 0.001, slow = 0;
    long fault_at = -1;
    char *save = NULL;
    for (char *t = strtok_r(conf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(t, '=');
        if (!eq) continue;
        *eq++ = 0;
        if (!strcmp(t, "display")) snprintf(display, sizeof display, "%s", eq);
        else if (!strcmp(t, "seed")) seed = atof(eq);
        else if (!strcmp(t, "gain")) gain = atof(eq);
        else if (!strcmp(t, "noise")) noise = atof(eq);
        else if (!strcmp(t, "slow")) slow = atof(eq);
        else if (!strcmp(t, "fault")) {
            char *at = strchr(eq, '@');
            if (at) {
                *at = 0;
                fault_at = atol(at + 1);
            }
            snprintf(fault, sizeof fault, "%s", eq);
        }
    }
    if (!strcmp(fault, "noinst")) {
        out("Unknown, inappropriate or no instrument detected\n");
        return 1;
    }
    if (!strcmp(fault, "initfail")) {
        out("Instrument initialisation failed with 'Battery too low' (Device error)!\n");
        return 1;
    }
    emu_light l;
    char why[256];
    if (emu_light_open(&l, display, why, sizeof why)) {
        fprintf(stdout, "Diagnostic: %s\n", why);
        return 1;
    }
    l.seed = (uint64_t)seed;
    l.gain = gain;
    l.noise_rel = noise;
    l.noise_abs = 0.0005;
    struct termios t;
    if (tcgetattr(0, &t) == 0) { /* single key presses, no echo, as spotread sets its console */
        cfmakeraw(&t);
        t.c_oflag |= OPOST | ONLCR;
        tcsetattr(0, TCSANOW, &t);
    }
    out(prompt);
    for (long n = 0;; n++) {
        char c;
        ssize_t r = read(0, &c, 1);
        if (r <= 0 || c == 'q' || c == 'Q' || c == 27) {
            emu_light_close(&l);
            return 0;
        }
        if (slow > 0) usleep((useconds_t)(slow * 1e6));
        int hit = n == fault_at;
        if (hit && !strcmp(fault, "timeout")) {
            for (;;) pause();
        }
        if (hit && !strcmp(fault, "crash")) _exit(3); /* no clean-up, as a crash */
        if (hit && !strcmp(fault, "unplug")) {
            out("\nSpot read failed due to communication problem.\n");
            _exit(1);
        }
        const char *misread = !hit ? NULL : !strcmp(fault, "dark") ? "Light level is too low"
                                          : !strcmp(fault, "over") ? "Too bright to read accuractly"
                                          : !strcmp(fault, "battery") ? "Battery too low" : NULL;
        if (misread) {
            printf("\nSpot read failed due to misread (%s)\n\nHit Esc or Q to give up, any other key to retry:", misread);
            fflush(stdout);
            continue;
        }
        double xyz[3];
        if (emu_light_measure(&l, xyz, why, sizeof why)) {
            printf("\nSpot read failed due to misread (%s)\n", why);
            fflush(stdout);
            continue;
        }
        double s = xyz[0] + xyz[1] + xyz[2];
        char line[256];
        snprintf(line, sizeof line, "\n Result is XYZ: %f %f %f, Yxy: %f %f %f\n\n", xyz[0], xyz[1], xyz[2], xyz[1],
                 s > 0 ? xyz[0] / s : 0, s > 0 ? xyz[1] / s : 0);
        if (hit && !strcmp(fault, "garbage")) snprintf(line, sizeof line, "\n Result is XYZ: 12.5 nan?? ##\n\n");
        if (hit && !strcmp(fault, "truncated")) {
            line[strlen(line) / 2] = 0;
            out(line);
            for (;;) pause();
        }
        out(line);
        out("Hit ESC or Q to exit, any other key to take a reading: ");
    }
}
