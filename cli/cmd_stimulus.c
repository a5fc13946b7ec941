/* csfcal stimulus: the presenter's self-check, the local geometry of the station, and a preview
 * of a session's stimulus (cli/cmd_stimulus_show.c).
 *   csfcal stimulus check --freq F --ecc E --contrast C [--velocity V] [--frames N] [--json]
 *                         [--photometer sim:display=lcd | --profile P]
 *   csfcal stimulus geometry [--ecc E] [--polar P] [--json]
 *   csfcal stimulus show [--freq F ...] [--windowed] [--clean] [--png FILE | --frames N --png DIR/]
 * The check renders offscreen, reads the frames back, turns pixels into luminance through the
 * simulated display's truth (--photometer sim:...) or a profile, and reports requested against
 * measured values plus the effective luminance resolution; a drifting carrier's speed and phase
 * continuity are measured from the frames' carrier phases against their presentation times. */
#include <getopt.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/motion.h"
#include "core/spec.h"
#include "cli/cmd_stimulus.h"
#include "cli/commands.h"

enum {
    OPT_FREQ = CSF_OPT_FIRST_FREE,
    OPT_ECC,
    OPT_POLAR,
    OPT_CONTRAST,
    OPT_FRAMES,
    OPT_ORIENT,
    OPT_SIGMA,
    OPT_MEAN,
    OPT_LEVELS,
    OPT_BITS,
    OPT_GRATING,
    OPT_HELP,
    OPT_VELOCITY,
    OPT_MISS_RATE,
    OPT_DROP,
    OPT_WINDOWED,
    OPT_CLEAN,
    OPT_PNG,
    OPT_QUIT_AFTER,
    OPT_KEYS,
    OPT_NO_FIX
};

static const char usage[] =
    "usage: csfcal stimulus check --freq CPD --ecc DEG --contrast C [options]\n"
    "       csfcal stimulus geometry [--ecc DEG] [--polar DEG]\n"
    "       csfcal stimulus show [--freq CPD --ecc DEG --contrast C ...] [--windowed] [--clean]\n"
    "                            [--png FILE | --frames N --png DIR/]\n"
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
    "  --velocity DPS      drifting carrier: speed in deg/s along the modulation direction (sign =\n"
    "                      direction; temporal frequency = velocity x freq, refused at or above\n"
    "                      half the refresh rate). The check then MEASURES the drift: the carrier\n"
    "                      phase fitted on every frame, unwrapped against the presentation times,\n"
    "                      gives the speed (target: within 1 %) and the phase steps (continuous:\n"
    "                      a held frame's step is 2 pi tf x its interval); exit status 1 when a\n"
    "                      target is missed\n"
    "  --drop-frame K      drifting: frame K of the trial (0 = onset) is presented one refresh late\n"
    "                      (repeatable, up to 16)\n"
    "  --miss-rate P       drifting: each frame is late by one refresh with probability P (0 to 0.5)\n"
    "Luminance truth: --photometer sim[:display=crt|lcd|oled|file=PATH.csv,lmax=,black=,gamma=]\n"
    "uses that simulated display (and, without --profile, its exact curve as the profile);\n"
    "--profile FILE uses a measured profile; neither uses the documented default display.\n"
    "\n"
    "geometry: local pixels per degree and Nyquist limit at an eccentricity, screen reach.\n"
    "\n"
    "show: draws what a session draws at these settings (Gabor or --grating, --freq (default 2),\n"
    "--ecc, --polar, --contrast (default 0.5), --sigma, --orientation, --velocity, fixation mark,\n"
    "--mean through the display profile) fullscreen (--windowed: in a desktop window). Keys:\n"
    "f/F or Right/Left frequency up/down an octave, c/C or Up/Down contrast up/down 0.1 log10,\n"
    "e/E eccentricity +-1 deg, v/V velocity +-1 deg/s, Escape or q quits. A caption line shows\n"
    "the values and the Michelson contrast measured on the frame; --clean hides it.\n"
    "  --png FILE          write one frame as PNG, headless, and exit\n"
    "  --frames N --png DIR/  write N frames DIR/frame_0000.png ... (the folder must exist)\n"
    "  --no-fixation       leave the fixation mark out (sessions draw it)\n"
    "  --quit-after-frames N  quit by itself after N frames\n"
    "  --keys KEYS         press these keys (f F c C e E v V q), one per frame, as typed\n"
    "With --json, show prints its last settings and measured contrast when it ends.\n";

/* Display-model spec from a simulated photometer spec: display=/file= and the model keys;
 * the instrument's own keys (noise, drift, ...) do not affect pixels and are skipped. */
