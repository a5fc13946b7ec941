/* `csfcal study run|report|export`: user studies (docs/studies.md). */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "studies/study_export.h"
#include "studies/study_report.h"
#include "studies/study_run.h"
#include "core/file_write.h"

enum { OPT_PARTICIPANT = CSF_OPT_FIRST_FREE, OPT_CSV, OPT_QUIET, OPT_BOOT, OPT_VERSION, OPT_PER_PARTICIPANT };

static void usage(FILE *f)
{
    fprintf(
        f,
        "usage: csfcal study run STUDY.conf --participant ID [--version N] [options]\n"
        "       csfcal study report STUDY.conf|NAME [--version N] [--json] [-o report.pdf] [--csv FILE]\n"
        "       csfcal study export STUDY.conf|NAME [--version N] [-o trials.csv] [--per-participant DIR]\n\n"
        "A study is a settings file (key = value) naming a conditions CSV, one row per condition\n"
        "(docs/studies.md; examples in examples/studies/). Designs: 2afc (two places), 2ifc (two\n"
        "intervals), same_different (image pairs), yes_no (with catch trials).\n\n"
        "run: checks the study files, the images and every stimulus on this display before the\n"
        "first trial (bad files exit 2, naming file, line and problem), then runs the\n"
        "participant's trials, storing each answer as it is given. Running the same command\n"
        "again after a crash, Escape or Ctrl-C continues the participant's unfinished session.\n"
        "  --participant ID     pseudonymous code: a letter or digit, then up to 62 letters,\n"
        "                       digits, '_', '-', '.' (no '..') (required)\n"
        "  --version N          the study version (default 1). A version is the exact content of the\n"
        "                       settings, the conditions and every image (SHA-256, kept with each\n"
        "                       session, the images stored in the store): a participant is added or\n"
        "                       resumed only when nothing changed; after a change start a new version\n"
        "  --observer sim[:...] simulated observer (docs/observer-calibration.md keys) or human\n"
        "                       (window, keyboard and mouse: 1/Left = first interval or left place,\n"
        "                       same, no; 2/Right = second or right, different, yes)\n"
        "  --set experimenter=NAME, --set notes=TEXT\n"
        "                       session metadata, kept with the session and shown by sessions show,\n"
        "                       the report and the export (printable text, at most 255 bytes)\n"
        "  --quiet              no progress on stderr\n\n"
        "report: proportion correct with exact (Clopper-Pearson) 95%% intervals per condition;\n"
        "forced choice: an exact binomial test against chance (0.5); yes/no and same/different:\n"
        "hit and false-alarm rates, Fisher's exact test of hits against false alarms, and d'\n"
        "with its 95%% interval (yes/no: Gourevitch & Galanter; same/different: the differencing\n"
        "model's profile likelihood, or the independent-observation model, as the study says);\n"
        "Weibull fits with lapse (maximum likelihood, a grid search\n"
        "polished by simplex) with 95%% intervals for threshold and slope from the marginal\n"
        "posterior (flat priors on t, the width 1/beta and lapse: psignifit 4's interval); the\n"
        "JSON also gives parametric-bootstrap percentile intervals (they under-cover: about 90%%\n"
        "for t); pooled and per participant. Given the settings file, the report covers exactly the\n"
        "sessions that ran these files (given a name, --version N or the only version held), lists\n"
        "each session's participant, version and whether it finished, and names the other versions.\n"
        "  --json               the report as JSON on stdout\n"
        "  -o, --out FILE       pages (.pdf one page each, .png, .svg): per curve the data against\n"
        "                       contrast in %%, the fit, a table of thresholds and the criterion;\n"
        "                       per condition the proportions (yes/no, same/different: hits, false\n"
        "                       alarms, d' and its interval, pooled and per participant)\n"
        "  --csv FILE           tidy CSV, one row per scope and condition or curve\n"
        "  --bootstrap N        bootstrap samples for the JSON's bootstrap intervals (default:\n"
        "                       the study's, 200; 0 = none)\n\n"
        "export: one CSV row per trial of the sessions a report covers: study, version, participant,\n"
        "session, block, trial, condition, every column of the conditions file (yours included),\n"
        "the stimulus shown, images and their SHA-256, response, correct, rt_s, flags\n"
        "(docs/studies.md).\n"
        "  -o, --out FILE       the CSV (default: standard output)\n"
        "  --per-participant DIR  also one file per participant: DIR/PARTICIPANT.csv\n\n%s",
        csf_cli_common_help);
}

