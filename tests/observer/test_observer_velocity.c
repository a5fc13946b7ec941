/* The simulated person sees motion: the velocity keys of the spec, the Kelly-Daly gain over the
 * static threshold, 3-D observer tables (velocity_dps column), and the _v trial functions, which at
 * velocity 0 must give exactly the answers of the static ones. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "model/csf_velocity.h"
#include "model/observer_images.h"
#include "model/observer_sim.h"
#include "model/psychometric.h"
#include "tests/check.h"

static csf_observer_sim *make(const char *spec, uint64_t seed)
{
    csf_observer_sim *o = NULL;
    csf_error err;
    CHECK_MSG(csf_observer_sim_create(spec, seed, &o, &err) == CSF_OK, "%s: %s", spec, err.msg);
    return o;
}

/* v = 0 is the static person, draw for draw. */
static void test_static_unchanged(void)
{
    const char *specs[] = {"sim", "sim:vc1=0.4,vc2=3,vsteep=2", "sim:decision=sdt,vsteep=draw,fatigue=0.1"};
    for (size_t s = 0; s < sizeof specs / sizeof specs[0]; s++) {
        csf_observer_sim *o = make(specs[s], 7 + s);
        if (!o) continue;
        int same = 0, n = 0;
        for (int i = 0; i < 400; i++) {
            double f = 0.5 + 0.05 * i, e = (i % 7) * 3.0, c2[2] = {0, 0.002 * (1 + i % 9)}, rt1, rt2;
            double c4[4] = {0.001, 0.003 * (1 + i % 5), 0.001, 0};
            n += 4;
            same += csf_observer_sim_threshold_v(o, f, e, 0) == csf_observer_sim_threshold(o, f, e);
            same += csf_observer_sim_trial_threshold_v(o, f, e, 0, (uint64_t)i) ==
                    csf_observer_sim_trial_threshold(o, f, e, (uint64_t)i);
            same += csf_observer_sim_2afc_v(o, (uint64_t)i, f, e, 0, c2, &rt1) ==
                        csf_observer_sim_2afc(o, (uint64_t)i, f, e, c2, &rt2) &&
                    rt1 == rt2;
            same += csf_observer_sim_afc_v(o, (uint64_t)i, f, e, 0, c4, 4, &rt1) ==
                        csf_observer_sim_afc(o, (uint64_t)i, f, e, c4, 4, &rt2) &&
                    rt1 == rt2;
            csf_sim_fade_trial a, b;
            csf_observer_sim_fade_begin_v(o, (uint64_t)i, f, e, 0, 30, 0, 4, &a);
            csf_observer_sim_fade_begin(o, (uint64_t)i, f, e, 30, 0, 4, &b);
            CHECK(memcmp(&a, &b, sizeof a) == 0);
        }
        CHECK_INT_EQ(same, n);
        csf_observer_sim_free(o);
    }
}

