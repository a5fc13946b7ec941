/* `csfcal display calibrate|verify|export|info`: photometric calibration of a monitor, checks of
 * an existing profile, and exports for other renderers. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "cli/display_placement.h"
#include "calib/display_calib.h"
#include "calib/display_verify.h"
#include "calib/meter_check.h"
#include "devices/photometer.h"
#include "core/file_write.h"
#include "results/colour_export.h"
#include "results/display_profile.h"
#include "results/store/store.h"
#include "stimuli/presenter.h"

static const char display_help[] =
    "usage: csfcal display calibrate --photometer SPEC --out PROFILE [--store DB] [--seed N]\n"
    "                                [--resume ID] [--target REL] [--budget N] [--checks N]\n"
    "                                [--no-channels]\n"
    "                                [--name NAME] [--quiet] [--render|--no-render]\n"
    "                                [--patch-deg D] [--background DRIVE] [--render-width N]\n"
    "       csfcal display verify PROFILE --photometer SPEC [--levels N] [--tolerance REL]\n"
    "                                [--channels] [--render|--no-render] [--patch-deg D]\n"
    "                                [--background DRIVE]\n"
    "       csfcal display export PROFILE --format clf|ctf|cube|icc|ocio [-o OUT] [--icc-version 2|4]\n"
    "       csfcal display info PROFILE\n\n"
    "calibrate  warm-up check, dark reading, adaptive grey and r/g/b sweeps until the profile\n"
    "           meets its accuracy target; every reading is stored as it is taken. After an\n"
    "           instrument fault, --resume ID finishes the session from its stored readings.\n"
    "  --target REL    max relative luminance error above 10 %% of peak (default 0.0025)\n"
    "  --budget N      most sweep readings for grey plus channels (default 48, 8 to 4096)\n"
    "  --checks N      spot checks per curve between the sweep's levels, never fitted: the\n"
    "                  stated error takes what they show (a LUT's ripple, a clipped channel)\n"
    "                  where the levels cannot (default 4, 0 to 64; 0: none)\n"
    "  --no-channels   grey only (no r, g, b curves, no additivity check)\n"
    "  --name NAME     display name for the profile id (default: the photometer spec)\n"
    "  --warmup-wait S seconds between the warm-up white readings (default 5; 0 to 600); a\n"
    "                  monitor that is already warm settles after six readings whatever S is\n"
    "  --render        draw every patch through the stimulus presenter (drive values dithered\n"
    "                  to the framebuffer depth) and, for the simulated photometer, measure the\n"
    "                  rendered frame: the patch's framebuffer pixels over the frames one reading\n"
    "                  integrates, through the simulated display (the default; --no-render tells\n"
    "                  the simulator the drive values directly, without drawing)\n"
    "  --patch-deg D   side of the square patch at the screen centre (default 10 deg; 0 = full\n"
    "                  field); --background DRIVE: grey drive around it (default 0); at least\n"
    "                  2 x a spot meter's field or a contact meter's face + 10 mm. A real meter\n"
    "                  is first placed on a target mark (Space goes on, Escape leaves;\n"
    "                  --no-placement: it is mounted on the patch already, no screen)\n"
    "  --render-width N  offscreen render width for the simulator (default 128 px; height by\n"
    "                  the screen's aspect)\n"
    "verify     waits for the monitor to warm up (the same check as calibrate), re-measures\n"
    "           white and a few grey levels (--channels: and r, g, b) and reports drift against\n"
    "           the profile; exit 1 when it exceeds --tolerance (default 0.02) or when the\n"
    "           monitor is not warm yet. Old profiles are flagged (profile_max_age_days).\n"
    "info       the profile's id, levels and the grey drive for 10/50/90 %% of white, where\n"
    "           \"%% of white\" is luminance over white, black included (L / white), as in every\n"
    "           export\n"
    "--json     calibrate, verify, info and export print one JSON object on stdout\n"
    "A photometer must be named (--photometer, or photometer in the station configuration):\n"
    "there is no default; the simulator is chosen with sim[:...] and says so on stderr.\n"
    "export     clf/ctf (OpenColorIO), cube (OpenColorIO Baker), icc (Little CMS), ocio (a\n"
    "           config with display + view, and its .clf beside it). See docs/display-profile.md.\n"
    "  --icc-version 2|4  ICC v2.4 (default: read by every ICC reader) or v4.3\n"
    "Simulated photometer: sim[:display=crt|lcd|oled|file=PATH.csv,noise=REL,abs_noise=CDM2,\n"
    "  warmup_s=S,drift=REL,integration_s=S,floor_cdm2=L,sat_cdm2=L,fault=KIND@N]\n"
    "USB meters: colorcal2[:SERIAL][,zero=1][,zero_wait_s=S][,timeout_s=S] (CRS ColorCAL MkII),\n"
    "  colorhug2[:SERIAL][,integration_ms=MS][,calibration=N][,timeout_s=S] (Hughski ColorHug2)\n"
    "Serial meters: ls100:PORT[,timeout_s=S][,floor_cdm2=L] (also ls110, cs100a: Konica Minolta),\n"
    "  pr655:PORT[,timeout_s=S] (also pr670: Photo Research), e.g. ls100:/dev/ttyUSB0\n"
    "ArgyllCMS: spotread[:ARGS] (any instrument spotread drives; ARGS are its options)\n"
    "A real meter measures this screen: the patches are drawn in a window on it. See\n"
    "docs/instruments.md\n\n";

enum {
    OPT_OUT = CSF_OPT_FIRST_FREE,
    OPT_TARGET,
    OPT_BUDGET,
    OPT_NOCH,
    OPT_NAME,
    OPT_QUIET,
    OPT_LEVELS,
    OPT_TOL,
    OPT_FORMAT,
    OPT_HELP,
    OPT_RENDER,
    OPT_NORENDER,
    OPT_PATCHDEG,
    OPT_BG,
    OPT_RWIDTH,
    OPT_ICCVER,
    OPT_CHANNELS,
    OPT_WARMWAIT,
    OPT_NOPLACE,
    OPT_CHECKS
};

static const struct option display_options[] = {
    {"out", required_argument, 0, 'o'},
    {"output", required_argument, 0, 'o'},
    {"target", required_argument, 0, OPT_TARGET},
    {"budget", required_argument, 0, OPT_BUDGET},
    {"checks", required_argument, 0, OPT_CHECKS},
    {"no-channels", no_argument, 0, OPT_NOCH},
    {"name", required_argument, 0, OPT_NAME},
    {"quiet", no_argument, 0, OPT_QUIET},
    {"levels", required_argument, 0, OPT_LEVELS},
    {"tolerance", required_argument, 0, OPT_TOL},
    {"format", required_argument, 0, OPT_FORMAT},
    {"help", no_argument, 0, OPT_HELP},
    {"render", no_argument, 0, OPT_RENDER},
    {"no-render", no_argument, 0, OPT_NORENDER},
    {"patch-deg", required_argument, 0, OPT_PATCHDEG},
    {"background", required_argument, 0, OPT_BG},
    {"render-width", required_argument, 0, OPT_RWIDTH},
    {"icc-version", required_argument, 0, OPT_ICCVER},
    {"channels", no_argument, 0, OPT_CHANNELS},
    {"warmup-wait", required_argument, 0, OPT_WARMWAIT},
    {"no-placement", no_argument, 0, OPT_NOPLACE},
    CSF_CLI_COMMON_OPTIONS,
    {0, 0, 0, 0},
};

typedef struct {
    csf_cli cli;
    const char *out, *name, *format, *file;
    double target, tol;
    long budget, levels, checks; /* checks < 0: the default */
    int no_channels, channels, quiet, help;
    int photometer_given; /* --photometer on the command line (else from the configuration) */
    unsigned long given;  /* bit (opt - OPT_OUT) per subcommand option given, 'o' as OPT_OUT */
    int render; /* 1 --render, -1 --no-render, 0 default (render) */
    double patch_deg, background;
    int patch_deg_set;
    long render_width;
    long icc_version; /* 0: the default */
    double warmup_wait_s; /* --warmup-wait; < 0: the default */
    int no_placement;     /* --no-placement: the meter is mounted on the patch already */
} dargs;

