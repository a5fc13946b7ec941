/* A user study on disk (docs/studies.md): a settings file of `key = value` lines (the station
 * configuration's format, cli/config.h) naming a conditions table, a CSV with one row per
 * condition (PsychoPy's conditions-file convention: a header row of column names, then one row
 * per condition). Everything that can be checked without a display is checked here, with the
 * file, line and problem in the message; the display-dependent checks (on screen, Nyquist, frame
 * timing) are csf_study_check_display in studies/study_run.h. Both run before the first trial. */
#ifndef CSF_STUDY_FILE_H
#define CSF_STUDY_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

typedef enum {
    CSF_DESIGN_2AFC = 0,     /* two places at once (by location); which one held the target */
    CSF_DESIGN_2IFC = 1,     /* two intervals at one place; which one held the target */
    CSF_DESIGN_SAME_DIFF = 2,/* two intervals; were the two images the same or different */
    CSF_DESIGN_YES_NO = 3,   /* one interval; was there a target (catch trials have none) */
} csf_study_design;

typedef enum { CSF_COND_GABOR = 0, CSF_COND_GRATING = 1, CSF_COND_IMAGE = 2 } csf_cond_kind;

#define CSF_STUDY_MAX_CONDITIONS 256
#define CSF_STUDY_LABEL_MAX 64

typedef struct {
    int line;                       /* line in the conditions file (header = 1) */
    char label[CSF_STUDY_LABEL_MAX];
    csf_cond_kind kind;
    /* gratings and Gabors (results in cpd, deg, deg/s, Hz, cd/m2; stimuli/presenter.h) */
    double freq_cpd, orientation_deg, phase_deg, sigma_deg, radius_deg, drift_hz;
    double velocity_dps, motion_dir_deg;
    double contrast;                /* fixed Michelson level; NaN when adaptive */
    int adaptive;                   /* contrast = "adaptive": driven by method */
    char method[16];                /* adaptive procedure (calib/procedure.h), default "2afc" */
    /* where (all kinds) */
    double ecc_deg, polar_deg;
    double mean_lum_cdm2;           /* 0 = the display's mid luminance */
    /* image pairs: paths resolved against the conditions file's folder; width in degrees */
    char image_a[1024], image_b[1024];
    double size_deg;
    char curve[CSF_STUDY_LABEL_MAX];/* conditions with the same curve name are fitted together
                                       (default: the label) */
    int group;                      /* blocked_by: the block of this condition's value (0-based, in
                                       the order the file first gives the values); else 0 */
    int practice_pool;              /* named in practice_conditions (all are when none is named) */
} csf_study_condition;

/* Condition order within a block (docs/studies.md, "Designs"). */
typedef enum {
    CSF_ORDER_RANDOM = 0,     /* shuffled within each block */
    CSF_ORDER_SEQUENTIAL = 1, /* the conditions in order, each pass once (PsychoPy's sequential) */
} csf_study_order;

/* Counterbalancing across participants: a balanced Latin square (Williams 1949) whose row is
 * chosen by the participant's index in the study. */
typedef enum { CSF_LATIN_NONE = 0, CSF_LATIN_BLOCKS = 1, CSF_LATIN_CONDITIONS = 2 } csf_study_latin;

/* Which trials show "Correct"/"Wrong" (people only). */
typedef enum { CSF_FEEDBACK_NONE = 0, CSF_FEEDBACK_ALL = 1, CSF_FEEDBACK_PRACTICE = 2 } csf_study_feedback;

#define CSF_STUDY_INSTRUCTIONS_MAX 4096
#define CSF_STUDY_META_MAX 256 /* a session's experimenter or notes (study run --set), with the NUL */

