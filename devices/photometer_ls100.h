/* Konica Minolta LS-100 / LS-110 (luminance meters) and CS-100A (chroma meter) over RS-232:
 * 4800 baud, 7 data bits, even parity, 2 stop bits; commands end in CR LF. The instrument must be
 * in communication mode (switched on with F held: the display shows '['). csfcal sends MDS,04
 * (absolute measurement) once and MES per reading.
 *   MES reply  LS-100/110: "OKnn,<lum>"   CS-100A: "OKnn,<lum>,<x>,<y>"   (fields may be padded)
 *   error      "ERnn": 00 command error, 01 setting error, 10 measuring range over, 11 memory value
 *              error, 19 display range over, 20 EEPROM error, 30 battery exhausted.
 * Specs: ls100:PATH, ls110:PATH, cs100a:PATH [,timeout_s=S][,floor_cdm2=L] (see docs/instruments.md). */
#ifndef CSF_PHOTOMETER_LS100_H
#define CSF_PHOTOMETER_LS100_H

#include <stddef.h>

#include "core/csf_status.h"

typedef struct {
    int ok;         /* 1: "OKnn..." ; 0: "ERnn" */
    int code;       /* nn */
    int n_values;   /* numbers after "OKnn," (0..3) */
    double v[3];    /* luminance [, x, y] */
} csf_minolta_reply;

/* Parses one reply line (line ending already removed). CSF_E_PROTOCOL with the reason when it is
 * neither form, or a number is not finite. Pure: no I/O (fuzzed by tests/fuzz/fuzz_minolta_reply). */
csf_status csf_minolta_parse(const char *line, size_t len, csf_minolta_reply *out, csf_error *err);
/* The manual's sentence for an ER code, and the csfcal status it maps to. */
const char *csf_minolta_error_text(int code);
csf_status csf_minolta_error_status(int code);

#endif