static int parse(int argc, char **argv, dargs *a)
{
    optind = 0;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":o:h", display_options, NULL)) != -1) {
        int bad = 0;
        if (c == 'o') a->given |= 1ul;
        else if (c >= OPT_OUT && c <= OPT_CHECKS && c != OPT_HELP) a->given |= 1ul << (c - OPT_OUT);
        switch (c) {
        case 'o': a->out = optarg; break;
        case OPT_TARGET: bad = csf_parse_double(optarg, "target", 1e-5, 0.5, &a->target); break;
        case OPT_BUDGET: bad = csf_parse_int(optarg, "budget", 8, 4096, &a->budget); break;
        case OPT_CHECKS: bad = csf_parse_int(optarg, "checks", 0, CSF_DISPLAY_MAX_CHECKS, &a->checks); break;
        case OPT_NOCH: a->no_channels = 1; break;
        case OPT_CHANNELS: a->channels = 1; break;
        case OPT_WARMWAIT: bad = csf_parse_double(optarg, "warmup-wait", 0, 600, &a->warmup_wait_s); break;
        case OPT_NAME: {
            /* The display's name is stored and shown on every station: printable text only. */
            csf_error e;
            if (!*optarg || strlen(optarg) > 255) {
                fprintf(stderr, "csfcal: display: --name: 1 to 255 characters (it is not shortened)\n");
                bad = -1;
            } else if (csf_store_check_text(optarg, "--name", &e) != CSF_OK) {
                fprintf(stderr, "csfcal: display: %s\n", e.msg);
                bad = -1;
            }
            a->name = optarg;
            break;
        }
        case OPT_QUIET: a->quiet = 1; break;
        case OPT_LEVELS: bad = csf_parse_int(optarg, "levels", 1, 64, &a->levels); break;
        case OPT_TOL: bad = csf_parse_double(optarg, "tolerance", 1e-5, 1, &a->tol); break;
        case OPT_FORMAT: a->format = optarg; break;
        case OPT_RENDER: a->render = 1; break;
        case OPT_NORENDER: a->render = -1; break;
        case OPT_NOPLACE: a->no_placement = 1; break;
        case OPT_PATCHDEG: bad = csf_parse_double(optarg, "patch-deg", 0, 90, &a->patch_deg); a->patch_deg_set = 1; break;
        case OPT_BG: bad = csf_parse_double(optarg, "background", 0, 1, &a->background); break;
        case OPT_RWIDTH: bad = csf_parse_int(optarg, "render-width", 16, 4096, &a->render_width); break;
        case OPT_ICCVER:
            bad = csf_parse_int(optarg, "icc-version", 2, 4, &a->icc_version);
            if (!bad && a->icc_version == 3) {
                fprintf(stderr, "csfcal: display: --icc-version 3 does not exist: give 2 (v2.4) or 4 (v4.3)\n");
                bad = 2;
            }
            break;
        case 'h':
        case OPT_HELP: a->help = 1; break;
        case ':': fprintf(stderr, "csfcal: display: option %s needs a value\n", argv[optind - 1]); return 2;
        case '?': fprintf(stderr, "csfcal: display: unknown option '%s' (see csfcal display --help)\n", argv[optind - 1]); return 2;
        default: {
            if (c == CSF_OPT_PHOTOMETER) a->photometer_given = 1;
            int r = csf_cli_common_option(&a->cli, c, optarg);
            if (r < 0) return 2;
            if (r == 0) {
                fprintf(stderr, "csfcal: display: unexpected option\n");
                return 2;
            }
        }
        }
        if (bad) return 2;
    }
    return 0;
}

static void age_warning(const csf_display_profile *p, const csf_cli *cli)
{
    char msg[400];
    if (csf_profile_age_warning(p, cli->cfg.profile_max_age_days, msg, sizeof msg))
        fprintf(stderr, "csfcal: warning: %s\n", msg);
}

/* ---- --json ---- */
static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *u = (const unsigned char *)(s ? s : ""); *u; u++) {
        if (*u == '"' || *u == '\\') fprintf(f, "\\%c", *u);
        else if (*u == '\n') fputs("\\n", f);
        else if (*u < 0x20) fprintf(f, "\\u%04x", *u);
        else fputc(*u, f);
    }
    fputc('"', f);
}

/* JSON has no NaN or infinity: null */
static void json_num(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.10g", v);
    else fputs("null", f);
}

/* A key (with its separator) and a number. */
static void json_field(const char *key, double v)
{
    fputs(key, stdout);
    json_num(stdout, v);
}

/* The photometer to use. There is no default instrument: without one the command is refused,
 * and a simulated one is announced on stderr (a simulated "ok" says nothing about the monitor).
 * Returns the spec, or NULL after printing why (exit 2). */
static const char *photometer_spec(const dargs *a, const char *what)
{
    const char *spec = a->cli.cfg.photometer[0] ? a->cli.cfg.photometer : NULL;
    if (!spec) {
        fprintf(stderr, "csfcal: %s: no photometer: give --photometer SPEC, or set photometer = SPEC in the "
                        "station configuration (csfcal devices lists the instruments it finds; "
                        "--photometer sim:display=lcd measures a simulated monitor instead)\n", what);
        return NULL;
    }
    if (strncmp(spec, "sim", 3) == 0 && (spec[3] == 0 || spec[3] == ':'))
        fprintf(stderr, "csfcal: %s: note: photometer '%s' (from %s) is the SIMULATOR: no light of this "
                        "monitor is measured\n", what, spec,
                a->photometer_given ? "--photometer" : a->cli.cfg.source);
    return spec;
}

/* ---- --render: patches drawn through the presenter, the simulator reads the rendered frame ----
 * The calibration's show_patch hook draws the first frame of the patch. For the simulated
 * photometer it then installs a screen source whose pixels callback (run inside the reading)
 * draws the rest of the frames the instrument integrates (integration time x refresh rate) and
 * hands over the patch's framebuffer levels from every one of them; the simulator averages the
 * light of all those pixels through its display model, as a sensor integrates over space and time.
 * Without --render (or when no presenter opens) the simulator is told the drive values. */
