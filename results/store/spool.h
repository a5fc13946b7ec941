/* The PostgreSQL store's local spool (results/store/spool.c): an SQLite store on the station that
 * keeps a server session's writes, under the session's uuid, while the server cannot be
 * reached, and sends them once it can. When to spool and when to try the server again is the
 * server backend's (results/store/pg.c); this module owns the spool file and what goes in and
 * out of it. */
#ifndef CSF_STORE_SPOOL_H
#define CSF_STORE_SPOOL_H

#include <stddef.h>
#include <stdint.h>

#include "results/store/backend.h"

typedef struct {
    char location[1024]; /* the server store's location, as its messages name it */
    char path[1024];
    csf_store *store; /* opened at the first write that needs it */
    int spooling;     /* rows are in the spool that the server does not have yet */
    int n_spooled;
} csf_spool;

/* One write that may be spooled: what it is and its arguments. */
typedef enum {
    CSF_SPOOL_TRIAL,
    CSF_SPOOL_READING,
    CSF_SPOOL_FRAMES,
    CSF_SPOOL_STATE,
    CSF_SPOOL_THRESHOLDS,
    CSF_SPOOL_ARTIFACT,
    CSF_SPOOL_LINK,
    CSF_SPOOL_PERSON
} csf_spool_kind;

typedef struct {
    csf_spool_kind kind;
    int64_t sid;
    const csf_trial *t;
    const csf_reading *r;
    const double *iv;
    int n, seq;
    csf_session_state state;       /* CSF_SPOOL_STATE */
    const csf_threshold_row *rows; /* CSF_SPOOL_THRESHOLDS: n_rows of them */
    size_t n_rows;
    const char *art_kind, *path; /* CSF_SPOOL_ARTIFACT */
    const void *blob;
    size_t len;
    int64_t participant_id;   /* CSF_SPOOL_LINK */
    const char *study, *code; /* CSF_SPOOL_LINK in the spool: the names the server's ids stand for */
    /* CSF_SPOOL_PERSON: the session's person time after this write, seconds (a total, not the
     * amount added, so a repeat or a second send changes nothing); exact: the server must hold
     * just this total after it (an addition), not more (a copy's raise). */
    double person_s;
    int person_exact;
} csf_spool_write;

/* Sets the spool's path (CSF_STORE_SPOOL, else $XDG_DATA_HOME/csfcal/spool.sqlite, else
 * ~/.local/share/csfcal/spool.sqlite) for the server store at location; opens nothing. */
void csf_spool_init(csf_spool *sp, const char *location);
void csf_spool_close(csf_spool *sp);

/* Opens the spool file at path as a writable SQLite store. */
csf_status csf_spool_open_file(const char *path, csf_store **out, csf_error *err);

/* The spool's copy of server session k (made on first use, the spool opened with it). */
csf_status csf_spool_session(csf_spool *sp, const csf_session_info *k, int64_t *lsid, csf_error *err);

/* Writes w to spool session lsid; the first spooled write says on stderr where rows now go. */
csf_status csf_spool_put(csf_spool *sp, int64_t lsid, const csf_spool_write *w, csf_error *err);

/* Records a start the server may have committed although the station never heard back: the
 * spool keeps its uuid as an aborted session with no rows. Says on stderr what happened. */
void csf_spool_unsure_begin(csf_spool *sp, const csf_store_session_new *nw);

/* Sends the spool's copies of sessions (the server's sessions this station ran) to server;
 * CSF_OK when the server has them all. */
csf_status csf_spool_send(csf_spool *sp, csf_store *server, const csf_session_info *sessions, size_t n,
                          csf_error *err);

/* Sends the rows an earlier run left in the spool file to server, for the sessions server has
 * (by uuid), leaving each one's state as server has it; abort_phantom is asked about each one
 * (1: it marked server's copy aborted). Failures are said on stderr, never returned. */
void csf_spool_recover(csf_spool *sp, csf_store *server,
                       int (*abort_phantom)(csf_store *server, const csf_session_info *local, int64_t sid));

#endif
