/* csfcal stimulus: the presenter's self-check and the local geometry of the station.
 *   csfcal stimulus check --freq F --ecc E --contrast C [--frames N] [--json]
 *                         [--photometer sim:display=lcd | --profile P]
 *   csfcal stimulus geometry [--ecc E] [--polar P] [--json]
 * The check renders offscreen, reads the frames back, turns pixels into luminance through the
 * simulated display's truth (--photometer sim:...) or a profile, and reports requested against
 * measured values plus the effective luminance resolution. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "model/display_model.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"
#include "stimuli/selfcheck.h"

enum {
    OPT_FREQ = CSF_OPT_FIRST_FREE, OPT_ECC, OPT_POLAR, OPT_CONTRAST, OPT_FRAMES, OPT_ORIENT,
    OPT_SIGMA, OPT_MEAN, OPT_LEVELS, OPT_BITS, OPT_GRATING, OPT_HELP
};

static const char usage[] =
    "usage: csfcal stimulus check --freq CPD --ecc DEG --contrast C [options]\n"
    "       csfcal stimulus geometry [--ecc DEG] [--polar DEG]\n"
    "\n"
    "check: draws a Gabor offscreen, reads the frames back and reports requested against\n"
    "measured spatial frequency, orientation, position, Michelson contrast (averaged over\n"
    "frames), mean luminance, and the effective luminance resolution in bits.\n"
    "  --freq CPD          carrier frequency (0.05 to 100 cpd; refused above the local Nyquist limit)\n"
    "  --ecc DEG           eccentricity of the patch centre (0 to 89)\n"
    "  --polar DEG         polar angle, 0 = right, 90 = up (default 0)\n"
    "  --contrast C        Michelson contrast (0.0001 to 1)\n"
    "  --orientation DEG   carrier modulation direction, 0 = vertical bars (default 0)\n"
    "  --sigma DEG         Gabor envelope sd (default 1; 0.05 to 20)\n"
    "  --grating           windowed grating (radius 3 sigma) instead of a Gabor\n"
    "  --mean CDM2         mean luminance (default: middle of the display's range)\n"
    "  --frames N          frames averaged (default 60; 1 to 10000)\n"
    "  --levels N          random grey levels for the resolution check (default 16; 0 = skip)\n"
    "  --bits 8|10         framebuffer depth (default from the configuration)\n"
    "Luminance truth: --photometer sim[:display=crt|lcd|oled|file=PATH.csv,lmax=,black=,gamma=]\n"
    "uses that simulated display (and, without --profile, its exact curve as the profile);\n"
    "--profile FILE uses a measured profile; neither uses the documented default display.\n"
    "\n"
    "geometry: local pixels per degree and Nyquist limit at an eccentricity, screen reach.\n";

/* Display-model spec from a simulated photometer spec: display=/file= and the model keys;
 * the instrument's own keys (noise, drift, ...) do not affect pixels and are skipped. */
static int model_spec_from_photometer(const char *phot, char *out, size_t len)
{
    if (csf_display_model_spec_from_sim_photometer(phot, out, len) != 0) {
        fprintf(stderr,
                "csfcal: stimulus check: --photometer '%s': only simulated photometers (sim[:...]) "
                "have a known display truth; use --profile with a real one\n", phot);
        return -1;
    }
    return 0;
}

static double model_lum(void *ctx, double r, double g, double b)
{
    return csf_display_model_lum((const csf_display_model *)ctx, r, g, b);
}
static double model_grey(void *ctx, double d)
{
    return csf_display_model_lum((const csf_display_model *)ctx, d, d, d);
}
/* Profile as truth: grey pixels through the grey curve; mixed pixels additively from channels. */
static double profile_lum(void *ctx, double r, double g, double b)
{
    const csf_display_profile *p = ctx;
    if (r == g && g == b) return csf_profile_grey_lum(p, r);
    if (!csf_profile_has_channels(p)) return csf_profile_grey_lum(p, (r + g + b) / 3);
    return csf_profile_lum_black(p) + csf_profile_channel_lum(p, 0, r) +
           csf_profile_channel_lum(p, 1, g) + csf_profile_channel_lum(p, 2, b);
}