typedef struct {
    csf_presenter *pres;
    csf_photometer *ph;
    csf_patch patch;
    int simulated;
    int frames;          /* frames per reading */
    int rw, rh, bits;
    int px, py, pw, ph_; /* patch rectangle in readback coordinates */
    uint16_t *frame;     /* one readback, rw*rh*3 */
    void *buf;           /* collected patch pixels: unsigned char (8 bit) or uint16_t */
    size_t n_px, cap_px;
    long frames_drawn;
    double wall_s;
    csf_error err;
    int failed;
} render_ctx;

static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Draws one frame of the current patch and, for the simulator, appends its patch pixels. */
static csf_status render_frame(render_ctx *r)
{
    double t0 = wall_now();
    csf_status st = csf_presenter_draw_patch(r->pres, &r->patch, NULL, &r->err);
    if (!st && r->simulated) {
        st = csf_presenter_readback_levels(r->pres, r->frame, &r->err);
        if (!st) {
            size_t need = r->n_px + (size_t)r->pw * r->ph_;
            if (need > r->cap_px) {
                size_t cap = need * 2;
                void *nb = realloc(r->buf, cap * 3 * (r->bits <= 8 ? 1 : sizeof(uint16_t)));
                if (!nb) return csf_error_set(&r->err, CSF_E_NOMEM, "out of memory");
                r->buf = nb;
                r->cap_px = cap;
            }
            for (int y = r->py; y < r->py + r->ph_; y++) {
                const uint16_t *row = r->frame + ((size_t)y * r->rw + r->px) * 3;
                size_t o = r->n_px * 3;
                for (int i = 0; i < r->pw * 3; i++) {
                    if (r->bits <= 8) ((unsigned char *)r->buf)[o + i] = (unsigned char)row[i];
                    else ((uint16_t *)r->buf)[o + i] = row[i];
                }
                r->n_px += (size_t)r->pw;
            }
        }
    }
    r->frames_drawn++;
    r->wall_s += wall_now() - t0;
    return st;
}

static csf_status rendered_pixels(void *user, const void **rgb, size_t *n_px, int *bits)
{
    render_ctx *r = user;
    for (int f = 1; f < r->frames; f++) {
        if (render_frame(r)) {
            r->failed = 1;
            return r->err.code ? r->err.code : CSF_E_DEVICE;
        }
    }
    *rgb = r->buf;
    *n_px = r->n_px;
    *bits = r->bits;
    return CSF_OK;
}

static int render_show_patch(void *user, const double rgb01[3], uint64_t reading_index)
{
    render_ctx *r = user;
    /* each reading's frames are numbered from its reading index, so the dither a reading
     * integrates does not depend on what was drawn before it (a resumed session draws exactly
     * what the uninterrupted one drew) */
    csf_presenter_set_frame_index(r->pres, (long)(reading_index * (uint64_t)r->frames));
    for (int c = 0; c < 3; c++) r->patch.drive01[c] = rgb01[c] < 0 ? 0 : rgb01[c] > 1 ? 1 : rgb01[c];
    r->n_px = 0;
    if (render_frame(r)) {
        r->failed = 1;
        return 1;
    }
    if (r->simulated) {
        csf_screen_source src = {NULL, rendered_pixels, r};
        csf_photometer_set_source(r->ph, &src);
    }
    return 0;
}

static void render_close(render_ctx *r)
{
    csf_presenter_close(r->pres);
    free(r->frame);
    free(r->buf);
    memset(r, 0, sizeof *r);
}

/* Opens the presenter for --render. Returns 0 (r->pres set), 1 when rendering was only the
 * default and no presenter opened (a note is printed; the caller goes on without), 2 on error. */
static int render_open(const dargs *a, csf_photometer *ph, uint64_t seed, render_ctx *r, const char *what)
{
    memset(r, 0, sizeof *r);
    int real = !(csf_photometer_caps(ph) & CSF_PHOT_CAP_SIMULATED);
    if (a->render < 0) {
        /* an emulator learns the patch from the screen mirror (CSFCAL_SCREEN_MIRROR); a real
         * instrument would measure whatever the screen happens to show */
        if (real && !getenv("CSFCAL_SCREEN_MIRROR"))
            fprintf(stderr, "csfcal: %s: warning: --no-render with a real instrument: no patch is drawn, the "
                            "instrument measures whatever the screen shows\n", what);
        return 1;
    }
    csf_error e;
    csf_error_clear(&e);
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    if (csf_geometry_init(&pc.geometry, CSF_GEOMETRY_FROM_CONFIG(a->cli.cfg), &e)) {
        fprintf(stderr, "csfcal: %s: %s\n", what, e.msg);
        return 2;
    }
    r->simulated = (csf_photometer_caps(ph) & CSF_PHOT_CAP_SIMULATED) != 0;
    if (real && a->cli.headless) {
        /* an offscreen patch is light no instrument can see */
        fprintf(stderr, "csfcal: %s: --headless with a real instrument: a photometer measures the light of "
                        "this screen, so the patches are drawn in a window on it; leave out --headless and "
                        "run on the station's display\n", what);
        return 2;
    }
    pc.headless = r->simulated; /* a real instrument looks at the real screen */
    pc.refresh_hz = a->cli.cfg.refresh_hz;
    pc.framebuffer_bits = a->cli.cfg.framebuffer_bits;
    pc.seed = seed; /* the session's: a resumed session dithers as the original did */
    if (r->simulated) {
        int w = a->render_width > 0 ? (int)a->render_width : 128;
        int h = (int)lround((double)w * pc.geometry.height_px / pc.geometry.width_px);
        pc.render_width_px = w;
        pc.render_height_px = h < 1 ? 1 : h;
    }
    if (csf_presenter_open(&pc, &r->pres, &e)) {
        if (a->render > 0 || real) {
            fprintf(stderr, "csfcal: %s: %s: %s%s\n", what, a->render > 0 ? "--render" : "drawing the patches",
                    e.msg, real ? " (a real instrument needs the patches drawn on this screen)" : "");
            return 2;
        }
        fprintf(stderr, "csfcal: note: no presenter (%s); patches are given to the simulator as drive "
                        "values (--no-render to silence this)\n", e.msg);
        return 1;
    }
    r->ph = ph;
    r->patch.size_deg = a->patch_deg_set ? a->patch_deg : 10.0;
    for (int c = 0; c < 3; c++) r->patch.bg_drive01[c] = a->background;
    csf_presenter_render_size(r->pres, &r->rw, &r->rh);
    r->bits = csf_presenter_bits(r->pres);
    if (csf_presenter_patch_rect(r->pres, &r->patch, &r->px, &r->py, &r->pw, &r->ph_, &e)) {
        fprintf(stderr, "csfcal: %s: %s\n", what, e.msg);
        render_close(r);
        return 2;
    }
    double integ = csf_photometer_integration_s(ph);
    double hz = csf_presenter_refresh_hz(r->pres);
    r->frames = integ > 0 ? (int)ceil(integ * hz - 1e-9) : 1;
    if (r->frames < 1) r->frames = 1;
    if (r->frames > 600) r->frames = 600;
    r->frame = malloc(sizeof(uint16_t) * 3 * (size_t)r->rw * r->rh);
    if (!r->frame) {
        fprintf(stderr, "csfcal: %s: out of memory\n", what);
        render_close(r);
        return 2;
    }
    return 0;
}

