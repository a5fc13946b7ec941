#define _POSIX_C_SOURCE 200809L
#include "lod_args.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void lod_options_defaults(options *o)
{
    *o = (options){.width_px = 512,
                   .height_px = 512,
                   .views = 4,
                   .subdiv = 6,
                   .ppd = 32,
                   .object_deg = 12,
                   .seed = 1,
                   .n_levels = 3,
                   .fps = 60,
                   .object_velocity_dps = 12,
                   .coarse_factor = 4,
                   .judge_trials = 200,
                   .levels = {{1, 1, "d1"}, {8, 1, "d8"}, {32, 1, "d32"}},
                   .shade = {.light_dir = {0.48f, 0.64f, 0.6f},
                             .albedo = 0.85f,
                             .ambient = 0.2f,
                             .background = 0.5f,
                             .lum_peak_cdm2 = 200,
                             .lum_black_cdm2 = 0.5}};
}


void lod_usage(FILE *f)
{
    fprintf(f, "usage: lod --table FILE.csflut --out DIR [options]\n"
               "  --size WxH              image size in pixels (16..4096 each; default 512x512)\n"
               "  --ppd P                 pixels per degree at the screen centre (2..200; default 32)\n"
               "  --distance-mm D --pixel-mm P  the same from the viewing distance and pixel pitch\n"
               "  --gaze X,Y              gaze point in pixels from the top left (default: the centre)\n"
               "  --object-deg A          angular diameter of the model (1..120; default 12)\n"
               "  --views N               viewpoints (1..64; default 4)\n"
               "  --subdiv S              mesh detail: 20*4^S triangles (3..7; default 6)\n"
               "  --seed N                the mesh's ridges (default 1)\n"
               "  --distance-factors L    simplify as if the viewer were d times farther, for each d in\n"
               "                          the comma-separated list (1..1000; default 1,8,32); d = 1 is\n"
               "                          the imperceptible simplification, d > 1 deliberately perceptible\n"
               "  --threshold-factors L   also simplify with every threshold k times higher, for each k\n"
               "                          in the list (1..1000; default none)\n"
               "  --lum-peak L --lum-black L  display luminance of white and black (cd/m2; 200, 0.5)\n"
               "  --diff-images           also write diff_IMAGE.png: |full - simplified| x 8\n"
               "moving sequence (instead of the still views; README.md, \"Motion\"):\n"
               "  --frames N              frames of a moving object (2..240; default none)\n"
               "  --fps F                 frame rate (10..240 Hz; default 60)\n"
               "  --object-velocity V     the object crosses the screen at V deg/s (0..80; default 12)\n"
               "  --spin V                and turns about its vertical axis at V deg/s (0..720; default 0)\n"
               "  --eye fixate|pursuit    fixate: the eye holds the gaze point, retinal = screen velocity\n"
               "                          (default); pursuit: it follows the object (Daly 1998)\n"
               "  --coarse-factor K       the deliberately coarser simplification: thresholds x K\n"
               "                          (1..1000; default 4)\n"
               "  --judge-trials N        same/different trials per pair kind for the simulated\n"
               "                          judge (10..100000; default 200)\n"
               "  --json FILE             also write the sequence's summary as JSON\n"
               "  --help\n");
}

static int bad(const char *opt, const char *val, const char *why)
{
    fprintf(stderr, "lod: %s %s: %s\n", opt, val ? val : "(missing)", why);
    return 2;
}

static int parse_num(const char *opt, const char *s, double lo, double hi, double *out)
{
    char *end;
    if (!s) return bad(opt, s, "needs a value");
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !(v >= lo && v <= hi)) {
        char why[96];
        snprintf(why, sizeof why, "expected a number from %g to %g", lo, hi);
        return bad(opt, s, why);
    }
    *out = v;
    return 0;
}

