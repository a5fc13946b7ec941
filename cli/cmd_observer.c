/* csfcal observer calibrate: the command line of the per-user CSF calibration session. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "calib/observer_calib.h"
#include "calib/procedure.h"
#include "devices/responder.h"
#include "results/store/store.h"

enum {
    OPT_OUT = CSF_OPT_FIRST_FREE,
    OPT_PLOT,
    OPT_FREQS,
    OPT_ECCS,
    OPT_TRIALS,
    OPT_METHOD,
    OPT_PRACTICE,
    OPT_BREAK,
    OPT_RENDER_EVERY,
    OPT_RENDER_SIZE,
    OPT_QUIET,
    OPT_AFC,
    OPT_ALLOW_PROFILE,
    OPT_RESPONDER,
    OPT_FADE_ANCHORS,
    OPT_VELOCITIES,
    OPT_DRIFT_DIRECTION,
    OPT_PRECISION,
    OPT_DEMO
};

static void usage(FILE *f)
{
    fprintf(f,
            "usage: csfcal observer calibrate --out FILE.csflut [options]\n\n"
            "Measures one person's contrast thresholds over spatial frequency and eccentricity and\n"
            "writes the threshold table a perceptual LOD renderer reads. Every trial is stored as it\n"
            "happens; an interrupted session continues with --resume ID.\n\n"
            "Options:\n"
            "  --out FILE.csflut    threshold table to write (required)\n"
            "  --plot FILE          report plot (.png, .pdf or .svg)\n"
            "  --method M           bayes (default), fade (Luebke & Hallen 2001 fade-in) or 2afc\n"
            "                       (Psi per cell)\n"
            "  --trials N           trial budget (default 120, 1 to 5000); with --precision the cap\n"
            "                       (default 40 per cell)\n"
            "  --precision SE       stop when the table's predicted RMS error over its visible cells\n"
            "                       (the method's own stated errors) is at or below SE log10 units,\n"
            "                       e.g. 0.10; progress and the person's time on the terminal\n"
            "  --afc 2|4            forced-choice layout of bayes and 2afc: 4 (default) shows the\n"
            "                       grating at one of four places at once wherever they fit on the\n"
            "                       screen (guess rate 1/4), two intervals at the fovea; 2 uses two\n"
            "                       intervals everywhere. Kept with the session for --resume\n"
            "  --fade-anchors S     fade: the share of the trials (0 to 0.5, default 0.25) spent at\n"
            "                       the end on two-interval forced-choice trials that measure how\n"
            "                       far the person's yes/no threshold sits from the forced-choice\n"
            "                       one (it depends on their criterion); 0 = a yes/no session only\n"
            "  --freqs F1,F2,...    spatial frequencies in cpd (default 6 log-spaced 0.5-16,\n"
            "                       capped by the display's Nyquist limit)\n"
            "  --eccs E1,E2,...     eccentricities in deg (default 0,5,10,20, capped by the screen)\n"
            "  --velocities V1,...  drift velocities in deg/s (0 = static; default: static only):\n"
            "                       the carrier drifts inside a stationary Gabor envelope while the\n"
            "                       person fixates the mark, so retinal velocity = screen velocity,\n"
            "                       and the table gets a velocity axis. A cell whose temporal\n"
            "                       frequency v*f reaches half the refresh rate cannot be shown:\n"
            "                       bayes predicts it, fade and 2afc refuse such a grid. Default\n"
            "                       budget with velocities: 5 trials per cell shown\n"
            "  --drift-direction D  random (default: drawn per trial), forward or backward (along\n"
            "                       or against the carrier's modulation axis)\n"
            "  --practice N         practice trials before the measurement (default 3)\n"
            "  --demo               show the task to a participant: six practice trials at falling\n"
            "                       contrast, each followed by what was right; nothing is stored\n"
            "                       or written (no --out needed)\n"
            "  --break-every N      a break every N trials (default 40)\n"
            "  --render-every N     simulated sessions: rasterise every N-th frame (default 1;\n"
            "                       -1 = no rasterisation, timing and contrast bookkeeping only;\n"
            "                       default -1 with --observer sim:view=frame, whose person\n"
            "                       rasterises the places it looks at at full resolution)\n"
            "  --render-size WxH    simulated sessions: offscreen render size (default 64x36)\n"
            "  --quiet              no notes or progress on stderr\n"
            "  --allow-profile-change  with --resume: go on with a display profile other than the\n"
            "                       one the session was measured with (refused otherwise); the\n"
            "                       change is recorded in the session and the table names both\n\n"
            "Every option, the output paths and the grid on this screen (its reach, the local\n"
            "Nyquist limit) are checked before the first trial; --freqs and --eccs are sorted,\n"
            "a value given twice is refused.\n\n"
            "Observers: --observer sim[:key=value,...] (a simulated person; see\n"
            "docs/observer-calibration.md for the keys) or --observer human (a window, keyboard and\n"
            "mouse: Space or a click when something is visible, then a click where it was; 2AFC:\n"
            "1/Left or 2/Right, or the left/right mouse button; four places: a click on the place,\n"
            "or keypad 9/7/1/3 or I/U/J/K for upper right/upper left/lower left/lower right;\n"
            "Escape pauses: R resumes, S stops\n"
            "and keeps the session for --resume). --responder SPEC: keyboard, mouse, gamepad[:N][,map=...]\n"
            "or hid:VID:PID[,map=...] (docs/instruments.md; default: the station's responder key). Default: "
            "the station configuration's observer,\n"
            "else human when a display is available and sim without one.\n\n%s",
            csf_cli_common_help);
}

/* After a failure that left the session resumable: what is kept and the command that finishes it
 * (the same outputs, profile and station settings). */