static int model_spec_from_photometer(const char *phot, char *out, size_t len)
{
    csf_spec items;
    csf_error err;
    if (!strncmp(phot, "sim:", 4) && csf_spec_split(phot + 4, "--photometer", &items, &err) != CSF_OK) {
        fprintf(stderr, "csfcal: stimulus: %s\n", err.msg);
        return -1;
    }
    if (csf_display_model_spec_from_sim_photometer(phot, out, len) != 0) {
        fprintf(stderr,
                "csfcal: stimulus: --photometer '%s': only simulated photometers (sim[:...]) "
                "have a known display truth; use --profile with a real one\n",
                phot);
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

/* --drop-frame K: one more frame of the trial presented late. */
static int parse_drop(const char *arg, stim_args *a)
{
    if (a->n_drops >= STIM_MAX_DROPS) {
        fprintf(stderr, "csfcal: --drop-frame: at most %d frames\n", STIM_MAX_DROPS);
        return -1;
    }
    return csf_parse_int(arg, "--drop-frame", 1, 100000, &a->drop_frames[a->n_drops++]);
}

/* One option of the stimulus subcommands' own into a. Returns 0, or -1 after a message. */
static int stim_option(int opt, const char *arg, stim_args *a)
{
    switch (opt) {
    case OPT_FREQ: return csf_parse_double(arg, "--freq", 0.05, 100, &a->freq_cpd);
    case OPT_ECC: return csf_parse_double(arg, "--ecc", 0, 89, &a->ecc_deg);
    case OPT_POLAR: return csf_parse_double(arg, "--polar", -360, 360, &a->polar_deg);
    case OPT_CONTRAST: return csf_parse_double(arg, "--contrast", 0.0001, 1, &a->contrast);
    case OPT_ORIENT: return csf_parse_double(arg, "--orientation", -360, 360, &a->orientation_deg);
    case OPT_SIGMA: return csf_parse_double(arg, "--sigma", 0.05, 20, &a->sigma_deg);
    case OPT_MEAN: return csf_parse_double(arg, "--mean", 0.001, 10000, &a->mean_lum_cdm2);
    case OPT_FRAMES: a->frames_set = 1; return csf_parse_int(arg, "--frames", 1, 10000, &a->frames);
    case OPT_LEVELS: return csf_parse_int(arg, "--levels", 0, 1000, &a->levels);
    case OPT_VELOCITY: return csf_parse_double(arg, "--velocity", -1000, 1000, &a->velocity_dps);
    case OPT_MISS_RATE: return csf_parse_double(arg, "--miss-rate", 0, 0.5, &a->miss_rate);
    case OPT_DROP: return parse_drop(arg, a);
    case OPT_QUIT_AFTER: return csf_parse_int(arg, "--quit-after-frames", 1, 10000000, &a->quit_after_frames);
    case OPT_PNG: a->png = arg; return 0;
    case OPT_KEYS: a->keys = arg; return 0;
    case OPT_GRATING: a->grating = 1; return 0;
    case OPT_WINDOWED: a->windowed = 1; return 0;
    case OPT_CLEAN: a->clean = 1; return 0;
    case OPT_NO_FIX: a->no_fixation = 1; return 0;
    case OPT_BITS:
        if (csf_parse_int(arg, "--bits", 8, 10, &a->bits)) return -1;
        if (a->bits != 8 && a->bits != 10) {
            fprintf(stderr, "csfcal: --bits: %ld is not 8 or 10\n", a->bits);
            return -1;
        }
        return 0;
    default: return 1;
    }
}

int stim_parse_options(int argc, char **argv, const char *sub, csf_cli *cli, stim_args *a)
{
    static const struct option opts[] = {{"freq", required_argument, 0, OPT_FREQ},
                                         {"ecc", required_argument, 0, OPT_ECC},
                                         {"polar", required_argument, 0, OPT_POLAR},
                                         {"contrast", required_argument, 0, OPT_CONTRAST},
                                         {"frames", required_argument, 0, OPT_FRAMES},
                                         {"orientation", required_argument, 0, OPT_ORIENT},
                                         {"sigma", required_argument, 0, OPT_SIGMA},
                                         {"mean", required_argument, 0, OPT_MEAN},
                                         {"levels", required_argument, 0, OPT_LEVELS},
                                         {"bits", required_argument, 0, OPT_BITS},
                                         {"grating", no_argument, 0, OPT_GRATING},
                                         {"help", no_argument, 0, OPT_HELP},
                                         {"velocity", required_argument, 0, OPT_VELOCITY},
                                         {"miss-rate", required_argument, 0, OPT_MISS_RATE},
                                         {"drop-frame", required_argument, 0, OPT_DROP},
                                         {"windowed", no_argument, 0, OPT_WINDOWED},
                                         {"clean", no_argument, 0, OPT_CLEAN},
                                         {"png", required_argument, 0, OPT_PNG},
                                         {"quit-after-frames", required_argument, 0, OPT_QUIT_AFTER},
                                         {"keys", required_argument, 0, OPT_KEYS},
                                         {"no-fixation", no_argument, 0, OPT_NO_FIX},
                                         CSF_CLI_COMMON_OPTIONS,
                                         {0, 0, 0, 0}};
    *a = (stim_args){.freq_cpd = NAN, .contrast = NAN, .sigma_deg = 1, .frames = 60, .levels = 16};
    int opt;
    optind = 1;
    opterr = 1;
    while ((opt = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        if (opt == OPT_HELP) {
            printf("%s", usage);
            return 0;
        }
        int r = stim_option(opt, optarg, a);
        if (r < 0) return 2;
        if (r == 0) continue;
        int c = csf_cli_common_option(cli, opt, optarg);
        if (c == 1) continue;
        if (c == 0) fprintf(stderr, "csfcal: stimulus: unknown option (see csfcal stimulus --help)\n");
        return 2;
    }
    if (optind < argc) {
        fprintf(stderr, "csfcal: stimulus %s: unexpected argument '%s'\n", sub, argv[optind]);
        return 2;
    }
    return -1;
}

void stim_close_truth(stim_truth *t)
{
    csf_display_model_free(t->model);
    csf_profile_free(t->profile);
    csf_profile_free(t->deflt);
}

int stim_open_truth(const csf_cli *cli, const char *cmd, csf_presenter_config *pc, stim_truth *t)
{
    csf_error e;
    memset(t, 0, sizeof *t);
    const char *phot = cli->cfg.photometer;
    if (phot[0] && strncmp(phot, "sim", 3) != 0 && !cli->cfg.display_profile[0]) {
        fprintf(stderr,
                "csfcal: %s: photometer '%s' is a real instrument; measuring a frame needs a "
                "known luminance truth: give --profile FILE (measured with it) or --photometer sim\n",
                cmd, phot);
        return 2;
    }
    if (phot[0] && strncmp(phot, "sim", 3) == 0) {
        char spec[700];
        if (model_spec_from_photometer(phot, spec, sizeof spec)) return 2;
        if (csf_display_model_create(spec, &t->model, &e)) return csf_cli_report(cmd, &e);
        snprintf(t->truth, sizeof t->truth, "simulated display %.600s", spec);
    }
    if (cli->cfg.display_profile[0]) {
        if (csf_profile_load(cli->cfg.display_profile, &t->profile, &e)) {
            stim_close_truth(t);
            return csf_cli_report(cmd, &e);
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

void stim_from_args(const stim_args *a, csf_stimulus *s)
{
    memset(s, 0, sizeof *s);
    s->kind = a->grating ? CSF_STIM_GRATING : CSF_STIM_GABOR;
    s->freq_cpd = a->freq_cpd;
    s->ecc_deg = a->ecc_deg;
    s->polar_deg = a->polar_deg;
    s->contrast = a->contrast;
    s->orientation_deg = a->orientation_deg;
    s->sigma_deg = a->sigma_deg;
    s->radius_deg = a->grating ? 3 * a->sigma_deg : 0;
    s->mean_lum_cdm2 = a->mean_lum_cdm2;
    /* with fixation on a mark the carrier's screen velocity is its retinal velocity, and a grating
     * moving at v deg/s flickers at v f Hz at each point (Kelly 1979) */
    s->drift_hz = a->velocity_dps * a->freq_cpd;
}

int stim_check_aliasing(const stim_args *a, double refresh_hz, char *msg, size_t len)
{
    /* the sessions' own limit (calib/motion.h): v f at or above half the refresh rate aliases */
    double vmax = csf_motion_max_velocity_dps(a->freq_cpd, refresh_hz);
    if (fabs(a->velocity_dps) < vmax) return 0;
    snprintf(msg, len,
             "--velocity %g deg/s at %g cpd drifts at %g Hz, at or above half the refresh rate "
             "(%g Hz): the carrier would alias; at %g cpd the velocity must stay below %.4g deg/s",
             a->velocity_dps, a->freq_cpd, fabs(a->velocity_dps) * a->freq_cpd, 0.5 * refresh_hz, a->freq_cpd,
             vmax);
    return -1;
}

/* The requested and measured stimulus, as a table or (--json) as one object. */
static void print_check(const csf_cli *cli, const stim_args *a, csf_presenter *p, const stim_truth *t,
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

/* The drift measurement as one JSON object (through jansson: the truth names come from the
 * user's own settings). */
static void print_drift_json(const stim_args *a, csf_presenter *p, const stim_truth *t,
                             const csf_selfcheck_drift_result *r)
{
    const csf_drift_fit *f = &r->fit;
    json_t *o = json_pack(
        "{s:{s:f,s:f,s:f,s:f,s:f,s:f,s:f,s:i},s:{s:f,s:f,s:f,s:f,s:f},s:f,s:f}", "requested", "freq_cpd",
        a->freq_cpd, "orientation_deg", a->orientation_deg, "ecc_deg", a->ecc_deg, "polar_deg", a->polar_deg,
        "contrast", a->contrast, "velocity_dps", a->velocity_dps, "drift_hz", f->tf_asked_hz, "frames",
        (int)a->frames, "measured", "freq_cpd", r->freq_cpd, "contrast", r->contrast, "mean_lum_cdm2",
        r->mean_lum_cdm2, "velocity_dps", r->speed_measured_dps, "drift_hz", f->tf_measured_hz,
        "speed_rel_error", r->speed_rel_error, "contrast_rel_error", r->contrast / a->contrast - 1);
    json_t *d = json_pack("{s:i,s:i,s:f,s:f,s:f,s:f,s:b,s:b}", "frames_measured", f->frames, "frames_missed",
                          f->frames_missed, "frame_step_rad", f->frame_step_rad, "step_tolerance_rad",
                          f->step_tolerance_rad, "max_step_error_rad", f->max_step_error_rad,
                          "max_held_step_error_rad", f->max_held_step_error_rad, "continuous", f->continuous,
                          "speed_ok", r->speed_ok);
    json_object_set_new(d, "held_step_rad",
                        isnan(f->held_step_rad) ? json_null() : json_real(f->held_step_rad));
    json_object_set_new(d, "held_step_expected_rad",
                        isnan(f->held_step_expected_rad) ? json_null()
                                                         : json_real(f->held_step_expected_rad));
    json_object_set_new(o, "drift", d);
    json_object_set_new(o, "refresh_hz", json_real(csf_presenter_refresh_hz(p)));
    json_object_set_new(o, "framebuffer_bits", json_integer(csf_presenter_bits(p)));
    json_object_set_new(o, "truth", json_string(t->truth));
    json_object_set_new(o, "presenter_profile", json_string(csf_presenter_profile_id(p)));
    json_dumpf(o, stdout, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    fputc('\n', stdout);
    json_decref(o);
}

static void print_drift(const csf_cli *cli, const stim_args *a, csf_presenter *p, const stim_truth *t,
                        const csf_selfcheck_drift_result *r)
{
    if (cli->json) {
        print_drift_json(a, p, t, r);
        return;
    }
    const csf_drift_fit *f = &r->fit;
    printf("drifting stimulus self-check (%d-bit framebuffer, %.4g Hz, %d frames measured, %d missed)\n",
           csf_presenter_bits(p), csf_presenter_refresh_hz(p), f->frames, f->frames_missed);
    printf("  luminance truth:   %s\n  presenter profile: %s\n", t->truth, csf_presenter_profile_id(p));
    printf("  %-22s %12s %12s\n", "", "requested", "measured");
    printf("  %-22s %12.5g %12.5g\n", "frequency (cpd)", a->freq_cpd, r->freq_cpd);
    printf("  %-22s %12.5g %12.5g  (%+.2f %%)\n", "Michelson contrast", a->contrast, r->contrast,
           100 * (r->contrast / a->contrast - 1));
    printf("  %-22s %12.5g %12.5g\n", "drift (Hz)", f->tf_asked_hz, f->tf_measured_hz);
    printf("  %-22s %12.5g %12.5g  (%+.3f %%, target within %.0f %%: %s)\n", "velocity (deg/s)",
           a->velocity_dps, r->speed_measured_dps, 100 * r->speed_rel_error, 100 * CSF_DRIFT_SPEED_TOL,
           r->speed_ok ? "met" : "MISSED");
    printf(
        "  phase steps: largest deviation %.4f rad (one refresh's step %.4f rad, tolerance %.4f rad): %s\n",
        f->max_step_error_rad, f->frame_step_rad, f->step_tolerance_rad,
        f->continuous ? "continuous" : "DISCONTINUOUS");
    if (f->frames_missed > 0)
        printf("  over a held frame: step %.4f rad, 2 pi tf x interval says %.4f rad\n", f->held_step_rad,
               f->held_step_expected_rad);
}

/* The drift measurement of a drifting carrier: one trial with the asked dropped frames. */
static int check_drift(const csf_cli *cli, const stim_args *a, csf_presenter *p, const stim_truth *t,
                       const csf_stimulus *s)
{
    char why[400];
    if (stim_check_aliasing(a, csf_presenter_refresh_hz(p), why, sizeof why)) {
        fprintf(stderr, "csfcal: stimulus check: %s\n", why);
        return 2;
    }
    csf_error e;
    long base = csf_presenter_frame_index(p);
    for (int i = 0; i < a->n_drops; i++)
        if (csf_presenter_inject_missed(p, base + a->drop_frames[i], 1, &e))
            return csf_cli_report("stimulus check", &e);
    csf_presenter_set_miss_rate(p, a->miss_rate);
    csf_selfcheck_drift_result r;
    if (csf_selfcheck_drift(p, s, (int)a->frames, t->lum, t->lum_ctx, &r, &e))
        return csf_cli_report("stimulus check", &e);
    print_drift(cli, a, p, t, &r);
    if (!r.speed_ok || !r.fit.continuous) {
        fprintf(stderr, "csfcal: stimulus check: drift target missed:%s%s\n",
                r.speed_ok ? "" : " measured speed off by more than 1 %",
                r.fit.continuous ? "" : " carrier phase not continuous across frames");
        return 1;
    }
    return 0;
}

/* The static measurement (and, with --levels, the luminance resolution). */
static int check_static(const csf_cli *cli, const stim_args *a, csf_presenter *p, const stim_truth *t,
                        const csf_stimulus *s)
{
    csf_error e;
    csf_selfcheck_result r;
    csf_selfcheck_resolution res;
    memset(&r, 0, sizeof r);
    memset(&res, 0, sizeof res);
    if (csf_selfcheck_stimulus(p, s, (int)a->frames, t->lum, t->lum_ctx, &r, &e))
        return csf_cli_report("stimulus check", &e);
    if (a->levels > 0) {
        int rw, rh;
        csf_presenter_render_size(p, &rw, &rh);
        int patch = rw < rh ? rw : rh;
        if (patch > 64) patch = 64;
        if (csf_selfcheck_resolution_run(p, (int)a->levels, 8, patch, cli->seed, t->lum, t->lum_ctx, &res,
                                         &e))
            return csf_cli_report("stimulus check", &e);
    }
    print_check(cli, a, p, t, &r, &res);
    return 0;
}

/* Renders the stimulus offscreen and measures it: static, or (--velocity) its drift. */
static int cmd_check(const csf_cli *cli, const stim_args *a)
{
    if (isnan(a->freq_cpd) || isnan(a->contrast)) {
        fprintf(stderr, "csfcal: stimulus check: --freq and --contrast are required\n");
        return 2;
    }
    if (a->velocity_dps == 0 && (a->n_drops > 0 || a->miss_rate > 0)) {
        fprintf(stderr, "csfcal: stimulus check: --drop-frame and --miss-rate need a drifting "
                        "carrier (--velocity)\n");
        return 2;
    }
    if (a->velocity_dps != 0 && a->frames < 3) {
        fprintf(stderr, "csfcal: stimulus check: a drift is measured over at least 3 frames (--frames %ld)\n",
                a->frames);
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
    stim_truth t;
    int status = stim_open_truth(cli, "stimulus check", &pc, &t);
    if (status >= 0) return status;
    csf_presenter *p = NULL;
    csf_stimulus s;
    stim_from_args(a, &s);
    if (csf_presenter_open(&pc, &p, &e)) status = csf_cli_report("stimulus check", &e);
    else if (a->velocity_dps != 0) status = check_drift(cli, a, p, &t, &s);
    else status = check_static(cli, a, p, &t, &s);
    csf_presenter_close(p);
    stim_close_truth(&t);
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
    if (strcmp(sub, "check") != 0 && strcmp(sub, "geometry") != 0 && strcmp(sub, "show") != 0) {
        fprintf(stderr, "csfcal: stimulus: unknown subcommand '%s' (check, geometry, show)\n", sub);
        return 2;
    }
    argc--;
    argv++;
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    stim_args a;
    rc = stim_parse_options(argc, argv, sub, &cli, &a);
    if (rc >= 0) return rc;
    if (!strcmp(sub, "geometry")) return cmd_geometry(&cli, a.ecc_deg, a.polar_deg);
    if (!strcmp(sub, "show")) return csf_cmd_stimulus_show(&cli, &a);
    return cmd_check(&cli, &a);
}
