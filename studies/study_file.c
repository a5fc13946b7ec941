/* Study settings and conditions files (see study_file.h, docs/studies.md). */
#include "studies/study_file.h"

#include <errno.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/csv.h"
#include "core/file_read.h"
#include "results/store/store.h"
#include "stimuli/image.h"

#define SETTINGS_MAX_BYTES (1u << 20)
#define CONDITIONS_MAX_BYTES (4u << 20)
#define INSTRUCTIONS_MAX_BYTES (64u << 10)
#define CSV_MAX_COLUMNS 32

const char *csf_study_design_name(csf_study_design d)
{
    switch (d) {
    case CSF_DESIGN_2AFC: return "2afc";
    case CSF_DESIGN_2IFC: return "2ifc";
    case CSF_DESIGN_SAME_DIFF: return "same_different";
    case CSF_DESIGN_YES_NO: return "yes_no";
    }
    return "?";
}

uint64_t csf_fnv1a64(const void *data, size_t len, uint64_t h)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < len; i++) {
        h ^= p[i];
        h *= 0x100000001b3ULL;
    }
    return h;
}

static void settings_defaults(csf_study *s)
{
    s->design = CSF_DESIGN_2AFC;
    s->trials_per_condition = 40;
    s->practice_trials = 4;
    s->blocks = 1;
    s->stimulus_s = 0.5;
    s->isi_s = 0.5;
    s->response_window_s = 0;
    s->iti_s = 0.5;
    s->fixation_s = 0.5;
    s->feedback_s = 0.4;
    s->seed = 1;
    s->counterbalance = 1;
    s->catch_fraction = 0.25;
    s->same_fraction = 0.5;
    s->sd_differencing = 1;
    s->max_lapse = 0.06;
    s->bootstrap = 200;
    s->adaptive_max_contrast = 0.5;
    snprintf(s->break_text, sizeof s->break_text, "Take a short break. Press any key to go on.");
}

/* A number in [lo, hi], the whole value (no trailing text, no NaN). */
static int parse_num(const char *v, double lo, double hi, double *out)
{
    if (!*v) return -1;
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    if (errno || *end || !isfinite(d) || d < lo || d > hi) return -1;
    *out = d;
    return 0;
}

static int parse_bool(const char *v, int *out)
{
    if (!strcmp(v, "yes") || !strcmp(v, "true") || !strcmp(v, "1") || !strcmp(v, "on")) *out = 1;
    else if (!strcmp(v, "no") || !strcmp(v, "false") || !strcmp(v, "0") || !strcmp(v, "off")) *out = 0;
    else return -1;
    return 0;
}

typedef struct {
    const char *name;
    double lo, hi;
    const char *unit;
    size_t off;    /* offsetof in csf_study; int fields flagged by is_int */
    int is_int;
} num_key;

#define NK(n, f, lo, hi, u) {n, lo, hi, u, offsetof(csf_study, f), 0}
#define IK(n, f, lo, hi, u) {n, lo, hi, u, offsetof(csf_study, f), 1}
static const num_key num_keys[] = {
    IK("trials_per_condition", trials_per_condition, 1, 10000, "trials"),
    IK("practice_trials", practice_trials, 0, 200, "trials"),
    IK("blocks", blocks, 1, 100, "blocks"),
    NK("stimulus_s", stimulus_s, 0.001, 60, "s"),
    NK("isi_s", isi_s, 0, 60, "s"),
    NK("response_window_s", response_window_s, 0, 600, "s (0 = no limit)"),
    NK("iti_s", iti_s, 0, 60, "s"),
    NK("fixation_s", fixation_s, 0, 60, "s"),
    NK("feedback_s", feedback_s, 0, 10, "s"),
    NK("catch_fraction", catch_fraction, 0, 0.9, ""),
    NK("same_fraction", same_fraction, 0.05, 0.95, ""),
    NK("max_lapse", max_lapse, 0, 0.2, ""),
    IK("bootstrap", bootstrap, 0, 100000, "samples"),
    NK("adaptive_max_contrast", adaptive_max_contrast, 0.001, 1, "Michelson"),
};

/* A word from a list: its index, or -1. */
static int pick(const char *v, const char *const *words)
{
    for (int i = 0; words[i]; i++)
        if (!strcmp(v, words[i])) return i;
    return -1;
}

/* counterbalance: yes/no balance the target place or interval within each condition and block
 * (as before); none is no; latin_blocks and latin_conditions balance the targets too and order
 * blocks or conditions by a balanced Latin square across participants. */
static csf_status set_counterbalance(csf_study *s, const char *v, const char *where, int line, csf_error *err)
{
    static const char *const latin[] = {"none", "latin_blocks", "latin_conditions", NULL};
    int b, k = pick(v, latin);
    if (k >= 0) {
        s->counterbalance = k != 0;
        s->latin = (csf_study_latin)k;
    } else if (!parse_bool(v, &b)) {
        s->counterbalance = b;
        s->latin = CSF_LATIN_NONE;
    } else {
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s:%d: counterbalance = '%s': expected yes, no, none, "
                             "latin_blocks or latin_conditions",
                             where, line, v);
    }
    return CSF_OK;
}

/* instructions: one line, "\n" a line break (the text screen's), printable text only. */
static csf_status set_instructions(csf_study *s, const char *v, const char *where, int line, csf_error *err)
{
    size_t k = 0;
    for (const char *p = v; *p; p++) {
        if (k + 1 >= sizeof s->instructions)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: instructions: at most %zu characters", where,
                                 line, sizeof s->instructions - 1);
        if (p[0] == '\\' && p[1] == 'n') {
            s->instructions[k++] = '\n';
            p++;
        } else {
            s->instructions[k++] = *p;
        }
    }
    s->instructions[k] = '\0';
    return CSF_OK;
}

