#include <stdio.h>
#include <string.h>

#include "cli/commands.h"

static const struct {
    const char *name;
    int (*run)(int, char **);
    const char *summary;
} commands[] = {
    {"observer", csf_cmd_observer,
     "observer calibrate: measure a person's thresholds, write a .csflut table"},
    {"display", csf_cmd_display,
     "display calibrate|verify|export|info: photometric calibration of a monitor"},
    {"stimulus", csf_cmd_stimulus, "stimulus check|geometry|show: measure, place and look at a stimulus"},
    {"lut", csf_cmd_lut, "lut info|lookup|export|import: inspect and convert threshold tables"},
    {"study", csf_cmd_study, "study run|report|export: user studies (2AFC, 2IFC, yes/no, same/different)"},
    {"sessions", csf_cmd_sessions, "sessions [list]|show|export|abort|push|init: the results store"},
    {"report", csf_cmd_report, "report ID -o FILE: plots and summary of a session (PDF/PNG/SVG)"},
    {"devices", csf_cmd_devices, "devices: list photometers, responders and displays"},
};

static void usage(FILE *out)
{
    fprintf(out, "usage: csfcal COMMAND [options]\n\n"
                 "csfcal measures contrast thresholds and display luminance and writes the\n"
                 "threshold tables that perceptual level-of-detail renderers read.\n\nCommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(out, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\n'csfcal COMMAND --help' describes each command. csfcal --version prints the version.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("csfcal %s\n", CSF_VERSION);
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0) return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "csfcal: unknown command '%s' (try csfcal --help)\n", argv[1]);
    return 2;
}
