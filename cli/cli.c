#include "cli/cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/spec.h"
#include "results/store/store.h"

const char csf_cli_common_help[] =
    "Common options:\n"
    "  --config FILE        station configuration (default $XDG_CONFIG_HOME/csfcal/station.conf)\n"
    "  --set KEY=VALUE      override one configuration key (see csfcal(1) for the keys)\n"
    "  --store PATH|URI     results store: an SQLite file (default\n"
    "                       $XDG_DATA_HOME/csfcal/csfcal.sqlite) or a PostgreSQL server\n"
    "                       (postgresql://[user@]host/db?..., service=NAME; no password)\n"
    "  --seed N             seed for simulated devices (reproducible runs)\n"
    "  --headless           render offscreen through EGL (automatic without a display)\n"
    "  --photometer SPEC    photometer, e.g. sim or sim:display=lcd,noise=0.002\n"
    "  --observer SPEC      observer, e.g. sim or sim:smax=200,fmax=2.5 or human\n"
    "  --distance-mm D      viewing distance in mm\n"
    "  --screen-mm WxH      visible screen size in mm\n"
    "  --screen-px WxH      screen resolution in pixels\n"
    "  --profile FILE       display profile to use for luminance\n"
    "  --monitor N|NAME     monitor for the fullscreen window\n"
    "  --resume ID          continue an unfinished session from the store\n"
    "  --json               machine-readable output\n";

int csf_cli_init(csf_cli *cli, int argc, char **argv)
{
    memset(cli, 0, sizeof *cli);
    cli->seed = 1;
    csf_config_defaults(&cli->cfg);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0 && i + 1 < argc) cli->config_path = argv[i + 1];
        else if (strncmp(argv[i], "--config=", 9) == 0) cli->config_path = argv[i] + 9;
    }
    csf_error err;
    csf_error_clear(&err);
    if (csf_config_load(&cli->cfg, cli->config_path, &err) != CSF_OK) {
        fprintf(stderr, "csfcal: %s\n", err.msg);
        return 2;
    }
    return 0;
}

static int parse_pair(const char *text, const char *name, double lo, double hi, double *a, double *b)
{
    char buf[128];
    snprintf(buf, sizeof buf, "%s", text);
    char *x = strchr(buf, 'x');
    if (!x) {
        fprintf(stderr, "csfcal: --%s: expected WIDTHxHEIGHT, got '%s'\n", name, text);
        return -1;
    }
    *x = '\0';
    if (csf_parse_double(buf, name, lo, hi, a) < 0) return -1;
    if (csf_parse_double(x + 1, name, lo, hi, b) < 0) return -1;
    return 0;
}

static int set_key(csf_cli *cli, const char *key, const char *value)
{
    csf_error err;
    csf_error_clear(&err);
    if (csf_config_set(&cli->cfg, key, value, "command line", &err) != CSF_OK) {
        fprintf(stderr, "csfcal: %s\n", err.msg);
        return -1;
    }
    return 1;
}

/* --set KEY=VALUE: one configuration key, checked as station.conf checks it. */
static int set_option(csf_cli *cli, const char *arg)
{
    char buf[1200];
    snprintf(buf, sizeof buf, "%s", arg);
    char *eq = strchr(buf, '=');
    if (!eq) {
        fprintf(stderr, "csfcal: --set: expected KEY=VALUE, got '%s'\n", arg);
        return -1;
    }
    *eq = '\0';
    /* An empty store or profile would silently mean the default one, as with --store ''. */
    if (!eq[1] && !strcmp(buf, "store")) {
        char def[1024];
        csf_config_default_store_path(def, sizeof def);
        fprintf(stderr,
                "csfcal: --set store=: empty path (give a file, or leave it out for the default %s)\n", def);
        return -1;
    }
    if (!eq[1] && !strcmp(buf, "display_profile")) {
        fprintf(stderr,
                "csfcal: --set display_profile=: empty path (give a display profile file, or leave it "
                "out for the default display model)\n");
        return -1;
    }
    if (!strcmp(buf, "monitor")) cli->monitor_given = 1;
    return set_key(cli, buf, eq + 1);
}