static int parse_levels(options *o, const char *opt, const char *list, int by_distance)
{
    if (!list) return bad(opt, list, "needs a comma-separated list");
    char buf[256];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        double v;
        if (o->n_levels == LOD_MAX_LEVELS) return bad(opt, list, "at most 16 simplification levels in all");
        if (parse_num(opt, tok, 1, 1000, &v)) return 2;
        level *l = &o->levels[o->n_levels++];
        l->distance_factor = by_distance ? v : 1;
        l->threshold_factor = by_distance ? 1 : v;
        snprintf(l->name, sizeof l->name, "%c%g", by_distance ? 'd' : 'k', v);
    }
    return 0;
}

/* The object's path must keep it inside the image: its centre sweeps velocity * (frames - 1) / fps
 * degrees across, centred on the screen, and the model spans object_deg around it. */
static int check_path(const options *o)
{
    if (!o->frames) return 0;
    double width_deg = 2 * atan(0.5 * o->width_px / (o->ppd * 180 / LOD_PI)) * 180 / LOD_PI;
    double sweep_deg = o->object_velocity_dps * (o->frames - 1) / o->fps;
    if (sweep_deg + o->object_deg > width_deg) {
        fprintf(stderr,
                "lod: --object-velocity %g deg/s over %d frames at %g Hz sweeps %.3g deg; with the %g deg "
                "model that "
                "needs %.3g deg, and the image is %.3g deg wide\n",
                o->object_velocity_dps, o->frames, o->fps, sweep_deg, o->object_deg,
                sweep_deg + o->object_deg, width_deg);
        return 2;
    }
    return 0;
}