/* A text value that must fit its field. */
static csf_status set_text(char *dst, size_t cap, const char *key, const char *v, const char *where, int line,
                           csf_error *err)
{
    if (!*v || strlen(v) >= cap)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: %s: 1 to %zu characters", where, line, key,
                             cap - 1);
    snprintf(dst, cap, "%s", v);
    return CSF_OK;
}

/* The keys of a design's order, counterbalancing, instructions, feedback and practice
 * (docs/studies.md, "Designs"). */
static csf_status set_design_key(csf_study *s, const char *key, const char *v, const char *where, int line,
                                 csf_error *err)
{
    static const char *const orders[] = {"random", "sequential", NULL};
    static const char *const feedbacks[] = {"none", "all", "practice", NULL};
    if (!strcmp(key, "counterbalance")) return set_counterbalance(s, v, where, line, err);
    if (!strcmp(key, "instructions")) return set_instructions(s, v, where, line, err);
    if (!strcmp(key, "instructions_file"))
        return set_text(s->instructions_file, sizeof s->instructions_file, key, v, where, line, err);
    if (!strcmp(key, "blocked_by"))
        return set_text(s->blocked_by, sizeof s->blocked_by, key, v, where, line, err);
    if (!strcmp(key, "practice_conditions")) {
        s->practice_line = line;
        return set_text(s->practice_labels, sizeof s->practice_labels, key, v, where, line, err);
    }
    if (!strcmp(key, "order")) {
        int k = pick(v, orders);
        if (k < 0)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s:%d: order = '%s': expected random or sequential "
                                 "(blocks by a column: blocked_by = COLUMN)",
                                 where, line, v);
        s->order = (csf_study_order)k;
        return CSF_OK;
    }
    if (!strcmp(key, "feedback")) {
        int b = 0, k = pick(v, feedbacks);
        if (k < 0 && parse_bool(v, &b))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s:%d: feedback = '%s': expected none, practice "
                                 "or all (yes = all, no = none)",
                                 where, line, v);
        s->feedback = k >= 0 ? (csf_study_feedback)k : b ? CSF_FEEDBACK_ALL : CSF_FEEDBACK_NONE;
        return CSF_OK;
    }
    return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: unknown key '%s' (see docs/studies.md)", where, line,
                         key);
}

static csf_status set_key(csf_study *s, const char *key, const char *v, const char *where, int line,
                          csf_error *err)
{
    for (size_t i = 0; i < sizeof num_keys / sizeof num_keys[0]; i++) {
        const num_key *k = &num_keys[i];
        if (strcmp(k->name, key)) continue;
        double d;
        if (parse_num(v, k->lo, k->hi, &d) || (k->is_int && d != floor(d)))
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: %s = '%s': expected %s from %g to %g %s",
                                 where, line, key, v, k->is_int ? "a whole number" : "a number", k->lo,
                                 k->hi, k->unit);
        if (k->is_int) *(int *)((char *)s + k->off) = (int)d;
        else *(double *)((char *)s + k->off) = d;
        return CSF_OK;
    }
    if (!strcmp(key, "name")) {
        if (!*v || strlen(v) >= sizeof s->name || strpbrk(v, "\"'\\"))
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: name: 1 to %zu characters, no quotes "
                                 "(\" or ') or backslashes", where, line, sizeof s->name - 1);
        snprintf(s->name, sizeof s->name, "%s", v);
    } else if (!strcmp(key, "design")) {
        if (!strcmp(v, "2afc")) s->design = CSF_DESIGN_2AFC;
        else if (!strcmp(v, "2ifc")) s->design = CSF_DESIGN_2IFC;
        else if (!strcmp(v, "same_different")) s->design = CSF_DESIGN_SAME_DIFF;
        else if (!strcmp(v, "yes_no")) s->design = CSF_DESIGN_YES_NO;
        else return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: design = '%s': expected 2afc, 2ifc, "
                                  "same_different or yes_no", where, line, v);
    } else if (!strcmp(key, "conditions")) {
        if (!*v || strlen(v) >= sizeof s->conditions_path)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: conditions: a file name of 1 to %zu "
                                 "characters", where, line, sizeof s->conditions_path - 1);
        snprintf(s->conditions_path, sizeof s->conditions_path, "%s", v);
    } else if (!strcmp(key, "seed")) {
        double d;
        if (parse_num(v, 0, 9007199254740991.0, &d) || d != floor(d))
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: seed = '%s': expected a whole number "
                                 "from 0 to 2^53-1", where, line, v);
        s->seed = (uint64_t)d;
    } else if (!strcmp(key, "sd_model")) {
        if (!strcmp(v, "differencing")) s->sd_differencing = 1;
        else if (!strcmp(v, "independent")) s->sd_differencing = 0;
        else return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: sd_model = '%s': expected differencing "
                                  "or independent", where, line, v);
    } else if (!strcmp(key, "break_text")) {
        if (strlen(v) >= sizeof s->break_text)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: break_text: at most %zu characters",
                                 where, line, sizeof s->break_text - 1);
        snprintf(s->break_text, sizeof s->break_text, "%s", v);
    } else {
        return set_design_key(s, key, v, where, line, err);
    }
    return CSF_OK;
}