int csf_cli_common_option(csf_cli *cli, int opt, const char *arg)
{
    switch (opt) {
    case CSF_OPT_CONFIG: return 1; /* already read in csf_cli_init */
    case CSF_OPT_STORE:
        /* An empty path would silently mean the default store: the data would go elsewhere. */
        if (!*arg) {
            char def[1024];
            csf_config_default_store_path(def, sizeof def);
            fprintf(stderr, "csfcal: --store: empty path (give a file, or leave --store out for the "
                            "default %s)\n", def);
            return -1;
        }
        /* A password here would sit in shell history and process lists: libpq reads it from
         * ~/.pgpass, PGPASSFILE or a service file instead. The message does not repeat it. */
        {
            csf_error err;
            if (csf_store_check_location(arg, "--store", &err) != CSF_OK) {
                fprintf(stderr, "csfcal: %s\n", err.msg);
                return -1;
            }
        }
        return set_key(cli, "store", arg);
    case CSF_OPT_SEED: {
        long v;
        if (csf_parse_int(arg, "seed", 0, 0x7fffffffL, &v) < 0) return -1;
        cli->seed = (uint64_t)v;
        cli->seed_set = 1;
        return 1;
    }
    case CSF_OPT_HEADLESS: cli->headless = 1; return 1;
    case CSF_OPT_JSON: cli->json = 1; return 1;
    case CSF_OPT_PHOTOMETER: return set_key(cli, "photometer", arg);
    case CSF_OPT_OBSERVER: return set_key(cli, "observer", arg);
    case CSF_OPT_PROFILE:
        if (!*arg) {
            fprintf(stderr, "csfcal: --profile: empty path (give a display profile file, or leave "
                            "--profile out for the default display model)\n");
            return -1;
        }
        return set_key(cli, "display_profile", arg);
    case CSF_OPT_MONITOR: cli->monitor_given = 1; return set_key(cli, "monitor", arg);
    case CSF_OPT_DISTANCE: return set_key(cli, "viewing_distance_mm", arg);
    case CSF_OPT_SET: return set_option(cli, arg);
    case CSF_OPT_SCREEN_MM: {
        double w, h;
        if (parse_pair(arg, "screen-mm", 30, 10000, &w, &h) < 0) return -1;
        cli->cfg.screen_width_mm = w;
        cli->cfg.screen_height_mm = h;
        return 1;
    }
    case CSF_OPT_SCREEN_PX: {
        double w, h;
        if (parse_pair(arg, "screen-px", 64, 16384, &w, &h) < 0) return -1;
        if (w != floor(w) || h != floor(h)) {
            fprintf(stderr, "csfcal: --screen-px: pixel counts must be whole numbers\n");
            return -1;
        }
        cli->cfg.screen_width_px = (int)w;
        cli->cfg.screen_height_px = (int)h;
        return 1;
    }
    case CSF_OPT_RESUME: {
        long v;
        if (csf_parse_int(arg, "resume", 1, 0x7fffffffL, &v) < 0) return -1;
        cli->resume_id = (int)v;
        return 1;
    }
    default: return 0;
    }
}

const char *csf_cli_option_name(char **argv, char *buf, size_t len)
{
    /* A short option may sit inside a cluster ("-qz"): getopt names it in optopt. A long one is
     * the whole argument, without any "=value" (a value may be long or private). */
    if (optopt > 0 && optopt < 256 && optopt != '?') {
        snprintf(buf, len, "-%c", optopt);
        return buf;
    }
    const char *arg = optind > 0 ? argv[optind - 1] : "";
    size_t n = strcspn(arg, "=");
    snprintf(buf, len, "%.*s", (int)(n < len ? n : len - 1), arg);
    return buf;
}

int csf_cli_option_default(csf_cli *cli, const char *cmd, const char *help, int opt, char **argv)
{
    switch (opt) {
    case 'h':
        fputs(help, stdout);
        fputs(csf_cli_common_help, stdout);
        return 0;
    case ':':
        fprintf(stderr, "csfcal: %s: option %s needs a value\n", cmd, argv[optind - 1]);
        return 2;
    case '?': {
        char name[64];
        fprintf(stderr, "csfcal: %s: unknown option '%s' (try csfcal %s --help)\n", cmd,
                csf_cli_option_name(argv, name, sizeof name), cmd);
        return 2;
    }
    default: {
        int h = csf_cli_common_option(cli, opt, optarg);
        if (h < 0) return 2;
        if (h == 0) {
            char name[64];
            fprintf(stderr, "csfcal: %s: option '%s' is not handled here (try csfcal %s --help)\n", cmd,
                    csf_cli_option_name(argv, name, sizeof name), cmd);
            return 2;
        }
        return -1;
    }
    }
}

int csf_cli_want_headless(const csf_cli *cli)
{
    if (cli->headless) return 1;
    const char *x = getenv("DISPLAY"), *w = getenv("WAYLAND_DISPLAY");
    return !((x && *x) || (w && *w));
}

const char *csf_cli_offscreen_reason(const csf_cli *cli)
{
    if (!csf_cli_want_headless(cli)) return NULL;
    return cli->headless ? "--headless was given"
                         : "there is no display (neither DISPLAY nor WAYLAND_DISPLAY is set)";
}

int csf_cli_refuse_monitor(const csf_cli *cli, const char *cmd, const char *offscreen_why)
{
    if (!cli->monitor_given || !offscreen_why) return 0;
    /* Refused, not ignored: whoever names a monitor expects a person to look at it, and a
     * session drawn offscreen would pass for one shown there. */
    fprintf(stderr,
            "csfcal: %s: --monitor %s: this session draws offscreen because %s, so no window opens on "
            "any monitor; leave out --monitor (a window opens only on the station's display, without "
            "--headless or --png)\n",
            cmd, cli->cfg.monitor, offscreen_why);
    return 2;
}