/* The patch against the meter's measuring field at this station's viewing distance, before the
 * first reading: refused (2) when the meter cannot fit inside it, a warning when it is far larger
 * than needed. --no-render shows no patch of ours, so there is nothing to check. */
static int check_patch_size(const dargs *a, csf_photometer *ph, const char *what)
{
    if (a->render < 0) return 0;
    csf_geometry g;
    csf_error e;
    csf_error_clear(&e);
    if (csf_geometry_init(&g, CSF_GEOMETRY_FROM_CONFIG(a->cli.cfg), &e)) {
        fprintf(stderr, "csfcal: %s: %s\n", what, e.msg);
        return 2;
    }
    double fdeg, fmm;
    csf_photometer_field(ph, &fdeg, &fmm);
    char why[600];
    double patch_deg = a->patch_deg_set ? a->patch_deg : 10.0;
    int r = csf_patch_for_meter(patch_deg, g.distance_mm, fmin(g.width_mm, g.height_mm), fdeg, fmm, why,
                                sizeof why);
    if (r == 2) {
        fprintf(stderr, "csfcal: %s: photometer %s: %s\n", what, csf_photometer_driver_name(ph), why);
        return 2;
    }
    if (r == 1)
        fprintf(stderr, "csfcal: %s: warning: photometer %s: %s\n", what, csf_photometer_driver_name(ph),
                why);
    return 0;
}

/* A real meter is put on the patch before its first reading (the placement screen); the
 * simulator needs no placing. 0: go on; otherwise the exit status (1: left with Escape, nothing
 * measured or stored; 1 also after a fault, which was printed). */
static int place_meter(const dargs *a, render_ctx *r, const char *what)
{
    if (r->simulated || a->no_placement) return 0;
    int pr = csf_display_placement(r->pres, &r->patch, r->ph, what);
    if (pr == 1)
        fprintf(stderr, "csfcal: %s: left the placement screen with Escape: nothing was measured or stored\n",
                what);
    return pr == 0 ? 0 : 1;
}

/* The refusals that need the instrument (the patch against its field, --monitor with the
 * simulator): 0 to go on, else 2, said on stderr. Before anything is opened or written. */
static int refuse_patches(const dargs *a, csf_photometer *ph, const char *what)
{
    if (check_patch_size(a, ph, what)) return 2;
    if ((csf_photometer_caps(ph) & CSF_PHOT_CAP_SIMULATED) &&
        csf_cli_refuse_monitor(&a->cli, what, "the simulated photometer measures patches drawn offscreen"))
        return 2;
    return 0;
}

/* Everything between the refusals and the first reading: the presenter (*ro as render_open
 * returns it), the placement screen. 0 to go on (the presenter open when *ro is 0), else the exit
 * status, with nothing left open but ph. */
static int prepare_patches(const dargs *a, csf_photometer *ph, uint64_t seed, render_ctx *r, int *ro,
                           const char *what)
{
    *ro = render_open(a, ph, seed, r, what);
    if (*ro == 2) return 1;
    int placed = *ro == 0 ? place_meter(a, r, what) : 0;
    if (placed) render_close(r);
    return placed;
}

/* A session the calibration took off the resumable list (damaged stored settings), or one in a
 * state this build does not know (which it never resumes), gets no resume hint. */
static int session_aborted(csf_store *store, int64_t sid)
{
    csf_session_info si;
    csf_error e;
    memset(&si, 0, sizeof si);
    if (csf_store_get_session(store, sid, &si, &e) != CSF_OK) return 0;
    int aborted = si.state == CSF_SESSION_ABORTED || si.state == CSF_SESSION_STATE_UNKNOWN;
    csf_session_info_free(&si);
    return aborted;
}

/* What a finished calibration reports. */
typedef struct {
    const char *spec, *out, *rinfo;
    const csf_display_profile *p;
    const csf_display_calib_result *res;
    double target_rel, wall_s;
    int budget;
    int64_t sid;
    int simulated, rendered;
} calib_report;

static void print_calibration_json(const calib_report *r)
{
    static const char *chn[CSF_CH_COUNT] = {"r", "g", "b", "grey"};
    const csf_display_calib_result *res = r->res;
    /* the session's own setting decides on --resume (stored), not this command line */
    int has_ch = csf_profile_has_channels(r->p);
    printf("{\"profile_id\": ");
    json_str(stdout, csf_profile_id(r->p));
    printf(", \"out\": ");
    json_str(stdout, r->out);
    printf(", \"session\": %lld, \"photometer\": ", (long long)r->sid);
    json_str(stdout, r->spec);
    printf(", \"simulated\": %s, \"black_cdm2\": ", r->simulated ? "true" : "false");
    json_num(stdout, csf_profile_lum_black(r->p));
    printf(", \"white_cdm2\": ");
    json_num(stdout, csf_profile_lum_max(r->p));
    printf(", \"readings\": %d, \"sweep_readings\": %d, \"warmup_readings\": %d, \"check_readings\": %d, "
           "\"warmup_stable\": %s",
           res->n_readings, res->n_sweep, res->n_warmup, res->n_check, res->warmup_stable ? "true" : "false");
    printf(", \"target_rel\": ");
    json_num(stdout, r->target_rel);
    printf(", \"error_indicator_rel\": {");
    for (int c = CSF_CH_GREY, k = 0; k < (has_ch ? 4 : 1); k++, c = k - 1) {
        printf("%s\"%s\": ", k ? ", " : "", chn[c]);
        json_num(stdout, res->est_error_rel[c]);
    }
    printf("}, \"met_error_rel\": {");
    for (int c = CSF_CH_GREY, k = 0; k < (has_ch ? 4 : 1); k++, c = k - 1) {
        printf("%s\"%s\": ", k ? ", " : "", chn[c]);
        json_num(stdout, res->met_error_rel[c]);
    }
    printf("}, \"check_error_rel\": {");
    for (int c = CSF_CH_GREY, k = 0; k < (has_ch ? 4 : 1); k++, c = k - 1) {
        printf("%s\"%s\": ", k ? ", " : "", chn[c]);
        json_num(stdout, res->check_error_rel[c]);
    }
    printf("}, \"target_met\": %s, \"checks_raised\": %s, \"budget\": %d, \"noise_rel\": ",
           res->target_met ? "true" : "false", res->checks_raised ? "true" : "false", r->budget);
    json_num(stdout, res->noise_rel);
    printf(", \"drift_rel\": ");
    json_num(stdout, res->drift_rel);
    printf(", \"additivity_error\": ");
    json_num(stdout, has_ch ? res->additivity_error : NAN);
    printf(", \"monotonic\": %s, \"rendered\": %s", res->monotonic_violations ? "false" : "true",
           r->rendered ? "true" : "false");
    printf(", \"wall_s\": ");
    json_num(stdout, r->wall_s);
    printf("}\n");
}

