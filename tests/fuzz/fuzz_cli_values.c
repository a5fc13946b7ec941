/* Command-line values are outside input: every common option's value (--set KEY=VALUE,
 * --screen-mm WxH, --distance-mm, --seed, --resume, the device specs ...) and the number lists
 * (--freqs, --eccs) must be refused with a message or accepted inside their documented range.
 * The first input byte picks the option, the rest is its value. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const int opts[] = {
    CSF_OPT_STORE, CSF_OPT_SEED, CSF_OPT_PHOTOMETER, CSF_OPT_OBSERVER, CSF_OPT_SET,
    CSF_OPT_DISTANCE, CSF_OPT_SCREEN_MM, CSF_OPT_SCREEN_PX, CSF_OPT_PROFILE, CSF_OPT_MONITOR,
    CSF_OPT_RESUME,
};
enum { N_OPTS = sizeof opts / sizeof opts[0], PICK_LIST = N_OPTS, PICK_DOUBLE, PICK_INT, N_PICKS };

static void check_config(const csf_config *c)
{
    /* the ranges cli/config.c and cli/cli.c document */
    if (!(c->screen_width_mm >= 30 && c->screen_width_mm <= 10000)) abort();
    if (!(c->screen_height_mm >= 30 && c->screen_height_mm <= 10000)) abort();
    if (c->screen_width_px < 64 || c->screen_width_px > 16384) abort();
    if (c->screen_height_px < 64 || c->screen_height_px > 16384) abort();
    if (!(c->viewing_distance_mm >= 100 && c->viewing_distance_mm <= 10000)) abort();
    if (!memchr(c->store_path, '\0', sizeof c->store_path)) abort();
    if (!memchr(c->photometer, '\0', sizeof c->photometer)) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 4096) return 0;
    int pick = data[0] % N_PICKS;
    char *arg = malloc(size);
    memcpy(arg, data + 1, size - 1);
    arg[size - 1] = '\0';
    if (pick < N_OPTS) {
        csf_cli cli;
        memset(&cli, 0, sizeof cli);
        csf_config_defaults(&cli.cfg);
        int r = csf_cli_common_option(&cli, opts[pick], arg);
        if (r != 1 && r != -1) abort(); /* a common option is always handled */
        check_config(&cli.cfg);
        if (r == 1 && opts[pick] == CSF_OPT_RESUME && cli.resume_id < 1) abort();
    } else if (pick == PICK_LIST) {
        double v[16];
        int n = csf_parse_double_list(arg, "freqs", 0.05, 100, v, 16);
        if (n == 0 || n > 16) abort();
        for (int i = 0; i < n; i++)
            if (!(v[i] >= 0.05 && v[i] <= 100)) abort();
    } else if (pick == PICK_DOUBLE) {
        double v;
        if (csf_parse_double(arg, "ecc", 0, 89, &v) == 0 && !(v >= 0 && v <= 89)) abort();
    } else {
        long v;
        if (csf_parse_int(arg, "trials", 1, 5000, &v) == 0 && (v < 1 || v > 5000)) abort();
    }
    free(arg);
    return 0;
}