static void print_resume_hint(const csf_cli *cli, const csf_obs_options *o, const csf_obs_result *res)
{
    /* Every word the user pastes is quoted for the shell; the prose names the store as shown. */
    char where[1024];
    csf_store_redact(o->store_path, where, sizeof where);
    const char *raw[] = {o->store_path, o->out_path, o->plot_path, cli->cfg.display_profile,
                         cli->config_path};
    char *q[5];
    for (int i = 0; i < 5; i++) q[i] = raw[i] && *raw[i] ? csf_shell_quote(raw[i]) : NULL;
    fprintf(stderr, "csfcal: %d trials kept in session %lld of %s%s; after fixing the cause, finish it with:\n"
                    "  csfcal observer calibrate --resume %lld --store %s --out %s%s%s%s%s%s%s\n",
            res->n_stored, (long long)res->session_id, where,
            res->table_written ? " (the table was written)" : "", (long long)res->session_id,
            q[0] ? q[0] : "?", q[1] ? q[1] : "?", q[2] ? " --plot " : "", q[2] ? q[2] : "",
            q[3] ? " --profile " : "", q[3] ? q[3] : "", q[4] ? " --config " : "", q[4] ? q[4] : "");
    for (int i = 0; i < 5; i++) free(q[i]);
}

/* One option from getopt_long into o (or cli). Returns -1 to go on, or the exit status: 0 after
 * --help, 2 for a bad value or an unknown option. */
/* The options given as words or shapes rather than numbers: a drift direction, a method, a render
 * size, a responder, a layout. Returns -1 to go on, or the exit status (2) after saying why. */
static int apply_word_option(int c, csf_cli *cli, csf_obs_options *o)
{
    switch (c) {
    case OPT_DRIFT_DIRECTION:
        if (strcmp(optarg, "random") == 0) o->drift_direction = 0;
        else if (strcmp(optarg, "forward") == 0) o->drift_direction = 1;
        else if (strcmp(optarg, "backward") == 0) o->drift_direction = -1;
        else {
            fprintf(stderr, "csfcal: --drift-direction: '%s' is not allowed (random, forward, backward)\n",
                    optarg);
            return 2;
        }
        break;
    case OPT_METHOD:
        if (strcmp(optarg, "fade") && strcmp(optarg, "2afc") && strcmp(optarg, "bayes")) {
            fprintf(stderr, "csfcal: --method: '%s' is unknown (bayes, fade, 2afc)\n", optarg);
            return 2;
        }
        o->method = optarg;
        break;
    case OPT_RENDER_SIZE: {
        int w, h;
        char tail;
        if (sscanf(optarg, "%dx%d%c", &w, &h, &tail) != 2 || w < 16 || h < 16 || w > 4096 || h > 4096) {
            fprintf(stderr, "csfcal: --render-size: expected WxH, each 16 to 4096, got '%s'\n", optarg);
            return 2;
        }
        o->render_w = w;
        o->render_h = h;
        break;
    }
    case OPT_RESPONDER:
        if (strlen(optarg) >= sizeof cli->cfg.responder) {
            fprintf(stderr, "csfcal: --responder: longer than %zu characters\n",
                    sizeof cli->cfg.responder - 1);
            return 2;
        }
        snprintf(cli->cfg.responder, sizeof cli->cfg.responder, "%s", optarg);
        break;
    case OPT_AFC:
        if (strcmp(optarg, "2") == 0) o->afc = 2;
        else if (strcmp(optarg, "4") == 0) o->afc = 4;
        else {
            fprintf(stderr,
                    "csfcal: --afc: '%s' is not allowed (2: two intervals, 4: four places "
                    "where they fit)\n",
                    optarg);
            return 2;
        }
        break;
    default: break;
    }
    return -1;
}

