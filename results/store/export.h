/* Tidy exports of one session from the store: one row per trial, reading or threshold, with
 * column names that carry their units (freq_cpd, lum_cdm2, rt_s ...), readable by pandas
 * (read_csv / read_json) and R (read.csv / jsonlite::fromJSON) without options.
 *   CSV: RFC 4180, header row, '.' decimal point, empty cell = missing (NA / NaN), "Inf" for an
 *        infinite threshold, text quoted only when it holds a comma, quote or newline.
 *   JSON: an array of flat records (one object per row); missing = null, infinite = null with
 *        a companion field (threshold_infinite = true) so nothing is lost. */
#ifndef CSF_STORE_EXPORT_H
#define CSF_STORE_EXPORT_H

#include <stdint.h>
#include <stdio.h>

#include "results/store/store.h"

typedef enum { CSF_EXPORT_CSV, CSF_EXPORT_JSON } csf_export_format;
typedef enum {
    CSF_TABLE_AUTO, CSF_TABLE_TRIALS, CSF_TABLE_READINGS, CSF_TABLE_THRESHOLDS,
    CSF_TABLE_FRAMES /* one row per frame interval: session_id, trial_seq, frame, interval_s */
} csf_export_table;

/* AUTO: readings for display sessions, trials otherwise. Writes to out; reports write errors. */
csf_status csf_store_export(csf_store *s, int64_t session_id, csf_export_table table,
                            csf_export_format format, FILE *out, csf_error *err);

#endif
