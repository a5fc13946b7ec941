/* The tidy trial export of a study (`csfcal study export`, docs/studies.md): one row per stored
 * trial of the sessions a report of the same arguments analyses (studies/study_sessions.h), each
 * row able to stand alone in a re-analysis:
 *   study, version, study_sha256, participant, session, session_finished, trial (the session's
 *   0-based sequence number), block (1-based; 0 for practice), practice, condition (the label);
 *   every column of the conditions file as written, the user's own included (text as given);
 *   the stimulus as presented (stim_* parameters, contrast requested and measured on the frames
 *   shown, frame counts), the target (forced choice: the interval or place 1 or 2 that held it;
 *   yes/no: 1 present, 0 catch; same/different: 1 different pair, 0 same pair), the images shown
 *   first and second with their SHA-256, the response, correct (1, 0; empty when invalid),
 *   rt_s, valid and flags.
 * CSV as results/store/export.h writes it (RFC 4180, '.' decimals, empty = missing), written
 * through core/file_write so a reader never sees half a file. */
#ifndef CSF_STUDY_EXPORT_H
#define CSF_STUDY_EXPORT_H

#include "core/csf_status.h"

/* out: a file, or "-" for standard output. per_participant_dir (may be NULL): also one file per
 * participant there, PARTICIPANT.csv (the folder is made when missing). *n_rows: trials written. */
csf_status csf_study_export(const char *store_path, const char *study, int version, const char *out,
                            const char *per_participant_dir, int *n_rows, csf_error *err);

#endif