static int apply_calibrate_option(int c, char **argv, csf_cli *cli, csf_obs_options *o)
{
    long v;
    switch (c) {
    case 'h': usage(stdout); return 0;
    case 'o':
    case OPT_OUT: o->out_path = optarg; break;
    case OPT_PLOT: o->plot_path = optarg; break;
    case OPT_FREQS:
        o->n_freqs = csf_parse_double_list(optarg, "freqs", 0.01, 200, o->freqs_cpd, CSF_OBS_MAX_AXIS);
        if (o->n_freqs < 0) return 2;
        break;
    case OPT_ECCS:
        o->n_eccs = csf_parse_double_list(optarg, "eccs", 0, 80, o->eccs_deg, CSF_OBS_MAX_AXIS);
        if (o->n_eccs < 0) return 2;
        break;
    case OPT_DEMO: o->demo = 1; break;
    case OPT_PRECISION:
        if (csf_parse_double(optarg, "precision", 0.001, 2.0, &o->precision_log10) < 0) return 2;
        break;
    case OPT_VELOCITIES:
        o->n_vels = csf_parse_double_list(optarg, "velocities", 0, CSF_PROC_MAX_VELOCITY_DPS, o->vels_dps,
                                          CSF_OBS_MAX_AXIS);
        if (o->n_vels < 0) return 2;
        break;
    case OPT_TRIALS:
        if (csf_parse_int(optarg, "trials", 1, 5000, &v) < 0) return 2;
        o->trials = (int)v;
        break;
    case OPT_PRACTICE:
        if (csf_parse_int(optarg, "practice", 0, 50, &v) < 0) return 2;
        o->practice = (int)v;
        break;
    case OPT_BREAK:
        if (csf_parse_int(optarg, "break-every", 1, 5000, &v) < 0) return 2;
        o->break_every = (int)v;
        break;
    case OPT_RENDER_EVERY:
        if (csf_parse_int(optarg, "render-every", -1, 1000, &v) < 0) return 2;
        if (v == 0) v = 1;
        o->render_every = (int)v;
        break;
    case OPT_QUIET: o->quiet = 1; break;
    case OPT_ALLOW_PROFILE: o->allow_profile_change = 1; break;
    case OPT_FADE_ANCHORS: {
        double share;
        if (csf_parse_double(optarg, "fade-anchors", 0, 0.5, &share) < 0) return 2;
        o->fade_anchor_share = share > 0 ? share : -1;
        break;
    }
    case OPT_DRIFT_DIRECTION:
    case OPT_METHOD:
    case OPT_RENDER_SIZE:
    case OPT_RESPONDER:
    case OPT_AFC: return apply_word_option(c, cli, o);
    default: {
        int r = csf_cli_option_default(cli, "observer calibrate", "", c, argv);
        if (r >= 0) return r;
    }
    }
    return -1;
}

/* What the options must say together once all are read: no stray argument, an --out, a
 * responder spec that opens (--responder or the station's responder key) before the first
 * trial. Returns -1 to go on or 2. */
