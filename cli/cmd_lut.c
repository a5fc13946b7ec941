/* `csfcal lut info|lookup|export|import`: inspect, query and convert threshold tables (.csflut).
 * Thin layer over the csflut library: everything a renderer sees through the library, a user can
 * see from the shell. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "results/csflut/csflut.h"
#include "core/file_read.h"
#include "core/file_write.h"

static const char lut_help[] =
    "usage: csfcal lut info FILE [--json] [--raw]\n"
    "       csfcal lut lookup FILE --freq CPD --ecc DEG [--contrast C] [--velocity DPS]\n"
    "                         [--lum CDM2] [--raw] [--shift K] [--json]\n"
    "       csfcal lut export FILE --format csv|json|c|glsl [-o OUT] [--raw] [--prefix NAME]\n"
    "       csfcal lut import GRID.csv -o FILE.csflut [--observer S] [--display-profile S]\n"
    "                         [--method S] [--date ISO8601] [--distance-mm D] [--mean-lum L]\n"
    "                         [--trials N]\n\n"
    "Threshold tables hold threshold Michelson contrast over spatial frequency (cpd) and\n"
    "eccentricity (deg), optionally velocity (deg/s) and luminance (cd/m2); see docs/csflut.md.\n"
    "Queries use the conservative view unless --raw is given: below the peak frequency the\n"
    "threshold is the peak's, and it never falls as frequency or eccentricity rises.\n"
    "  --shift K   lower the conservative view by K standard errors (0 to 10)\n"
    "  --contrast  also say whether that contrast is visible, and the highest visible frequency\n"
    "  --velocity  deg/s (0 = static, its sign does not matter); default: the table's lowest\n"
    "CSV for import: header freq_cpd,ecc_deg[,velocity_dps][,lum_cdm2],threshold[,stderr_log10],\n"
    "one row per grid point, 'inf' = never visible, '#' starts a comment, '# meta.KEY: value'\n"
    "a metadata pair.\n";

enum {
    OPT_FREQ = CSF_OPT_FIRST_FREE, OPT_ECC, OPT_CONTRAST, OPT_VEL, OPT_LUM, OPT_RAW, OPT_SHIFT,
    OPT_JSON, OPT_FORMAT, OPT_PREFIX, OPT_OBSERVER, OPT_DISPLAY, OPT_METHOD, OPT_DATE, OPT_DIST,
    OPT_MEANLUM, OPT_TRIALS, OPT_HELP
};

static const struct option lut_options[] = {
    {"freq", required_argument, 0, OPT_FREQ},
    {"ecc", required_argument, 0, OPT_ECC},
    {"contrast", required_argument, 0, OPT_CONTRAST},
    {"velocity", required_argument, 0, OPT_VEL},
    {"lum", required_argument, 0, OPT_LUM},
    {"raw", no_argument, 0, OPT_RAW},
    {"shift", required_argument, 0, OPT_SHIFT},
    {"json", no_argument, 0, OPT_JSON},
    {"format", required_argument, 0, OPT_FORMAT},
    {"prefix", required_argument, 0, OPT_PREFIX},
    {"output", required_argument, 0, 'o'},
    {"observer", required_argument, 0, OPT_OBSERVER},
    {"display-profile", required_argument, 0, OPT_DISPLAY},
    {"method", required_argument, 0, OPT_METHOD},
    {"date", required_argument, 0, OPT_DATE},
    {"distance-mm", required_argument, 0, OPT_DIST},
    {"mean-lum", required_argument, 0, OPT_MEANLUM},
    {"trials", required_argument, 0, OPT_TRIALS},
    {"help", no_argument, 0, OPT_HELP},
    {0, 0, 0, 0},
};

typedef struct {
    const char *file, *out, *prefix, *format;
    const char *observer, *display, *method, *date;
    double freq, ecc, contrast, vel, lum, shift, dist, meanlum;
    int have_freq, have_ecc, have_contrast, have_vel, have_lum, have_trials, raw, json, help;
    long trials;
} lut_args;

static int parse_args(int argc, char **argv, lut_args *a)
{
    memset(a, 0, sizeof *a);
    a->vel = a->lum = a->dist = a->meanlum = NAN;
    optind = 0; /* full getopt re-initialisation (GNU) */
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":o:h", lut_options, NULL)) != -1) {
        int bad = 0;
        switch (c) {
        case OPT_FREQ: bad = csf_parse_double(optarg, "freq", 1e-6, 1e6, &a->freq); a->have_freq = 1; break;
        case OPT_ECC: bad = csf_parse_double(optarg, "ecc", 0, 180, &a->ecc); a->have_ecc = 1; break;
        case OPT_CONTRAST: bad = csf_parse_double(optarg, "contrast", 0, 1e6, &a->contrast); a->have_contrast = 1; break;
        case OPT_VEL: bad = csf_parse_double(optarg, "velocity", 0, 1e6, &a->vel); a->have_vel = 1; break;
        case OPT_LUM: bad = csf_parse_double(optarg, "lum", 1e-9, 1e9, &a->lum); a->have_lum = 1; break;
        case OPT_SHIFT: bad = csf_parse_double(optarg, "shift", 0, 10, &a->shift); break;
        case OPT_DIST: bad = csf_parse_double(optarg, "distance-mm", 1, 1e6, &a->dist); break;
        case OPT_MEANLUM: bad = csf_parse_double(optarg, "mean-lum", 1e-9, 1e9, &a->meanlum); break;
        case OPT_TRIALS:
            bad = csf_parse_int(optarg, "trials", 0, 0x7fffffffL, &a->trials);
            a->have_trials = 1;
            break;
        case OPT_RAW: a->raw = 1; break;
        case OPT_JSON: a->json = 1; break;
        case OPT_FORMAT: a->format = optarg; break;
        case OPT_PREFIX: a->prefix = optarg; break;
        case 'o': a->out = optarg; break;
        case OPT_OBSERVER: a->observer = optarg; break;
        case OPT_DISPLAY: a->display = optarg; break;
        case OPT_METHOD: a->method = optarg; break;
        case OPT_DATE: a->date = optarg; break;
        case OPT_HELP: case 'h': a->help = 1; break;
        case ':':
            fprintf(stderr, "csfcal: lut: option %s needs a value\n", argv[optind - 1]);
            return 2;
        default:
            fprintf(stderr, "csfcal: lut: unknown option '%s' (see csfcal lut --help)\n",
                    argv[optind - 1]);
            return 2;
        }
        if (bad < 0) return 2;
    }
    if (a->help) return 0;
    if (optind < argc) a->file = argv[optind++];
    if (optind < argc) {
        fprintf(stderr, "csfcal: lut: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    return 0;
}

static int open_table(const lut_args *a, csflut_table **t)
{
    if (!a->file) {
        fprintf(stderr, "csfcal: lut: no table file given (see csfcal lut --help)\n");
        return 2;
    }
    csflut_diag d;
    csflut_status st = csflut_open_file_diag(a->file, t, &d);
    if (st != CSFLUT_OK) {
        /* an I/O message already names the file and the OS error */
        if (st == CSFLUT_E_IO) fprintf(stderr, "csfcal: lut: %s\n", d.message);
        else fprintf(stderr, "csfcal: lut: %s: %s (%s)\n", a->file, d.message, csflut_strerror(st));
        return 1;
    }
    csflut_set_conservative(*t, !a->raw);
    if (a->shift > 0 && csflut_set_stderr_shift(*t, a->shift) != CSFLUT_OK) {
        fprintf(stderr, "csfcal: lut: --shift %g refused\n", a->shift);
        csflut_close(*t);
        return 2;
    }
    return 0;
}

static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

/* JSON numbers: non-finite values become null (JSON has no infinity); the meaning is documented
 * next to each field in docs/csflut.md. */
static void json_num(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.17g", v);
    else fputs("null", f);
}

/* What `lut info` says of a table besides its axes and metadata. */
typedef struct {
    size_t n, n_inf;
    double tmin, peak, peak_thr;
    const char *mk[5], *mv[5];
} info_facts;

static void info_facts_of(const csflut_table *t, info_facts *f)
{
    f->n = csflut_node_count(t);
    f->n_inf = 0;
    const double *raw = csflut_raw_thresholds(t);
    f->tmin = HUGE_VAL;
    for (size_t i = 0; i < f->n; i++) {
        if (isinf(raw[i])) f->n_inf++;
        if (raw[i] < f->tmin) f->tmin = raw[i];
    }
    f->peak = csflut_peak_frequency(t, 0);
    f->peak_thr = csflut_threshold(t, f->peak, 0);
    const char *mk[5] = {"observer", "display_profile_id", "method", "date_utc", "tool_version"};
    const char *mv[5] = {csflut_observer(t), csflut_display_profile_id(t), csflut_method(t),
                         csflut_date_utc(t), csflut_tool_version(t)};
    memcpy(f->mk, mk, sizeof mk);
    memcpy(f->mv, mv, sizeof mv);
}

static void print_info_json(const lut_args *a, const csflut_table *t, const info_facts *f)
{
    size_t n = f->n, n_inf = f->n_inf;
    double tmin = f->tmin, peak = f->peak, peak_thr = f->peak_thr;
    const char *const *mk = f->mk, *const *mv = f->mv;
    printf("{\"file\": ");
    json_str(stdout, a->file);
    printf(", \"version\": \"%d.%d\"", csflut_version_major(t), csflut_version_minor(t));
    for (int k = 0; k < 5; k++) {
        printf(", \"%s\": ", mk[k]);
        json_str(stdout, mv[k]);
    }
    printf(", \"viewing_distance_mm\": ");
    json_num(stdout, csflut_viewing_distance_mm(t));
    printf(", \"mean_lum_cdm2\": ");
    json_num(stdout, csflut_mean_lum_cdm2(t));
    printf(", \"trials\": %d, \"axes\": [", csflut_trials(t));
    int first = 1;
    for (int ax = 0; ax < 4; ax++) {
        int na = csflut_axis_size(t, (csflut_axis)ax);
        if (!na) continue;
        const double *p = csflut_axis_points(t, (csflut_axis)ax);
        printf("%s{\"name\": \"%s\", \"unit\": \"%s\", \"scale\": \"%s\", \"points\": [", first ? "" : ", ",
               csflut_axis_name((csflut_axis)ax), csflut_axis_unit((csflut_axis)ax),
               csflut_axis_scale(t, (csflut_axis)ax) == CSFLUT_SCALE_LOG ? "log" : "linear");
        for (int i = 0; i < na; i++) {
            if (i) printf(", ");
            json_num(stdout, p[i]);
        }
        printf("]");
        if (ax == CSFLUT_AXIS_VEL && !isnan(csflut_velocity_warp_v0(t)))
            printf(", \"warp\": \"log(|v| + v0)\", \"warp_v0_dps\": %.17g", csflut_velocity_warp_v0(t));
        printf("}");
        first = 0;
    }
    printf("], \"nodes\": %zu, \"never_visible_nodes\": %zu, \"has_stderr\": %s", n, n_inf,
           csflut_stderr_log10(t) ? "true" : "false");
    printf(", \"view\": \"%s\", \"min_threshold\": ", a->raw ? "raw" : "conservative");
    json_num(stdout, tmin);
    printf(", \"peak_freq_cpd_fovea\": ");
    json_num(stdout, peak);
    printf(", \"peak_threshold_fovea\": ");
    json_num(stdout, peak_thr);
    printf(", \"meta\": {");
    for (int k = 0; k < csflut_meta_count(t); k++) {
        printf(k ? ", " : "");
        json_str(stdout, csflut_meta_key(t, k));
        printf(": ");
        json_str(stdout, csflut_meta_value(t, k));
    }
    printf("}}\n");
}

static void print_info_text(const lut_args *a, const csflut_table *t, const info_facts *f)
{
    size_t n = f->n, n_inf = f->n_inf;
    double tmin = f->tmin, peak = f->peak, peak_thr = f->peak_thr;
    const char *const *mk = f->mk, *const *mv = f->mv;
    printf("file:              %s\n", a->file);
    printf("format version:    %d.%d\n", csflut_version_major(t), csflut_version_minor(t));
    for (int k = 0; k < 5; k++) printf("%-18s %s\n", mk[k], *mv[k] ? mv[k] : "(not recorded)");
    printf("viewing distance:  ");
    if (isfinite(csflut_viewing_distance_mm(t))) printf("%g mm\n", csflut_viewing_distance_mm(t));
    else printf("(not recorded)\n");
    printf("mean luminance:    ");
    if (isfinite(csflut_mean_lum_cdm2(t))) printf("%g cd/m2\n", csflut_mean_lum_cdm2(t));
    else printf("(not recorded)\n");
    printf("trials:            %d\n", csflut_trials(t));
    for (int ax = 0; ax < 4; ax++) {
        int na = csflut_axis_size(t, (csflut_axis)ax);
        if (!na) continue;
        const double *p = csflut_axis_points(t, (csflut_axis)ax);
        double v0 = ax == CSFLUT_AXIS_VEL ? csflut_velocity_warp_v0(t) : NAN;
        char scale[48];
        if (!isnan(v0)) snprintf(scale, sizeof scale, "warp log(|v| + %g)", v0);
        else
            snprintf(scale, sizeof scale, "%s scale",
                     csflut_axis_scale(t, (csflut_axis)ax) == CSFLUT_SCALE_LOG ? "log" : "linear");
        printf("axis %-9s    %d points, %s, %g to %g %s:", csflut_axis_name((csflut_axis)ax), na, scale, p[0],
               p[na - 1], csflut_axis_unit((csflut_axis)ax));
        for (int i = 0; i < na; i++) printf(" %g", p[i]);
        printf("\n");
    }
    printf("nodes:             %zu (%zu never visible), stderr %s\n", n, n_inf,
           csflut_stderr_log10(t) ? "present" : "absent");
    printf("lowest threshold:  %.4g (sensitivity %.4g)\n", tmin, 1 / tmin);
    printf("fovea peak (%s): %g cpd, threshold %.4g\n", a->raw ? "raw" : "conservative", peak, peak_thr);
    if (csflut_axis_size(t, CSFLUT_AXIS_VEL))
        printf("(the fovea peak and the 2-D queries are at the lowest velocity, %g deg/s)\n",
               csflut_default_velocity(t));
    for (int k = 0; k < csflut_meta_count(t); k++)
        printf("meta %-13s %s\n", csflut_meta_key(t, k), csflut_meta_value(t, k));
}

static int cmd_info(const lut_args *a)
{
    csflut_table *t;
    int rc = open_table(a, &t);
    if (rc) return rc;
    info_facts f;
    info_facts_of(t, &f);
    if (a->json) print_info_json(a, t, &f);
    else print_info_text(a, t, &f);
    csflut_close(t);
    return 0;
}

static int cmd_lookup(const lut_args *a)
{
    if (!a->have_freq || !a->have_ecc) {
        fprintf(stderr, "csfcal: lut lookup: --freq and --ecc are required\n");
        return 2;
    }
    csflut_table *t;
    int rc = open_table(a, &t);
    if (rc) return rc;
    if (a->have_vel && !csflut_axis_size(t, CSFLUT_AXIS_VEL)) {
        fprintf(stderr,
                "csfcal: lut lookup: %s has no velocity axis, so --velocity cannot apply "
                "(csfcal lut info shows the axes)\n",
                a->file);
        csflut_close(t);
        return 2;
    }
    double vel = a->have_vel ? a->vel : csflut_default_velocity(t);
    double lum = a->have_lum ? a->lum : csflut_default_luminance(t);
    double thr = csflut_threshold4(t, a->freq, a->ecc, vel, lum);
    double maxf = a->have_contrast ? csflut_max_frequency4(t, a->ecc, vel, lum, a->contrast) : NAN;
    int vis = a->have_contrast ? a->contrast >= thr : 0;
    if (a->json) {
        printf("{\"freq_cpd\": %.17g, \"ecc_deg\": %.17g", a->freq, a->ecc);
        if (csflut_axis_size(t, CSFLUT_AXIS_VEL)) printf(", \"velocity_dps\": %.17g", vel);
        if (csflut_axis_size(t, CSFLUT_AXIS_LUM)) printf(", \"lum_cdm2\": %.17g", lum);
        printf(", \"view\": \"%s\", \"threshold\": ", a->raw ? "raw" : "conservative");
        json_num(stdout, thr);
        printf(", \"never_visible\": %s, \"sensitivity\": %.17g", isinf(thr) ? "true" : "false",
               1 / thr);
        if (a->have_contrast) {
            printf(", \"contrast\": %.17g, \"perceptible\": %s, \"max_frequency_cpd\": ",
                   a->contrast, vis ? "true" : "false");
            if (isinf(maxf)) printf("\"inf\"");
            else json_num(stdout, maxf);
        }
        printf("}\n");
    } else {
        printf("threshold at %g cpd, %g deg", a->freq, a->ecc);
        if (csflut_axis_size(t, CSFLUT_AXIS_VEL)) printf(", %g deg/s", vel);
        if (csflut_axis_size(t, CSFLUT_AXIS_LUM)) printf(", %g cd/m2", lum);
        if (isinf(thr)) printf(" (%s): never visible\n", a->raw ? "raw" : "conservative");
        else printf(" (%s): %.6g (sensitivity %.5g)\n", a->raw ? "raw" : "conservative", thr, 1 / thr);
        if (a->have_contrast) {
            printf("contrast %g: %s\n", a->contrast, vis ? "perceptible" : "not perceptible");
            if (isinf(maxf)) printf("visible at every frequency (above the table's highest, %g cpd)\n",
                                    csflut_axis_points(t, CSFLUT_AXIS_FREQ)[csflut_axis_size(t, CSFLUT_AXIS_FREQ) - 1]);
            else if (maxf == 0) printf("not visible at any frequency at %g deg\n", a->ecc);
            else printf("highest visible frequency at %g deg: %.6g cpd\n", a->ecc, maxf);
        }
    }
    csflut_close(t);
    return 0;
}

/* The names the C and GLSL exports generate all start with the prefix (PREFIX_threshold,
 * PREFIX_NF, ...), so it must be a C identifier that GLSL and C++ also accept; the library
 * refuses the same prefixes (csflut_export), this says which rule. 1 = refused (message given). */
static int prefix_refused(const char *p)
{
    size_t n = strlen(p);
    int ident = n > 0 && n <= 64 && !(p[0] >= '0' && p[0] <= '9');
    for (size_t i = 0; i < n && ident; i++)
        ident = (p[i] >= 'a' && p[i] <= 'z') || (p[i] >= 'A' && p[i] <= 'Z') ||
                (p[i] >= '0' && p[i] <= '9') || p[i] == '_';
    if (!ident) {
        int printable = 1;
        for (size_t i = 0; i < n; i++) printable &= p[i] >= 0x20 && p[i] < 0x7f;
        fprintf(stderr, "csfcal: lut export: --prefix %s%s%sis not a C identifier (a letter or _, "
                        "then letters, digits or _; at most 64 characters)\n",
                printable ? "'" : "", printable ? p : "", printable ? "' " : "");
        return 1;
    }
    if (strncmp(p, "gl_", 3) == 0) {
        fprintf(stderr, "csfcal: lut export: --prefix '%s' starts with \"gl_\": GLSL reserves names "
                        "starting with gl_ and refuses to compile them\n", p);
        return 1;
    }
    if (strstr(p, "__") || p[n - 1] == '_') {
        if (strstr(p, "__"))
            fprintf(stderr, "csfcal: lut export: --prefix '%s' contains \"__\": GLSL and C++ reserve "
                            "names containing two consecutive underscores\n", p);
        else
            fprintf(stderr, "csfcal: lut export: --prefix '%s' ends with '_', so %s_threshold would "
                            "contain \"__\": GLSL and C++ reserve names containing two consecutive "
                            "underscores\n", p, p);
        return 1;
    }
    return 0;
}

static int cmd_export(const lut_args *a)
{
    if (!a->format) {
        fprintf(stderr, "csfcal: lut export: --format csv|json|c|glsl is required\n");
        return 2;
    }
    csflut_format fmt;
    if (strcmp(a->format, "csv") == 0) fmt = CSFLUT_FORMAT_CSV;
    else if (strcmp(a->format, "json") == 0) fmt = CSFLUT_FORMAT_JSON;
    else if (strcmp(a->format, "c") == 0) fmt = CSFLUT_FORMAT_C;
    else if (strcmp(a->format, "glsl") == 0) fmt = CSFLUT_FORMAT_GLSL;
    else {
        fprintf(stderr, "csfcal: lut export: --format '%s' is not one of csv, json, c, glsl\n", a->format);
        return 2;
    }
    if (a->prefix && prefix_refused(a->prefix)) return 2;
    csf_error werr;
    if (a->out && csf_check_output_path(a->out, "export", &werr) != CSF_OK) {
        fprintf(stderr, "csfcal: lut export: %s\n", werr.msg);
        return 2;
    }
    csflut_table *t;
    int rc = open_table(a, &t);
    if (rc) return rc;
    char *text;
    size_t len;
    csflut_status st = csflut_export(t, fmt, a->prefix, &text, &len);
    csflut_close(t);
    if (st == CSFLUT_E_ARG) { /* the library's rule is the one above: not reached */
        fprintf(stderr, "csfcal: lut export: --prefix refused by the library\n");
        return 2;
    }
    if (st) {
        fprintf(stderr, "csfcal: lut export: %s\n", csflut_strerror(st));
        return 1;
    }
    if (a->out) { /* temporary beside it, fsync, rename: never a partial file */
        csf_status ws = csf_write_file_atomic(a->out, "export", text, len, &werr);
        free(text);
        if (ws != CSF_OK) {
            fprintf(stderr, "csfcal: lut export: %s\n", werr.msg);
            return 1;
        }
        return 0;
    }
    int ok = fwrite(text, 1, len, stdout) == len;
    ok = (fflush(stdout) == 0) && ok;
    free(text);
    if (!ok) {
        fprintf(stderr, "csfcal: lut export: cannot write to stdout: %s\n", strerror(errno));
        return 1;
    }
    return 0;
}

/* A real UTC date and time in the form csfcal writes, YYYY-MM-DDTHH:MM:SSZ (ISO 8601). */
static int valid_iso8601_utc(const char *s)
{
    static const char form[] = "dddd-dd-ddTdd:dd:ddZ";
    if (strlen(s) != sizeof form - 1) return 0;
    for (size_t i = 0; form[i]; i++)
        if (form[i] == 'd' ? !(s[i] >= '0' && s[i] <= '9') : s[i] != form[i]) return 0;
    int y, mo, d, h, mi, se;
    if (sscanf(s, "%4d-%2d-%2dT%2d:%2d:%2dZ", &y, &mo, &d, &h, &mi, &se) != 6) return 0;
    static const int mdays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    if (y < 1 || mo < 1 || mo > 12 || d < 1) return 0;
    if (d > mdays[mo - 1] + (mo == 2 && leap)) return 0;
    return h <= 23 && mi <= 59 && se <= 60; /* 60: a leap second */
}

static int cmd_import(const lut_args *a)
{
    if (!a->file || !a->out) {
        fprintf(stderr, "csfcal: lut import: give the CSV file and -o FILE.csflut\n");
        return 2;
    }
    if (a->date && !valid_iso8601_utc(a->date)) {
        fprintf(stderr, "csfcal: lut import: --date '%s' is not a UTC date and time in the form "
                        "YYYY-MM-DDTHH:MM:SSZ (ISO 8601, e.g. 2026-11-23T14:05:00Z)\n", a->date);
        return 2;
    }
    csf_error werr;
    if (csf_check_output_path(a->out, "threshold table", &werr) != CSF_OK) {
        fprintf(stderr, "csfcal: lut import: %s\n", werr.msg);
        return 2;
    }
    size_t len;
    char *text;
    csf_error rerr;
    if (csf_read_file(a->file, "threshold grid", (size_t)512 << 20, &text, &len, &rerr) != CSF_OK) {
        fprintf(stderr, "csfcal: lut import: %s\n", rerr.msg);
        return 1;
    }
    csflut_grid *g;
    csflut_diag d;
    csflut_status st = csflut_import_csv(text, len, &g, &d);
    free(text);
    if (st) {
        fprintf(stderr, "csfcal: lut import: %s: %s\n", a->file, d.message);
        return 1;
    }
    csflut_build *b = csflut_grid_build(g);
    char date[32];
    time_t now = time(NULL);
    struct tm tmv;
    gmtime_r(&now, &tmv);
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    /* an option overrides the CSV's metadata comments (what `lut export` writes), which override
     * the defaults */
    if (a->observer) b->observer = a->observer;
    if (a->display) b->display_profile_id = a->display;
    if (a->method) b->method = a->method;
    else if (!b->method || !*b->method) b->method = "import";
    if (a->date) b->date_utc = a->date;
    else if (!b->date_utc || !*b->date_utc) b->date_utc = date;
    if (!b->tool_version || !*b->tool_version) b->tool_version = "csfcal " CSF_VERSION;
    if (!isnan(a->dist)) b->viewing_distance_mm = a->dist;
    if (!isnan(a->meanlum)) b->mean_lum_cdm2 = a->meanlum;
    if (a->have_trials) b->trials = (int)a->trials;
    unsigned char *blob = NULL;
    size_t blen = 0, n_meta = 0;
    const csflut_meta *meta = csflut_grid_meta(g, &n_meta); /* "# meta.KEY: value" comments */
    st = csflut_write_memory_meta(b, meta, n_meta, &blob, &blen, &d);
    csflut_grid_free(g);
    if (st) {
        fprintf(stderr, "csfcal: lut import: %s: %s\n", a->out, d.message);
        return 1;
    }
    csf_status ws = csf_write_file_atomic(a->out, "threshold table", blob, blen, &werr);
    free(blob);
    if (ws != CSF_OK) {
        fprintf(stderr, "csfcal: lut import: %s\n", werr.msg);
        return 1;
    }
    return 0;
}

int csf_cmd_lut(int argc, char **argv)
{
    if (argc < 2) {
        fputs(lut_help, stderr);
        return 2;
    }
    const char *sub = argv[1];
    if (strcmp(sub, "--help") == 0 || strcmp(sub, "-h") == 0 || strcmp(sub, "help") == 0) {
        fputs(lut_help, stdout);
        return 0;
    }
    int (*run)(const lut_args *) = NULL;
    if (strcmp(sub, "info") == 0) run = cmd_info;
    else if (strcmp(sub, "lookup") == 0) run = cmd_lookup;
    else if (strcmp(sub, "export") == 0) run = cmd_export;
    else if (strcmp(sub, "import") == 0) run = cmd_import;
    else {
        fprintf(stderr, "csfcal: lut: unknown subcommand '%s' (info, lookup, export, import)\n", sub);
        return 2;
    }
    lut_args a;
    int rc = parse_args(argc - 1, argv + 1, &a);
    if (rc) return rc;
    if (a.help) {
        fputs(lut_help, stdout);
        return 0;
    }
    return run(&a);
}