/* The largest of a result's per-curve figures (NaN entries: curves not measured). */
static double worst_curve(const double v[CSF_CH_COUNT])
{
    double worst = 0;
    for (int c = 0; c < CSF_CH_COUNT; c++)
        if (!isnan(v[c])) worst = fmax(worst, v[c]);
    return worst;
}

static void print_calibration_text(const calib_report *r)
{
    const csf_display_calib_result *res = r->res;
    int has_ch = csf_profile_has_channels(r->p);
    printf("display profile %s written to %s (session %lld)\n", csf_profile_id(r->p), r->out, (long long)r->sid);
    printf("  black %.4g cd/m2, white %.4g cd/m2\n", csf_profile_lum_black(r->p), csf_profile_lum_max(r->p));
    printf("  readings: %d sweep (grey + channels), %d spot checks, %d in all (%d warm-up%s)\n", res->n_sweep,
           res->n_check, res->n_readings, res->n_warmup, res->warmup_stable ? "" : ", white never settled");
    if (res->n_check > 0)
        printf("  spot checks between the levels: a systematic error of about %.3f %% at most (in the "
               "statement where it is larger than the model's)\n",
               100 * worst_curve(res->check_error_rel));
    printf("  stated max error above 10 %% of peak (noise + model; target %.3f %%, %s): grey %.3f %%",
           100 * r->target_rel, res->target_met ? "met" : "NOT MET", 100 * res->est_error_rel[CSF_CH_GREY]);
    if (has_ch)
        printf(", r %.3f %%, g %.3f %%, b %.3f %%", 100 * res->est_error_rel[0], 100 * res->est_error_rel[1],
               100 * res->est_error_rel[2]);
    printf("\n  at most %.3f %% with 90 %% confidence (what \"met\" is judged on)",
           100 * worst_curve(res->met_error_rel));
    printf("\n  instrument noise %.3f %%, white drift during the session %+.3f %%\n", 100 * res->noise_rel,
           100 * res->drift_rel);
    if (has_ch) printf("  additivity (black + r + g + b vs white): %+.2f %%\n", 100 * res->additivity_error);
    printf("  monotonic: %s\n", res->monotonic_violations ? res->monotonic_msg : "yes");
    fputs(r->rinfo, stdout);
}

/* A resumed session: its own seed (so a simulated instrument continues the same noise sequence)
 * unless --seed says otherwise, and a warning when the display differs from the one it began on. */
static csf_status resume_calibration(const dargs *a, csf_store *store, int64_t sid, const char *spec, uint64_t *seed,
                                     csf_error *err)
{
    csf_session_info si;
    memset(&si, 0, sizeof si);
    csf_status st = csf_store_get_session(store, sid, &si, err);
    if (st != CSF_OK) return st;
    if (!a->cli.seed_set) *seed = si.seed;
    const char *now = a->name ? a->name : spec;
    if (strncmp(si.display, now, sizeof si.display - 1) != 0)
        fprintf(stderr, "csfcal: warning: session %lld was measured on '%s', resuming with '%s': "
                        "the profile mixes both if they are different monitors\n",
                (long long)sid, si.display, now);
    csf_session_info_free(&si);
    return CSF_OK;
}

/* The calibration's options from the command line. */
static void calibration_options(const dargs *a, csf_display_calib_opts *o)
{
    csf_display_calib_defaults(o);
    if (a->target > 0) o->target_rel = a->target;
    if (a->budget > 0) o->budget = (int)a->budget;
    if (a->checks >= 0) o->checks = (int)a->checks;
    if (a->warmup_wait_s >= 0) o->warmup_wait_s = a->warmup_wait_s;
    o->channels = !a->no_channels;
    o->display_name = a->name;
    o->progress = !a->quiet && isatty(2);
}

/* A calibration that ran on a monitor the warm-up check never called warm: how much drift the
 * settling model still expects, and how long it expected the monitor to take. */
static void warn_not_warm(const csf_display_calib_result *res, double target_rel)
{
    if (res->warmup_remaining_rel > 0 && isfinite(res->warmup_wait_s))
        fprintf(stderr,
                "csfcal: warning: the monitor was not warm after the warm-up check: white would still "
                "move %.2f %% during an hour's session (the target is %.3f %%); it was expected to "
                "settle in about %.0f s more; the profile may drift\n",
                100 * res->warmup_remaining_rel, 100 * target_rel, res->warmup_wait_s);
    else
        fprintf(stderr,
                "csfcal: warning: white did not settle during the warm-up check; the profile may drift\n");
}

/* The line on how the patches were shown; closes the renderer (NULL: nothing was drawn). */
static void render_info(render_ctx *rctx, int simulated, double t_cal, char *rinfo, size_t len)
{
    if (rctx) {
        snprintf(rinfo, len,
                 "  rendered: %ld frames of a %d x %d px patch (%d frames per reading, "
                 "%d-bit, %d x %d render), %.2f s drawing, %.2f s in all\n",
                 rctx->frames_drawn, rctx->pw, rctx->ph_, rctx->frames, rctx->bits, rctx->rw, rctx->rh,
                 rctx->wall_s, t_cal);
        render_close(rctx);
    } else {
        snprintf(rinfo, len,
                 simulated ? "  not rendered: the simulator was told the drive values (%.2f s)\n"
                           : "  not rendered: nothing was drawn (%.2f s)\n",
                 t_cal);
    }
}

/* After a failure that kept readings: the command that finishes the session. It is pasted into a
 * shell: its words are quoted for one. */
static void print_calibration_resume(const dargs *a, const char *store_path, const char *spec, int64_t sid,
                                     int n_readings)
{
    char where[1024];
    csf_store_redact(store_path, where, sizeof where);
    char *qs = csf_shell_quote(store_path), *qo = csf_shell_quote(a->out), *qp = csf_shell_quote(spec);
    fprintf(stderr,
            "csfcal: %d readings kept in session %lld of %s; after fixing the cause, finish it with:\n"
            "  csfcal display calibrate --resume %lld --store %s --photometer %s --out %s\n",
            n_readings, (long long)sid, where, (long long)sid, qs ? qs : "?", qp ? qp : "?", qo ? qo : "?");
    free(qs);
    free(qo);
    free(qp);
}

/* What a finished calibration should warn of: a curve that had to be made monotonic, a display
 * not warm, a target the budget did not meet. */
static void warn_calibration(const csf_display_calib_result *res, const csf_display_calib_opts *o)
{
    if (res->monotonic_violations) fprintf(stderr, "csfcal: warning: %s\n", res->monotonic_msg);
    if (!res->warmup_stable) warn_not_warm(res, o->target_rel);
    if (!res->target_met) {
        double worst = worst_curve(res->est_error_rel), met = worst_curve(res->met_error_rel);
        if (res->checks_raised) /* structure finer than the levels is not what more sweep readings remove */
            fprintf(stderr,
                    "csfcal: warning: target not met: the sweep met the target %.3f %% at its levels, but "
                    "the spot checks between them show a systematic error the levels cannot follow (a "
                    "LUT's ripple, dithered native levels, a clipped channel): stated error %.3f %% (at "
                    "most %.3f %% with 90 %% confidence; the profile records it). The display's own curve "
                    "is rougher than the target; a larger --budget would not meet it\n",
                    100 * o->target_rel, 100 * worst, 100 * met);
        else
            fprintf(
                stderr,
                "csfcal: warning: target not met: the budget of %d sweep readings ended with a stated "
                "error of %.3f %% (at most %.3f %% with 90 %% confidence) against the target %.3f %% (the "
                "profile records it); a larger --budget or a quieter instrument would meet it\n",
                o->budget, 100 * worst, 100 * met, 100 * o->target_rel);
    }
}

