/* The simulated person's clock counts reading: a text screen costs its words at the reading rate
 * (obs_reading_s), as it costs a real person on the session's clock, so the person time a
 * simulated session reports includes its instructions. */
#include <math.h>
#include <string.h>

#include "calib/observer_person.h"
#include "model/observer_sim.h"
#include "tests/check.h"

int main(void)
{
    CHECK_NEAR(obs_reading_s(""), 0.0, 0);
    CHECK_NEAR(obs_reading_s("  \n\t "), 0.0, 0);
    CHECK_NEAR(obs_reading_s("Look at the mark."), 4 * 60.0 / 238.0, 1e-12);
    CHECK_NEAR(obs_reading_s("  two\nwords  "), 2 * 60.0 / 238.0, 1e-12);
    /* a screen of 119 words takes half a minute */
    char text[119 * 4 + 1] = "";
    for (int k = 0; k < 119; k++) strcat(text, k % 7 ? "ab " : "c\n\t ");
    CHECK_NEAR(obs_reading_s(text), 30.0, 1e-9);

    person p;
    memset(&p, 0, sizeof p);
    csf_error err;
    CHECK(csf_observer_sim_create("sim", 1, &p.sim, &err) == CSF_OK);
    p.sim_rt_total_s = 2.5; /* answers so far */
    CHECK(obs_person_screen(&p, "Break. 40 of 120 trials done.\nPress a key to go on.", &err) == CSF_OK);
    CHECK_NEAR(p.sim_rt_total_s, 2.5 + 12 * 60.0 / 238.0, 1e-12);
    CHECK(!p.paused);
    csf_observer_sim_free(p.sim);
    return CHECK_RESULT();
}