static int cmd_geometry(csf_cli *cli, double ecc, double polar)
{
    csf_geometry g;
    csf_error e;
    if (csf_geometry_init(&g, CSF_GEOMETRY_FROM_CONFIG(cli->cfg), &e)) return csf_cli_report("stimulus geometry", &e);
    double rad, tan_, x, y;
    csf_geometry_px_per_deg(&g, ecc, polar, &rad, &tan_);
    double ny = csf_geometry_nyquist_cpd_any(&g, ecc, polar), reach = csf_geometry_max_ecc(&g, polar);
    int on = csf_geometry_deg_to_mm(&g, ecc, polar, &x, &y) && csf_geometry_on_screen(&g, x, y);
    if (cli->json) {
        printf("{\"ecc_deg\": %.6g, \"polar_deg\": %.6g, \"on_screen\": %s, \"x_mm\": %.6g, \"y_mm\": %.6g, "
               "\"px_per_deg_radial\": %.6g, \"px_per_deg_tangential\": %.6g, \"nyquist_cpd\": %.6g, "
               "\"max_ecc_deg\": %.6g}\n",
               ecc, polar, on ? "true" : "false", on ? x : 0.0, on ? y : 0.0, rad, tan_, ny, reach);
    } else {
        printf("screen %.1f x %.1f mm, %d x %d px, viewing distance %.0f mm\n", g.width_mm, g.height_mm,
               g.width_px, g.height_px, g.distance_mm);
        printf("at eccentricity %.3g deg, polar %.3g deg: %s\n", ecc, polar, on ? "on screen" : "OFF SCREEN");
        printf("  pixels per degree: radial %.3f, tangential %.3f\n", rad, tan_);
        printf("  Nyquist limit (any orientation): %.3f cpd\n", ny);
        printf("  screen reaches %.3g deg along this polar angle\n", reach);
    }
    return on ? 0 : 1;
}

/* What `stimulus check` and `stimulus geometry` were asked to show. */
typedef struct {
    double freq_cpd, ecc_deg, polar_deg, contrast, orientation_deg, sigma_deg, mean_lum_cdm2;
    long frames, levels, bits;
    int grating;
} stim_args;

/* The options into a (and the station's settings into cli). Returns -1 to go on, or the exit
 * status: 0 after --help, 2 for a bad option. */