/* Checks between settings that each were fine alone. */
static csf_status check_settings(const csf_study *s, const char *where, csf_error *err)
{
    if (!s->conditions_path[0])
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: no 'conditions = FILE.csv' line", where);
    if (!s->name[0])
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: no 'name = ...' line (the study's name in the "
                             "store)", where);
    if (s->trials_per_condition % s->blocks)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: trials_per_condition %d cannot be split into %d "
                             "equal blocks", where, s->trials_per_condition, s->blocks);
    if ((s->design == CSF_DESIGN_2IFC || s->design == CSF_DESIGN_SAME_DIFF) && !(s->isi_s > 0))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: isi_s = 0: a %s design needs a gap between its "
                             "two intervals (isi_s > 0)", where, csf_study_design_name(s->design));
    if (s->response_window_s > 0 && s->response_window_s < 0.2)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: response_window_s = %g s: nobody answers that "
                             "fast (0 = no limit, else at least 0.2 s)", where, s->response_window_s);
    if (s->blocked_by[0] && s->blocks != 1)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s: blocked_by = %s makes one block per value of "
                             "that column: blocks = %d cannot be given with it",
                             where, s->blocked_by, s->blocks);
    if (s->latin == CSF_LATIN_BLOCKS && !s->blocked_by[0])
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s: counterbalance = latin_blocks orders blocks that "
                             "differ: it needs blocked_by = COLUMN (without it every block holds the "
                             "same trials)",
                             where);
    if (s->latin == CSF_LATIN_CONDITIONS && s->order != CSF_ORDER_SEQUENTIAL)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s: counterbalance = latin_conditions orders the "
                             "conditions: it needs order = sequential (in random order they are "
                             "shuffled anyway)",
                             where);
    if (s->design == CSF_DESIGN_YES_NO && !(s->catch_fraction > 0))
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: a yes_no design needs catch trials "
                             "(catch_fraction > 0): without them no false-alarm rate can be measured",
                             where);
    return CSF_OK;
}

/* A line of a study file is shown in messages and stored with every session: tabs and the CR
 * of a CRLF line end apart, it holds printable text only (the message names the character and
 * its position in the line). */
static csf_status check_line(const char *l, const char *where, int line, csf_error *err)
{
    char tmp[8192], what[1100];
    snprintf(tmp, sizeof tmp, "%s", l);
    size_t n = strlen(tmp);
    if (n > 0 && tmp[n - 1] == '\r') tmp[n - 1] = '\0';
    for (char *t = tmp; *t; t++)
        if (*t == '\t') *t = ' ';
    snprintf(what, sizeof what, "%.1080s:%d", where, line);
    return csf_store_check_text(tmp, what, err);
}

/* check_line as the line reader's check: every line as read, comments included. */
typedef struct {
    const char *where;
    csf_error *err;
} line_check;

static int check_line_cb(void *ctx, const char *raw, int line)
{
    const line_check *c = ctx;
    return check_line(raw, c->where, line, c->err) != CSF_OK;
}

/* The keys met so far, to find one given twice (where the last would silently win). */
typedef struct {
    char key[32][32];
    int line[32];
    int n;
} seen_keys;

static void note_key(seen_keys *k, csf_study *s, const char *key, int line)
{
    for (int i = 0; i < k->n; i++)
        if (!strcmp(k->key[i], key)) {
            if (!s->dup_line) {
                snprintf(s->dup_key, sizeof s->dup_key, "%s", key);
                s->dup_line = line;
                s->dup_first_line = k->line[i];
            }
            return;
        }
    if (k->n < 32 && strlen(key) < sizeof k->key[0]) {
        snprintf(k->key[k->n], sizeof k->key[0], "%s", key);
        k->line[k->n++] = line;
    }
}

csf_status csf_study_parse_settings(csf_study *s, const char *text, size_t len, const char *where,
                                    csf_error *err)
{
    settings_defaults(s);
    if (len > SETTINGS_MAX_BYTES)
        return csf_error_set(err, CSF_E_FORMAT, "%s: larger than %u bytes", where, SETTINGS_MAX_BYTES);
    if (memchr(text, '\0', len))
        return csf_error_set(err, CSF_E_FORMAT, "%s: holds a NUL byte (not a text file)", where);
    seen_keys seen = {0};
    line_check lc = {where, err};
    csf_lines lines;
    if (csf_lines_open(&lines, text, len, 2047)) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    lines.hash_comments = 1;
    lines.check = check_line_cb;
    lines.check_ctx = &lc;
    char *l;
    csf_status st = CSF_OK;
    int got;
    while (st == CSF_OK && (got = csf_lines_next(&lines, &l)) != 0) {
        int line = lines.line;
        if (got < 0) {
            st = lines.why ? csf_error_set(err, CSF_E_FORMAT, "%s:%d: %s", where, line, lines.why)
                           : CSF_E_INVALID_ARG;
            break;
        }
        if (!strcmp(l, "[study]")) continue;
        char *eq = strchr(l, '=');
        if (!eq) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s:%d: expected 'key = value', got '%.60s'", where, line,
                               l);
            break;
        }
        *eq = '\0';
        char *key = csf_trim(l), *val = csf_trim(eq + 1);
        size_t vl = strlen(val);
        if (vl >= 2 && val[0] == '"' && val[vl - 1] == '"') {
            val[vl - 1] = '\0';
            val++;
        }
        st = set_key(s, key, val, where, line, err);
        if (st == CSF_OK) note_key(&seen, s, key, line);
    }
    csf_lines_close(&lines);
    if (st != CSF_OK) return st;
    return check_settings(s, where, err);
}

/* ---- conditions CSV ------------------------------------------------------------------------ */

enum {
    COL_LABEL, COL_STIMULUS, COL_FREQ, COL_CONTRAST, COL_METHOD, COL_ECC, COL_POLAR, COL_ORIENT,
    COL_PHASE, COL_SIGMA, COL_RADIUS, COL_DRIFT, COL_VELOCITY, COL_MOTION_DIR, COL_MEAN_LUM,
    COL_IMAGE_A, COL_IMAGE_B, COL_SIZE, COL_CURVE, N_COLS
};
static const char *const col_names[N_COLS] = {
    "label", "stimulus", "freq_cpd", "contrast", "method", "ecc_deg", "polar_deg", "orientation_deg",
    "phase_deg", "sigma_deg", "radius_deg", "drift_hz", "velocity_dps", "motion_dir_deg",
    "mean_lum_cdm2", "image_a", "image_b", "size_deg", "curve"};

typedef struct {
    const char *where;
    int line;
    const char *label;
    csf_error *err;
} row_ctx;