static int cmd_calibrate(dargs *a)
{
    if (!a->out) {
        fprintf(stderr, "csfcal: display calibrate: --out PROFILE is required\n");
        return 2;
    }
    const char *spec = photometer_spec(a, "display calibrate");
    if (!spec) return 2;
    csf_error err;
    csf_error_clear(&err);
    /* before the first reading: a calibration takes minutes of the instrument's time */
    if (csf_check_output_path(a->out, "display profile", &err) != CSF_OK) {
        csf_cli_report("display calibrate", &err);
        return 2;
    }
    csf_display_calib_opts o;
    calibration_options(a, &o);
    const char *store_path = csf_cli_store_path(&a->cli);
    csf_store *store = NULL;
    csf_status st = CSF_OK;
    int64_t sid = a->cli.resume_id;
    uint64_t seed = a->cli.seed;
    csf_photometer *ph = NULL;
    /* a resumed session's seed is in its store; a new session's store is opened (and made) only
     * once the instrument is known to fit the patch, so a refusal leaves no empty store behind */
    if (sid > 0 && (st = csf_store_open(store_path, &store, &err)) == CSF_OK)
        st = resume_calibration(a, store, sid, spec, &seed, &err);
    if (st == CSF_OK) st = csf_photometer_open(spec, seed, &ph, &err);
    if (st) {
        csf_store_close(store);
        return csf_cli_report("display calibrate", &err);
    }
    if (refuse_patches(a, ph, "display calibrate")) {
        csf_photometer_close(ph);
        csf_store_close(store);
        return 2;
    }
    if (!store && csf_store_open(store_path, &store, &err) != CSF_OK) {
        csf_photometer_close(ph);
        return csf_cli_report("display calibrate", &err);
    }
    int simulated = (csf_photometer_caps(ph) & CSF_PHOT_CAP_SIMULATED) != 0;
    render_ctx rctx;
    int ro, rc_early = prepare_patches(a, ph, seed, &rctx, &ro, "display calibrate");
    if (rc_early) {
        csf_photometer_close(ph);
        csf_store_close(store);
        return rc_early;
    }
    if (ro == 0) {
        o.show_patch = render_show_patch;
        o.show_patch_user = &rctx;
    }
    csf_display_profile *p = NULL;
    csf_display_calib_result res;
    double t_cal0 = wall_now();
    st = csf_display_calibrate(ph, &o, store, &sid, seed, &p, &res, &err);
    double t_cal = wall_now() - t_cal0;
    if (st && ro == 0 && rctx.failed && rctx.err.msg[0])
        fprintf(stderr, "csfcal: display calibrate: drawing the patch: %s\n", rctx.err.msg);
    char rinfo[300] = "";
    render_info(ro == 0 ? &rctx : NULL, simulated, t_cal, rinfo, sizeof rinfo);
    csf_photometer_close(ph);
    if (st) {
        int rc = csf_cli_report("display calibrate", &err);
        if (sid > 0 && !session_aborted(store, sid))
            print_calibration_resume(a, store_path, spec, sid, res.n_readings);
        csf_store_close(store);
        return rc;
    }
    st = csf_profile_save(p, a->out, &err);
    if (st == CSF_OK) {
        csf_error e2;
        csf_store_add_artifact(store, sid, "profile", a->out, NULL, 0, &e2);
    }
    csf_store_close(store);
    if (st) {
        csf_profile_free(p);
        return csf_cli_report("display calibrate", &err);
    }
    calib_report r = {spec, a->out, rinfo, p, &res, o.target_rel, t_cal, o.budget, sid, simulated, ro == 0};
    if (a->cli.json) print_calibration_json(&r);
    else if (!a->quiet) print_calibration_text(&r);
    warn_calibration(&res, &o);
    csf_profile_free(p);
    return 0;
}

static int load_profile(const char *path, csf_display_profile **p)
{
    csf_error err;
    csf_error_clear(&err);
    if (csf_profile_load(path, p, &err)) return csf_cli_report("display", &err);
    return 0;
}

/* Why verify did not call the monitor warm, and how long the settling model expects it to take. */
static void print_not_warm(const csf_display_profile *p, const csf_display_verify_result *vr)
{
    printf("profile %s: the monitor is NOT WARM YET after %.0f s (%d readings): ", csf_profile_id(p),
           vr->warmup_s, vr->n_warmup);
    if (vr->warmup_remaining_rel > 0 && isfinite(vr->warmup_wait_s))
        printf("white is %.2f %% from where it settles and would move %.2f %% during an hour's session; "
               "expected wait about %.0f s more\n",
               100 * vr->warmup_settled_gap_rel, 100 * vr->warmup_remaining_rel, vr->warmup_wait_s);
    else if (vr->warmup_remaining_rel > 0)
        printf("white keeps drifting without settling; check the monitor's power saving and dimming\n");
    else
        printf("white still changed by %.2f %% between the last readings; verify again when it has been on "
               "longer\n",
               100 * vr->warmup_change_rel);
}

/* verify's result as one JSON object on stdout. */
static void print_verify_json(const csf_display_profile *p, const char *spec,
                              const csf_display_verify_result *r, const char *verdict, double tol)
{
    const csf_display_verify_result vr = *r;
    static const char *chn[CSF_CH_COUNT] = {"r", "g", "b", "grey"};
    printf("{\"profile_id\": ");
    json_str(stdout, csf_profile_id(p));
    printf(", \"photometer\": ");
    json_str(stdout, spec);
    printf(", \"verdict\": \"%s\", \"warm\": %s, \"warmup_readings\": %d, \"warmup_s\": ", verdict,
           vr.warm ? "true" : "false", vr.n_warmup);
    json_num(stdout, vr.warmup_s);
    printf(", \"warmup_change_rel\": ");
    json_num(stdout, vr.warmup_change_rel);
    json_field(", \"warmup_remaining_rel\": ", vr.warmup_remaining_rel);
    json_field(", \"warmup_expected_wait_s\": ", vr.warmup_wait_s);
    printf(", \"white_dev_rel\": ");
    json_num(stdout, vr.white_dev_rel);
    printf(", \"max_dev_rel\": ");
    json_num(stdout, vr.max_dev_rel);
    printf(", \"tolerance_rel\": ");
    json_num(stdout, tol);
    printf(", \"curves\": {");
    int first = 1;
    for (int c = 0; c < CSF_CH_COUNT; c++) {
        if (!isfinite(vr.dev_rel[c])) continue;
        printf("%s\"%s\": {\"max_dev_rel\": ", first ? "" : ", ", chn[c]);
        json_num(stdout, vr.dev_rel[c]);
        printf(", \"levels\": %d}", vr.n_checked[c]);
        first = 0;
    }
    printf("}, \"readings\": %d, \"profile_target_met\": %s, \"profile_stated_rel\": ", vr.n_readings,
           vr.profile_target_met < 0 ? "null"
           : vr.profile_target_met   ? "true"
                                     : "false");
    json_num(stdout, vr.profile_stated_rel);
    printf(", \"allowed_dev_rel\": ");
    json_num(stdout, vr.allowed_dev_rel);
    printf(", \"within_stated\": %s}\n", vr.within_stated < 0 ? "null" : vr.within_stated ? "true" : "false");
}

