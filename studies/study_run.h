/* Running a user study (`csfcal study run STUDY --participant ID`, docs/studies.md): the study
 * files and the display checks before the first trial, the participant's session in the store
 * (study files and their hash, seed, observer), the planned trials (studies/study_plan.h) through
 * the presenter, every answer stored before the next trial, and resume: running the same command
 * again after a crash, Escape or a signal continues the participant's unfinished session from its
 * stored trials (adaptive procedures are rebuilt by replaying them). */
#ifndef CSF_STUDY_RUN_H
#define CSF_STUDY_RUN_H

#include <stdint.h>

#include "core/station.h"
#include "studies/study_file.h"
#include "core/csf_status.h"
#include "stimuli/presenter.h"

typedef struct {
    const csf_config *cfg;
    const char *study_path;
    const char *participant;     /* 1-63 characters of [A-Za-z0-9_.-] */
    const char *observer_spec;   /* "sim[:key=value,...]" or "human"; NULL = cfg->observer, else sim */
    const char *store_path;
    int version;              /* the study version (docs/studies.md); 0 = 1 */
    const char *experimenter; /* session metadata (study run --set); NULL = not given */
    const char *notes;
    int headless;
    int quiet;
} csf_study_run_options;

typedef struct {
    int64_t session_id, study_id, participant_id;
    int n_planned, n_stored, n_run_now;
    int resumed, finished;
    uint64_t seed, hash;
    int version;
    char sha256[65];       /* the study's identity (studies/study_identity.h) */
    int participant_index; /* the participant's place in the version (docs/studies.md) */
    int latin_row;         /* the Latin-square row it picked (0 without counterbalance = latin_*) */
} csf_study_run_result;

/* A session's metadata value (--set experimenter=..., notes=...): printable text of at most
 * CSF_STUDY_META_MAX - 1 bytes. CSF_E_INVALID_ARG naming the key, the problem and the limit. */
csf_status csf_study_check_meta(const char *key, const char *value, csf_error *err);

/* CSF_E_INVALID_ARG / CSF_E_FORMAT / CSF_E_NOT_FOUND: the study or the options were refused
 * before any trial (nothing stored), among them files that differ from those the version's
 * sessions ran (or the participant's session began with), named in the message. CSF_E_ABORTED: paused (Escape, SIGINT/SIGTERM); the same
 * command resumes. */
csf_status csf_study_run(const csf_study_run_options *opt, csf_study_run_result *res, csf_error *err);

/* The display-dependent checks: each condition's stimulus at each of its places is on screen and
 * below the local Nyquist limit (presenter validation), images are not drawn finer than the
 * display's pixels, and every duration lasts at least one frame. Messages name the conditions
 * file, line and label. */
csf_status csf_study_check_display(const csf_study *s, csf_presenter *pres, csf_error *err);

/* The places of a condition's target in this design: 2afc two opposite places (place 0 opposite
 * the condition's polar angle, place 1 at it), otherwise one. Returns the count. */
int csf_study_places(const csf_study *s, const csf_study_condition *c, double polar_deg[2]);

#endif
