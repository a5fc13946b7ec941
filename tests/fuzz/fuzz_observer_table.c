/* The simulated observer's truth table (--observer sim:table=FILE.csv) is outside input: the
 * parser must refuse garbage with a message and never read out of bounds. Also the spec parser
 * (the part of the input after "sim:"), and a lookup on whatever table parsed. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model/observer_sim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_obs_table *t = NULL;
    csf_error err;
    if (csf_obs_table_parse((const char *)data, size, &t, &err) == CSF_OK) {
        /* Lookups anywhere, including outside the grid and at any speed (either direction),
         * must stay finite or +inf; a 2-D table's value does not depend on the speed. */
        static const double f[] = {0.01, 0.5, 3, 40, 2000}, e[] = {0, 7, 90, 200},
                            vel[] = {0, 0.3, -4, 17, 5000};
        for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
            for (size_t j = 0; j < sizeof e / sizeof e[0]; j++)
                for (size_t k = 0; k < sizeof vel / sizeof vel[0]; k++) {
                    double v = csf_obs_table_threshold_v(t, f[i], e[j], vel[k]);
                    if (!(v > 0)) abort();
                    if (t->n_vel == 0 && v != csf_obs_table_threshold(t, f[i], e[j])) abort();
                }
        csf_obs_table_free(t);
    } else if (t != NULL || err.msg[0] == '\0') {
        abort(); /* failure must leave no table and must say why */
    }
    /* The same bytes as an observer spec (NUL-terminated copy, table= stripped of file access). */
    char spec[512];
    size_t n = size < sizeof spec - 5 ? size : sizeof spec - 5;
    memcpy(spec, "sim:", 4);
    memcpy(spec + 4, data, n);
    spec[4 + n] = '\0';
    if (strstr(spec, "table=")) return 0;
    csf_observer_sim *o = NULL;
    if (csf_observer_sim_create(spec, 1, &o, &err) == CSF_OK) {
        double th = csf_observer_sim_threshold(o, 3, 0);
        if (!(th > 0)) abort();
        /* whatever the velocity keys say: a threshold at any speed, exactly the static one at 0 */
        if (!(csf_observer_sim_threshold_v(o, 3, 0, 6) > 0) || csf_observer_sim_threshold_v(o, 3, 0, 0) != th)
            abort();
        csf_observer_sim_free(o);
    }
    return 0;
}
