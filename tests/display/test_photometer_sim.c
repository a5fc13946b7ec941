/* Simulated photometer: noise statistics, reproducibility by reading number, warm-up drift,
 * range limits, faults, and measuring framebuffer pixels through the display model. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model/display_model.h"
#include "devices/photometer.h"
#include "tests/check.h"

static csf_photometer *open_sim(const char *spec, uint64_t seed)
{
    csf_photometer *p = NULL;
    csf_error err;
    csf_error_clear(&err);
    csf_status st = csf_photometer_open(spec, seed, &p, &err);
    CHECK_MSG(st == CSF_OK, "%s: %s", spec, err.msg);
    return p;
}

static double read1(csf_photometer *p, double r, double g, double b, csf_status *st_out, csf_error *err)
{
    csf_photometer_reading rd;
    csf_photometer_show_patch(p, r, g, b);
    csf_status st = csf_photometer_measure(p, &rd, err);
    if (st_out) *st_out = st;
    return st ? NAN : rd.lum_cdm2;
}

typedef struct {
    unsigned char px[3 * 4];
} px_src;

static csf_status pixels_cb(void *user, const void **rgb, size_t *n_px, int *bits)
{
    px_src *s = user;
    *rgb = s->px;
    *n_px = 4;
    *bits = 8;
    return CSF_OK;
}

int main(void)
{
    csf_error err;
    csf_display_model *truth = NULL;
    csf_display_model_create("lcd", &truth, &err);
    /* noise: no drift, 0.5 % relative noise: sample mean and sd match */
    csf_photometer *p = open_sim("sim:display=lcd,noise=0.005,abs_noise=0,drift=0", 3);
    if (!p || !truth) return CHECK_RESULT();
    char id[256];
    CHECK_INT_EQ(csf_photometer_identify(p, id, sizeof id, &err), CSF_OK);
    CHECK_STR_CONTAINS(id, "display=lcd");
    CHECK(csf_photometer_caps(p) & CSF_PHOT_CAP_XYZ);
    double want = csf_display_model_lum(truth, 0.5, 0.5, 0.5);
    double s = 0, ss = 0;
    const int N = 2000;
    double first[5];
    for (int i = 0; i < N; i++) {
        double l = read1(p, 0.5, 0.5, 0.5, NULL, &err) / want - 1;
        if (i < 5) first[i] = l;
        s += l;
        ss += l * l;
    }
    double mean = s / N, sd = sqrt(ss / N - mean * mean);
    CHECK_NEAR(mean, 0, 4 * 0.005 / sqrt(N));
    CHECK_NEAR(sd, 0.005, 0.0005);
    csf_photometer_close(p);
    /* same seed: same readings; resume_at continues the sequence exactly */
    p = open_sim("sim:display=lcd,noise=0.005,abs_noise=0,drift=0", 3);
    for (int i = 0; i < 5; i++) CHECK_NEAR(read1(p, 0.5, 0.5, 0.5, NULL, &err) / want - 1, first[i], 1e-15);
    csf_photometer_close(p);
    p = open_sim("sim:display=lcd,noise=0.005,abs_noise=0,drift=0", 3);
    csf_photometer_resume_at(p, 3, 10.0);
    CHECK_NEAR(read1(p, 0.5, 0.5, 0.5, NULL, &err) / want - 1, first[3], 1e-15);
    csf_photometer_close(p);
    /* a different seed differs */
    p = open_sim("sim:display=lcd,noise=0.005,abs_noise=0,drift=0", 4);
    CHECK(fabs(read1(p, 0.5, 0.5, 0.5, NULL, &err) / want - 1 - first[0]) > 1e-9);
    csf_photometer_close(p);

    /* warm-up drift: early readings low, settled after several time constants; wait advances time */
    p = open_sim("sim:display=crt,noise=0,abs_noise=0,drift=0.05,warmup_s=10,integration_s=1", 1);
    double w_early = read1(p, 1, 1, 1, NULL, &err);
    csf_photometer_wait(p, 100);
    double w_late = read1(p, 1, 1, 1, NULL, &err);
    CHECK_NEAR(w_early / 95.05, 1 - 0.05 * exp(-0.1), 1e-9);
    CHECK_NEAR(w_late / 95.05, 1 - 0.05 * exp(-10.2), 1e-9);
    csf_photometer_close(p);

    /* range: too dark and saturated, with the limit in the message */
    csf_status st;
    p = open_sim("sim:display=oled,floor_cdm2=0.05,sat_cdm2=200", 1);
    read1(p, 0, 0, 0, &st, &err);
    CHECK_INT_EQ(st, CSF_E_TOO_DARK);
    CHECK_STR_CONTAINS(err.msg, "0.05 cd/m2 floor");
    read1(p, 1, 1, 1, &st, &err);
    CHECK_INT_EQ(st, CSF_E_SATURATED);
    CHECK_STR_CONTAINS(err.msg, "200 cd/m2 range");
    csf_photometer_close(p);

    /* faults */
    struct { const char *spec; int at; csf_status code; const char *msg; int persists; } f[] = {
        {"sim:fault=unplug@3", 3, CSF_E_GONE, "disconnected", 1},
        {"sim:fault=timeout@2", 2, CSF_E_TIMEOUT, "did not answer", 0},
        {"sim:fault=garbage@1", 1, CSF_E_PROTOCOL, "unreadable", 0},
        {"sim:fault=dark@4", 4, CSF_E_TOO_DARK, "too dark", 1},
        {"sim:fault=saturate@2", 2, CSF_E_SATURATED, "saturated", 1},
    };
    for (size_t k = 0; k < sizeof f / sizeof f[0]; k++) {
        p = open_sim(f[k].spec, 1);
        if (!p) continue;
        for (int i = 0; i < f[k].at; i++) {
            read1(p, 1, 1, 1, &st, &err);
            CHECK_INT_EQ(st, CSF_OK);
        }
        csf_error_clear(&err);
        read1(p, 1, 1, 1, &st, &err);
        CHECK_MSG(st == f[k].code, "%s: status %d", f[k].spec, (int)st);
        CHECK_STR_CONTAINS(err.msg, f[k].msg);
        read1(p, 1, 1, 1, &st, &err);
        CHECK_MSG((st != CSF_OK) == f[k].persists, "%s: after the fault status %d", f[k].spec, (int)st);
        csf_photometer_close(p);
    }

    /* pixels under the sensor: luminance (not drive) is averaged */
    p = open_sim("sim:display=crt,noise=0,abs_noise=0,drift=0", 1);
    px_src src = {{255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0}};
    csf_screen_source ss_src = {NULL, pixels_cb, &src};
    csf_photometer_set_source(p, &ss_src);
    csf_photometer_reading rd;
    CHECK_INT_EQ(csf_photometer_measure(p, &rd, &err), CSF_OK);
    CHECK_NEAR(rd.lum_cdm2, 0.5 * (95.05 + 0.05), 1e-9);
    /* show_patch goes back to the built-in uniform patch */
    csf_photometer_show_patch(p, 0.5, 0.5, 0.5);
    CHECK_INT_EQ(csf_photometer_measure(p, &rd, &err), CSF_OK);
    csf_display_model *crt = NULL;
    csf_display_model_create("crt", &crt, &err);
    CHECK_NEAR(rd.lum_cdm2, csf_display_model_lum(crt, 0.5, 0.5, 0.5), 1e-9);
    CHECK(rd.has_xyz);
    csf_display_model_free(crt);
    csf_photometer_close(p);

    /* bad specs */
    const char *bad[] = {"colorimeter9000", "sim:noise=2", "sim:bogus=1", "sim:fault=explode@3", "sim:fault=unplug",
                         "sim:display=plasma", "sim:noise"};
    const char *msg[] = {"unknown photometer", "out of range", "unknown option", "fault=explode@3", "KIND@N",
                         "unknown display kind", "not key=value"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        csf_photometer *q = NULL;
        csf_error_clear(&err);
        CHECK(csf_photometer_open(bad[k], 1, &q, &err) != CSF_OK);
        CHECK(q == NULL);
        CHECK_STR_CONTAINS(err.msg, msg[k]);
    }
    csf_display_model_free(truth);
    /* fault=KIND@N+COUNT: readings N .. N+COUNT-1 only (a sensor that slips off and back) */
    {
        csf_photometer *q = open_sim("sim:display=lcd,fault=dark@2+2", 3);
        csf_photometer_reading rr;
        csf_error e2;
        for (int i = 0; q && i < 6; i++) {
            csf_photometer_show_patch(q, 1, 1, 1);
            csf_status fst = csf_photometer_measure(q, &rr, &e2);
            CHECK_MSG(fst == ((i == 2 || i == 3) ? CSF_E_TOO_DARK : CSF_OK), "reading %d: status %d", i, (int)fst);
        }
        csf_photometer_close(q);
        const char *badc[] = {"sim:fault=dark@2+0", "sim:fault=dark@2+x", "sim:fault=dark@+2", "sim:fault=dark@2+1.5"};
        for (int k = 0; k < 4; k++) {
            q = NULL;
            csf_error_clear(&e2);
            CHECK_INT_EQ(csf_photometer_open(badc[k], 1, &q, &e2), CSF_E_INVALID_ARG);
            CHECK_STR_CONTAINS(e2.msg, "KIND@N+COUNT");
            CHECK(q == NULL);
        }
    }
    return CHECK_RESULT();
}