/* A numeric cell: column c of the row, default dflt when the column is absent or the cell empty. */
static csf_status cell_num(const row_ctx *r, const int *col, char fields[][CSF_CSV_FIELD_MAX], int c,
                           double lo, double hi, const char *unit, double dflt, double *out)
{
    *out = dflt;
    if (col[c] < 0 || !fields[col[c]][0]) return CSF_OK;
    if (parse_num(fields[col[c]], lo, hi, out))
        return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): %s = '%.40s': expected a number "
                             "from %g to %g %s", r->where, r->line, r->label, col_names[c],
                             fields[col[c]], lo, hi, unit);
    return CSF_OK;
}

static csf_status resolve(const char *base_dir, const char *rel, char *out, size_t cap, const row_ctx *r,
                          const char *col)
{
    int n = (rel[0] == '/' || !base_dir || !*base_dir) ? snprintf(out, cap, "%s", rel)
                                                       : snprintf(out, cap, "%s/%s", base_dir, rel);
    if (n < 0 || (size_t)n >= cap)
        return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): %s path longer than %zu characters",
                             r->where, r->line, r->label, col, cap - 1);
    return CSF_OK;
}

/* Radius of a condition's patch in degrees (images: half the width; the height is known only
 * once the image is read, so csf_study_load checks images again). */
static double patch_radius_deg(const csf_study_condition *c)
{
    switch (c->kind) {
    case CSF_COND_GABOR: return 3.0 * c->sigma_deg;
    case CSF_COND_GRATING: return c->radius_deg + 0.25;
    case CSF_COND_IMAGE: return 0.5 * c->size_deg;
    }
    return 0;
}

static csf_status parse_row(csf_study *s, csf_study_condition *c, const int *col,
                            char fields[][CSF_CSV_FIELD_MAX], const char *base_dir, row_ctx *r)
{
    memset(c, 0, sizeof *c);
    c->line = r->line;
    const char *lab = fields[col[COL_LABEL]];
    if (!*lab || strlen(lab) >= sizeof c->label || strpbrk(lab, "\"\\,"))
        return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d: label: 1 to %zu characters, no quotes, "
                             "commas or backslashes", r->where, r->line, sizeof c->label - 1);
    snprintf(c->label, sizeof c->label, "%s", lab);
    r->label = c->label;
    const char *kind = col[COL_STIMULUS] >= 0 && fields[col[COL_STIMULUS]][0] ? fields[col[COL_STIMULUS]] : "gabor";
    if (!strcmp(kind, "gabor")) c->kind = CSF_COND_GABOR;
    else if (!strcmp(kind, "grating")) c->kind = CSF_COND_GRATING;
    else if (!strcmp(kind, "image")) c->kind = CSF_COND_IMAGE;
    else return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): stimulus = '%.40s': expected gabor, "
                              "grating or image", r->where, r->line, c->label, kind);
    csf_status st;
    if ((st = cell_num(r, col, fields, COL_ECC, 0, 80, "deg", NAN, &c->ecc_deg)) != CSF_OK) return st;
    if (isnan(c->ecc_deg))
        return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): ecc_deg is empty: every condition "
                             "needs its eccentricity", r->where, r->line, c->label);
    if ((st = cell_num(r, col, fields, COL_POLAR, -360, 360, "deg", 0, &c->polar_deg)) != CSF_OK) return st;
    if ((st = cell_num(r, col, fields, COL_MEAN_LUM, 0, 10000, "cd/m2", 0, &c->mean_lum_cdm2)) != CSF_OK) return st;
    const char *cu = col[COL_CURVE] >= 0 && fields[col[COL_CURVE]][0] ? fields[col[COL_CURVE]] : c->label;
    if (strlen(cu) >= sizeof c->curve || strpbrk(cu, "\"\\,"))
        return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): curve: at most %zu characters, no "
                             "quotes, commas or backslashes", r->where, r->line, c->label, sizeof c->curve - 1);
    snprintf(c->curve, sizeof c->curve, "%s", cu);
    if (c->kind == CSF_COND_IMAGE) {
        if (col[COL_IMAGE_A] < 0 || col[COL_IMAGE_B] < 0 || col[COL_SIZE] < 0)
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): image conditions need the columns "
                                 "image_a, image_b and size_deg", r->where, r->line, c->label);
        if (!fields[col[COL_IMAGE_A]][0] || !fields[col[COL_IMAGE_B]][0])
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): image_a and image_b must both name "
                                 "a PNG file", r->where, r->line, c->label);
        if ((st = resolve(base_dir, fields[col[COL_IMAGE_A]], c->image_a, sizeof c->image_a, r, "image_a")) != CSF_OK ||
            (st = resolve(base_dir, fields[col[COL_IMAGE_B]], c->image_b, sizeof c->image_b, r, "image_b")) != CSF_OK)
            return st;
        if ((st = cell_num(r, col, fields, COL_SIZE, 0.05, 160, "deg", NAN, &c->size_deg)) != CSF_OK) return st;
        if (isnan(c->size_deg))
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): size_deg is empty: an image needs "
                                 "its width in degrees", r->where, r->line, c->label);
        c->contrast = 1;
        if (s->design == CSF_DESIGN_YES_NO)
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): image pairs are judged in 2afc, "
                                 "2ifc or same_different designs, not yes_no", r->where, r->line, c->label);
    } else {
        if (col[COL_FREQ] < 0 || col[COL_CONTRAST] < 0)
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): %s conditions need the columns "
                                 "freq_cpd and contrast", r->where, r->line, c->label, kind);
        if ((st = cell_num(r, col, fields, COL_FREQ, 0.01, 1000, "cpd", NAN, &c->freq_cpd)) != CSF_OK) return st;
        if (isnan(c->freq_cpd))
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): freq_cpd is empty", r->where,
                                 r->line, c->label);
        const char *ct = fields[col[COL_CONTRAST]];
        if (!strcmp(ct, "adaptive")) {
            c->adaptive = 1;
            c->contrast = NAN;
            const char *m = col[COL_METHOD] >= 0 && fields[col[COL_METHOD]][0] ? fields[col[COL_METHOD]] : "2afc";
            if (strcmp(m, "2afc") && strcmp(m, "bayes"))
                return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): method = '%.40s': expected 2afc "
                                     "or bayes (adaptive forced-choice procedures)", r->where, r->line,
                                     c->label, m);
            snprintf(c->method, sizeof c->method, "%s", m);
            if (s->design != CSF_DESIGN_2AFC && s->design != CSF_DESIGN_2IFC)
                return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): adaptive contrast needs a 2afc "
                                     "or 2ifc design (the procedures are forced-choice)", r->where, r->line,
                                     c->label);
        } else {
            if (parse_num(ct, 0.0001, 1, &c->contrast))
                return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): contrast = '%.40s': expected a "
                                     "Michelson contrast from 0.0001 to 1, or 'adaptive'", r->where, r->line,
                                     c->label, ct);
        }
        if ((st = cell_num(r, col, fields, COL_ORIENT, -360, 360, "deg", 0, &c->orientation_deg)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_PHASE, -360, 360, "deg", 0, &c->phase_deg)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_SIGMA, 0.05, 20, "deg", 1.0, &c->sigma_deg)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_RADIUS, 0.1, 40, "deg", 2.0, &c->radius_deg)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_DRIFT, -60, 60, "Hz", 0, &c->drift_hz)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_VELOCITY, 0, 200, "deg/s", 0, &c->velocity_dps)) != CSF_OK ||
            (st = cell_num(r, col, fields, COL_MOTION_DIR, -360, 360, "deg", 0, &c->motion_dir_deg)) != CSF_OK)
            return st;
        if (s->design == CSF_DESIGN_SAME_DIFF)
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): a same_different design compares "
                                 "image pairs (stimulus = image)", r->where, r->line, c->label);
    }
    if (s->design == CSF_DESIGN_2AFC) {
        /* the two places are opposite each other on the condition's eccentricity ring */
        double rad = patch_radius_deg(c);
        if (c->ecc_deg < rad)
            return csf_error_set(r->err, CSF_E_INVALID_ARG, "%s:%d (%s): in a 2afc design the two places at "
                                 "%g deg either side of fixation overlap (patch radius %.3g deg): ecc_deg "
                                 "must be at least %.3g", r->where, r->line, c->label, c->ecc_deg, rad, rad);
    }
    return CSF_OK;
}

