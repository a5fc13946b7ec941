/* The sessions a store holds of one study, with the version and identity each was run with
 * (studies/study_identity.h): what `study run` checks a new or resumed session against, and
 * what `study report` and `study export` select from. A version is a number the lab gives
 * (`study run --version N`, default 1); every session of one version must have run the same
 * files, byte for byte. Sessions stored before identities were kept carry only a 64-bit hash of
 * the two study files ("hash"); they form a version of their own (legacy = 1). */
#ifndef CSF_STUDY_SESSIONS_H
#define CSF_STUDY_SESSIONS_H

#include <stdint.h>
#include <stdio.h>

#include "results/store/store.h"
#include "studies/study_identity.h"
#include "studies/study_plan.h"

typedef struct {
    int64_t id;
    char participant[64]; /* as stored (check before showing: csf_store_printable) */
    int version;          /* 1 when the session names none */
    csf_session_state state;
    char state_text[16];      /* as stored, for display only (csf_store_printable) */
    char key[CSF_SHA256_HEX]; /* the identity's sha256; legacy: the 16 hex digits of "hash" */
    int legacy;
    csf_study_identity identity; /* parsed when !legacy */
    int n_trials;
    int participant_index; /* place in the order of the version's first sessions (0-based; 0 when
                              the session names none): picks the Latin-square row */
    char experimenter[CSF_STUDY_META_MAX], notes[CSF_STUDY_META_MAX]; /* --set; "" when not given */
} csf_study_session;

/* Every session of the study named, oldest first; *out malloc'd (free with
 * csf_study_sessions_free). A session whose settings cannot be read is left out. */
csf_status csf_study_sessions_list(csf_store *store, const char *study, csf_study_session **out, int *n,
                                   csf_error *err);
void csf_study_sessions_free(csf_study_session *list, int n);

/* The name the store's studies table holds a version under: the study's name for version 1,
 * "NAME #N" after (a '#' starts a comment in a settings file, so no study is named so). */
void csf_study_store_name(const char *study, int version, char *out, size_t cap);

/* One line per version the list holds ("version 2 (sha256 1a2b3c4d5e6f...): 3 sessions, 2
 * finished"), each prefixed by indent; skip_key: leave that identity out (NULL: none). Returns the
 * number of versions written. */
int csf_study_versions_print(const csf_study_session *list, int n, const char *skip_key, const char *indent,
                             FILE *fp);
/* The same as text into out (lines joined by "; "). */
void csf_study_versions_text(const csf_study_session *list, int n, const char *skip_key, char *out,
                             size_t cap);
/* The highest version number held (0 when none). */
int csf_study_versions_max(const csf_study_session *list, int n);

/* The sessions a report or an export covers. study: a settings file (its files' identity picks
 * the sessions that ran exactly these files; version, when > 0, must agree) or a study's name
 * (version > 0 picks that version; 0: the one version the store holds, refused naming them when
 * it holds several). CSF_E_NOT_FOUND, naming the versions held, when nothing matches. */
typedef struct {
    char name[128];
    int version;
    char key[CSF_SHA256_HEX];
    int legacy;
    csf_study_session *all; /* every session of the study */
    int n_all;
    int *sel; /* indices into all, oldest first */
    int n_sel;
} csf_study_selection;

csf_status csf_study_select(csf_store *store, const char *study, int version, csf_study_selection *out,
                            csf_error *err);
void csf_study_selection_free(csf_study_selection *s);

/* One selected session's material, rebuilt from the store alone: the study from the session's
 * stored copy of its files, the trial plan its stored seed gives (so each stored trial maps to its
 * condition) and its stored trials; with the conditions file's table when asked for. */
typedef struct {
    const csf_study_session *x; /* in the selection's list */
    csf_study *study;
    csf_study_trial *plan;
    int n_plan;
    csf_trial *trials;
    size_t n_trials;
    csf_study_table table; /* filled when loaded with want_table */
} csf_study_session_data;

/* The walk over a selection's sessions that the report and the export share: each selected
 * session loaded, oldest first, into *out (malloc'd; free with csf_study_session_data_free). A
 * session without stored study files (a start cut short before it stored them) holds nothing to
 * analyse and is left out; note (may be NULL) names the caller in a line on stderr saying so.
 * Any other failure is an error naming the session. *n may be 0. */
csf_status csf_study_sessions_load(csf_store *store, const csf_study_selection *sel, int want_table,
                                   const char *note, csf_study_session_data **out, int *n, csf_error *err);
void csf_study_session_data_free(csf_study_session_data *d, int n);

#endif
