/* `csfcal report ID -o FILE`: the session report (summary with verdicts, CSF or display plots,
 * frame-timing histogram) as PDF, PNG or SVG, drawn from what the store holds. */
#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "results/plot.h"
#include "results/store/store.h"

static const char report_help[] =
    "usage: csfcal report ID -o FILE.pdf|FILE.png|FILE.svg [--store PATH]\n\n"
    "Draws the report of one session (IDs: csfcal sessions list):\n"
    "  - a summary page: counts of trials (valid/invalid, practice, catch), missed frames,\n"
    "    photometer readings, duration, and verdict lines marked OK / CHECK / PROBLEM;\n"
    "  - observer sessions: sensitivity vs spatial frequency (log-log), one curve per\n"
    "    eccentricity, measured thresholds with +-1 standard error bars and a fitted\n"
    "    log-parabola;\n"
    "  - display sessions: luminance vs drive level per channel and the residuals from the\n"
    "    stored display profile (or from the neighbouring readings when there is none);\n"
    "  - every session: a histogram of frame intervals with the missed-frame limit.\n"
    "PDF (A4 landscape, for printing; the frame timing shares the summary page when it fits)\n"
    "has one page per panel; PNG and SVG stack the panels on one tall page. The file is\n"
    "written whole or not at all.\n\n";

static const struct option report_options[] = {
    {"output", required_argument, 0, 'o'},
    {"help", no_argument, 0, 'h'},
    CSF_CLI_COMMON_OPTIONS,
    {0, 0, 0, 0},
};

int csf_cmd_report(int argc, char **argv)
{
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    const char *out_path = NULL;
    optind = 0;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":o:h", report_options, NULL)) != -1) {
        switch (c) {
        case 'o': out_path = optarg; break;
        default:
            rc = csf_cli_option_default(&cli, "report", report_help, c, argv);
            if (rc >= 0) return rc;
        }
    }
    if (argc - optind != 1) {
        fprintf(stderr, "csfcal: report: expected one session ID (see csfcal sessions list)\n");
        return 2;
    }
    long id;
    if (csf_parse_int(argv[optind], "session ID", 1, 0x7fffffffL, &id) < 0) return 2;
    if (!out_path) {
        fprintf(stderr, "csfcal: report: -o FILE is required (.pdf, .png or .svg)\n");
        return 2;
    }
    const char *ext = strrchr(out_path, '.');
    if (!ext || (strcasecmp(ext, ".pdf") && strcasecmp(ext, ".png") && strcasecmp(ext, ".svg"))) {
        fprintf(stderr, "csfcal: report: %s: unknown file type (allowed .pdf, .png, .svg)\n", out_path);
        return 2;
    }
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open_readonly(csf_cli_store_path(&cli), &s, &err) != CSF_OK) return csf_cli_report("report", &err);
    csf_status st = csf_report_write(s, id, out_path, &err);
    csf_store_close(s);
    if (st != CSF_OK) return csf_cli_report("report", &err);
    printf("wrote %s\n", out_path);
    return 0;
}