/* A column of the user's own (PsychoPy's corrAns, notes, ...): carried through to the trial
 * export as text. Its name is an identifier, not one the export writes itself, and not a known
 * column in other letter case (a mistyped "Contrast" would otherwise be carried along unused). */
static csf_status check_extra_column(const char *name, const char *where, int line, csf_error *err)
{
    size_t n = strlen(name);
    int ok = n >= 1 && n <= 63 && !(name[0] >= '0' && name[0] <= '9');
    for (size_t i = 0; ok && i < n; i++) {
        char ch = name[i];
        ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
             ch == '.';
    }
    if (!ok)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "%s:%d: column '%.40s': a column of your own is named by a "
                             "letter or '_', then up to 62 letters, digits, '_' or '.'",
                             where, line, name);
    for (int k = 0; k < N_COLS; k++)
        if (!strcasecmp(name, col_names[k]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s:%d: column '%s': did you mean '%s'? (column names "
                                 "are lower case)",
                                 where, line, name, col_names[k]);
    for (int k = 0; csf_study_export_columns[k]; k++)
        if (!strcasecmp(name, csf_study_export_columns[k]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s:%d: column '%s' is one the trial export writes "
                                 "itself (docs/studies.md): rename it",
                                 where, line, name);
    return CSF_OK;
}

/* The header row: every column given once, label and ecc_deg among them; col[k] is the field of
 * known column k, -1 where absent; other columns are the user's own. */
static csf_status parse_header(char (*fields)[CSF_CSV_FIELD_MAX], int nf, int *col, const char *where,
                               int line, csf_error *err)
{
    csf_status st;
    for (int i = 0; i < nf; i++) {
        for (int j = 0; j < i; j++)
            if (!strcmp(fields[i], fields[j]))
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: column '%.40s' appears twice", where,
                                     line, fields[i]);
        int k = 0;
        while (k < N_COLS && strcmp(fields[i], col_names[k])) k++;
        if (k == N_COLS) {
            if ((st = check_extra_column(fields[i], where, line, err)) != CSF_OK) return st;
            continue;
        }
        col[k] = i;
    }
    if (col[COL_LABEL] < 0 || col[COL_ECC] < 0) {
        st = csf_error_set(err, CSF_E_INVALID_ARG,
                           "%s:%d: missing column '%s' (every conditions "
                           "file needs label and ecc_deg)",
                           where, line, col[COL_LABEL] < 0 ? "label" : "ecc_deg");
        return st;
    }
    return CSF_OK;
}

/* One data row as the next condition of s, its label not used before. */
static csf_status add_condition(csf_study *s, const int *col, char (*fields)[CSF_CSV_FIELD_MAX], int nf,
                                int n_header, const char *base_dir, const char *where, int line,
                                csf_error *err)
{
    csf_status st;
    if (nf != n_header) {
        st = csf_error_set(err, CSF_E_FORMAT, "%s:%d: %d fields, the header has %d", where, line, nf,
                           n_header);
        return st;
    }
    if (s->n_conds == CSF_STUDY_MAX_CONDITIONS) {
        st = csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: more than %d conditions", where, line,
                           CSF_STUDY_MAX_CONDITIONS);
        return st;
    }
    row_ctx r = {where, line, "?", err};
    csf_study_condition *c = &s->conds[s->n_conds];
    st = parse_row(s, c, col, fields, base_dir, &r);
    if (st != CSF_OK) return st;
    for (int i = 0; i < s->n_conds; i++)
        if (!strcmp(s->conds[i].label, c->label)) {
            st = csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: label '%s' already used on line %d", where,
                               line, c->label, s->conds[i].line);
            return st;
        }
    s->n_conds++;
    return CSF_OK;
}

