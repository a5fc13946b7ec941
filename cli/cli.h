/* Shared command-line plumbing for the csfcal subcommands: common options (config, store, seed,
 * headless, simulated devices, geometry overrides), checked number parsing, and error printing. */
#ifndef CSF_CLI_H
#define CSF_CLI_H

#include <getopt.h>
#include <stddef.h>
#include <stdint.h>

#include "cli/config.h"

typedef struct {
    csf_config cfg;          /* station configuration with command-line overrides applied */
    const char *config_path; /* --config */
    uint64_t seed;           /* --seed (default 1) */
    int seed_set;
    int headless;            /* --headless, or forced when no display is available */
    int json;                /* --json */
    int resume_id;           /* --resume ID (0 = none) */
    int monitor_given;       /* --monitor or --set monitor= on the command line */
} csf_cli;

/* Long options every subcommand accepts; append to a subcommand's own getopt table with
 * CSF_CLI_COMMON_OPTIONS. Their values are >= 1000 so they do not clash with short options. */
enum {
    CSF_OPT_CONFIG = 1000, CSF_OPT_STORE, CSF_OPT_SEED, CSF_OPT_HEADLESS, CSF_OPT_JSON,
    CSF_OPT_PHOTOMETER, CSF_OPT_OBSERVER, CSF_OPT_SET, CSF_OPT_DISTANCE, CSF_OPT_SCREEN_MM,
    CSF_OPT_SCREEN_PX, CSF_OPT_PROFILE, CSF_OPT_MONITOR, CSF_OPT_RESUME,
    CSF_OPT_FIRST_FREE = 1100 /* subcommands number their own long-only options from here */
};

#define CSF_CLI_COMMON_OPTIONS                                         \
    {"config", required_argument, 0, CSF_OPT_CONFIG},                  \
    {"store", required_argument, 0, CSF_OPT_STORE},                    \
    {"seed", required_argument, 0, CSF_OPT_SEED},                      \
    {"headless", no_argument, 0, CSF_OPT_HEADLESS},                    \
    {"json", no_argument, 0, CSF_OPT_JSON},                            \
    {"photometer", required_argument, 0, CSF_OPT_PHOTOMETER},          \
    {"observer", required_argument, 0, CSF_OPT_OBSERVER},              \
    {"set", required_argument, 0, CSF_OPT_SET},                        \
    {"distance-mm", required_argument, 0, CSF_OPT_DISTANCE},           \
    {"screen-mm", required_argument, 0, CSF_OPT_SCREEN_MM},            \
    {"screen-px", required_argument, 0, CSF_OPT_SCREEN_PX},            \
    {"profile", required_argument, 0, CSF_OPT_PROFILE},                \
    {"monitor", required_argument, 0, CSF_OPT_MONITOR},                \
    {"resume", required_argument, 0, CSF_OPT_RESUME}

/* Help text for the common options, for subcommands' --help. */
extern const char csf_cli_common_help[];

/* Loads the configuration: call once before getopt. It pre-scans argv for --config so the file
 * is read before any override. Returns 0, or prints the error and returns the exit status (2). */
int csf_cli_init(csf_cli *cli, int argc, char **argv);

/* Handles one common option from getopt_long. Returns 1 if handled, 0 if not a common option,
 * -1 on a bad value (already reported on stderr). */
int csf_cli_common_option(csf_cli *cli, int opt, const char *arg);

/* Decides headless mode: true if --headless was given or no X11/Wayland display is reachable. */
int csf_cli_want_headless(const csf_cli *cli);

/* Why a session draws offscreen, for messages ("--headless was given", or that there is no
 * display); NULL when it opens a window (csf_cli_want_headless is false). */
const char *csf_cli_offscreen_reason(const csf_cli *cli);

/* A monitor named on the command line (--monitor, --set monitor=) for a session that draws
 * offscreen for the reason offscreen_why: prints that it is refused and why, and returns 2.
 * Returns 0 when no monitor was named or offscreen_why is NULL. cmd names the command. */
int csf_cli_refuse_monitor(const csf_cli *cli, const char *cmd, const char *offscreen_why);

/* word as one POSIX shell word, for commands printed for the user to paste: unchanged when it
 * holds only letters, digits and @%+=:,./_- (and is not empty), else in single quotes with each
 * ' written as '\''. malloc'd (free()); NULL when out of memory. */
char *csf_shell_quote(const char *word);

/* Resolved store path (config/--store, else the XDG default); creates the parent directory. */
const char *csf_cli_store_path(csf_cli *cli);

/* Checked number parsing: on failure prints "csfcal: --name: ... (allowed lo to hi)" and returns -1. */
int csf_parse_double(const char *text, const char *name, double lo, double hi, double *out);
int csf_parse_int(const char *text, const char *name, long lo, long hi, long *out);
/* Comma-separated list of doubles, each in [lo, hi]; at most max values; an empty item ("2,,4")
 * is refused, naming it. Returns the count or -1. name may carry its dashes or not. */
int csf_parse_double_list(const char *text, const char *name, double lo, double hi, double *out, int max);

/* The default: branch of a subcommand's getopt_long loop (optstring starting with ':', opterr 0),
 * for every option the subcommand does not handle itself. 'h' (-h, and --help given as 'h' in the
 * option table) prints help and csf_cli_common_help to stdout; ':' prints "csfcal: CMD: option
 * --x needs a value"; '?' prints "csfcal: CMD: unknown option '--x' (try csfcal CMD --help)"; any
 * other goes to csf_cli_common_option. Returns -1 to go on parsing, else the exit status to return
 * at once: 0 after help, 2 after a usage error (already reported on stderr). */
int csf_cli_option_default(csf_cli *cli, const char *cmd, const char *help, int opt, char **argv);

/* The option getopt_long just stopped at, as the user typed it ("--freqz", "-x"), without any
 * "=value"; for messages. buf holds the result. */
const char *csf_cli_option_name(char **argv, char *buf, size_t len);

/* Prints "csfcal: <msg>" to stderr and returns the exit status for the error (1 runtime, 2 usage). */
int csf_cli_report(const char *context, const csf_error *err);

#endif
