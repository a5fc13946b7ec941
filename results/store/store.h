/* Results store: every photometer reading and every trial is written to the store the moment it
 * is made, so a crash, a power cut or an Escape loses nothing that was reported as stored, and any
 * unfinished session can be resumed from its stored trials.
 *
 * Two backends sit behind this one interface (results/store/backend.h): an SQLite file (the
 * default, embedded, one station) and a PostgreSQL server through libpq (several stations of a
 * lab), chosen by the location given to csf_store_open: a file path, or a libpq connection URI
 * (postgresql://... or postgres://...) or service=NAME. The procedures do not know which is in use.
 *
 * Durability contract: every csf_store_add_* and csf_store_put_* call runs in its own transaction
 * and is durably committed when it returns CSF_OK; a caller may show the next stimulus only after
 * that. SQLite: WAL journal, synchronous=FULL, foreign keys on. PostgreSQL: synchronous_commit on
 * and a server with fsync on (a server without is refused). If the server goes away mid-session,
 * rows are kept in a local SQLite spool and sent when it is back (docs/store.md).
 *
 * Portability: the schema uses only INTEGER, REAL, TEXT and BLOB columns and plain SQL (mapped to
 * BIGINT, DOUBLE PRECISION, TEXT and BYTEA on PostgreSQL). The schema is versioned (table
 * schema_version) and migrated forward on open.
 *
 * Sessions on a server are claimed: the station that starts or resumes one holds it (a PostgreSQL
 * advisory lock, released when the station ends or its connection dies), and a second station
 * that tries to resume or change it is refused.
 *
 * Open refuses, with a message naming the store and the cause, a read-only file or directory, a
 * file that is not a database or is malformed, a full disk, an unreachable server and a password
 * in the location: before anything is shown. Messages never show a password.
 * All functions return csf_status and fill *err (may be NULL) on failure. A csf_store is not
 * shared between threads. */
#ifndef CSF_STORE_H
#define CSF_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "core/csf_status.h"

typedef struct csf_store csf_store;

/* Newest schema version this build writes (older stores are migrated forward on open; a newer
 * one is refused rather than misread). */
#define CSF_STORE_SCHEMA_VERSION 8

/* Creates the file if missing, migrates it to CSF_STORE_SCHEMA_VERSION, and checks it can be
 * written (a probe write inside a transaction that is rolled back). */
csf_status csf_store_open(const char *path, csf_store **out, csf_error *err);
void csf_store_close(csf_store *s);

/* Opens an existing store for reading only (listing, export, reports): no migration, no write
 * probe, works on read-only files, folders and media (a store there is read as immutable, so a
 * WAL left by a crash on such media is not seen). CSF_E_NOT_FOUND when the file does not exist;
 * corrupt files and schemas other than CSF_STORE_SCHEMA_VERSION are refused. The add_* and
 * put_* calls on such a store fail with a read-only error. */
csf_status csf_store_open_readonly(const char *path, csf_store **out, csf_error *err);

/* 1 when location names a PostgreSQL server (postgresql://, postgres:// or service=NAME). */
int csf_store_is_server(const char *location);
/* The one form in which a location is shown. A server location is read as libpq reads it
 * (PQconninfoParse, after its own percent-decoding): one without a secret is shown as given,
 * one with a password (however spelled: user:pw@, pass%77ord=, after a '#') is rebuilt as
 * key=value pairs without it, and one libpq cannot read is not shown. Bytes that are not
 * printable text are escaped (csf_store_printable). out is always terminated. */
void csf_store_redact(const char *location, char *out, size_t cap);
/* 1 when libpq would read a password (or another option it hides) from the location. */
int csf_store_has_password(const char *location);
/* What csf_store_open checks before anything else, for --store, --to and `store =`: 1 to 1023
 * bytes of printable text; a server location must be one libpq reads, with no password and no
 * control character in any value it decodes. Messages start with where and never repeat a
 * secret. */
csf_status csf_store_check_location(const char *location, const char *where, csf_error *err);

/* Text that is to be shown (NULL passes): well-formed UTF-8 without control characters (C0,
 * DEL, C1, line separators, direction overrides). The message starts with what and names the
 * refused character as \xNN bytes and its 1-based position. */
csf_status csf_store_check_text(const char *s, const char *what, csf_error *err);
/* A name or label to be stored (observer, display, study, participant code, ...): at most max
 * bytes (at least 1 when required; NULL passes when not) that csf_store_check_text accepts;
 * nothing is shortened. */
csf_status csf_store_check_name(const char *v, const char *what, size_t max, int required,
                                csf_error *err);
/* Text read from a store (or any outside text) as it may be put on a terminal: printable UTF-8
 * as it is, every other byte and the backslash escaped by csf_quote_bytes. Clipped to cap at a
 * character boundary; out is always terminated. */