/* blocked_by: the header field holding the column, or -1 with the error set. */
static int blocked_column(const csf_study *s, char (*fields)[CSF_CSV_FIELD_MAX], int nf, const char *where,
                          csf_error *err)
{
    for (int i = 0; i < nf; i++)
        if (!strcmp(fields[i], s->blocked_by)) return i;
    csf_error_set(err, CSF_E_INVALID_ARG, "%s: blocked_by = %s: %s has no column of that name", s->path,
                  s->blocked_by, where);
    return -1;
}

/* The block of the condition just added: its blocked_by value's, a new one for a value not met
 * before (blocks come in the order the file first gives their values). */
static void assign_group(csf_study *s, char (*values)[CSF_CSV_FIELD_MAX], const char *value)
{
    csf_study_condition *c = &s->conds[s->n_conds - 1];
    snprintf(values[s->n_conds - 1], CSF_CSV_FIELD_MAX, "%s", value);
    for (int i = 0; i < s->n_conds - 1; i++)
        if (!strcmp(values[i], value)) {
            c->group = s->conds[i].group;
            return;
        }
    c->group = s->n_groups++;
}

/* practice_conditions: each label named must be a condition's; those conditions alone are drawn
 * for practice. Without it every condition is. */
static csf_status resolve_practice(csf_study *s, const char *where, csf_error *err)
{
    for (int i = 0; i < s->n_conds; i++) s->conds[i].practice_pool = !s->practice_labels[0];
    if (!s->practice_labels[0]) return CSF_OK;
    char list[sizeof s->practice_labels];
    snprintf(list, sizeof list, "%s", s->practice_labels);
    char *save = NULL;
    for (char *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        const char *label = csf_trim(tok);
        int found = 0;
        for (int i = 0; i < s->n_conds; i++)
            if (!strcmp(s->conds[i].label, label)) found = s->conds[i].practice_pool = 1;
        if (!found)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s:%d: practice_conditions: no condition of %s is "
                                 "labelled '%.64s'",
                                 s->path, s->practice_line, where, label);
    }
    return CSF_OK;
}

csf_status csf_study_parse_conditions(csf_study *s, const char *text, size_t len, const char *where,
                                      const char *base_dir, csf_error *err)
{
    free(s->conds);
    s->conds = NULL;
    s->n_conds = 0;
    if (len > CONDITIONS_MAX_BYTES)
        return csf_error_set(err, CSF_E_FORMAT, "%s: larger than %u bytes", where, CONDITIONS_MAX_BYTES);
    if (memchr(text, '\0', len))
        return csf_error_set(err, CSF_E_FORMAT, "%s: holds a NUL byte (not a CSV file)", where);
    char(*fields)[CSF_CSV_FIELD_MAX] = malloc(CSV_MAX_COLUMNS * sizeof *fields);
    csf_lines lines;
    int lines_ok = csf_lines_open(&lines, text, len, 8191) == 0;
    line_check lc = {where, err};
    lines.check = check_line_cb;
    lines.check_ctx = &lc;
    s->conds = calloc(CSF_STUDY_MAX_CONDITIONS, sizeof *s->conds);
    s->n_groups = s->blocked_by[0] ? 0 : 1;
    char(*values)[CSF_CSV_FIELD_MAX] =
        s->blocked_by[0] ? malloc(CSF_STUDY_MAX_CONDITIONS * sizeof *values) : NULL;
    csf_status st = CSF_OK;
    if (!fields || !lines_ok || !s->conds || (s->blocked_by[0] && !values)) {
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
        goto out;
    }
    int col[N_COLS];
    for (int i = 0; i < N_COLS; i++) col[i] = -1;
    int n_header = 0, group_col = -1, got;
    char *l;
    while ((got = csf_lines_next(&lines, &l)) != 0) {
        int line = lines.line;
        if (got < 0) {
            st = lines.why ? csf_error_set(err, CSF_E_FORMAT, "%s:%d: %s", where, line, lines.why)
                           : CSF_E_INVALID_ARG;
            goto out;
        }
        const char *why = NULL;
        int nf = csf_csv_split(l, fields, CSV_MAX_COLUMNS, &why);
        if (nf < 0) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s:%d: %s", where, line, why);
            goto out;
        }
        if (!n_header) {
            if ((st = parse_header(fields, nf, col, where, line, err)) != CSF_OK) goto out;
            if (s->blocked_by[0] && (group_col = blocked_column(s, fields, nf, where, err)) < 0) {
                st = CSF_E_INVALID_ARG;
                goto out;
            }
            n_header = nf;
            continue;
        }
        if ((st = add_condition(s, col, fields, nf, n_header, base_dir, where, line, err)) != CSF_OK)
            goto out;
        if (group_col >= 0) assign_group(s, values, fields[group_col]);
    }
    if (!n_header) st = csf_error_set(err, CSF_E_FORMAT, "%s: empty (no header row)", where);
    else if (!s->n_conds) st = csf_error_set(err, CSF_E_INVALID_ARG, "%s: no conditions after the header", where);
    else st = resolve_practice(s, where, err);
out:
    free(fields);
    free(values);
    csf_lines_close(&lines);
    if (st != CSF_OK) {
        free(s->conds);
        s->conds = NULL;
        s->n_conds = 0;
    }
    return st;
}

/* Every image exists, decodes, and the two of a pair have the same size. */
static csf_status check_images(const csf_study *s, csf_error *err)
{
    for (int i = 0; i < s->n_conds; i++) {
        const csf_study_condition *c = &s->conds[i];
        if (c->kind != CSF_COND_IMAGE) continue;
        csf_image *im[2] = {NULL, NULL};
        const char *paths[2] = {c->image_a, c->image_b};
        for (int k = 0; k < 2; k++) {
            csf_error e;
            if (csf_image_load_png(paths[k], &im[k], &e) != CSF_OK) {
                csf_image_free(im[0]);
                return csf_error_set(err, CSF_E_NOT_FOUND, "%s:%d (%s): %s: %s", s->conditions_path, c->line,
                                     c->label, k ? "image_b" : "image_a", e.msg);
            }
        }
        int same = im[0]->width == im[1]->width && im[0]->height == im[1]->height;
        int w0 = im[0]->width, h0 = im[0]->height, w1 = im[1]->width, h1 = im[1]->height;
        csf_image_free(im[0]);
        csf_image_free(im[1]);
        if (!same)
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): image_a is %dx%d px, image_b %dx%d px: "
                                 "a pair must have one size", s->conditions_path, c->line, c->label, w0, h0,
                                 w1, h1);
    }
    return CSF_OK;
}