/* threshold(f, e, v) = threshold(f, e) / 10^gain with the person's own velocity parameters. */
static void test_parametric_gain(void)
{
    csf_observer_sim *o = make("sim:vc1=0.5,vc2=2.5,vsteep=1.3,vmin=0.2", 3);
    if (!o) return;
    csf_velocity_params vp = {.c1 = 0.5, .c2 = 2.5, .v_min_dps = 0.2, .steepness = 1.3};
    const double fs[] = {0.5, 2, 6}, vs[] = {0.1, 1, 4, 16, -4};
    for (size_t i = 0; i < 3; i++)
        for (size_t j = 0; j < 5; j++) {
            double t0 = csf_observer_sim_threshold(o, fs[i], 5);
            double want = t0 / pow(10.0, csf_velocity_log10_gain(&vp, fs[i], vs[j]));
            double got = csf_observer_sim_threshold_v(o, fs[i], 5, vs[j]);
            if (want >= 1) CHECK(isinf(got));
            else CHECK_NEAR(log10(got), log10(want), 1e-12);
            CHECK_NEAR(csf_observer_sim_velocity_log10_gain(o, fs[i], 5, vs[j]),
                       csf_velocity_log10_gain(&vp, fs[i], vs[j]), 1e-12);
        }
    /* Kelly's shape: a fine grating is harder to see when it moves fast, a coarse one easier
     * when it drifts a few deg/s (its temporal frequency nears the transient channel's peak). */
    CHECK(csf_observer_sim_threshold_v(o, 6, 0, 16) > 2 * csf_observer_sim_threshold(o, 6, 0));
    CHECK(csf_observer_sim_threshold_v(o, 0.5, 0, 4) < csf_observer_sim_threshold(o, 0.5, 0));
    CHECK_STR_CONTAINS(csf_observer_sim_describe(o), "vsteep=1.3");
    csf_observer_sim_free(o);

    /* vsteep=0: motion changes nothing. */
    o = make("sim:vsteep=0", 3);
    if (o) {
        CHECK(csf_observer_sim_threshold_v(o, 6, 0, 16) == csf_observer_sim_threshold(o, 6, 0));
        csf_observer_sim_free(o);
    }
    /* vsteep=draw: from the seed, in its documented range, people differ. */
    double lo = INFINITY, hi = -INFINITY;
    for (uint64_t seed = 1; seed <= 40; seed++) {
        csf_observer_sim *a = make("sim:vsteep=draw", seed), *b = make("sim:vsteep=draw", seed);
        if (!a || !b) break;
        double s = csf_observer_sim_params_get(a)->velocity.steepness;
        CHECK(s == csf_observer_sim_params_get(b)->velocity.steepness);
        CHECK(csf_observer_sim_params_get(a)->vsteep_drawn == 1);
        lo = fmin(lo, s), hi = fmax(hi, s);
        csf_observer_sim_free(a), csf_observer_sim_free(b);
    }
    CHECK(lo >= 0.5 && hi <= 1.5 && hi - lo > 0.5);

    struct {
        const char *spec, *msg;
    } bad[] = {
        {"sim:vc1=5", "vc1=5 outside 0.2 to 2"},       {"sim:vc2=0.1", "vc2=0.1 outside 0.5 to 5"},
        {"sim:vsteep=-1", "vsteep=-1 outside 0 to 3"}, {"sim:vmin=1", "vmin=1 outside 0.05 to 0.5"},
        {"sim:vc1=draw", "vc1=draw outside"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        csf_observer_sim *x = NULL;
        csf_error e = {0};
        CHECK_MSG(csf_observer_sim_create(bad[i].spec, 1, &x, &e) == CSF_E_INVALID_ARG, "%s", bad[i].spec);
        CHECK(x == NULL);
        CHECK_STR_CONTAINS(e.msg, bad[i].msg);
    }
}

/* A moving grating whose threshold is higher is answered correctly less often at one contrast. */
static void test_trials_follow_velocity(void)
{
    csf_observer_sim *o = make("sim", 11);
    if (!o) return;
    double f = 6, v = 2, c = 2 * csf_observer_sim_threshold(o, f, 0);
    CHECK(csf_observer_sim_threshold_v(o, f, 0, v) > 2 * c);
    int ok_static = 0, ok_moving = 0, n = 2000;
    for (int i = 0; i < n; i++) {
        double shown[2] = {0, c};
        ok_static += csf_observer_sim_2afc_v(o, (uint64_t)i, f, 0, 0, shown, NULL) == 1;
        ok_moving += csf_observer_sim_2afc_v(o, (uint64_t)i, f, 0, v, shown, NULL) == 1;
    }
    /* Weibull at 2 t: 0.98 - 0.48 exp(-2^3.5) = 0.975; at c well below the moving threshold: near 0.5 */
    double pt = csf_psy_p4(log10(c), log10(csf_observer_sim_threshold(o, f, 0)), 3.5, 0.5, 0.02);
    double pv = csf_psy_p4(log10(c), log10(csf_observer_sim_threshold_v(o, f, 0, v)), 3.5, 0.5, 0.02);
    CHECK_NEAR((double)ok_static / n, pt, 0.03);
    CHECK_NEAR((double)ok_moving / n, pv, 0.03);
    int det = 0;
    for (int i = 0; i < n; i++) {
        csf_sim_fade_trial tr;
        csf_observer_sim_fade_begin_v(o, (uint64_t)i, f, 0, v, 0, 0, 1, &tr);
        CHECK(tr.velocity_dps == v);
        CHECK_NEAR(tr.t_sens_log10, log10(csf_observer_sim_threshold_v(o, f, 0, v)), 1e-12);
        double press;
        det += csf_observer_sim_fade_frame(o, &tr, 0.0, c, &press) && !tr.press_spontaneous;
    }
    CHECK(det < n / 50); /* far below the moving threshold: hardly ever seen */
    csf_observer_sim_free(o);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

static void test_table_3d(void)
{
    const char *text = "# a person measured at three speeds\n"
                       "velocity_dps,freq_cpd,ecc_deg,threshold\n"
                       "0,1,0,0.004\n0,4,0,0.005\n0,1,10,0.01\n0,4,10,0.05\n"
                       "2,1,0,0.003\n2,4,0,0.008\n2,1,10,0.008\n2,4,10,inf\n"
                       "8,1,0,0.004\n8,4,0,0.02\n8,1,10,0.01\n8,4,10,inf\n";
    csf_obs_table *t = NULL;
    csf_error err;
    CHECK(csf_obs_table_parse(text, strlen(text), &t, &err) == CSF_OK);
    if (!t) return;
    CHECK_INT_EQ(t->n_vel, 3);
    CHECK_NEAR(csf_obs_table_threshold_v(t, 4, 0, 2), 0.008, 1e-12);
    CHECK_NEAR(csf_obs_table_threshold_v(t, 4, 0, -2), 0.008, 1e-12); /* either direction */
    CHECK_NEAR(csf_obs_table_threshold(t, 4, 0), 0.005, 1e-12);
    CHECK(isinf(csf_obs_table_threshold_v(t, 4, 10, 8)));
    /* along velocity: linear in log10(|v| + 0.5) on log10 threshold */
    double wm = 0.5 * (csf_velocity_warp(2) + csf_velocity_warp(8)), vm = pow(10.0, wm) - 0.5;
    CHECK_NEAR(log10(csf_obs_table_threshold_v(t, 4, 0, vm)), 0.5 * (log10(0.008) + log10(0.02)), 1e-12);
    /* and as before across frequency (log) and eccentricity within a slice */
    CHECK_NEAR(log10(csf_obs_table_threshold_v(t, 2, 5, 0)),
               0.25 * (log10(0.004) + log10(0.005) + log10(0.01) + log10(0.05)), 1e-12);
    CHECK_NEAR(csf_obs_table_threshold_v(t, 1, 0, 100), 0.004, 1e-12); /* held beyond the axis */
    csf_obs_table_free(t);

    /* The same person as an observer: the table's own values, no parametric gain on top. */
    char path[] = "/tmp/csf_vel_tableXXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0) return;
    close(fd);
    write_file(path, text);
    char spec[128];
    snprintf(spec, sizeof spec, "sim:table=%s", path);
    csf_observer_sim *o = make(spec, 1);
    if (o) {
        CHECK_NEAR(csf_observer_sim_threshold_v(o, 4, 0, 8), 0.02, 1e-12);
        CHECK_NEAR(csf_observer_sim_velocity_log10_gain(o, 4, 0, 8), log10(0.005 / 0.02), 1e-12);
        csf_observer_sim_free(o);
    }
    /* A 2-D table at v != 0 takes the parametric gain. */
    write_file(path, "freq_cpd,ecc_deg,threshold\n1,0,0.004\n4,0,0.005\n");
    snprintf(spec, sizeof spec, "sim:table=%s,vsteep=1.2", path);
    o = make(spec, 1);
    if (o) {
        csf_velocity_params vp = csf_velocity_default();
        vp.steepness = 1.2;
        CHECK_NEAR(csf_observer_sim_threshold_v(o, 4, 0, 6),
                   0.005 / pow(10.0, csf_velocity_log10_gain(&vp, 4, 6)), 1e-12);
        CHECK(csf_observer_sim_threshold_v(o, 4, 0, 0) == csf_observer_sim_threshold(o, 4, 0));
        CHECK_NEAR(csf_observer_sim_threshold(o, 4, 0), 0.005, 1e-12);
        csf_observer_sim_free(o);
    }
    remove(path);
}

static void test_table_3d_refused(void)
{
    char many[4096] = "freq_cpd,ecc_deg,velocity_dps,threshold\n";
    for (int i = 0; i < 65; i++)
        snprintf(many + strlen(many), sizeof many - strlen(many), "1,0,%d,0.01\n", i);
    struct {
        const char *text, *msg;
    } bad[] = {
        {"freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n1,0,2,0.02\n4,0,0,0.01\n",
         "no row for 4 cpd at 0 deg moving at 2 deg/s"},
        {"freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,0,0.01\n1,0,0,0.02\n",
         "line 3: duplicate row for 1 cpd at 0 deg moving at 0"},
        {"freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,-2,0.01\n",
         "line 2: velocity_dps -2 outside [0, 1000]"},
        {"freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,nan,0.01\n", "line 2: not a number"},
        {"freq_cpd,ecc_deg,velocity_dps,threshold\n1,0,2\n", "line 2: expected 4"},
        {"1,0,2,0.01\n", "needs a header"},
        {"freq_cpd,ecc_deg,velocity_dps,velocity_dps\n1,0,2,0.01\n", "line 1: header must name"},
        {"freq_cpd,ecc_deg,speed,threshold\n1,0,2,0.01\n", "line 1: header must name"},
        {many, "line 66: more than 64 distinct"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        csf_obs_table *t = NULL;
        csf_error e = {0};
        CHECK_MSG(csf_obs_table_parse(bad[i].text, strlen(bad[i].text), &t, &e) == CSF_E_FORMAT, "case %zu",
                  i);
        CHECK(t == NULL);
        CHECK_STR_CONTAINS(e.msg, bad[i].msg);
    }
}

/* The image observer of studies judges a moving pair as moving: a Gabor difference of freq_cpd
 * (1-deg sigma) in a 128 px image of 4 deg. */
static double image_r(const csf_observer_sim *o, double freq_cpd, double velocity_dps, int use_v)
{
    enum { N = 128 };
    const double ppd = 32;
    float *a = malloc(sizeof(float) * N * N), *b = malloc(sizeof(float) * N * N);
    if (!a || !b) abort();
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            double dx = (x + 0.5 - N / 2.0) / ppd, dy = (y + 0.5 - N / 2.0) / ppd;
            a[y * N + x] = 0.5f;
            b[y * N + x] =
                (float)(0.5 * (1 + 0.01 * exp(-(dx * dx + dy * dy) / 2) * sin(2 * M_PI * freq_cpd * dx)));
        }
    csf_image_pair_eval ev;
    int rc = use_v ? csf_image_pair_evaluate_v(o, a, b, N, N, N / ppd, 2, 0, velocity_dps, &ev)
                   : csf_image_pair_evaluate(o, a, b, N, N, N / ppd, 2, 0, &ev);
    CHECK(rc == 0);
    free(a);
    free(b);
    return ev.r;
}

static void test_image_observer(void)
{
    csf_observer_sim *o = make("sim", 5);
    if (!o) return;
    CHECK(image_r(o, 4, 0, 1) == image_r(o, 4, 0, 0)); /* static: exactly as before */
    double r4 = image_r(o, 4, 0, 0), r4m = image_r(o, 4, 6, 1);
    double r1 = image_r(o, 1, 0, 0), r1m = image_r(o, 1, 3, 1);
    printf("image pairs: 4 cpd r %.3g static, %.3g at 6 deg/s; 1 cpd r %.3g static, %.3g at 3 deg/s\n", r4,
           r4m, r1, r1m);
    CHECK(r4 > 0 && r4m < 0.5 * r4); /* a fine difference moving fast is harder to see */
    CHECK(r1m > 1.2 * r1);           /* a coarse one drifting a few deg/s easier */
    float one = 0.5f;
    csf_image_pair_eval ev;
    CHECK(csf_image_pair_evaluate_v(o, &one, &one, 1, 1, 1, 0, 0, NAN, &ev) == -1);
    csf_observer_sim_free(o);
}

int main(void)
{
    test_image_observer();
    test_static_unchanged();
    test_parametric_gain();
    test_trials_follow_velocity();
    test_table_3d();
    test_table_3d_refused();
    return CHECK_RESULT();
}