/* Creates the folders above path that are missing, and says so: a store folder appearing
 * silently (a typing mistake, an example's /data/lab) would hide where the sessions went. */
static void mkdir_parents(const char *path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    char *slash = strrchr(buf, '/');
    if (!slash || slash == buf) return;
    *slash = '\0';
    struct stat st;
    if (stat(buf, &st) == 0) return;
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char c = *p;
            *p = '\0';
            mkdir(buf, 0755);
            *p = c;
            if (!c) break;
        }
    }
    if (stat(buf, &st) == 0 && S_ISDIR(st.st_mode))
        fprintf(stderr, "csfcal: note: the store's folder %s did not exist; created it\n", buf);
}

const char *csf_cli_store_path(csf_cli *cli)
{
    if (cli->cfg.store_path[0] == '\0')
        csf_config_default_store_path(cli->cfg.store_path, sizeof cli->cfg.store_path);
    if (!csf_store_is_server(cli->cfg.store_path)) mkdir_parents(cli->cfg.store_path);
    return cli->cfg.store_path;
}

/* Callers name options with or without their dashes; messages show exactly two. */
static const char *bare(const char *name)
{
    while (*name == '-') name++;
    return name;
}

int csf_parse_double(const char *text, const char *name, double lo, double hi, double *out)
{
    name = bare(name);
    double v = 0;
    csf_num_result r = csf_number_parse(text, lo, hi, &v);
    if (r == CSF_NUM_NOT_A_NUMBER) {
        fprintf(stderr, "csfcal: --%s: '%s' is not a number (allowed %g to %g)\n", name, text, lo, hi);
        return -1;
    }
    if (r == CSF_NUM_OUT_OF_RANGE) {
        fprintf(stderr, "csfcal: --%s: %g is out of range (allowed %g to %g)\n", name, v, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int csf_parse_int(const char *text, const char *name, long lo, long hi, long *out)
{
    name = bare(name);
    long v = 0;
    csf_num_result r = csf_whole_parse(text, lo, hi, &v);
    if (r == CSF_NUM_NOT_A_NUMBER) {
        fprintf(stderr, "csfcal: --%s: '%s' is not a whole number (allowed %ld to %ld)\n", name, text, lo, hi);
        return -1;
    }
    if (r == CSF_NUM_OUT_OF_RANGE) {
        fprintf(stderr, "csfcal: --%s: %ld is out of range (allowed %ld to %ld)\n", name, v, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int csf_parse_double_list(const char *text, const char *name, double lo, double hi, double *out, int max)
{
    name = bare(name);
    if (strlen(text) >= 1024) {
        fprintf(stderr, "csfcal: --%s: list longer than 1023 characters\n", name);
        return -1;
    }
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", text);
    if (buf[0] == '\0') {
        fprintf(stderr, "csfcal: --%s: empty list\n", name);
        return -1;
    }
    int n = 0;
    /* Split by hand: strtok would skip empty items ("2,,4"), and an empty item is a typing
     * mistake the user should hear about, not a value to drop. */
    for (char *tok = buf;;) {
        char *comma = strchr(tok, ',');
        if (comma) *comma = '\0';
        if (*tok == '\0') {
            fprintf(stderr, "csfcal: --%s: item %d of '%s' is empty\n", name, n + 1, text);
            return -1;
        }
        if (n >= max) {
            fprintf(stderr, "csfcal: --%s: too many values (at most %d)\n", name, max);
            return -1;
        }
        if (csf_parse_double(tok, name, lo, hi, &out[n]) < 0) return -1;
        n++;
        if (!comma) break;
        tok = comma + 1;
    }
    return n;
}

int csf_cli_report(const char *context, const csf_error *err)
{
    if (context && *context) fprintf(stderr, "csfcal: %s: %s\n", context, err->msg);
    else fprintf(stderr, "csfcal: %s\n", err->msg);
    return err->code == CSF_E_INVALID_ARG ? 2 : 1;
}

char *csf_shell_quote(const char *word)
{
    if (!word) word = "";
    /* Words made only of these need no quotes in any POSIX shell; they keep hints readable. */
    static const char plain[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                "@%+=:,./_-";
    size_t n = strlen(word);
    char *out = malloc(4 * n + 3);
    if (!out) return NULL;
    if (n && strspn(word, plain) == n) return memcpy(out, word, n + 1);
    size_t o = 0;
    out[o++] = '\'';
    for (const char *p = word; *p; p++) {
        if (*p == '\'') {
            memcpy(out + o, "'\\''", 4); /* close, a quoted quote, reopen */
            o += 4;
        } else {
            out[o++] = *p;
        }
    }
    out[o++] = '\'';
    out[o] = '\0';
    return out;
}
