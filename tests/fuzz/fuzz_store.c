/* A results store file is outside input (copied between stations, restored from backups,
 * damaged by a bad disk): opening it, listing, reading every table, exporting and drawing the
 * report must refuse or cope, never crash or read out of bounds. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "results/plot.h"
#include "results/store/store.h"
#include "results/store/export.h"
#include "fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    if (fuzz_file_write("store", data, size, path)) return 0;
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) == CSF_OK) {
        csf_session_info *list = NULL;
        size_t n = 0;
        if (csf_store_list_sessions(s, &list, &n, &err) == CSF_OK) {
            FILE *null_out = fopen("/dev/null", "w");
            for (size_t i = 0; i < n && i < 4; i++) {
                int64_t id = list[i].id;
                csf_trial *t = NULL;
                csf_reading *r = NULL;
                csf_threshold_row *th = NULL;
                double *fi = NULL;
                size_t k = 0;
                csf_store_get_trials(s, id, &t, &k, &err);
                csf_store_get_readings(s, id, &r, &k, &err);
                csf_store_get_thresholds(s, id, &th, &k, &err);
                csf_store_get_frame_intervals(s, id, &fi, &k, &err);
                free(t), free(r), free(th), free(fi);
                char c[32], u[32];
                csf_store_session_times(s, id, c, u, &err);
                if (null_out) {
                    csf_store_export(s, id, CSF_TABLE_AUTO, CSF_EXPORT_CSV, null_out, &err);
                    csf_store_export(s, id, CSF_TABLE_THRESHOLDS, CSF_EXPORT_JSON, null_out, &err);
                }
                if (i == 0) {
                    char out[80];
                    snprintf(out, sizeof out, "%s-report.svg", path);
                    csf_report_write(s, id, out, &err);
                    unlink(out);
                }
            }
            if (null_out) fclose(null_out);
            csf_session_list_free(list, n);
        }
        csf_store_close(s);
    }
    fuzz_file_remove(path);
    return 0;
}
