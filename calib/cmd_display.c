#include <stdio.h>
#include <string.h>

#include "calib/commands.h"

int csf_cmd_display(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--help") == 0) {
        printf("usage: csfcal display ...\n(not available yet in this build)\n");
        return 0;
    }
    fprintf(stderr, "csfcal: display: not available yet in this build\n");
    return 1;
}
