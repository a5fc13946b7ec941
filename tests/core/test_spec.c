/* core/spec: the one key=value splitter and number parser every simulated device's spec goes
 * through. What it refuses (an empty item, a key twice) it refuses for all of them. */
#include "core/spec.h"

#include <math.h>

#include "devices/photometer.h"
#include "model/display_model.h"
#include "model/observer_sim.h"
#include "tests/check.h"

static void test_split(void)
{
    static csf_spec s;
    csf_error err;
    CHECK(csf_spec_split("smax=250,fmax=3,field=nasal", "--observer", &s, &err) == CSF_OK);
    CHECK(s.n == 3);
    CHECK(s.n == 3 && !strcmp(s.item[0].key, "smax") && !strcmp(s.item[0].value, "250"));
    CHECK(s.n == 3 && !strcmp(s.item[2].key, "field") && !strcmp(s.item[2].value, "nasal"));
    /* the first '=' splits: a path may hold more */
    CHECK(csf_spec_split("lcd,file=a=b.csv", "display", &s, &err) == CSF_OK);
    CHECK(s.n == 2 && s.item[0].value == NULL && !strcmp(s.item[1].value, "a=b.csv"));
    CHECK(csf_spec_split("", "x", &s, &err) == CSF_OK && s.n == 0);

    CHECK(csf_spec_split("smax=250,smax=300", "--observer", &s, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "--observer: key 'smax' given twice (items 1 and 2 of 'smax=250,smax=300')");
    CHECK(csf_spec_split("smax=250,,fmax=3", "--observer", &s, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "--observer: item 2 of 'smax=250,,fmax=3' is empty");
    CHECK(csf_spec_split("smax=250,", "--observer", &s, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "item 2 of");
    CHECK(csf_spec_split(",smax=250", "--observer", &s, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "item 1 of");
    /* a control byte in the text is shown escaped, never raw */
    CHECK(csf_spec_split("a=1,\x1b[2J=2,,", "x", &s, &err) == CSF_E_INVALID_ARG);
    CHECK(strchr(err.msg, '\x1b') == NULL);
}

static void test_numbers(void)
{
    double v = 0;
    long w = 0;
    CHECK(csf_number_parse(" 570", 100, 10000, &v) == CSF_NUM_OK && v == 570);
    CHECK(csf_number_parse("570mm", 100, 10000, &v) == CSF_NUM_NOT_A_NUMBER);
    CHECK(csf_number_parse("", 0, 1, &v) == CSF_NUM_NOT_A_NUMBER);
    CHECK(csf_number_parse("nan", -INFINITY, INFINITY, &v) == CSF_NUM_NOT_A_NUMBER);
    CHECK(csf_number_parse("1e999", -INFINITY, INFINITY, &v) == CSF_NUM_NOT_A_NUMBER);
    CHECK(csf_number_parse("20000", 100, 10000, &v) == CSF_NUM_OUT_OF_RANGE && v == 20000);
    CHECK(csf_whole_parse("12", 1, 5000, &w) == CSF_NUM_OK && w == 12);
    CHECK(csf_whole_parse("1.5", 1, 5000, &w) == CSF_NUM_NOT_A_NUMBER);
    CHECK(csf_whole_parse("0", 1, 5000, &w) == CSF_NUM_OUT_OF_RANGE && w == 0);
}

/* The three simulators take the refusals from the splitter, and keep their own messages. */
static void test_simulators(void)
{
    csf_error err;
    csf_observer_sim *o = NULL;
    CHECK(csf_observer_sim_create("sim:smax=250,smax=300", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "key 'smax' given twice");
    CHECK(csf_observer_sim_create("sim:smax=250,,fmax=3", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "item 2 of 'smax=250,,fmax=3' is empty");
    CHECK(csf_observer_sim_create("sim:smax=1", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "--observer: smax=1 outside 2 to 5000");
    CHECK(csf_observer_sim_create("sim:smax=250,fmax=3,field=nasal", 1, &o, &err) == CSF_OK);
    csf_observer_sim_free(o);

    csf_display_model *m = NULL;
    CHECK(csf_display_model_create("lcd,gamma=2.2,gamma=2.4", &m, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "key 'gamma' given twice (items 2 and 3");
    CHECK(csf_display_model_create("lcd,,gamma=2.2", &m, &err) == CSF_E_INVALID_ARG);
    CHECK(csf_display_model_create("lcd,gamma=9", &m, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "display option gamma=9 out of range");
    CHECK(csf_display_model_create("lcd,gamma", &m, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "display option 'gamma' is not key=value");
    CHECK(csf_display_model_create("oled,lmax=300,black=0.01", &m, &err) == CSF_OK);
    csf_display_model_free(m);

    csf_photometer *ph = NULL;
    CHECK(csf_photometer_open("sim:noise=0.01,noise=0.02", 1, &ph, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "sim photometer: key 'noise' given twice (items 1 and 2");
    CHECK(csf_photometer_open("sim:display=lcd,,noise=0.01", 1, &ph, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "item 2 of 'display=lcd,,noise=0.01' is empty");
    CHECK(csf_photometer_open("sim:noise=0.5", 1, &ph, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "sim photometer: noise=0.5 out of range (relative sd 0 to 0.2)");
    CHECK(csf_photometer_open("sim:display=crt,noise=0.01,fault=stuck@3+2", 1, &ph, &err) == CSF_OK);
    csf_photometer_close(ph);
}

int main(void)
{
    test_split();
    test_numbers();
    test_simulators();
    return CHECK_RESULT();
}
