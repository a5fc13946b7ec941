/* ArgyllCMS spotread as a bridge to every instrument Argyll supports (i1Display Pro, Spyder,
 * i1Pro, ColorMunki, K-10, JETI, ...). csfcal runs `spotread -e -x [ARGS]` from PATH on a
 * pseudo-terminal (spotread reads single key presses from its console), waits for its prompt
 * "... any other key to take a reading:", sends a space per reading and reads the documented
 * result line " Result is XYZ: X Y Z, Yxy: Y x y" (emissive mode: absolute cd/m2).
 * Failures it prints are mapped: "Unknown, inappropriate or no instrument detected" and
 * "Instrument initialisation failed" -> CSF_E_NOT_FOUND / CSF_E_DEVICE; "Spot read failed due to
 * misread (REASON)" -> CSF_E_TOO_DARK (too low / too dark), CSF_E_SATURATED (saturated / too
 * bright / too high), CSF_E_DEVICE (others, a low battery included); "Spot read failed due to
 * communication problem" or spotread exiting -> CSF_E_GONE; silence -> CSF_E_TIMEOUT. After a
 * failure spotread is ended and started again for the next reading.
 * Spec: spotread[:ARGS] -- ARGS separated by spaces: spotread options (e.g. "-c 2 -y l"), plus
 * csfcal's own timeout_s=S (per reading, default 60) and start_timeout_s=S (instrument start-up
 * and calibration, default 60). */
#ifndef CSF_PHOTOMETER_SPOTREAD_H
#define CSF_PHOTOMETER_SPOTREAD_H

#include <stddef.h>

#include "core/csf_status.h"

enum {
    CSF_SPOT_NONE = 0,   /* nothing complete yet: read more */
    CSF_SPOT_PROMPT,     /* ready for a key press */
    CSF_SPOT_RESULT,     /* xyz holds a reading */
    CSF_SPOT_FAIL,       /* status + reason */
    CSF_SPOT_ASK,        /* spotread asks for something csfcal cannot do (calibration position) */
};

typedef struct {
    int kind;
    double xyz[3];
    csf_status status;   /* for CSF_SPOT_FAIL */
    char reason[200];    /* the line spotread printed (FAIL, ASK) */
    size_t consumed;     /* bytes of the input this event used up */
} csf_spotread_event;

/* Scans spotread's output text for the first complete event. Pure (fuzzed by fuzz_spotread). A
 * result line whose numbers do not parse is CSF_SPOT_FAIL with CSF_E_PROTOCOL. */
void csf_spotread_scan(const char *buf, size_t len, csf_spotread_event *ev);

#endif