void csf_store_printable(const char *in, char *out, size_t cap);
/* "sqlite" or "postgresql". */
const char *csf_store_backend(const csf_store *s);

/* Schema version stored in the open database (after migration: CSF_STORE_SCHEMA_VERSION). */
int csf_store_schema_version(csf_store *s);
/* Location the store was opened with, without any password. */
const char *csf_store_path(const csf_store *s);

/* ---- sessions ---------------------------------------------------------------------------- */

/* What a session is and where it stands. The store keeps each as text (the CHECK constraints name
 * the same words, see csf_session_kind_name): a row holding a word this build does not know (a
 * store written by a newer csfcal, or by hand) reads as the UNKNOWN value, which no code treats
 * as any known one, and its stored text is kept beside it for display. UNKNOWN is 0, so a
 * zeroed struct is no known value either. */
typedef enum {
    CSF_SESSION_KIND_UNKNOWN = 0,
    CSF_SESSION_DISPLAY,  /* "display": a display calibration (photometer readings) */
    CSF_SESSION_OBSERVER, /* "observer": an observer calibration (trials, thresholds) */
    CSF_SESSION_STUDY,    /* "study": one participant's run of a user study */
} csf_session_kind;

typedef enum {
    CSF_SESSION_STATE_UNKNOWN = 0,
    CSF_SESSION_RUNNING,  /* "running" */
    CSF_SESSION_PAUSED,   /* "paused" */
    CSF_SESSION_FINISHED, /* "finished" */
    CSF_SESSION_ABORTED,  /* "aborted" */
} csf_session_state;

/* The stored word of a known value; NULL for UNKNOWN and for any value outside the enum. */
const char *csf_session_kind_name(csf_session_kind k);
const char *csf_session_state_name(csf_session_state st);
/* The value a stored word names; UNKNOWN for NULL and for any other word (exact match only). */
csf_session_kind csf_session_kind_from_name(const char *name);
csf_session_state csf_session_state_from_name(const char *name);
/* 1 for a session that can still be continued (running or paused); 0 for a closed one and for
 * an unknown state, which is never resumed nor changed as if it were open. */
int csf_session_state_open(csf_session_state st);
/* 1 for a closed session (finished or aborted); 0 for an open and for an unknown state. */
int csf_session_state_closed(csf_session_state st);

typedef struct {
    int64_t id;
    csf_session_kind kind;
    csf_session_state state;
    char kind_text[16];   /* kind and state as stored (cut to 15 bytes), for display only: */
    char state_text[16];  /* may hold any bytes, so shown through csf_store_printable */
    char observer[256];   /* observer name (observer/study sessions), "" otherwise; whole */
    char display[256];    /* display name, whole; "" when unknown */
    int names_cut;        /* 1 when the stored observer or display name is longer than these
                             fields (a row written past csfcal): shown cut, never copied */
    char profile_id[128]; /* observer and study sessions: id of the display profile the stimuli
                             were mapped through ("" when none was recorded) */
    char *settings_json;  /* malloc'd; the settings the session was started with */
    uint64_t seed;
    char tool_version[32];
    char created_utc[32]; /* ISO 8601, e.g. 2026-11-22T05:31:00Z */
    int n_trials, n_readings;
    char uuid[40];        /* random, given at the start; "" for a session stored before schema
                             v6 that was never pushed */
    double person_s;      /* the participant's time in the session, seconds, every run of it
                             added up (csf_store_add_person_time); NaN = unknown (a session
                             stored before schema v7, or whose runs never said) */
} csf_session_info;

void csf_session_info_free(csf_session_info *s); /* frees settings_json */

/* Starts a session in state running. kind must be a known value (else CSF_E_INVALID_ARG).
 * observer/display may be NULL or "" (stored as ""); named observers and displays are also
 * recorded in their own tables. settings_json NULL = "{}". */
csf_status csf_store_begin_session(csf_store *s, csf_session_kind kind, const char *observer,
                                   const char *display, const char *settings_json, uint64_t seed, int64_t *id,
                                   csf_error *err);
/* The same, for a session that shows stimuli through a display profile: display is the display
 * the profile was measured on, profile_id the profile's id (NULL or "" = none). The display is
 * recorded in its own table and the profile in the display's profile history; the display's
 * current profile changes only when it has none. */
csf_status csf_store_begin_session_profile(csf_store *s, csf_session_kind kind, const char *observer,
                                           const char *display, const char *profile_id,
                                           const char *settings_json, uint64_t seed, int64_t *id,
                                           csf_error *err);
