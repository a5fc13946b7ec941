/* ColorCAL MkII replies (devices/colorcal2_proto.h) are outside input: bytes from a USB device.
 * Every parser must refuse with a message or give finite numbers in the documented ranges. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/colorcal2_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_error e;
    csf_cc2_reply r;
    e.msg[0] = '\0';
    if (csf_cc2_parse_reply("MES", data, size, &r, &e) != CSF_OK) {
        if (!e.msg[0]) abort();
    } else {
        if (r.n_fields < 0 || r.n_fields > 6 || r.code < 0 || r.code > 99) abort();
        for (int k = 0; k < r.n_fields; k++)
            if (!isfinite(r.field[k])) abort();
    }
    double raw[3], row[3];
    e.msg[0] = '\0';
    if (csf_cc2_parse_measurement(data, size, raw, &e) == CSF_OK) {
        for (int k = 0; k < 3; k++)
            if (!isfinite(raw[k]) || fabs(raw[k]) > 1e7) abort();
    } else if (!e.msg[0]) {
        abort();
    }
    e.msg[0] = '\0';
    if (csf_cc2_parse_matrix_row(data, size, 1, row, &e) == CSF_OK) {
        for (int k = 0; k < 3; k++)
            if (!(fabs(row[k]) <= 10)) abort();
    } else if (!e.msg[0]) {
        abort();
    }
    long serial, rom, build;
    e.msg[0] = '\0';
    if (csf_cc2_parse_identity(data, size, &serial, &rom, &build, &e) == CSF_OK) {
        if (serial < 0 || rom < 0 || build < 0) abort();
    } else if (!e.msg[0]) {
        abort();
    }
    return 0;
}
