/* Every person of every set in bench/honest_sets.h is one the benches can build, without running
 * any method on anyone (an unseen set must stay unseen):
 *  - each set fits the benches' per-set arrays (MAX_HONEST_OBS) and holds held-out people;
 *  - each spec builds a simulated person (csf_observer_sim_create: the keys parse, and a table
 *    loads, is complete and has positive thresholds);
 *  - the sets a bench runs by default (1 to N_SEEN_SETS) exist.
 * It reads no threshold and prints nothing about anyone. Run from the source root (the specs name
 * their tables from there; meson sets the working folder). */
#include <stdio.h>

#include "honest_sets.h"
#include "model/observer_sim.h"
#include "tests/check.h"

int main(void)
{
    CHECK((int)N_SEEN_SETS >= 1 && (int)N_SEEN_SETS <= (int)N_HONEST_SETS);
    for (int k = 0; k < (int)N_HONEST_SETS; k++) {
        int held_out = 0;
        CHECK_MSG(HONEST_SETS[k].n >= 1 && HONEST_SETS[k].n <= MAX_HONEST_OBS,
                  "set %d: %d people, at most %d", k + 1, HONEST_SETS[k].n, (int)MAX_HONEST_OBS);
        for (int p = 0; p < HONEST_SETS[k].n; p++) {
            const honest_observer *h = &HONEST_SETS[k].obs[p];
            csf_observer_sim *o = NULL;
            csf_error err = {0};
            csf_status st = csf_observer_sim_create(h->spec, 1, &o, &err);
            CHECK_MSG(st == CSF_OK && o, "set %d, %s: %s", k + 1, h->name, err.msg);
            csf_observer_sim_free(o);
            held_out += h->held_out;
        }
        CHECK_MSG(held_out >= 1, "set %d holds no held-out person", k + 1);
    }
    printf("%d sets, %d of them seen\n", (int)N_HONEST_SETS, (int)N_SEEN_SETS);
    return CHECK_RESULT();
}