csf_status csf_store_get_session(csf_store *s, int64_t id, csf_session_info *out, csf_error *err);
/* state: a known value (else CSF_E_INVALID_ARG); also updates the session's updated time. */
csf_status csf_store_set_session_state(csf_store *s, int64_t id, csf_session_state state, csf_error *err);
/* All sessions, oldest first. *out is malloc'd; free each with csf_session_info_free, then free(*out). */
csf_status csf_store_list_sessions(csf_store *s, csf_session_info **out, size_t *n, csf_error *err);
/* Free a list from csf_store_list_sessions. */
void csf_session_list_free(csf_session_info *list, size_t n);

/* The most one run may add to a session's person time: 1e6 s is 11.6 days, far past any
 * sitting; a larger value is a clock read wrong (a difference of two unrelated clocks). */
#define CSF_STORE_PERSON_S_MAX 1e6

/* Adds seconds to the session's person time (the time the participant spent in it: stimuli,
 * responses, breaks and instructions, on the session's clock), so the runs of a resumed session
 * add up; a session with none stored (NULL) starts at 0. seconds must be finite, >= 0 and at
 * most CSF_STORE_PERSON_S_MAX (else CSF_E_INVALID_ARG naming the value and the limit). A
 * finished or aborted session is closed: refused with CSF_E_STORE (as its trials are on a lab's
 * server). CSF_E_NOT_FOUND for a session the store lacks. On a server the addition is sent
 * once: a repeat after a dropped connection does not add it twice, and while the server is away
 * it is spooled with the session's other writes. */
csf_status csf_store_add_person_time(csf_store *s, int64_t session_id, double seconds, csf_error *err);

/* Timestamps (ISO 8601 UTC) of a session: created, last updated (state change or any row added). */
csf_status csf_store_session_times(csf_store *s, int64_t id, char created_utc[32],
                                   char updated_utc[32], csf_error *err);

/* ---- photometer readings ----------------------------------------------------------------- */

/* How a photometer reading went, stored as text as the session's kind and state are. */
typedef enum {
    CSF_READING_STATUS_UNKNOWN = 0,
    CSF_READING_OK,        /* "ok" */
    CSF_READING_TOO_DARK,  /* "too_dark": below the meter's range */
    CSF_READING_SATURATED, /* "saturated": above it */
    CSF_READING_TIMEOUT,   /* "timeout": the meter did not answer in time */
    CSF_READING_ERROR,     /* "error": any other failure */
} csf_reading_status;

/* As csf_session_kind_name / _from_name. */
const char *csf_reading_status_name(csf_reading_status st);
csf_reading_status csf_reading_status_from_name(const char *name);

typedef struct {
    int64_t session_id;
    int seq;              /* 0, 1, 2 ... per session; unique */
    char channel[8];      /* "dark", "white", "grey", "r", "g", "b" */
    double drive01;       /* drive level in [0, 1] */
    double lum_cdm2;      /* measured luminance, NaN if the reading failed */
    double X, Y, Z;       /* CIE XYZ (Y in cd/m2) when has_xyz */
    int has_xyz;
    double t_s;           /* seconds since the session started */
    csf_reading_status status; /* a known value when added */
    char status_text[16];      /* the status as stored (cut to 15 bytes), for display only; not
                             read by csf_store_add_reading */
} csf_reading;

csf_status csf_store_add_reading(csf_store *s, const csf_reading *r, csf_error *err);
/* Ordered by seq. *out is malloc'd (free()). */
csf_status csf_store_get_readings(csf_store *s, int64_t session_id, csf_reading **out, size_t *n,
                                  csf_error *err);

/* ---- trials ------------------------------------------------------------------------------ */

typedef struct {
    int64_t session_id;
    int seq;                      /* 0, 1, 2 ... per session; unique; the resume point is max+1 */
    char method[16];              /* "fade", "2afc", "bayes", ... */
    double freq_cpd, ecc_deg, polar_deg, orientation_deg, sigma_deg, velocity_dps, mean_lum_cdm2;
    int is_catch, is_practice;
    double contrast_requested;    /* Michelson */
    double contrast_shown_mean, contrast_shown_max; /* measured on the frames actually shown */
    int frames_planned, frames_shown, frames_missed;
    int signal_interval;          /* forced choice: the interval (1, 2) or place (1-4) with the
                                     grating; 0 = not applicable */
    int response;                 /* method-specific code (e.g. 1 seen / 0 not, chosen interval
                                     or place) */
    double rt_s;                  /* response time, seconds; NaN = none */
    double click_x_deg, click_y_deg; /* click position in visual angle; NaN = none */
    int valid;                    /* 0 = excluded (missed frames, lapse of attention ...) */
    char flags[64];               /* comma-separated problems, e.g. "missed_frames,late" */
    int n_alternatives;           /* forced choice: 2 (two intervals) or 4 (four places shown at
                                     once); 0 = not a forced-choice trial (schema v4; rows stored
                                     earlier read 2 when signal_interval > 0, else 0) */
    int has_onset;                /* onset_s recorded (schema v8; rows stored earlier have none) */
    double onset_s;               /* the trial's first presentation (stimulus or, without one, its
                                     blank interval) on the session's clock, seconds; 0 when
                                     has_onset is 0 */
} csf_trial;

