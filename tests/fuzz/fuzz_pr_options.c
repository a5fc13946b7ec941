/* The options of a Photo Research spec after its port (pr670:/dev/ttyACM0,timeout_s=5,aperture=1/8)
 * are outside input (--photometer, the station configuration, a stored session's spec). The first
 * byte picks the model (even: pr655, odd: pr670), the rest is the option text. A refusal is
 * CSF_E_INVALID_ARG with a message; an accepted text gives a timeout in 0.1..600 s and one of the
 * PR-670's apertures (1, 1/2, 1/4, 1/8 deg), and a PR-655 never takes an aperture. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/photometer_pr655.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 600) return 0;
    char opts[601];
    memcpy(opts, data + 1, size - 1);
    opts[size - 1] = '\0';
    const char *model = data[0] & 1 ? "pr670" : "pr655";
    double timeout_s = 60, aperture_deg = 1;
    csf_error err = {0};
    if (csf_pr_parse_options(model, opts, &timeout_s, &aperture_deg, &err) != CSF_OK) {
        if (err.code != CSF_E_INVALID_ARG || err.msg[0] == '\0' || !memchr(err.msg, '\0', sizeof err.msg))
            abort();
        return 0;
    }
    if (!(timeout_s >= 0.1 && timeout_s <= 600)) abort();
    if (aperture_deg != 1 && aperture_deg != 0.5 && aperture_deg != 0.25 && aperture_deg != 0.125) abort();
    if (!(data[0] & 1) && aperture_deg != 1) abort();
    return 0;
}
