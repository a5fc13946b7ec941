#include <stdio.h>
#include <string.h>

#include "calib/commands.h"

int csf_cmd_sessions(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--help") == 0) {
        printf("usage: csfcal sessions ...\n(not available yet in this build)\n");
        return 0;
    }
    fprintf(stderr, "csfcal: sessions: not available yet in this build\n");
    return 1;
}
