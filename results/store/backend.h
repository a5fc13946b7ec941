/* The results store's backends (results/store/store.h is the interface the procedures see): one struct
 * of function pointers per backend, as libusb does per OS. results/store/store.c checks arguments,
 * picks the backend from the location (a file path: SQLite; a libpq URI or service=NAME:
 * PostgreSQL) and calls through the table; a backend may assume its arguments were checked.
 * Every backend's own store struct starts with a csf_store. */
#ifndef CSF_STORE_BACKEND_H
#define CSF_STORE_BACKEND_H

#include "results/store/store.h"

/* A session to insert: what begin_session was given, plus what a copy from another store
 * (csf_store_push) keeps: its uuid, creation time, state and tool version. */
typedef struct {
    csf_session_kind kind;   /* known values only: the caller checks */
    csf_session_state state; /* known values only: the caller checks */
    const char *observer, *display, *profile_id, *settings_json;
    uint64_t seed;
    const char *uuid;         /* 36 characters, never NULL */
    const char *created_utc;  /* NULL: now */
    const char *tool_version; /* NULL: this build's */
} csf_store_session_new;

/* One stored artifact as a copy between stores needs it: blob NULL for a path-only record. */
typedef struct {
    char kind[16];
    char path[1024];
    unsigned char *blob; /* malloc'd, len bytes */
    size_t len;
} csf_store_artifact;

/* Frees a list from list_artifacts. */
void csf_store_artifacts_free(csf_store_artifact *list, size_t n);

typedef struct csf_store_ops {
    const char *name; /* "sqlite", "postgresql" */
    void (*close)(csf_store *s);
    int (*schema_version)(csf_store *s);
    csf_status (*begin_session)(csf_store *s, const csf_store_session_new *nw, int64_t *id,
                                csf_error *err);
    /* Gives a session without a uuid (stored before schema v6) this one. */
    csf_status (*set_session_uuid)(csf_store *s, int64_t id, const char *uuid, csf_error *err);
    /* Frame intervals of one trial, in order; *out malloc'd (NULL when none). */
    csf_status (*get_trial_frames)(csf_store *s, int64_t session_id, int trial_seq, double **out,
                                   size_t *n, csf_error *err);
    /* CSF_E_NOT_FOUND when no session has that uuid. */
    csf_status (*find_session_uuid)(csf_store *s, const char *uuid, int64_t *id, csf_error *err);
    csf_status (*get_session)(csf_store *s, int64_t id, csf_session_info *out, csf_error *err);
    csf_status (*set_session_state)(csf_store *s, int64_t id, csf_session_state state,
                                    csf_error *err); /* state: a known value */
    csf_status (*list_sessions)(csf_store *s, csf_session_info **out, size_t *n, csf_error *err);
    /* Adds seconds (checked: finite, 0 to CSF_STORE_PERSON_S_MAX) to an open session's person
     * time; a closed one is refused. */
    csf_status (*add_person_time)(csf_store *s, int64_t id, double seconds, csf_error *err);
    /* Raises an open session's person time to total_s when it has none or less (a copy from
     * another store: push, the spool); the same or more is left as it is. A closed session is
     * refused, unless it already has total_s or more. */
    csf_status (*raise_person_time)(csf_store *s, int64_t id, double total_s, csf_error *err);
    csf_status (*session_times)(csf_store *s, int64_t id, char created_utc[32],
                                char updated_utc[32], csf_error *err);
    csf_status (*add_reading)(csf_store *s, const csf_reading *r, csf_error *err);
    csf_status (*get_readings)(csf_store *s, int64_t session_id, csf_reading **out, size_t *n,
                               csf_error *err);
    csf_status (*add_trial_frames)(csf_store *s, const csf_trial *t, const double *interval_s,
                                   int n, csf_error *err); /* interval_s NULL / n 0: trial only */
    csf_status (*get_trials)(csf_store *s, int64_t session_id, csf_trial **out, size_t *n,
                             csf_error *err);
    csf_status (*add_frame_intervals)(csf_store *s, int64_t session_id, int trial_seq,
                                      const double *interval_s, int n, csf_error *err);
    csf_status (*get_frame_intervals)(csf_store *s, int64_t session_id, double **out, size_t *n,
                                      csf_error *err);
    csf_status (*put_thresholds)(csf_store *s, int64_t session_id, const csf_threshold_row *rows,
                                 size_t n, csf_error *err);
    csf_status (*get_thresholds)(csf_store *s, int64_t session_id, csf_threshold_row **out,
                                 size_t *n, csf_error *err);
    csf_status (*add_artifact)(csf_store *s, int64_t session_id, const char *kind,
                               const char *path, const void *blob, size_t len, csf_error *err);
    csf_status (*get_artifact)(csf_store *s, int64_t session_id, const char *kind, void **blob,
                               size_t *len, char *path_out, size_t path_len, csf_error *err);
    csf_status (*upsert_display)(csf_store *s, const char *name, const char *profile_id,
                                 int64_t *id, csf_error *err);
    csf_status (*display_profile_id)(csf_store *s, const char *display, char *out, size_t cap,
                                     csf_error *err);
    csf_status (*upsert_observer)(csf_store *s, const char *name, int64_t *id, csf_error *err);
    csf_status (*create_study)(csf_store *s, const char *name, const char *design_json,
                               int64_t *id, csf_error *err);
    csf_status (*find_study)(csf_store *s, const char *name, int64_t *id, csf_error *err);
    csf_status (*add_participant)(csf_store *s, int64_t study_id, const char *code, int64_t *id,
                                  csf_error *err);
    csf_status (*count_participants)(csf_store *s, int64_t study_id, int *n, csf_error *err);
    csf_status (*link_session_participant)(csf_store *s, int64_t session_id,
                                           int64_t participant_id, csf_error *err);
    /* Every artifact of a session, oldest first; *out malloc'd (NULL when none). */
    csf_status (*list_artifacts)(csf_store *s, int64_t session_id, csf_store_artifact **out,
                                 size_t *n, csf_error *err);
    /* The study (name, design) and participant code a session is linked to; *design_json
     * malloc'd. CSF_E_NOT_FOUND when the session has no participant. */
    csf_status (*session_participant)(csf_store *s, int64_t session_id, char study[256],
                                      char **design_json, char code[64], csf_error *err);
    /* Links a session to participant code of the study named, making the study (with
     * design_json) and the participant when missing; a link already there is kept: a repeat
     * changes nothing. */
    csf_status (*link_named)(csf_store *s, int64_t session_id, const char *study,
                             const char *design_json, const char *code, csf_error *err);
} csf_store_ops;

struct csf_store {
    const csf_store_ops *ops;
    /* The location as given, with any password removed: what every message names. */
    char path[1024];
    int readonly;
};

/* A random (version 4) uuid, 36 characters; -1 when the system has no random bytes. */
int csf_store_new_uuid(char out[40]);

/* The backends' open functions: path is checked (non-empty, shorter than 1024). */
csf_status csf_store_sqlite_open(const char *path, int readonly, csf_store **out, csf_error *err);
csf_status csf_store_pg_open(const char *conninfo, int readonly, csf_store **out, csf_error *err);

#endif