/* Refusals before any trial are bad user input: exit 2. */
static int exit_for(const csf_error *err, int started)
{
    if (!started && (err->code == CSF_E_INVALID_ARG || err->code == CSF_E_FORMAT || err->code == CSF_E_NOT_FOUND))
        return 2;
    return 1;
}

/* study run needs a participant and takes none of the report's or the export's options; 0 (the
 * message printed) when the command line is wrong. */
static int run_usage_ok(const char *participant, int report_option, int export_option)
{
    const char *why = !participant    ? "--participant ID is required"
                      : report_option ? "-o and --csv belong to study report"
                      : export_option ? "--per-participant belongs to study export"
                                      : NULL;
    if (why) fprintf(stderr, "csfcal: study run: %s\n", why);
    return why == NULL;
}

/* Session metadata given with --set KEY=VALUE (the other keys are station settings). */
typedef struct {
    const char *experimenter, *notes;
} run_meta;

/* 1 when arg is a metadata key=value (taken into m), 0 when it is a station setting, -1 (message
 * printed) when its value is refused. */
static int take_meta(const char *arg, run_meta *m)
{
    static const char *const keys[] = {"experimenter", "notes"};
    for (int i = 0; i < 2; i++) {
        size_t n = strlen(keys[i]);
        if (strncmp(arg, keys[i], n) || arg[n] != '=') continue;
        csf_error err;
        if (csf_study_check_meta(keys[i], arg + n + 1, &err) != CSF_OK) {
            csf_cli_report("study run", &err);
            return -1;
        }
        if (i == 0) m->experimenter = arg + n + 1;
        else m->notes = arg + n + 1;
        return 1;
    }
    return 0;
}

static int cmd_run(csf_cli *cli, const char *study, const char *participant, int version, int quiet,
                   const run_meta *meta)
{
    csf_study_run_options o;
    memset(&o, 0, sizeof o);
    o.experimenter = meta->experimenter;
    o.notes = meta->notes;
    o.cfg = &cli->cfg;
    o.study_path = study;
    o.participant = participant;
    o.version = version;
    o.headless = csf_cli_want_headless(cli);
    if (csf_cli_refuse_monitor(cli, "study run", csf_cli_offscreen_reason(cli))) return 2;
    o.observer_spec = cli->cfg.observer[0] ? cli->cfg.observer : (o.headless ? "sim" : "human");
    if (!cli->cfg.observer[0] && o.headless)
        fprintf(stderr, "csfcal: study run: note: no display and no --observer: the SIMULATED observer "
                        "answers (--observer sim); no person is measured\n");
    o.store_path = csf_cli_store_path(cli);
    o.quiet = quiet || cli->json;
    csf_study_run_result res;
    csf_error err;
    csf_error_clear(&err);
    csf_status st = csf_study_run(&o, &res, &err);
    if (cli->json && res.session_id)
        printf("{\"session\":%lld,\"study_id\":%lld,\"participant\":\"%s\",\"trials_planned\":%d,"
               "\"trials_stored\":%d,\"trials_this_run\":%d,\"resumed\":%s,\"finished\":%s,\"seed\":%llu,"
               "\"hash\":\"%016llx\",\"version\":%d,\"sha256\":\"%s\",\"status\":\"%s\"}\n",
               (long long)res.session_id, (long long)res.study_id, participant, res.n_planned, res.n_stored,
               res.n_run_now, res.resumed ? "true" : "false", res.finished ? "true" : "false",
               (unsigned long long)res.seed, (unsigned long long)res.hash, res.version, res.sha256,
               st == CSF_OK ? "ok" : csf_status_name(st));
    if (st != CSF_OK) {
        csf_cli_report("study run", &err);
        return exit_for(&err, res.session_id != 0);
    }
    if (!cli->json)
        printf("study run: participant %s finished: %d trials in session %lld (%d this run%s)\n", participant,
               res.n_stored, (long long)res.session_id, res.n_run_now, res.resumed ? ", resumed" : "");
    return 0;
}

static int cmd_export(csf_cli *cli, const char *study, int version, const char *out, const char *dir)
{
    csf_error err;
    csf_error_clear(&err);
    if (out && strcmp(out, "-") && csf_check_output_path(out, "trial export", &err) != CSF_OK) {
        csf_cli_report("study export", &err);
        return 2;
    }
    int n = 0;
    csf_status st = csf_study_export(csf_cli_store_path(cli), study, version, out ? out : "-", dir, &n, &err);
    if (st != CSF_OK) {
        csf_cli_report("study export", &err);
        return exit_for(&err, 0);
    }
    if (out && strcmp(out, "-")) fprintf(stderr, "study export: %d trials written to %s\n", n, out);
    return 0;
}

