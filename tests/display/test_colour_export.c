/* Exports read back through OpenColorIO (clf, ctf, cube, ocio) and Little CMS (icc) agree with
 * the profile they came from to 1e-4 relative above 10 % of peak; OCIO's own ICC reader agrees too. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "results/colour_export.h"
#include "results/display_profile.h"
#include "tests/check.h"

int main(void)
{
    /* a profile with a non-power-law curve (toe + kink-like bend) and channels with primaries */
    csf_profile_reading r[200];
    size_t n = 0;
    const double w[3] = {0.22, 0.70, 0.08};
    const double xyz_per_y[3][3] = {{1.939, 1, 0.088}, {0.5, 1, 0.167}, {2.5, 1, 13.17}};
    for (int i = 0; i <= 24; i++) {
        double v = i / 24.0;
        double rel = pow(v, 2.3) * (1 + 0.08 * v * (1 - v)) / (1 + 0.0);
        double L = 0.4 + 160 * rel;
        double X = 0, Z = 0;
        for (int c = 0; c < 3; c++) {
            X += 160 * rel * w[c] * xyz_per_y[c][0];
            Z += 160 * rel * w[c] * xyz_per_y[c][2];
        }
        r[n++] = (csf_profile_reading){CSF_CH_GREY, v, L, {X + 0.38, L, Z + 0.43}, 1};
        for (int c = 0; i > 0 && c < 3; c++) {
            double Lc = 160 * rel * w[c];
            r[n++] = (csf_profile_reading){c, v, 0.4 + Lc, {0.38 + Lc * xyz_per_y[c][0], 0.4 + Lc, 0.43 + Lc * xyz_per_y[c][2]}, 1};
        }
    }
    csf_profile_meta meta = {"export test", "unit test", "2026-11-21T00:00:00Z", NULL, 0};
    csf_display_profile *p = NULL;
    csf_error err;
    csf_error_clear(&err);
    CHECK_INT_EQ(csf_profile_build(r, n, &meta, &p, &err), CSF_OK);
    if (!p) return CHECK_RESULT();
    char dir[] = "/tmp/csfcal-test-export-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    enum { NE = 1001 };
    double *v = malloc(NE * sizeof(double)), *got = malloc(NE * sizeof(double));
    for (int i = 0; i < NE; i++) v[i] = i / (double)(NE - 1);
    double black = csf_profile_lum_black(p), white = csf_profile_lum_max(p);
    for (int f = 0; f < CSF_EXPORT_COUNT; f++) {
        char path[700];
        snprintf(path, sizeof path, "%s/disp%s", dir, csf_export_extension((csf_export_format)f));
        csf_error_clear(&err);
        csf_status st = csf_colour_export(p, (csf_export_format)f, path, &err);
        CHECK_MSG(st == CSF_OK, "export %s: %s", csf_export_format_name((csf_export_format)f), err.msg);
        if (st) continue;
        st = csf_colour_export_eval(path, (csf_export_format)f, v, got, NE, &err);
        CHECK_MSG(st == CSF_OK, "read back %s: %s", path, err.msg);
        if (st) continue;
        double worst = 0;
        for (int i = 0; i < NE; i++) {
            double L = csf_profile_grey_lum(p, v[i]);
            if (L < 0.1 * white) continue;
            double want = (L - black) / (white - black);
            double e = fabs(got[i] / want - 1);
            if (e > worst) worst = e;
        }
        fprintf(stderr, "%s: max relative difference %.3g\n", csf_export_format_name((csf_export_format)f), worst);
        CHECK_MSG(worst <= 1e-4, "%s differs from the profile by %g", path, worst);
        if (f == CSF_EXPORT_ICC) {
            /* OpenColorIO reads the same ICC file (device RGB -> PCS XYZ, Y of white = 1) */
            st = csf_colour_export_eval_icc_ocio(path, v, got, NE, &err);
            CHECK_MSG(st == CSF_OK, "OCIO ICC read: %s", err.msg);
            double w2 = 0;
            for (int i = 0; st == CSF_OK && i < NE; i++) {
                double L = csf_profile_grey_lum(p, v[i]);
                if (L < 0.1 * white) continue;
                double e = fabs(got[i] / ((L - black) / (white - black)) - 1);
                if (e > w2) w2 = e;
            }
            fprintf(stderr, "icc via OpenColorIO: max relative difference %.3g\n", w2);
            CHECK_MSG(w2 <= 1e-3, "OCIO's ICC reading differs by %g", w2);
        }
        unlink(path);
        if (f == CSF_EXPORT_OCIO) {
            snprintf(path, sizeof path, "%s/disp.clf", dir);
            CHECK(access(path, R_OK) == 0);
            unlink(path);
        }
    }
    /* errors name the file */
    csf_error_clear(&err);
    CHECK(csf_colour_export(p, CSF_EXPORT_CLF, "/nonexistent/dir/x.clf", &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/dir/x.clf");
    CHECK(csf_colour_export_eval("/nonexistent/y.clf", CSF_EXPORT_CLF, v, got, 1, &err) != CSF_OK);
    CHECK_INT_EQ(csf_export_format_from_name("icc"), CSF_EXPORT_ICC);
    CHECK_INT_EQ(csf_export_format_from_name("exr"), -1);
    rmdir(dir);
    free(v);
    free(got);
    csf_profile_free(p);
    return CHECK_RESULT();
}
