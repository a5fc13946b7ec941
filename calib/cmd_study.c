/* `csfcal study run|report`: 2AFC user studies (seed 000 §6.2). The store already has studies and
 * participants; the study runner is the next piece of work and says so plainly until then. */
#include <stdio.h>
#include <string.h>

#include "calib/commands.h"

int csf_cmd_study(int argc, char **argv)
{
    if (argc > 1 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: csfcal study run|report ...\n\n"
               "2AFC user studies. Not part of this release: use `csfcal observer calibrate --method 2afc`\n"
               "for per-observer 2AFC thresholds.\n");
        return 0;
    }
    fprintf(stderr, "csfcal study: not part of this release (use `csfcal observer calibrate --method 2afc`)\n");
    return 1;
}