typedef struct {
    char name[128];
    char path[1024];               /* settings file */
    char conditions_path[1024];    /* resolved */
    csf_study_design design;
    int trials_per_condition, practice_trials, blocks;
    double stimulus_s, isi_s, response_window_s, iti_s, fixation_s, feedback_s;
    csf_study_feedback feedback; /* which answers get right/wrong shown */
    uint64_t seed;
    int counterbalance;            /* balance target place/interval (or pair order) within
                                      each condition and block */
    csf_study_latin latin;         /* counterbalance = latin_blocks|latin_conditions */
    csf_study_order order;
    char blocked_by[64];                           /* a conditions column: one block per value; "" = none */
    int n_groups;                                  /* blocked_by: the number of values (blocks) */
    char practice_labels[1024];                    /* practice_conditions as written; "" = every condition */
    int practice_line;                             /* its line in the settings file */
    char instructions[CSF_STUDY_INSTRUCTIONS_MAX]; /* "\n" in the file is a line break */
    char instructions_file[1024];                  /* as written; resolved and read by csf_study_load */
    char *instructions_text;                       /* the file's bytes (NULL without instructions_file) */
    double catch_fraction;         /* yes/no: share of each condition's trials without target */
    double same_fraction;          /* same/different: share of same pairs */
    int sd_differencing;           /* same/different d' model: 1 differencing (roving), 0 IO */
    double max_lapse;              /* report: fitted lapse limit */
    int bootstrap;                 /* report: parametric bootstrap samples */
    double adaptive_max_contrast;  /* adaptive procedures' ceiling (also capped by the display) */
    char break_text[256];
    csf_study_condition *conds;    /* malloc'd */
    int n_conds;
    char *settings_text, *conditions_text; /* the bytes read (stored with each session) */
    uint64_t hash;                         /* FNV-1a 64 of both files' bytes (and the instructions
                                      file's, when there is one): the study's identity */
    /* the first key given twice in the settings, for csf_study_load to refuse (a stored copy
       from an older csfcal is still read, last value winning as it did) */
    char dup_key[32];
    int dup_line, dup_first_line;
} csf_study;

const char *csf_study_design_name(csf_study_design d);

/* Settings from text; where names it in messages (a path). Sets defaults first. The conditions
 * path is taken as written (csf_study_load resolves it). */
csf_status csf_study_parse_settings(csf_study *s, const char *text, size_t len, const char *where,
                                    csf_error *err);
/* Conditions from CSV text for the design already in s; image paths are resolved against
 * base_dir (may be NULL or ""). Checks columns, values and their combination with the design;
 * does not open image files. */
csf_status csf_study_parse_conditions(csf_study *s, const char *text, size_t len, const char *where,
                                      const char *base_dir, csf_error *err);

/* Reads and checks both files and that every image exists and decodes (a missing or broken one is
 * named with the conditions file's line), and the rules a new run is held to: no settings key
 * given twice, a curve's conditions differing in contrast only, a catch or same fraction that
 * gives a whole number of trials per condition and block. CSF_E_INVALID_ARG / CSF_E_FORMAT /
 * CSF_E_NOT_FOUND. */
csf_status csf_study_load(const char *path, csf_study **out, csf_error *err);
/* The same from texts already in memory (a stored session's copy); check_images = 0 skips the
 * image files (a report needs only the design, not the pictures). */
csf_status csf_study_from_texts(const char *settings, const char *conditions, const char *path,
                                const char *conditions_path, int check_images, csf_study **out,
                                csf_error *err);
void csf_study_free(csf_study *s);

/* A participant code (docs/studies.md): a letter or digit, then up to 62 letters, digits, '_',
 * '-' or '.', no two dots in a row. 1 when p is one. */
int csf_study_participant_ok(const char *p);

/* The conditions file as written: its column names (the known ones and the user's own) and every
 * condition's cells as text, for the trial export. names[i] and cell(t, cond, i). */
#define CSF_STUDY_TABLE_MAX_COLUMNS 32
typedef struct {
    char (*names)[64];
    char (*cells)[1024]; /* CSF_STUDY_TABLE_MAX_COLUMNS per condition */
    int n_columns;
} csf_study_table;
#define CSF_STUDY_CELL(t, cond, col) ((t)->cells[(size_t)(cond)*CSF_STUDY_TABLE_MAX_COLUMNS + (col)])
csf_status csf_study_conditions_table(const csf_study *s, csf_study_table *t, csf_error *err);
void csf_study_table_free(csf_study_table *t);

/* The columns the trial export writes itself (NULL-terminated; studies/study_export.c): a
 * conditions file's own columns may not take these names. */
extern const char *const csf_study_export_columns[];

uint64_t csf_fnv1a64(const void *data, size_t len, uint64_t h);
#define CSF_FNV1A64_INIT 0xcbf29ce484222325ULL

#endif
