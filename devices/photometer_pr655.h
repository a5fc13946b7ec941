/* Photo Research PR-655 / PR-670 SpectraScan spectroradiometers over USB serial (CDC ACM,
 * /dev/ttyACM*). Remote mode is entered by sending the letters P H O T O (no line ending; the
 * instrument answers "REMOTE MODE") and left with Q. Commands end in CR; replies are
 * "NNNN[,field...]" CR LF, NNNN the error code (0000: none). csfcal sends D111 (model), D110
 * (serial number), then per reading M0 (measure) and D2 (CIE 1931 X, Y, Z: "NNNN,UUU,X,Y,Z", UUU
 * the units code). Error codes (the manual's; sign as the instrument sends it, csfcal reads |N|):
 * 1 light source not constant, 2 light overload, 3 cannot sync, 4 adaptive mode error, 8 weak
 * light, 9 sync error, 10 cannot auto sync, 12 adaptive mode time out, 1000 and above: command
 * errors. Specs: pr655:PATH, pr670:PATH [,timeout_s=S] [,aperture=1|1/2|1/4|1/8 on the PR-670] (see
 * docs/instruments.md). */
#ifndef CSF_PHOTOMETER_PR655_H
#define CSF_PHOTOMETER_PR655_H

#include <stddef.h>

#include "core/csf_status.h"

#define CSF_PR_MAX_FIELDS 8

typedef struct {
    long code;               /* NNNN, as sent (may be negative) */
    int n_fields;            /* fields after the code */
    char field[CSF_PR_MAX_FIELDS][40];
} csf_pr_reply;

/* Parses one reply line (line ending removed). CSF_E_PROTOCOL with the reason when the code is
 * not an integer, a field is too long, or there are too many. Pure (fuzzed by fuzz_pr_reply). */
csf_status csf_pr_parse(const char *line, size_t len, csf_pr_reply *out, csf_error *err);
/* Field i as a finite number; -1 when it is not one. */
int csf_pr_field_num(const csf_pr_reply *r, int i, double *out);
const char *csf_pr_error_text(long code);
/* The options after the port (spec_name "pr655" or "pr670"): timeout_s=S (0.1 to 600) and, on the
 * PR-670, aperture=1|1/2|1/4|1/8 (the aperture set on the instrument, in degrees). Sets only what
 * is given; CSF_E_INVALID_ARG naming the option otherwise. Pure (fuzzed by fuzz_pr_options). */
csf_status csf_pr_parse_options(const char *spec_name, const char *opts, double *timeout_s,
                                double *aperture_deg, csf_error *err);
csf_status csf_pr_error_status(long code);

#endif
