/* CRS ColorCAL MkII protocol: the bytes, without the USB. Commands are three ASCII letters (or
 * "r0N" for a matrix row) sent in one vendor control transfer; the answer is an ASCII line read
 * back in another, "OK00,..." on success or "ERnn" on an instrument error. Facts from the public
 * Psychtoolbox ColorCal2.m and PsychoPy colorcal.py; the code is ours.
 *
 *   IDR  -> OK00,1,<rom>,100.10,<serial>,<build>     identify
 *   MES  -> OK00,<x>,<y>,<z>                          raw tristimulus (decimal, before the matrix)
 *   UZC  -> OK00 | ER11                                zero calibration (ER11: too much light)
 *   r0N  -> OK00,<a>,<b>,<c>   N = 1..9               calibration matrix rows, Minolta format;
 *                                                      rows 1-3 are the factory matrix used here
 * The corrected XYZ is M * raw with M from rows 1..3. */
#ifndef CSF_COLORCAL2_PROTO_H
#define CSF_COLORCAL2_PROTO_H

#include <stddef.h>

#include "core/csf_status.h"

enum { CSF_CC2_USB_VID = 0x0861, CSF_CC2_USB_PID = 0x1001, CSF_CC2_REPLY_MAX = 64 };

typedef struct {
    int ok;        /* 1: "OK00"; 0: "ERnn" */
    int code;      /* nn of OKnn / ERnn */
    int n_fields;  /* numbers after the code */
    double field[6];
} csf_cc2_reply;

/* Parses one reply (len bytes, not NUL-terminated; trailing CR/LF/NUL/'>' ignored). Refuses
 * anything else with CSF_E_PROTOCOL and a message that shows the first bytes. `cmd` names the
 * command in the message. */
csf_status csf_cc2_parse_reply(const char *cmd, const unsigned char *buf, size_t len, csf_cc2_reply *out,
                               csf_error *err);

/* Minolta fixed-point: v < 50000 is v / 10000, otherwise -(v - 50000) / 10000. */
double csf_cc2_minolta_to_double(long v);
/* The inverse (for the emulator and tests); |x| < 5. */
long csf_cc2_double_to_minolta(double x);

/* Reply to r0N -> one matrix row (floats). */
csf_status csf_cc2_parse_matrix_row(const unsigned char *buf, size_t len, int row1, double out[3],
                                    csf_error *err);
/* Reply to IDR -> serial number, rom version and build. */
csf_status csf_cc2_parse_identity(const unsigned char *buf, size_t len, long *serial, long *rom,
                                  long *build, csf_error *err);
/* Reply to MES -> raw x y z. An ERnn reply is CSF_E_DEVICE naming the code. */
csf_status csf_cc2_parse_measurement(const unsigned char *buf, size_t len, double raw[3], csf_error *err);

/* xyz = m * raw; checks the matrix is usable (finite, invertible). */
int csf_cc2_matrix_usable(const double m[3][3]);
void csf_cc2_apply(const double m[3][3], const double raw[3], double xyz[3]);

#endif