static int cmd_report(csf_cli *cli, const char *study, int version, const char *out, const char *csv,
                      int n_boot)
{
    csf_error err;
    csf_error_clear(&err);
    if ((out && csf_check_output_path(out, "report plot", &err) != CSF_OK) ||
        (csv && csf_check_output_path(csv, "report CSV", &err) != CSF_OK)) {
        csf_cli_report("study report", &err);
        return 2;
    }
    csf_study_report *r = NULL;
    csf_status st = csf_study_report_build(csf_cli_store_path(cli), study, version, n_boot, &r, &err);
    if (st != CSF_OK) {
        csf_cli_report("study report", &err);
        return exit_for(&err, 0);
    }
    if (cli->json) {
        char *j = csf_study_report_json(r);
        if (j) printf("%s\n", j);
        free(j);
    } else {
        csf_study_report_print(r, stdout);
    }
    if (st == CSF_OK && csv) st = csf_study_report_csv(r, csv, &err);
    if (st == CSF_OK && out) st = csf_study_report_plot(r, out, &err);
    csf_study_report_free(r);
    if (st != CSF_OK) {
        csf_cli_report("study report", &err);
        return 1;
    }
    return 0;
}

int csf_cmd_study(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const char *sub = argv[1];
    if (strcmp(sub, "run") && strcmp(sub, "report") && strcmp(sub, "export")) {
        fprintf(stderr,
                "csfcal: study: unknown subcommand '%s' (run, report, export; try csfcal study --help)\n",
                sub);
        return 2;
    }
    argc--;
    argv++;
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    static const struct option opts[] = {
        {"participant", required_argument, 0, OPT_PARTICIPANT},
        {"csv", required_argument, 0, OPT_CSV},
        {"out", required_argument, 0, 'o'},
        {"quiet", no_argument, 0, OPT_QUIET},
        {"bootstrap", required_argument, 0, OPT_BOOT},
        {"version", required_argument, 0, OPT_VERSION},
        {"per-participant", required_argument, 0, OPT_PER_PARTICIPANT},
        {"help", no_argument, 0, 'h'},
        CSF_CLI_COMMON_OPTIONS,
        {0, 0, 0, 0},
    };
    const char *participant = NULL, *csv = NULL, *out = NULL, *per_dir = NULL;
    int quiet = 0, n_boot = -1, version = 0;
    run_meta meta = {NULL, NULL};
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":ho:", opts, NULL)) != -1) {
        long v;
        switch (c) {
        case 'h': usage(stdout); return 0;
        case 'o': out = optarg; break;
        case OPT_PARTICIPANT: participant = optarg; break;
        case OPT_CSV: csv = optarg; break;
        case OPT_QUIET: quiet = 1; break;
        case OPT_BOOT:
            if (csf_parse_int(optarg, "bootstrap", 0, 100000, &v) < 0) return 2;
            n_boot = (int)v;
            break;
        case OPT_VERSION:
            if (csf_parse_int(optarg, "version", 1, 1000000, &v) < 0) return 2;
            version = (int)v;
            break;
        case OPT_PER_PARTICIPANT: per_dir = optarg; break;
        default: {
            /* --set experimenter= and notes= are the session's; other keys the station's */
            int m = c == CSF_OPT_SET && !strcmp(sub, "run") ? take_meta(optarg, &meta) : 0;
            if (m < 0) return 2;
            if (m > 0) break;
            int r = csf_cli_option_default(&cli, "study", "", c, argv);
            if (r >= 0) return r;
        }
        }
    }
    if (optind + 1 != argc) {
        fprintf(stderr, "csfcal: study %s: expected one STUDY argument (a settings file%s)\n", sub,
                strcmp(sub, "run") ? " or a study name" : "");
        return 2;
    }
    const char *study = argv[optind];
    if (!strcmp(sub, "run"))
        return run_usage_ok(participant, out || csv, per_dir != NULL)
                   ? cmd_run(&cli, study, participant, version, quiet, &meta)
                   : 2;
    if (participant) {
        fprintf(stderr,
                "csfcal: study %s: --participant belongs to study run (the %s covers every "
                "participant)\n",
                sub, sub);
        return 2;
    }
    if (!strcmp(sub, "export")) {
        if (csv || n_boot >= 0) {
            fprintf(stderr,
                    "csfcal: study export: --csv and --bootstrap belong to study report (the export is "
                    "-o FILE)\n");
            return 2;
        }
        return cmd_export(&cli, study, version, out, per_dir);
    }
    if (per_dir) {
        fprintf(stderr, "csfcal: study report: --per-participant belongs to study export\n");
        return 2;
    }
    return cmd_report(&cli, study, version, out, csv, n_boot);
}