csf_status csf_store_add_trial(csf_store *s, const csf_trial *t, csf_error *err);
/* A trial and its frame-to-frame intervals in ONE transaction: after a crash either both are
 * stored or neither (with separate add_trial + add_frame_intervals calls a kill in between
 * leaves a trial without its frame timing). */
csf_status csf_store_add_trial_frames(csf_store *s, const csf_trial *t, const double *interval_s,
                                      int n, csf_error *err);
/* Ordered by seq (what a resumed procedure replays). *out is malloc'd (free()). */
csf_status csf_store_get_trials(csf_store *s, int64_t session_id, csf_trial **out, size_t *n,
                                csf_error *err);

/* Frame-to-frame intervals (seconds) of one trial, in order. */
csf_status csf_store_add_frame_intervals(csf_store *s, int64_t session_id, int trial_seq,
                                         const double *interval_s, int n, csf_error *err);
/* All frame intervals of a session (every trial, in trial then frame order). *out malloc'd. */
csf_status csf_store_get_frame_intervals(csf_store *s, int64_t session_id, double **out, size_t *n,
                                         csf_error *err);

/* ---- thresholds -------------------------------------------------------------------------- */

typedef struct {
    double freq_cpd, ecc_deg, velocity_dps, lum_cdm2;
    double threshold;     /* Michelson; INFINITY = never visible */
    double stderr_log10;  /* NaN = unknown */
    int n_trials;
} csf_threshold_row;

/* Replaces the session's thresholds with these rows (one transaction). */
csf_status csf_store_put_thresholds(csf_store *s, int64_t session_id, const csf_threshold_row *rows,
                                    size_t n, csf_error *err);
/* Ordered by lum, velocity, ecc, freq. *out is malloc'd (free()). */
csf_status csf_store_get_thresholds(csf_store *s, int64_t session_id, csf_threshold_row **out,
                                    size_t *n, csf_error *err);

/* ---- artifacts (files written from a session, kept with their bytes) --------------------- */

/* kind: "csflut", "profile", "plot" (others allowed, up to 15 chars). blob may be NULL (len 0).
 * One file is one row: a path-only record (blob NULL) completes the session's newest record of
 * that kind that has the bytes but no path, and bytes without a path complete a path-only
 * record, instead of adding a second, half record. */
csf_status csf_store_add_artifact(csf_store *s, int64_t session_id, const char *kind,
                                  const char *path, const void *blob, size_t len, csf_error *err);
/* Newest artifact of that kind for the session, preferring one stored with content over a
 * path-only record: *blob malloc'd (free(); NUL-terminated one byte past len), path copied into
 * path_out (may be NULL). CSF_E_NOT_FOUND if there is none. */
csf_status csf_store_get_artifact(csf_store *s, int64_t session_id, const char *kind,
                                  void **blob, size_t *len, char *path_out, size_t path_len,
                                  csf_error *err);

/* ---- displays, observers, studies, participants ------------------------------------------ */

/* Records (or finds) a display by name; profile_id may be NULL. */
csf_status csf_store_upsert_display(csf_store *s, const char *name, const char *profile_id,
                                    int64_t *id, csf_error *err);
/* Current profile id of a display: set by csf_store_upsert_display, and by storing a "profile"
 * artifact (its "id" and "display" header lines; each such artifact also adds a row to the
 * display's profile history). CSF_E_NOT_FOUND when none is recorded. */
csf_status csf_store_display_profile_id(csf_store *s, const char *display, char *out, size_t cap,
                                        csf_error *err);
/* Records (or finds) an observer by name. */
csf_status csf_store_upsert_observer(csf_store *s, const char *name, int64_t *id, csf_error *err);

/* Studies (2AFC user studies; the study runner comes later). design_json NULL = "{}". */
csf_status csf_store_create_study(csf_store *s, const char *name, const char *design_json,
                                  int64_t *id, csf_error *err);
csf_status csf_store_find_study(csf_store *s, const char *name, int64_t *id, csf_error *err);
/* code: a pseudonymous participant code, unique within the study. */
csf_status csf_store_add_participant(csf_store *s, int64_t study_id, const char *code,
                                     int64_t *id, csf_error *err);
csf_status csf_store_count_participants(csf_store *s, int64_t study_id, int *n, csf_error *err);
/* Ties a session to a study participant (study sessions). */
csf_status csf_store_link_session_participant(csf_store *s, int64_t session_id,
                                              int64_t participant_id, csf_error *err);

#endif