static void dir_of(const char *path, char *out, size_t cap)
{
    const char *slash = strrchr(path, '/');
    if (!slash) snprintf(out, cap, ".");
    else if (slash == path) snprintf(out, cap, "/");
    else snprintf(out, cap, "%.*s", (int)(slash - path), path);
}

csf_status csf_study_from_texts(const char *settings, const char *conditions, const char *path,
                                const char *conditions_path, int check_img, csf_study **out,
                                csf_error *err)
{
    *out = NULL;
    csf_study *s = calloc(1, sizeof *s);
    if (!s) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = csf_study_parse_settings(s, settings, strlen(settings), path, err);
    if (st == CSF_OK) {
        snprintf(s->path, sizeof s->path, "%s", path);
        snprintf(s->conditions_path, sizeof s->conditions_path, "%s", conditions_path);
        char dir[1024];
        dir_of(conditions_path, dir, sizeof dir);
        st = csf_study_parse_conditions(s, conditions, strlen(conditions), conditions_path, dir, err);
    }
    if (st == CSF_OK && check_img) st = check_images(s, err);
    if (st == CSF_OK) {
        s->settings_text = strdup(settings);
        s->conditions_text = strdup(conditions);
        if (!s->settings_text || !s->conditions_text) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
        uint64_t h = csf_fnv1a64(settings, strlen(settings), CSF_FNV1A64_INIT);
        h = csf_fnv1a64("\n--\n", 4, h);
        s->hash = csf_fnv1a64(conditions, strlen(conditions), h);
    }
    if (st != CSF_OK) {
        csf_study_free(s);
        return st;
    }
    *out = s;
    return CSF_OK;
}

/* A fraction of each condition's trials in a block (catch trials, same pairs) must be a whole
 * number of trials: the plan would round it, and the study would not be what its file says. */
static csf_status check_fraction(const csf_study *s, const char *key, double fraction, csf_error *err)
{
    int per_block = s->trials_per_condition / s->blocks;
    double trials = fraction * per_block;
    if (fabs(trials - floor(trials + 0.5)) < 1e-9) return CSF_OK;
    return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s = %g of %d trials per condition and block is "
                         "%.3g trials: the plan would round it; choose a fraction that gives a whole "
                         "number (%g or %g)", s->path, key, fraction, per_block, trials,
                         floor(trials) / per_block, ceil(trials) / per_block);
}

/* A psychometric curve varies contrast only: conditions sharing a curve name with different
 * frequencies or places would be fitted as one function (a slope of 0.5 from two thresholds). */
static csf_status check_curves(const csf_study *s, csf_error *err)
{
    for (int i = 0; i < s->n_conds; i++) {
        const csf_study_condition *a = &s->conds[i];
        if (a->kind == CSF_COND_IMAGE) continue;
        for (int j = 0; j < i; j++) {
            const csf_study_condition *b = &s->conds[j];
            if (b->kind == CSF_COND_IMAGE || strcmp(a->curve, b->curve)) continue;
            if (a->freq_cpd != b->freq_cpd || a->ecc_deg != b->ecc_deg || a->polar_deg != b->polar_deg)
                return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d (%s): curve '%s' mixes %g cpd at %g deg "
                                     "(line %d) and %g cpd at %g deg: the conditions of one psychometric "
                                     "curve differ in contrast only; give them different curve names",
                                     s->conditions_path, a->line, a->label, a->curve, b->freq_cpd,
                                     b->ecc_deg, b->line, a->freq_cpd, a->ecc_deg);
        }
    }
    return CSF_OK;
}

/* What a new run is held to beyond what a stored copy must satisfy to be read back. */
static csf_status check_new_study(const csf_study *s, csf_error *err)
{
    if (s->dup_line)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s:%d: %s given twice (first on line %d): keep one",
                             s->path, s->dup_line, s->dup_key, s->dup_first_line);
    csf_status st = CSF_OK;
    if (s->design == CSF_DESIGN_YES_NO) st = check_fraction(s, "catch_fraction", s->catch_fraction, err);
    if (st == CSF_OK && s->design == CSF_DESIGN_SAME_DIFF)
        st = check_fraction(s, "same_fraction", s->same_fraction, err);
    if (st == CSF_OK) st = check_curves(s, err);
    return st;
}

/* instructions_file, relative to the settings file's folder: printable text, each line checked as
 * the study files' are (it is shown to every participant and stored with every session). Its
 * bytes join the files' 64-bit hash. */
static csf_status load_instructions(csf_study *s, const char *dir, csf_error *err)
{
    char path[2048];
    if (s->instructions_file[0] == '/') snprintf(path, sizeof path, "%s", s->instructions_file);
    else snprintf(path, sizeof path, "%s/%s", dir, s->instructions_file);
    size_t len = 0;
    csf_error e;
    csf_status st =
        csf_read_file(path, "study instructions", INSTRUCTIONS_MAX_BYTES, &s->instructions_text, &len, &e);
    if (st != CSF_OK)
        return csf_error_set(err, st, "%s: instructions_file = %s: %s", s->path, s->instructions_file, e.msg);
    if (memchr(s->instructions_text, '\0', len))
        return csf_error_set(err, CSF_E_FORMAT, "%s: holds a NUL byte (not a text file)", path);
    char line[8192];
    int n = 0;
    for (const char *p = s->instructions_text; *p && st == CSF_OK;) {
        const char *nl = strchr(p, '\n');
        size_t k = nl ? (size_t)(nl - p) : strlen(p);
        if (k >= sizeof line)
            return csf_error_set(err, CSF_E_FORMAT, "%s:%d: line longer than %zu characters", path, n + 1,
                                 sizeof line - 1);
        memcpy(line, p, k);
        line[k] = '\0';
        st = check_line(line, path, ++n, err);
        p += k + (nl ? 1 : 0);
    }
    s->hash = csf_fnv1a64(s->instructions_text, len, csf_fnv1a64("\n--\n", 4, s->hash));
    return st;
}