int lod_parse_args(int argc, char **argv, options *o)
{
    double distance_mm = 0, pixel_mm = 0, v = 0; /* read even when parse_num refused the value */
    int levels_given = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        int rc = 0;
        if (!strcmp(a, "--help")) return 1;
        else if (!strcmp(a, "--diff-images")) { o->diff_images = 1; continue; }
        else if (!strcmp(a, "--table")) o->table = val;
        else if (!strcmp(a, "--out")) o->out_dir = val;
        else if (!strcmp(a, "--size")) {
            char *x = NULL, *end = NULL;
            long w = val ? strtol(val, &x, 10) : 0, h = x && *x == 'x' && x[1] >= '0' && x[1] <= '9' ? strtol(x + 1, &end, 10) : 0;
            if (!val || !end || *end || w < 16 || h < 16 || w > 4096 || h > 4096)
                return bad(a, val, "expected WxH, each from 16 to 4096 pixels");
            o->width_px = (int)w;
            o->height_px = (int)h;
        } else if (!strcmp(a, "--ppd")) rc = parse_num(a, val, 2, 200, &o->ppd);
        else if (!strcmp(a, "--distance-mm")) rc = parse_num(a, val, 50, 20000, &distance_mm);
        else if (!strcmp(a, "--pixel-mm")) rc = parse_num(a, val, 0.005, 5, &pixel_mm);
        else if (!strcmp(a, "--gaze")) {
            int n = 0;
            if (!val || sscanf(val, "%lf,%lf%n", &o->gaze_px[0], &o->gaze_px[1], &n) != 2 || val[n] ||
                !isfinite(o->gaze_px[0]) || !isfinite(o->gaze_px[1]))
                return bad(a, val, "expected X,Y in pixels");
            o->gaze_set = 1;
        } else if (!strcmp(a, "--object-deg")) rc = parse_num(a, val, 1, 120, &o->object_deg);
        else if (!strcmp(a, "--views")) { rc = parse_num(a, val, 1, 64, &v); o->views = (int)v; if (!rc && v != floor(v)) rc = bad(a, val, "expected a whole number"); }
        else if (!strcmp(a, "--subdiv")) { rc = parse_num(a, val, 3, 7, &v); o->subdiv = (int)v; if (!rc && v != floor(v)) rc = bad(a, val, "expected a whole number"); }
        else if (!strcmp(a, "--seed")) { rc = parse_num(a, val, 0, 1e15, &v); o->seed = (unsigned long long)v; }
        else if (!strcmp(a, "--distance-factors")) {
            if (!levels_given) o->n_levels = 0;
            levels_given = 1;
            rc = parse_levels(o, a, val, 1);
        } else if (!strcmp(a, "--threshold-factors")) rc = parse_levels(o, a, val, 0);
        else if (!strcmp(a, "--frames")) {
            rc = parse_num(a, val, 2, 240, &v);
            o->frames = (int)v;
            if (!rc && v != floor(v)) rc = bad(a, val, "expected a whole number");
        } else if (!strcmp(a, "--fps")) rc = parse_num(a, val, 10, 240, &o->fps);
        else if (!strcmp(a, "--object-velocity")) rc = parse_num(a, val, 0, 80, &o->object_velocity_dps);
        else if (!strcmp(a, "--spin")) rc = parse_num(a, val, 0, 720, &o->spin_dps);
        else if (!strcmp(a, "--eye")) {
            if (val && (!strcmp(val, "fixate") || !strcmp(val, "pursuit")))
                o->pursuit = !strcmp(val, "pursuit");
            else return bad(a, val, "expected fixate or pursuit");
        } else if (!strcmp(a, "--coarse-factor")) rc = parse_num(a, val, 1, 1000, &o->coarse_factor);
        else if (!strcmp(a, "--judge-trials")) {
            rc = parse_num(a, val, 10, 100000, &v);
            o->judge_trials = (int)v;
            if (!rc && v != floor(v)) rc = bad(a, val, "expected a whole number");
        } else if (!strcmp(a, "--json")) {
            if (!val) return bad(a, val, "needs a file name");
            o->json_path = val;
        } else if (!strcmp(a, "--lum-peak")) rc = parse_num(a, val, 1, 10000, &o->shade.lum_peak_cdm2);
        else if (!strcmp(a, "--lum-black")) rc = parse_num(a, val, 0.001, 100, &o->shade.lum_black_cdm2);
        else { fprintf(stderr, "lod: unknown option %s (see --help)\n", a); return 2; }
        if (rc) return rc;
        i++;
    }
    if (!o->table || !o->out_dir) { fprintf(stderr, "lod: --table and --out are required (see --help)\n"); return 2; }
    if ((distance_mm > 0) != (pixel_mm > 0)) { fprintf(stderr, "lod: --distance-mm and --pixel-mm go together\n"); return 2; }
    if (distance_mm > 0) o->ppd = distance_mm * tan(LOD_PI / 180) / pixel_mm;
    if (!(o->ppd >= 2 && o->ppd <= 200)) { fprintf(stderr, "lod: %.3g pixels per degree: expected 2 to 200\n", o->ppd); return 2; }
    if (o->shade.lum_black_cdm2 >= o->shade.lum_peak_cdm2) { fprintf(stderr, "lod: --lum-black must be below --lum-peak\n"); return 2; }
    if (!o->gaze_set) { o->gaze_px[0] = 0.5 * o->width_px; o->gaze_px[1] = 0.5 * o->height_px; }
    if (o->gaze_px[0] < 0 || o->gaze_px[1] < 0 || o->gaze_px[0] > o->width_px || o->gaze_px[1] > o->height_px) {
        fprintf(stderr, "lod: --gaze %g,%g is outside the %dx%d image\n", o->gaze_px[0], o->gaze_px[1], o->width_px, o->height_px);
        return 2;
    }
    double image_deg = 2 * atan(0.5 * (o->width_px < o->height_px ? o->width_px : o->height_px) / (o->ppd * 180 / LOD_PI)) * 180 / LOD_PI;
    if (o->object_deg > image_deg) {
        fprintf(stderr, "lod: --object-deg %g: the image spans only %.3g deg at %g pixels per degree\n", o->object_deg, image_deg, o->ppd);
        return 2;
    }
    return check_path(o);
}