/* verify's result for a person. */
static void print_verify_text(const dargs *a, const csf_display_profile *p,
                              const csf_display_verify_result *r, int drifted, double tol)
{
    const csf_display_verify_result vr = *r;
    if (!vr.warm) print_not_warm(p, &vr);
    printf("profile %s: white %+.2f %%, largest deviation above 10%% of peak %.2f %% (tolerance %.2f %%)",
           csf_profile_id(p), 100 * vr.white_dev_rel, 100 * vr.max_dev_rel, 100 * tol);
    if (a->channels)
        printf(" [grey %.2f %%, r %.2f %%, g %.2f %%, b %.2f %%]", 100 * vr.dev_rel[CSF_CH_GREY],
               100 * vr.dev_rel[0], 100 * vr.dev_rel[1], 100 * vr.dev_rel[2]);
    printf(": %s\n", !vr.warm ? "NOT WARM, not verified" : drifted ? "DRIFTED, recalibrate" : "ok");
    if (vr.within_stated >= 0)
        printf("  the profile states %.3f %% (target %s); a profile that good shows up to %.3f %% here: "
               "%s\n",
               100 * vr.profile_stated_rel, vr.profile_target_met ? "met" : "NOT met",
               100 * vr.allowed_dev_rel, vr.within_stated ? "agrees" : "WORSE THAN STATED");
}

static int cmd_verify(dargs *a)
{
    if (!a->file) {
        fprintf(stderr, "csfcal: display verify: give the PROFILE to check\n");
        return 2;
    }
    const char *spec = photometer_spec(a, "display verify");
    if (!spec) return 2;
    csf_display_profile *p;
    int rc = load_profile(a->file, &p);
    if (rc) return rc;
    age_warning(p, &a->cli);
    if (a->channels && !csf_profile_has_channels(p)) {
        fprintf(stderr, "csfcal: display verify: --channels: profile %s has no r, g, b curves (it was "
                        "calibrated with --no-channels); verify grey only, or calibrate with channels\n",
                csf_profile_id(p));
        csf_profile_free(p);
        return 2;
    }
    csf_error err;
    csf_error_clear(&err);
    csf_photometer *ph;
    if (csf_photometer_open(spec, a->cli.seed, &ph, &err)) {
        csf_profile_free(p);
        return csf_cli_report("display verify", &err);
    }
    render_ctx rctx;
    int ro = 1, rc_early = refuse_patches(a, ph, "display verify");
    if (!rc_early) rc_early = prepare_patches(a, ph, a->cli.seed, &rctx, &ro, "display verify");
    if (rc_early) {
        csf_photometer_close(ph);
        csf_profile_free(p);
        return rc_early;
    }
    double tol = a->tol > 0 ? a->tol : 0.02;
    csf_display_verify_opts vo;
    csf_display_verify_defaults(&vo);
    if (a->levels > 0) vo.n_levels = (int)a->levels;
    if (a->warmup_wait_s >= 0) vo.warmup_wait_s = a->warmup_wait_s;
    vo.channels = a->channels;
    if (ro == 0) {
        vo.show_patch = render_show_patch;
        vo.show_patch_user = &rctx;
    }
    csf_display_verify_result vr;
    csf_status st = csf_display_verify_run(ph, p, &vo, &vr, &err);
    if (st && ro == 0 && rctx.failed && rctx.err.msg[0])
        fprintf(stderr, "csfcal: display verify: drawing the patch: %s\n", rctx.err.msg);
    if (ro == 0) render_close(&rctx);
    csf_photometer_close(ph);
    if (st) {
        csf_profile_free(p);
        return csf_cli_report("display verify", &err);
    }
    int drifted = vr.max_dev_rel > tol;
    /* a display still warming up is neither "ok" nor "drifted": say so, and fail */
    const char *verdict = !vr.warm ? "not_warm" : drifted ? "drifted" : "ok";
    if (a->cli.json) print_verify_json(p, spec, &vr, verdict, tol);
    else print_verify_text(a, p, &vr, drifted, tol);
    if (vr.profile_target_met == 0)
        fprintf(stderr,
                "csfcal: warning: profile %s states that its calibration's budget ended before the target "
                "(stated %.3f %%)\n",
                csf_profile_id(p), 100 * vr.profile_stated_rel);
    csf_profile_free(p);
    return vr.warm && !drifted ? 0 : 1;
}

static int cmd_export(dargs *a)
{
    if (!a->file || !a->format) {
        fprintf(stderr, "csfcal: display export: give PROFILE and --format clf|ctf|cube|icc|ocio\n");
        return 2;
    }
    int f = csf_export_format_from_name(a->format);
    if (f < 0) {
        fprintf(stderr, "csfcal: display export: unknown format '%s' (clf, ctf, cube, icc, ocio)\n", a->format);
        return 2;
    }
    if (a->icc_version && f != CSF_EXPORT_ICC) {
        fprintf(stderr, "csfcal: display export: --icc-version applies to --format icc only\n");
        return 2;
    }
    csf_display_profile *p;
    int rc = load_profile(a->file, &p);
    if (rc) return rc;
    age_warning(p, &a->cli);
    char out[1200];
    if (a->out) {
        snprintf(out, sizeof out, "%s", a->out);
    } else {
        /* PROFILE with its extension replaced */
        snprintf(out, sizeof out, "%s", a->file);
        char *dot = strrchr(out, '.'), *slash = strrchr(out, '/');
        if (dot && (!slash || dot > slash)) *dot = 0;
        strncat(out, csf_export_extension((csf_export_format)f), sizeof out - strlen(out) - 1);
    }
    csf_error err;
    csf_error_clear(&err);
    csf_export_options opt = {(int)a->icc_version};
    csf_status st = csf_colour_export(p, (csf_export_format)f, &opt, out, &err);
    csf_profile_free(p);
    if (st) return csf_cli_report("display export", &err);
    if (a->cli.json) {
        printf("{\"wrote\": ");
        json_str(stdout, out);
        printf(", \"format\": \"%s\"}\n", a->format);
    } else {
        printf("wrote %s\n", out);
    }
    return 0;
}