static int parse_stimulus_options(int argc, char **argv, const char *sub, csf_cli *cli, stim_args *a)
{
    static const struct option opts[] = {
        {"freq", required_argument, 0, OPT_FREQ}, {"ecc", required_argument, 0, OPT_ECC},
        {"polar", required_argument, 0, OPT_POLAR}, {"contrast", required_argument, 0, OPT_CONTRAST},
        {"frames", required_argument, 0, OPT_FRAMES}, {"orientation", required_argument, 0, OPT_ORIENT},
        {"sigma", required_argument, 0, OPT_SIGMA}, {"mean", required_argument, 0, OPT_MEAN},
        {"levels", required_argument, 0, OPT_LEVELS}, {"bits", required_argument, 0, OPT_BITS},
        {"grating", no_argument, 0, OPT_GRATING}, {"help", no_argument, 0, OPT_HELP},
        CSF_CLI_COMMON_OPTIONS, {0, 0, 0, 0}};
    *a = (stim_args){.freq_cpd = NAN, .contrast = NAN, .sigma_deg = 1, .frames = 60, .levels = 16};
    int opt;
    optind = 1;
    opterr = 1;
    while ((opt = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        int r = 0;
        switch (opt) {
        case OPT_FREQ: r = csf_parse_double(optarg, "--freq", 0.05, 100, &a->freq_cpd); break;
        case OPT_ECC: r = csf_parse_double(optarg, "--ecc", 0, 89, &a->ecc_deg); break;
        case OPT_POLAR: r = csf_parse_double(optarg, "--polar", -360, 360, &a->polar_deg); break;
        case OPT_CONTRAST: r = csf_parse_double(optarg, "--contrast", 0.0001, 1, &a->contrast); break;
        case OPT_ORIENT: r = csf_parse_double(optarg, "--orientation", -360, 360, &a->orientation_deg); break;
        case OPT_SIGMA: r = csf_parse_double(optarg, "--sigma", 0.05, 20, &a->sigma_deg); break;
        case OPT_MEAN: r = csf_parse_double(optarg, "--mean", 0.001, 10000, &a->mean_lum_cdm2); break;
        case OPT_FRAMES: r = csf_parse_int(optarg, "--frames", 1, 10000, &a->frames); break;
        case OPT_LEVELS: r = csf_parse_int(optarg, "--levels", 0, 1000, &a->levels); break;
        case OPT_BITS:
            r = csf_parse_int(optarg, "--bits", 8, 10, &a->bits);
            if (!r && a->bits != 8 && a->bits != 10) {
                fprintf(stderr, "csfcal: --bits: %ld is not 8 or 10\n", a->bits);
                r = -1;
            }
            break;
        case OPT_GRATING: a->grating = 1; break;
        case OPT_HELP: printf("%s", usage); return 0;
        default: {
            int c = csf_cli_common_option(cli, opt, optarg);
            if (c == 1) break;
            if (c == 0) fprintf(stderr, "csfcal: stimulus: unknown option (see csfcal stimulus --help)\n");
            return 2;
        }
        }
        if (r) return 2;
    }
    if (optind < argc) {
        fprintf(stderr, "csfcal: stimulus %s: unexpected argument '%s'\n", sub, argv[optind]);
        return 2;
    }
    return -1;
}

/* The luminance the check measures the rendered frame against: a simulated display's exact
 * curves, a measured profile, or the default display model. */
typedef struct {
    csf_display_model *model;
    csf_display_profile *profile, *deflt;
    csf_pixel_lum_fn lum;
    void *lum_ctx;
    char truth[700];
} lum_truth;

static void close_truth(lum_truth *t)
{
    csf_display_model_free(t->model);
    csf_profile_free(t->profile);
    csf_profile_free(t->deflt);
}

/* Opens the truth and tells the presenter what it maps luminance through. Returns -1 to go on,
 * or the exit status. */
static int open_truth(const csf_cli *cli, csf_presenter_config *pc, lum_truth *t)
{
    csf_error e;
    memset(t, 0, sizeof *t);
    const char *phot = cli->cfg.photometer;
    if (phot[0] && strncmp(phot, "sim", 3) != 0 && !cli->cfg.display_profile[0]) {
        fprintf(stderr,
                "csfcal: stimulus check: photometer '%s' is a real instrument; the check needs a "
                "known luminance truth: give --profile FILE (measured with it) or --photometer sim\n",
                phot);
        return 2;
    }
    if (phot[0] && strncmp(phot, "sim", 3) == 0) {
        char spec[700];
        if (model_spec_from_photometer(phot, spec, sizeof spec)) return 2;
        if (csf_display_model_create(spec, &t->model, &e)) return csf_cli_report("stimulus check", &e);
        snprintf(t->truth, sizeof t->truth, "simulated display %.600s", spec);
    }
    if (cli->cfg.display_profile[0]) {
        if (csf_profile_load(cli->cfg.display_profile, &t->profile, &e)) {
            close_truth(t);
            return csf_cli_report("stimulus check", &e);
        }
        pc->profile = t->profile;
    } else if (t->model) {
        pc->grey_lum_fn = model_grey; /* a perfect calibration of the simulated display */
        pc->grey_lum_ctx = t->model;
        pc->grey_lum_name = "exact curve of the simulated display";
    }
    if (!t->model && !t->profile) t->deflt = csf_profile_default();
    t->lum = t->model ? model_lum : profile_lum;
    t->lum_ctx = t->model ? (void *)t->model : t->profile ? (void *)t->profile : (void *)t->deflt;
    if (!t->model) snprintf(t->truth, sizeof t->truth, "profile %s", csf_profile_id(t->profile ? t->profile : t->deflt));
    return -1;
}

/* The requested and measured stimulus, as a table or (--json) as one object. */
static void print_check(const csf_cli *cli, const stim_args *a, csf_presenter *p, const lum_truth *t,
                        const csf_selfcheck_result *r, const csf_selfcheck_resolution *res)
{
    double black, max;
    csf_presenter_lum_range(p, &black, &max);
    double want_mean = a->mean_lum_cdm2 > 0 ? a->mean_lum_cdm2 : 0.5 * (black + max);
    double c_err = r->contrast / a->contrast - 1, f_err = r->freq_cpd / a->freq_cpd - 1;
    if (cli->json) {
        printf("{\"requested\": {\"freq_cpd\": %.6g, \"orientation_deg\": %.6g, \"ecc_deg\": %.6g, "
               "\"polar_deg\": %.6g, \"contrast\": %.6g, \"mean_lum_cdm2\": %.6g, \"frames\": %ld},\n"
               " \"measured\": {\"freq_cpd\": %.6g, \"orientation_deg\": %.6g, \"ecc_deg\": %.6g, "
               "\"polar_deg\": %.6g, \"contrast\": %.6g, \"mean_lum_cdm2\": %.6g},\n"
               " \"contrast_rel_error\": %.6g, \"freq_rel_error\": %.6g,\n"
               " \"resolution\": {\"levels\": %d, \"max_err_frac\": %.6g, \"effective_bits\": %.4g},\n"
               " \"framebuffer_bits\": %d, \"truth\": \"%s\", \"presenter_profile\": \"%s\"}\n",
               a->freq_cpd, a->orientation_deg, a->ecc_deg, a->polar_deg, a->contrast, want_mean, a->frames,
               r->freq_cpd, r->orientation_deg, r->ecc_deg, r->polar_deg, r->contrast, r->mean_lum_cdm2, c_err,
               f_err, res->levels, res->max_err_frac, res->effective_bits, csf_presenter_bits(p), t->truth,
               csf_presenter_profile_id(p));
        return;
    }
    printf("stimulus self-check (%d-bit framebuffer, %ld frames)\n", csf_presenter_bits(p), a->frames);
    printf("  luminance truth:   %s\n  presenter profile: %s\n", t->truth, csf_presenter_profile_id(p));
    printf("  %-22s %12s %12s\n", "", "requested", "measured");
    printf("  %-22s %12.5g %12.5g  (%+.2f %%)\n", "frequency (cpd)", a->freq_cpd, r->freq_cpd, 100 * f_err);
    printf("  %-22s %12.5g %12.5g\n", "orientation (deg)", a->orientation_deg, r->orientation_deg);
    printf("  %-22s %12.5g %12.5g\n", "eccentricity (deg)", a->ecc_deg, r->ecc_deg);
    printf("  %-22s %12.5g %12.5g\n", "polar angle (deg)", a->polar_deg, r->polar_deg);
    printf("  %-22s %12.5g %12.5g  (%+.2f %%)\n", "Michelson contrast", a->contrast, r->contrast, 100 * c_err);
    printf("  %-22s %12.5g %12.5g\n", "mean luminance (cd/m2)", want_mean, r->mean_lum_cdm2);
    if (a->levels > 0)
        printf("  effective luminance resolution: %.2f bits (max patch-mean error %.3g of range, "
               "%d levels x 8 frames)\n", res->effective_bits, res->max_err_frac, res->levels);
}

/* Renders the stimulus offscreen and measures it (and, with --levels, the luminance resolution). */
static int cmd_check(const csf_cli *cli, const stim_args *a)
{
    if (isnan(a->freq_cpd) || isnan(a->contrast)) {
        fprintf(stderr, "csfcal: stimulus check: --freq and --contrast are required\n");
        return 2;
    }
    csf_error e;
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    if (csf_geometry_init(&pc.geometry, CSF_GEOMETRY_FROM_CONFIG(cli->cfg), &e))
        return csf_cli_report("stimulus check", &e);
    pc.headless = 1; /* the check always renders offscreen */
    pc.refresh_hz = cli->cfg.refresh_hz;
    pc.framebuffer_bits = a->bits ? (int)a->bits : cli->cfg.framebuffer_bits;
    pc.seed = cli->seed;
    lum_truth t;
    int status = open_truth(cli, &pc, &t);
    if (status >= 0) return status;
    status = 0;
    csf_presenter *p = NULL;
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = a->grating ? CSF_STIM_GRATING : CSF_STIM_GABOR;
    s.freq_cpd = a->freq_cpd;
    s.ecc_deg = a->ecc_deg;
    s.polar_deg = a->polar_deg;
    s.contrast = a->contrast;
    s.orientation_deg = a->orientation_deg;
    s.sigma_deg = a->sigma_deg;
    s.radius_deg = a->grating ? 3 * a->sigma_deg : 0;
    s.mean_lum_cdm2 = a->mean_lum_cdm2;
    csf_selfcheck_result r;
    csf_selfcheck_resolution res;
    memset(&r, 0, sizeof r); /* printed only when csf_selfcheck_stimulus filled it (status 0) */
    memset(&res, 0, sizeof res);
    if (csf_presenter_open(&pc, &p, &e) || csf_selfcheck_stimulus(p, &s, (int)a->frames, t.lum, t.lum_ctx, &r, &e)) {
        status = csf_cli_report("stimulus check", &e);
    } else if (a->levels > 0) {
        int rw, rh;
        csf_presenter_render_size(p, &rw, &rh);
        int patch = rw < rh ? rw : rh;
        if (patch > 64) patch = 64;
        if (csf_selfcheck_resolution_run(p, (int)a->levels, 8, patch, cli->seed, t.lum, t.lum_ctx, &res, &e))
            status = csf_cli_report("stimulus check", &e);
    }
    if (status == 0) print_check(cli, a, p, &t, &r, &res);
    csf_presenter_close(p);
    close_truth(&t);
    return status;
}

int csf_cmd_stimulus(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "%s", usage);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        printf("%s\n%s", usage, csf_cli_common_help);
        return 0;
    }
    const char *sub = argv[1];
    if (strcmp(sub, "check") != 0 && strcmp(sub, "geometry") != 0) {
        fprintf(stderr, "csfcal: stimulus: unknown subcommand '%s' (check, geometry)\n", sub);
        return 2;
    }
    argc--;
    argv++;
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    stim_args a;
    rc = parse_stimulus_options(argc, argv, sub, &cli, &a);
    if (rc >= 0) return rc;
    if (!strcmp(sub, "geometry")) return cmd_geometry(&cli, a.ecc_deg, a.polar_deg);
    return cmd_check(&cli, &a);
}