csf_status csf_study_load(const char *path, csf_study **out, csf_error *err)
{
    *out = NULL;
    char *settings = NULL, *conditions = NULL;
    size_t len = 0, clen = 0;
    csf_status st = csf_read_file(path, "study settings", SETTINGS_MAX_BYTES, &settings, &len, err);
    if (st != CSF_OK) return st;
    csf_study probe;
    memset(&probe, 0, sizeof probe);
    st = csf_study_parse_settings(&probe, settings, len, path, err);
    if (st != CSF_OK) {
        free(settings);
        return st;
    }
    char dir[1024], cpath[2048];
    dir_of(path, dir, sizeof dir);
    if (probe.conditions_path[0] == '/') snprintf(cpath, sizeof cpath, "%s", probe.conditions_path);
    else snprintf(cpath, sizeof cpath, "%s/%s", dir, probe.conditions_path);
    if (strlen(cpath) >= sizeof probe.conditions_path) {
        free(settings);
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: conditions path too long", path);
    }
    csf_error e;
    st = csf_read_file(cpath, "study conditions", CONDITIONS_MAX_BYTES, &conditions, &clen, &e);
    if (st != CSF_OK) {
        free(settings);
        return csf_error_set(err, st, "%s: conditions = %s: %s", path, probe.conditions_path, e.msg);
    }
    if (memchr(conditions, '\0', clen) || memchr(settings, '\0', len))
        st = csf_error_set(err, CSF_E_FORMAT, "%s: holds a NUL byte (not a text file)",
                           memchr(settings, '\0', len) ? path : cpath);
    else
        st = csf_study_from_texts(settings, conditions, path, cpath, 1, out, err);
    if (st == CSF_OK && (*out)->instructions_file[0]) st = load_instructions(*out, dir, err);
    if (st == CSF_OK) st = check_new_study(*out, err);
    if (st != CSF_OK) {
        csf_study_free(*out);
        *out = NULL;
    }
    free(settings);
    free(conditions);
    return st;
}

/* A participant code: a letter or digit, then up to 62 letters, digits, '_', '-' or '.', with no
 * two dots in a row. It names files (one trial file per participant) and sits on command lines,
 * so "..", "-P01" (read as an option) and a leading dot (a hidden file) are refused. */
int csf_study_participant_ok(const char *p)
{
    size_t n = strlen(p);
    if (n < 1 || n > 63) return 0;
    if (!((p[0] >= 'a' && p[0] <= 'z') || (p[0] >= 'A' && p[0] <= 'Z') || (p[0] >= '0' && p[0] <= '9')))
        return 0;
    for (size_t i = 0; i < n; i++) {
        char ch = p[i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
              ch == '-' || ch == '.'))
            return 0;
        if (ch == '.' && p[i + 1] == '.') return 0;
    }
    return 1;
}

void csf_study_free(csf_study *s)
{
    if (!s) return;
    free(s->conds);
    free(s->instructions_text);
    free(s->settings_text);
    free(s->conditions_text);
    free(s);
}

void csf_study_table_free(csf_study_table *t)
{
    if (!t) return;
    free(t->names);
    free(t->cells);
    memset(t, 0, sizeof *t);
}

/* The next header or data line of a conditions text (comments and blank lines skipped), split. */
static int next_row(csf_lines *lines, char (*fields)[CSF_CSV_FIELD_MAX])
{
    char *l;
    int got = csf_lines_next(lines, &l);
    if (got <= 0) return got;
    const char *why;
    return csf_csv_split(l, fields, CSV_MAX_COLUMNS, &why);
}

csf_status csf_study_conditions_table(const csf_study *s, csf_study_table *t, csf_error *err)
{
    memset(t, 0, sizeof *t);
    const char *text = s->conditions_text ? s->conditions_text : "";
    csf_lines lines;
    int lines_ok = csf_lines_open(&lines, text, strlen(text), 8191) == 0;
    char(*fields)[CSF_CSV_FIELD_MAX] = malloc(CSV_MAX_COLUMNS * sizeof *fields);
    t->names = calloc(CSV_MAX_COLUMNS, sizeof *t->names);
    t->cells = calloc((size_t)CSV_MAX_COLUMNS * (s->n_conds + 1), sizeof *t->cells);
    csf_status st = CSF_OK;
    if (!fields || !lines_ok || !t->names || !t->cells) st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    int nf = st == CSF_OK ? next_row(&lines, fields) : -1;
    if (st == CSF_OK && nf <= 0)
        st = csf_error_set(err, CSF_E_FORMAT, "%s: no header row", s->conditions_path);
    for (int i = 0; st == CSF_OK && i < nf; i++) snprintf(t->names[i], sizeof t->names[i], "%s", fields[i]);
    t->n_columns = st == CSF_OK ? nf : 0;
    for (int r = 0; st == CSF_OK && r < s->n_conds; r++) {
        if (next_row(&lines, fields) != t->n_columns) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: row %d does not match its header", s->conditions_path,
                               r + 1);
            break;
        }
        for (int i = 0; i < t->n_columns; i++)
            snprintf(t->cells[(size_t)r * CSV_MAX_COLUMNS + i], CSF_CSV_FIELD_MAX, "%s", fields[i]);
    }
    free(fields);
    csf_lines_close(&lines);
    if (st != CSF_OK) csf_study_table_free(t);
    return st;
}
