/* Copies a session from one store to another without doubling anything (csfcal sessions push:
 * a station that ran on its local file while the server was away sends its sessions later).
 * The session is matched by uuid (one is given to an older source session that has none),
 * trials and readings by seq: pushing twice, or pushing what the destination already partly
 * has, adds only what is missing. Trials go with their frame intervals; the thresholds are
 * replaced by the source's; every artifact the destination lacks (same kind, path and bytes) is
 * copied; the study participant the session is linked to is linked on the destination too (study
 * and participant made there by name and code when missing); the destination's person time is
 * raised to the source's (never lowered, never added twice); the destination session takes the
 * source's state. A session aborted before any trial or reading is not made on a destination
 * that lacks it (skipped_empty). */
#ifndef CSF_STORE_PUSH_H
#define CSF_STORE_PUSH_H

#include <stdint.h>

#include "results/store/store.h"

typedef struct {
    int64_t dest_id;  /* the session's id in the destination */
    int created;      /* 1: the destination had no such session */
    int trials_sent, trials_present, readings_sent, readings_present;
    int artifacts_sent;      /* artifacts the destination lacked */
    int participant_linked;  /* 1: the session's study participant is linked there */
    int skipped_empty;       /* 1: aborted with no trial or reading, and the destination
                                lacks it: not copied (dest_id 0) */
} csf_push_counts;

csf_status csf_store_push_session(csf_store *src, csf_store *dst, int64_t session_id,
                                  csf_push_counts *counts, csf_error *err);
/* The same without touching the destination session's state (and, on a server, without
 * claiming it): what a station's spool left by a crash sends when the store is next opened. */
csf_status csf_store_push_rows(csf_store *src, csf_store *dst, int64_t session_id,
                               csf_push_counts *counts, csf_error *err);

#endif
