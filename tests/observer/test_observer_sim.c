/* Simulated observer: spec parsing, CSV truth tables, and that its behaviour matches the model it
 * documents (fade-in detection follows the Weibull at the highest contrast shown, reaction times,
 * false alarms, 2AFC accuracy), measured over many seeded trials. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/observer_sim.h"
#include "model/psychometric.h"
#include "tests/check.h"

static void test_spec(void)
{
    csf_observer_sim *o;
    csf_error err;
    CHECK(csf_observer_sim_create("sim", 1, &o, &err) == CSF_OK);
    /* Default truth is the log-parabola x stelaCSF surface (model/csf_model.h): threshold at the
     * peak = 1/250 in the fovea. */
    CHECK_NEAR(csf_observer_sim_threshold(o, 3.0, 0.0), 1.0 / 250, 1e-9);
    CHECK(isinf(csf_observer_sim_threshold(o, 60.0, 20.0)));
    csf_observer_sim_free(o);

    CHECK(csf_observer_sim_create("sim:smax=100,fmax=2,slope=3,lapse=0.05,fa=0.3", 1, &o, &err) == CSF_OK);
    CHECK_NEAR(csf_observer_sim_threshold(o, 2.0, 0.0), 0.01, 1e-9);
    CHECK_NEAR(csf_observer_sim_params_get(o)->fa, 0.3, 0);
    CHECK_STR_CONTAINS(csf_observer_sim_describe(o), "smax=100");
    csf_observer_sim_free(o);

    CHECK(csf_observer_sim_create("sim:smax=1", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "smax=1 outside 2 to 5000");
    CHECK(csf_observer_sim_create("sim:colour=red", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "unknown key 'colour'");
    CHECK(csf_observer_sim_create("sim:lapse=abc", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK(csf_observer_sim_create("human", 1, &o, &err) == CSF_E_INVALID_ARG);
    CHECK(csf_observer_sim_create("sim:table=/nonexistent/x.csv", 1, &o, &err) == CSF_E_IO);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/x.csv");
}

static void test_table(void)
{
    const char *csv = "# truth\nfreq_cpd,ecc_deg,threshold\n"
                      "1,0,0.01\n4,0,0.001\n1,10,0.1\n4,10,inf\n";
    csf_obs_table *t;
    csf_error err;
    CHECK(csf_obs_table_parse(csv, strlen(csv), &t, &err) == CSF_OK);
    if (t) {
        CHECK_INT_EQ(t->n_freq, 2);
        CHECK_INT_EQ(t->n_ecc, 2);
        CHECK_NEAR(csf_obs_table_threshold(t, 1, 0), 0.01, 1e-12);
        CHECK_NEAR(csf_obs_table_threshold(t, 4, 0), 0.001, 1e-12);
        /* Midway in log frequency at ecc 0: geometric mean of the two thresholds. */
        CHECK_NEAR(csf_obs_table_threshold(t, 2, 0), sqrt(0.01 * 0.001), 1e-12);
        /* Midway in eccentricity at 1 cpd: log-linear. */
        CHECK_NEAR(csf_obs_table_threshold(t, 1, 5), sqrt(0.01 * 0.1), 1e-12);
        /* Held outside the grid. */
        CHECK_NEAR(csf_obs_table_threshold(t, 0.2, 0), 0.01, 1e-12);
        CHECK(isinf(csf_obs_table_threshold(t, 4, 10)));
        CHECK(isinf(csf_obs_table_threshold(t, 4, 30)));
        csf_obs_table_free(t);
    }
    const char *bad[] = {
        "1,0,0.01\n4,0,0.001\n1,10,0.1\n",           /* missing 4,10 */
        "1,0,0.01\n1,0,0.02\n",                         /* duplicate */
        "1,0,-0.01\n",                                  /* negative threshold */
        "0,0,0.01\n",                                   /* zero frequency */
        "1,200,0.01\n",                                 /* eccentricity out of range */
        "1,0\n",                                        /* two columns */
        "1,0,0.01,5\n",                                 /* four columns */
        "f,e,t\n1,0,0.01\n",                            /* wrong header */
        "1,0,x\n",                                      /* not a number */
        "",                                             /* empty */
    };
    const char *why[] = {"no row for 4 cpd at 10 deg", "duplicate", "must be > 0", "outside (0, 1000]",
                         "outside [0, 180]", "expected 3", "expected 3", "header", "not a number",
                         "no data rows"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        t = NULL;
        CHECK_MSG(csf_obs_table_parse(bad[i], strlen(bad[i]), &t, &err) == CSF_E_FORMAT, "case %zu", i);
        CHECK_STR_CONTAINS(err.msg, why[i]);
        CHECK(t == NULL);
    }
}

/* Fade-in detection: with a linear log ramp the fraction of trials detected by the time the ramp
 * reaches x must be F(x) (no lapses, no false alarms). */
static void test_fade_detection(void)
{
    csf_observer_sim *o;
    csf_error err;
    CHECK(csf_observer_sim_create("sim:lapse=0,fa=0,anticip=0,slope=3.5", 7, &o, &err) == CSF_OK);
    double th = csf_observer_sim_threshold(o, 3, 0), t = log10(th);
    const int n = 4000;
    const double x0 = t - 1.0, rate = 0.5, dt = 1.0 / 60;
    int det_below[3] = {0, 0, 0};
    const double probe[3] = {t - 0.2, t, t + 0.15};
    double rt_sum = 0;
    int n_rt = 0;
    for (int i = 0; i < n; i++) {
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin(o, (uint64_t)i, 3, 0, 0, 0, 5, &tr);
        for (int k = 0; k < 300; k++) {
            double x = x0 + rate * k * dt;
            double press;
            int pressed = csf_observer_sim_fade_frame(o, &tr, k * dt, pow(10, x), &press);
            if (pressed) {
                rt_sum += press - tr.t_detect_s;
                n_rt++;
                break;
            }
        }
        for (int j = 0; j < 3; j++)
            if (tr.detected && x0 + rate * tr.t_detect_s <= probe[j] + 1e-9) det_below[j]++;
    }
    for (int j = 0; j < 3; j++)
        CHECK_NEAR((double)det_below[j] / n, csf_psy_core(probe[j], t, 3.5), 0.025);
    /* Ex-Gaussian mean = mu + tau = 0.40 s. */
    CHECK(n_rt > n * 0.95);
    CHECK_NEAR(rt_sum / n_rt, 0.40, 0.01);

    /* A frozen display (same contrast repeated, as after missed frames) adds no detections. */
    int extra = 0;
    for (int i = 0; i < 2000; i++) {
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin(o, (uint64_t)(100000 + i), 3, 0, 0, 0, 5, &tr);
        csf_observer_sim_fade_frame(o, &tr, 0, pow(10, t - 0.3), NULL);
        int d0 = tr.detected;
        for (int k = 1; k < 100; k++) csf_observer_sim_fade_frame(o, &tr, k * dt, pow(10, t - 0.3), NULL);
        if (tr.detected && !d0) extra++;
    }
    CHECK_INT_EQ(extra, 0);
    csf_observer_sim_free(o);
}

static void test_false_alarms_and_clicks(void)
{
    csf_observer_sim *o;
    csf_error err;
    CHECK(csf_observer_sim_create("sim:fa=0.3,anticip=0,click_sd=0.5,click_sd_ecc=0", 3, &o, &err) == CSF_OK);
    int presses = 0;
    const int n = 3000;
    for (int i = 0; i < n; i++) {
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin(o, (uint64_t)i, 3, 10, 90, 0, 4, &tr);
        for (int k = 0; k < 240; k++)
            if (csf_observer_sim_fade_frame(o, &tr, k / 60.0, 0.0, NULL)) {
                presses++;
                break;
            }
    }
    CHECK_NEAR((double)presses / n, 0.3, 0.03);
    /* Clicks after a real detection scatter around the true position with the set sd. */
    double sx = 0, sy = 0, sxx = 0;
    int m = 0;
    for (int i = 0; i < n && m < 1000; i++) {
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin(o, (uint64_t)(50000 + i), 3, 10, 90, 0, 4, &tr);
        for (int k = 0; k < 240; k++)
            if (csf_observer_sim_fade_frame(o, &tr, k / 60.0, 0.2, NULL)) break;
        if (!tr.detected || tr.press_spontaneous) continue;
        double x, y;
        csf_observer_sim_click(o, &tr, &x, &y);
        sx += x; sy += y; sxx += x * x; m++;
    }
    CHECK(m > 500);
    CHECK_NEAR(sx / m, 0.0, 0.06);
    CHECK_NEAR(sy / m, 10.0, 0.06);
    CHECK_NEAR(sqrt(sxx / m - (sx / m) * (sx / m)), 0.5, 0.05);
    csf_observer_sim_free(o);
}

static void test_2afc(void)
{
    csf_observer_sim *o;
    csf_error err;
    CHECK(csf_observer_sim_create("sim:lapse=0.02", 11, &o, &err) == CSF_OK);
    double th = csf_observer_sim_threshold(o, 3, 5);
    int correct = 0, correct_hi = 0;
    const int n = 5000;
    for (int i = 0; i < n; i++) {
        int sig = i & 1;
        double c[2] = {0, 0};
        c[sig] = th;
        if (csf_observer_sim_2afc(o, (uint64_t)i, 3, 5, c, NULL) == sig) correct++;
        c[sig] = 0.9;
        if (csf_observer_sim_2afc(o, (uint64_t)(n + i), 3, 5, c, NULL) == sig) correct_hi++;
    }
    /* At threshold: 0.5 + 0.48 * (1 - 1/e) = 0.803; far above: 1 - lapse = 0.98. */
    CHECK_NEAR((double)correct / n, 0.5 + 0.48 * (1 - exp(-1)), 0.02);
    CHECK_NEAR((double)correct_hi / n, 0.98, 0.01);
    /* Reproducible: a pure function of (seed, trial). */
    double c[2] = {th, 0};
    CHECK(csf_observer_sim_2afc(o, 17, 3, 5, c, NULL) == csf_observer_sim_2afc(o, 17, 3, 5, c, NULL));
    csf_observer_sim_free(o);
}

/* m-alternative answers (four places shown at once): P(correct) = 1/m + (1 - 1/m - lapse) F,
 * wrong answers spread evenly over the other places, answers in range, reproducible, and the
 * two-interval function's answers untouched by it. */
static void test_afc(void)
{
    csf_observer_sim *o;
    csf_error err;
    CHECK(csf_observer_sim_create("sim:lapse=0.02", 11, &o, &err) == CSF_OK);
    double th = csf_observer_sim_threshold(o, 3, 5);
    const int n = 8000;
    int correct = 0, correct_hi = 0, correct_zero = 0, out_of_range = 0;
    int wrong_at[4][4] = {{0}};
    for (int i = 0; i < n; i++) {
        int sig = i % 4;
        double c[4] = {0, 0, 0, 0};
        c[sig] = th;
        int r = csf_observer_sim_afc(o, (uint64_t)i, 3, 5, c, 4, NULL);
        out_of_range += r < 0 || r > 3;
        if (r == sig) correct++;
        else if (r >= 0 && r < 4) wrong_at[sig][r]++;
        c[sig] = 0.9;
        r = csf_observer_sim_afc(o, (uint64_t)(n + i), 3, 5, c, 4, NULL);
        out_of_range += r < 0 || r > 3;
        correct_hi += r == sig;
        c[sig] = 0.0; /* nothing shown: pure guessing */
        r = csf_observer_sim_afc(o, (uint64_t)(2 * n + i), 3, 5, c, 4, NULL);
        out_of_range += r < 0 || r > 3;
        correct_zero += r == 0;
    }
    CHECK_INT_EQ(out_of_range, 0);
    /* At threshold: 0.25 + 0.73 * (1 - 1/e) = 0.711; far above: 1 - lapse; nothing: 1/4. */
    CHECK_NEAR((double)correct / n, 0.25 + 0.73 * (1 - exp(-1)), 0.02);
    CHECK_NEAR((double)correct_hi / n, 0.98, 0.01);
    CHECK_NEAR((double)correct_zero / n, 0.25, 0.02);
    /* Wrong answers: each of the three other places about a third of the time. */
    for (int sig = 0; sig < 4; sig++) {
        int tot = 0;
        for (int r = 0; r < 4; r++) tot += wrong_at[sig][r];
        for (int r = 0; r < 4; r++)
            if (r != sig) CHECK_NEAR((double)wrong_at[sig][r] / tot, 1.0 / 3, 0.08);
    }
    /* Reproducible, and m = 2 through this function uses guess 1/2 as well. */
    double c[4] = {0, 0, th, 0};
    double rt1, rt2;
    CHECK(csf_observer_sim_afc(o, 17, 3, 5, c, 4, &rt1) == csf_observer_sim_afc(o, 17, 3, 5, c, 4, &rt2));
    CHECK(rt1 == rt2 && rt1 > 0);
    int c2 = 0;
    for (int i = 0; i < n; i++) {
        double d[2] = {th, 0};
        c2 += csf_observer_sim_afc(o, (uint64_t)i, 3, 5, d, 2, NULL) == 0;
    }
    CHECK_NEAR((double)c2 / n, 0.5 + 0.48 * (1 - exp(-1)), 0.02);
    /* The two-interval function's answers are a pure function of (seed, trial) of their own:
     * the same whether or not m-alternative answers were drawn in between. */
    csf_observer_sim *o2;
    CHECK(csf_observer_sim_create("sim:lapse=0.02", 11, &o2, &err) == CSF_OK);
    for (int i = 0; i < 200; i++) {
        double d[2] = {i & 1 ? th : 0, i & 1 ? 0 : th};
        double r1, r2;
        int a1 = csf_observer_sim_2afc(o, (uint64_t)i, 3, 5, d, &r1);
        int a2 = csf_observer_sim_2afc(o2, (uint64_t)i, 3, 5, d, &r2);
        CHECK(a1 == a2 && r1 == r2);
    }
    csf_observer_sim_free(o2);
    csf_observer_sim_free(o);
}

/* view=frame and its keys: parsed, described, refused with the key named. */
static void test_view_spec(void)
{
    csf_observer_sim *o = NULL;
    csf_error e;
    CHECK(csf_observer_sim_create("sim", 1, &o, &e) == CSF_OK);
    CHECK(o && csf_observer_sim_params_get(o)->view_frame == 0);
    CHECK(o && strstr(csf_observer_sim_describe(o), "view") == NULL); /* the default's text unchanged */
    csf_observer_sim_free(o);
    CHECK(csf_observer_sim_create("sim:view=frame,display=crt,display_gamma=2.6,frame_step=5", 1, &o, &e) == CSF_OK);
    if (o) {
        const csf_observer_sim_params *p = csf_observer_sim_params_get(o);
        CHECK(p->view_frame == 1 && strcmp(p->display, "crt") == 0 && p->display_gamma == 2.6 &&
              p->frame_step == 5);
        CHECK_STR_CONTAINS(csf_observer_sim_describe(o), "view=frame,display=crt,frame_step=5,display_gamma=2.6");
    }
    csf_observer_sim_free(o);
    CHECK(csf_observer_sim_create("sim:view=frame", 1, &o, &e) == CSF_OK);
    CHECK(o && csf_observer_sim_params_get(o)->display[0] == '\0' && csf_observer_sim_params_get(o)->frame_step == 3);
    csf_observer_sim_free(o);
    CHECK(csf_observer_sim_create("sim:view=frame,display=file=/x/y.csv", 1, &o, &e) == CSF_OK);
    csf_observer_sim_free(o);
    static const struct {
        const char *spec, *msg;
    } bad[] = {
        {"sim:view=eyes", "view=eyes: must be plan or frame"},
        {"sim:display=lcd", "need view=frame"},
        {"sim:frame_step=2", "need view=frame"},
        {"sim:view=frame,display=plasma", "display=plasma: must be crt, lcd, oled, profile or file=PATH.csv"},
        {"sim:view=frame,display=file=", "display=file=: must be"},
        {"sim:view=frame,display=profile,display_gamma=2", "display_gamma= applies to display=crt, lcd or oled"},
        {"sim:view=frame,display_gamma=2", "display_gamma= applies"},
        {"sim:view=frame,display=crt,display_gamma=5", "display_gamma=5 outside 1 to 4"},
        {"sim:view=frame,frame_step=0", "frame_step=0 outside 1 to 30"},
        {"sim:view=frame,frame_step=2.5", "frame_step=2.5 must be a whole number"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        o = NULL;
        e.msg[0] = '\0';
        CHECK_MSG(csf_observer_sim_create(bad[i].spec, 1, &o, &e) == CSF_E_INVALID_ARG, "%s", bad[i].spec);
        CHECK(o == NULL);
        CHECK_STR_CONTAINS(e.msg, bad[i].msg);
    }
}

int main(void)
{
    test_view_spec();
    test_spec();
    test_table();
    test_fade_detection();
    test_false_alarms_and_clicks();
    test_2afc();
    test_afc();
    return CHECK_RESULT();
}