static int check_calibrate_options(int argc, char **argv, csf_cli *cli, const csf_obs_options *o)
{
    if (optind < argc) {
        fprintf(stderr, "csfcal: observer calibrate: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if (!o->out_path && !o->demo) {
        fprintf(stderr, "csfcal: observer calibrate: --out FILE.csflut is required\n");
        return 2;
    }
    {
        /* the responder spec (--responder or the station's responder key) before the first trial */
        csf_error rerr;
        const char *rs = cli->cfg.responder[0] ? cli->cfg.responder : "keyboard";
        if (csf_responder_check_spec(rs, &rerr)) {
            fprintf(stderr, "csfcal: observer calibrate: responder '%s': %s\n", rs, rerr.msg);
            return 2;
        }
    }
    return csf_cli_refuse_monitor(cli, "observer calibrate", csf_cli_offscreen_reason(cli)) ? 2 : -1;
}

/* The options into o (and the station's settings into cli). Returns -1 to go on, or the exit
 * status: 0 after --help, 2 for a bad option or a missing --out. */
static int parse_calibrate_options(int argc, char **argv, csf_cli *cli, csf_obs_options *o)
{
    static const struct option opts[] = {
        {"out", required_argument, 0, OPT_OUT},
        {"plot", required_argument, 0, OPT_PLOT},
        {"freqs", required_argument, 0, OPT_FREQS},
        {"eccs", required_argument, 0, OPT_ECCS},
        {"velocities", required_argument, 0, OPT_VELOCITIES},
        {"precision", required_argument, 0, OPT_PRECISION},
        {"demo", no_argument, 0, OPT_DEMO},
        {"drift-direction", required_argument, 0, OPT_DRIFT_DIRECTION},
        {"trials", required_argument, 0, OPT_TRIALS},
        {"method", required_argument, 0, OPT_METHOD},
        {"practice", required_argument, 0, OPT_PRACTICE},
        {"break-every", required_argument, 0, OPT_BREAK},
        {"render-every", required_argument, 0, OPT_RENDER_EVERY},
        {"render-size", required_argument, 0, OPT_RENDER_SIZE},
        {"quiet", no_argument, 0, OPT_QUIET},
        {"afc", required_argument, 0, OPT_AFC},
        {"fade-anchors", required_argument, 0, OPT_FADE_ANCHORS},
        {"allow-profile-change", no_argument, 0, OPT_ALLOW_PROFILE},
        {"responder", required_argument, 0, OPT_RESPONDER},
        {"help", no_argument, 0, 'h'},
        CSF_CLI_COMMON_OPTIONS,
        {0, 0, 0, 0},
    };
    optind = 1;
    opterr = 0; /* csf_cli_option_default names a bad option in our own words */
    int c;
    while ((c = getopt_long(argc, argv, ":ho:", opts, NULL)) != -1) {
        int r = apply_calibrate_option(c, argv, cli, o);
        if (r >= 0) return r;
    }
    return check_calibrate_options(argc, argv, cli, o);
}

/* What the options leave to the station: the seed, headless or not, who answers, the store. */
static void settle_calibrate_options(csf_cli *cli, csf_obs_options *o)
{
    o->seed = cli->seed;
    o->headless = csf_cli_want_headless(cli);
    /* Unless told otherwise, a station with a display measures the person in front of it; without
     * one there is nobody to ask, so the simulated observer runs (and says so in its summary). */
    o->observer_spec = cli->cfg.observer[0] ? cli->cfg.observer : (o->headless ? "sim" : "human");
    /* A table from the simulation must never pass for a person's: say it where the user looks,
     * even with --quiet, when nobody asked for the simulator. */
    if (!cli->cfg.observer[0] && o->headless && !cli->resume_id)
        fprintf(stderr, "csfcal: observer calibrate: note: no display and no --observer: the SIMULATED "
                        "observer answers (--observer sim); no person is measured\n");
    o->resume_id = cli->resume_id;
    o->store_path = csf_cli_store_path(cli);
    if (cli->json) o->quiet = 1;
}

/* Runs the session and reports it: the summary, or the error and how to resume; with --json
 * the result and its status on stdout. */
static int run_calibrate(csf_cli *cli, csf_obs_options *o)
{
    csf_obs_result res;
    csf_error err;
    csf_error_clear(&err);
    csf_status st = csf_observer_calibrate(o, &res, &err);
    if (cli->json && o->demo && st == CSF_OK)
        printf("{\"demo\":true,\"practice\":%d,\"right\":%d,\"status\":\"ok\"}\n", res.n_practice,
               res.n_valid);
    if (cli->json && res.session_id) {
        char buf[8192];
        csf_obs_result_json(&res, st == CSF_OK ? o->out_path : NULL, st == CSF_OK ? o->plot_path : NULL, buf,
                            sizeof buf);
        /* The status goes in too, so a script sees why there is no table. */
        size_t n = strlen(buf);
        if (n > 0 && buf[n - 1] == '}')
            snprintf(buf + n - 1, sizeof buf - n + 1, ",\"status\":\"%s\"}", st == CSF_OK ? "ok" : csf_status_name(st));
        printf("%s\n", buf);
    }
    if (st != CSF_OK) {
        int status = csf_cli_report("observer calibrate", &err);
        if (res.resumable) print_resume_hint(cli, o, &res);
        return status;
    }
    if (!cli->json) printf("%s\n", res.summary);
    return 0;
}

int csf_cmd_observer(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (strcmp(argv[1], "calibrate") != 0) {
        fprintf(stderr, "csfcal: observer: unknown subcommand '%s' (try csfcal observer --help)\n", argv[1]);
        return 2;
    }
    argc--;
    argv++;
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    csf_obs_options o;
    csf_obs_options_defaults(&o);
    o.cfg = &cli.cfg;
    int prc = parse_calibrate_options(argc, argv, &cli, &o);
    if (prc >= 0) return prc;
    settle_calibrate_options(&cli, &o);
    return run_calibrate(&cli, &o);
}