static int cmd_info(dargs *a)
{
    if (!a->file) {
        fprintf(stderr, "csfcal: display info: give the PROFILE\n");
        return 2;
    }
    csf_display_profile *p;
    int rc = load_profile(a->file, &p);
    if (rc) return rc;
    age_warning(p, &a->cli);
    /* "% of white": luminance over white, black included, as in every export (csf_profile_rel_lum) */
    static const double pct[3] = {0.1, 0.5, 0.9};
    double drv[3];
    for (int i = 0; i < 3; i++) drv[i] = csf_profile_grey_drive(p, csf_profile_lum_from_rel(p, pct[i]));
    if (a->cli.json) {
        printf("{\"id\": ");
        json_str(stdout, csf_profile_id(p));
        printf(", \"created_utc\": ");
        json_str(stdout, csf_profile_created_utc(p));
        printf(", \"age_days\": ");
        json_num(stdout, csf_profile_age_days(p));
        printf(", \"instrument\": ");
        json_str(stdout, csf_profile_instrument(p));
        printf(", \"black_cdm2\": ");
        json_num(stdout, csf_profile_lum_black(p));
        printf(", \"white_cdm2\": ");
        json_num(stdout, csf_profile_lum_max(p));
        printf(", \"channels\": %s, \"additivity_error\": ", csf_profile_has_channels(p) ? "true" : "false");
        json_num(stdout, csf_profile_additivity_error(p));
        printf(", \"knots\": {\"grey\": %zu", csf_profile_knots(p, CSF_CH_GREY, NULL, NULL));
        if (csf_profile_has_channels(p))
            printf(", \"r\": %zu, \"g\": %zu, \"b\": %zu", csf_profile_knots(p, 0, NULL, NULL),
                   csf_profile_knots(p, 1, NULL, NULL), csf_profile_knots(p, 2, NULL, NULL));
        printf("}, \"readings\": %zu, \"grey_drive_for_rel_lum\": {\"0.1\": ", csf_profile_readings(p, NULL));
        json_num(stdout, drv[0]);
        printf(", \"0.5\": ");
        json_num(stdout, drv[1]);
        printf(", \"0.9\": ");
        json_num(stdout, drv[2]);
        printf("}, \"rel_lum\": \"L / white (black included)\"}\n");
        csf_profile_free(p);
        return 0;
    }
    printf("id: %s\ncreated: %s (%.1f days ago)\ninstrument: %s\nblack: %.6g cd/m2\nwhite: %.6g cd/m2\n",
           csf_profile_id(p), csf_profile_created_utc(p), csf_profile_age_days(p), csf_profile_instrument(p),
           csf_profile_lum_black(p), csf_profile_lum_max(p));
    printf("channels: %s\nadditivity error: %.3f %%\nknots: grey %zu", csf_profile_has_channels(p) ? "r, g, b" : "none",
           100 * csf_profile_additivity_error(p), csf_profile_knots(p, CSF_CH_GREY, NULL, NULL));
    if (csf_profile_has_channels(p))
        printf(", r %zu, g %zu, b %zu", csf_profile_knots(p, 0, NULL, NULL), csf_profile_knots(p, 1, NULL, NULL),
               csf_profile_knots(p, 2, NULL, NULL));
    printf("\nreadings: %zu\ngrey drive for 10/50/90 %% of white (L / white, black included): %.4f %.4f %.4f\n",
           csf_profile_readings(p, NULL), drv[0], drv[1], drv[2]);
    csf_profile_free(p);
    return 0;
}

#define OPTBIT(o) (1ul << ((o) - OPT_OUT))
/* An option of another subcommand (calibrate --tolerance, verify --budget, info --out) would be
 * silently ignored: refuse it, naming it. */
static int refuse_foreign_options(const char *sub, const dargs *a)
{
    static const struct {
        const char *sub;
        unsigned long ok;
    } allowed[] = {
        {"calibrate", OPTBIT(OPT_OUT) | OPTBIT(OPT_TARGET) | OPTBIT(OPT_BUDGET) | OPTBIT(OPT_NOCH) |
                          OPTBIT(OPT_NAME) | OPTBIT(OPT_QUIET) | OPTBIT(OPT_RENDER) | OPTBIT(OPT_NORENDER) |
                          OPTBIT(OPT_PATCHDEG) | OPTBIT(OPT_BG) | OPTBIT(OPT_RWIDTH) | OPTBIT(OPT_WARMWAIT) |
                          OPTBIT(OPT_NOPLACE) | OPTBIT(OPT_CHECKS)},
        {"verify", OPTBIT(OPT_LEVELS) | OPTBIT(OPT_TOL) | OPTBIT(OPT_CHANNELS) | OPTBIT(OPT_RENDER) |
                       OPTBIT(OPT_NORENDER) | OPTBIT(OPT_PATCHDEG) | OPTBIT(OPT_BG) | OPTBIT(OPT_RWIDTH) |
                       OPTBIT(OPT_WARMWAIT) | OPTBIT(OPT_NOPLACE)},
        {"export", OPTBIT(OPT_OUT) | OPTBIT(OPT_FORMAT) | OPTBIT(OPT_ICCVER)},
        {"info", 0},
    };
    for (size_t i = 0; i < sizeof allowed / sizeof allowed[0]; i++) {
        if (strcmp(sub, allowed[i].sub) != 0) continue;
        unsigned long extra = a->given & ~allowed[i].ok;
        if (!extra) return 0;
        for (const struct option *o = display_options; o->name; o++) {
            int bit = o->val == 'o' ? 0 : o->val - OPT_OUT;
            if (bit >= 0 && bit < 63 && (extra >> bit) & 1ul) {
                fprintf(stderr, "csfcal: display %s: --%s does not apply to %s (see csfcal display --help)\n", sub,
                        o->name, sub);
                return 1;
            }
        }
        return 1;
    }
    return 0;
}

int csf_cmd_display(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        fprintf(argc < 2 ? stderr : stdout, display_help);
        fputs(csf_cli_common_help, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const char *sub = argv[1];
    dargs a;
    memset(&a, 0, sizeof a);
    a.warmup_wait_s = -1;
    a.checks = -1;
    int rc = csf_cli_init(&a.cli, argc - 1, argv + 1);
    if (rc) return rc;
    rc = parse(argc - 1, argv + 1, &a);
    if (rc) return rc;
    if (a.help) {
        printf(display_help);
        fputs(csf_cli_common_help, stdout);
        return 0;
    }
    int nfree = argc - 1 - optind;
    if (nfree > 1) {
        fprintf(stderr, "csfcal: display %s: unexpected argument '%s'\n", sub, argv[1 + optind + 1]);
        return 2;
    }
    if (nfree == 1) a.file = argv[1 + optind];
    if (refuse_foreign_options(sub, &a)) return 2;
    if (strcmp(sub, "calibrate") == 0) {
        if (a.file) {
            fprintf(stderr, "csfcal: display calibrate: unexpected argument '%s' (the profile goes in --out)\n", a.file);
            return 2;
        }
        return cmd_calibrate(&a);
    }
    if (strcmp(sub, "verify") == 0) return cmd_verify(&a);
    if (strcmp(sub, "export") == 0) return cmd_export(&a);
    if (strcmp(sub, "info") == 0) return cmd_info(&a);
    fprintf(stderr, "csfcal: display: unknown subcommand '%s' (calibrate, verify, export, info)\n", sub);
    return 2;
}
