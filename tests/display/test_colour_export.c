/* Exports read back through OpenColorIO (clf, ctf, cube, ocio) and through a real Little CMS
 * transform (icc, v2.4 and v4.3, both directions) agree with the profile they came from: luminance
 * relative to white, black included, so cd/m2 computed from the ICC alone matches the profile down
 * to black.
 * A write that fails part way (RLIMIT_FSIZE, which fails like a full disk) leaves the old files
 * and no temporary, and names the OS error. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <lcms2.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "results/colour_export.h"
#include "results/display_profile.h"
#include "tests/check.h"

enum { NE = 1001 };

static csf_display_profile *make_profile(void)
{
    /* a non-power-law curve (toe + bend), black 0.4 cd/m2, channels with primaries */
    static csf_profile_reading r[200];
    size_t n = 0;
    const double w[3] = {0.22, 0.70, 0.08};
    const double xyz_per_y[3][3] = {{1.939, 1, 0.088}, {0.5, 1, 0.167}, {2.5, 1, 13.17}};
    for (int i = 0; i <= 24; i++) {
        double v = i / 24.0;
        double rel = pow(v, 2.3) * (1 + 0.08 * v * (1 - v));
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
    return p;
}

/* Largest |got / want - 1| above `from` of white, want = L / white. */
static double worst_rel_from(const csf_display_profile *p, const double *v, const double *got, double from)
{
    double white = csf_profile_lum_max(p), worst = 0;
    for (int i = 0; i < NE; i++) {
        double L = csf_profile_grey_lum(p, v[i]);
        if (L < from * white) continue;
        double e = fabs(got[i] / (L / white) - 1);
        if (e > worst) worst = e;
    }
    return worst;
}

static double worst_rel(const csf_display_profile *p, const double *v, const double *got)
{
    return worst_rel_from(p, v, got, 0.1);
}

static void check_icc(const csf_display_profile *p, const char *path, int version, const double *v)
{
    double *lum = malloc(NE * sizeof(double)), white = 0;
    csf_error err;
    CHECK_MSG(csf_colour_export_icc_cdm2(path, v, lum, NE, &white, &err) == CSF_OK, "%s", err.msg);
    CHECK_NEAR(white, csf_profile_lum_max(p), 1e-6 * white); /* s15Fixed16: 1.5e-5 cd/m2 steps */
    /* cd/m2 from the ICC alone, black included: the largest relative error over every drive value
     * (16-bit TRC: one step is 7.6e-6 of white, so 2e-3 of a 0.4 cd/m2 black on a 160 cd/m2 white) */
    double worst_all = 0, at01 = 0;
    for (int i = 0; i < NE; i++) {
        double want = csf_profile_grey_lum(p, v[i]);
        double e = fabs(lum[i] / want - 1);
        if (e > worst_all) worst_all = e;
        if (i == 100) at01 = e;
    }
    fprintf(stderr, "icc v%d: cd/m2 from the ICC alone: largest relative error %.3g (drive 0.1: %.3g, black %.5g vs %.5g)\n",
            version, worst_all, at01, lum[0], csf_profile_lum_black(p));
    CHECK_MSG(worst_all <= (version == 2 ? 5e-3 : 1e-4), "icc v%d: cd/m2 off by %g", version, worst_all);
    CHECK_MSG(at01 <= (version == 2 ? 1e-3 : 1e-5), "icc v%d: cd/m2 at drive 0.1 off by %g", version, at01);
    cmsHPROFILE h = cmsOpenProfileFromFile(path, "r");
    CHECK(h != NULL);
    if (h) {
        /* the direction a renderer uses: PCS grey Y -> drive, against the profile's exact inverse */
        cmsHPROFILE xyz = cmsCreateXYZProfile();
        cmsHTRANSFORM t = cmsCreateTransform(xyz, TYPE_XYZ_DBL, h, TYPE_RGB_DBL, INTENT_RELATIVE_COLORIMETRIC, 0);
        cmsCloseProfile(xyz);
        CHECK(t != NULL);
        double worst_drive = 0, white_cd = csf_profile_lum_max(p);
        for (int i = 0; t && i < NE; i++) {
            double L = csf_profile_grey_lum(p, v[i]);
            if (L < 0.1 * white_cd) continue;
            double y = L / white_cd, want = csf_profile_grey_drive(p, L), rgb[3];
            cmsCIEXYZ in = {0.9642 * y, y, 0.8249 * y};
            cmsDoTransform(t, &in, rgb, 1);
            double e = fabs(rgb[1] - want);
            if (e > worst_drive) worst_drive = e;
        }
        if (t) cmsDeleteTransform(t);
        fprintf(stderr, "icc v%d: PCS -> drive through cmsDoTransform: largest drive error above 10 %% of white %.3g\n",
                version, worst_drive);
        CHECK_MSG(worst_drive <= (version == 2 ? 5e-5 : 1e-6), "icc v%d: inverse off by %g in drive", version, worst_drive);
        CHECK_INT_EQ(cmsGetEncodedICCversion(h), version == 2 ? 0x02400000 : 0x04300000);
        CHECK(cmsGetDeviceClass(h) == cmsSigDisplayClass);
        const cmsCIEXYZ *bk = cmsReadTag(h, cmsSigMediaBlackPointTag);
        if (version == 2) {
            /* v2 carries the media black point: Y = black / white, to one s15Fixed16 step */
            CHECK_MSG(bk && fabs(bk->Y - csf_profile_lum_black(p) / csf_profile_lum_max(p)) <= 1.0 / 65536,
                      "bkpt Y %g", bk ? bk->Y : -1);
        } else {
            CHECK(bk == NULL); /* v4 has no black point tag: the TRC holds the black */
        }
        cmsCloseProfile(h);
    }
    free(lum);
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    if (d) closedir(d);
    return n;
}

static int holds(const char *path, const char *want)
{
    char buf[64] = {0};
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == strlen(want) && memcmp(buf, want, n) == 0;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Every format, past a 1000-byte file size limit: the old files stay, nothing else appears. */
static void check_failed_writes(const csf_display_profile *p, const char *dir)
{
    signal(SIGXFSZ, SIG_IGN);
    char path[700], lut[700];
    snprintf(lut, sizeof lut, "%s/full.clf", dir);
    for (int f = 0; f < CSF_EXPORT_COUNT; f++) {
        snprintf(path, sizeof path, "%s/full%s", dir, csf_export_extension((csf_export_format)f));
        put(path, "old\n");
        if (f == CSF_EXPORT_OCIO) put(lut, "old lut\n");
        int before = count_entries(dir);
        struct rlimit old_lim, lim;
        getrlimit(RLIMIT_FSIZE, &old_lim);
        lim = old_lim;
        lim.rlim_cur = 1000;
        CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
        csf_error err;
        csf_error_clear(&err);
        csf_status st = csf_colour_export(p, (csf_export_format)f, NULL, path, &err);
        setrlimit(RLIMIT_FSIZE, &old_lim);
        CHECK_MSG(st == CSF_E_IO, "%s past the size limit: status %d", csf_export_format_name((csf_export_format)f), st);
        CHECK_MSG(strstr(err.msg, strerror(EFBIG)) && strstr(err.msg, dir), "message: %s", err.msg);
        CHECK_MSG(holds(path, "old\n"), "%s: old file not intact", path);
        if (f == CSF_EXPORT_OCIO) CHECK_MSG(holds(lut, "old lut\n"), "%s: old LUT not intact", lut);
        CHECK_INT_EQ(count_entries(dir), before);
        unlink(path);
    }
    unlink(lut);
}

int main(void)
{
    csf_display_profile *p = make_profile();
    if (!p) return CHECK_RESULT();
    char dir[] = "/tmp/csfcal-test-export-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    double *v = malloc(NE * sizeof(double)), *got = malloc(NE * sizeof(double));
    for (int i = 0; i < NE; i++) v[i] = i / (double)(NE - 1);
    csf_error err;
    for (int f = 0; f < CSF_EXPORT_COUNT; f++) {
        for (int version = 2; version <= (f == CSF_EXPORT_ICC ? 4 : 2); version += 2) {
            char path[700];
            snprintf(path, sizeof path, "%s/disp%s", dir, csf_export_extension((csf_export_format)f));
            csf_export_options opt = {version};
            csf_error_clear(&err);
            csf_status st = csf_colour_export(p, (csf_export_format)f, &opt, path, &err);
            CHECK_MSG(st == CSF_OK, "export %s: %s", csf_export_format_name((csf_export_format)f), err.msg);
            if (st) continue;
            st = csf_colour_export_eval(path, (csf_export_format)f, v, got, NE, &err);
            CHECK_MSG(st == CSF_OK, "read back %s: %s", path, err.msg);
            if (st) continue;
            double worst = worst_rel(p, v, got);
            fprintf(stderr, "%s%s: max relative difference above 10 %% of white %.3g\n",
                    csf_export_format_name((csf_export_format)f), f == CSF_EXPORT_ICC ? (version == 2 ? " v2" : " v4") : "", worst);
            /* ICC v2 through cmsDoTransform: 16-bit input and output rounding of the TRC (see
             * docs/display-profile.md); v4 adds float D2B/B2D tags, which Little CMS prefers */
            double tol = f == CSF_EXPORT_ICC && version == 2 ? 1.5e-4 : f == CSF_EXPORT_ICC ? 1e-5 : 1e-4;
            CHECK_MSG(worst <= tol, "%s differs from the profile by %g", path, worst);
            /* drive 0 is black: Y = black / white, not 0 */
            double yb = csf_profile_lum_black(p) / csf_profile_lum_max(p);
            CHECK_MSG(fabs(got[0] / yb - 1) < 5e-3, "%s: Y(0) %g, black/white %g", path, got[0], yb);
            if (f == CSF_EXPORT_ICC) {
                /* the 16-bit rounding is relative to white: above 20 % it stays within 1e-4 */
                double w20 = worst_rel_from(p, v, got, 0.2);
                fprintf(stderr, "icc v%d: above 20 %% of white %.3g\n", version, w20);
                CHECK_MSG(w20 <= 1e-4, "icc v%d above 20 %% of white: %g", version, w20);
                check_icc(p, path, version, v);
                /* OpenColorIO reads the same ICC file (device RGB -> PCS XYZ, Y of white = 1) */
                st = csf_colour_export_eval_icc_ocio(path, v, got, NE, &err);
                CHECK_MSG(st == CSF_OK, "OCIO ICC read: %s", err.msg);
                double w2 = st == CSF_OK ? worst_rel(p, v, got) : 1;
                fprintf(stderr, "icc v%d via OpenColorIO: max relative difference %.3g\n", version, w2);
                CHECK_MSG(w2 <= 1e-3, "OCIO's ICC reading differs by %g", w2);
            }
            unlink(path);
            if (f == CSF_EXPORT_OCIO) {
                snprintf(path, sizeof path, "%s/disp.clf", dir);
                CHECK(access(path, R_OK) == 0);
                unlink(path);
            }
        }
    }
    /* the default ICC version is 2.4 */
    char path[700];
    snprintf(path, sizeof path, "%s/default.icc", dir);
    CHECK(csf_colour_export(p, CSF_EXPORT_ICC, NULL, path, &err) == CSF_OK);
    cmsHPROFILE h = cmsOpenProfileFromFile(path, "r");
    CHECK(h && cmsGetEncodedICCversion(h) == 0x02400000);
    if (h) cmsCloseProfile(h);
    unlink(path);
    csf_export_options v3 = {3};
    CHECK(csf_colour_export(p, CSF_EXPORT_ICC, &v3, path, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "give 2");
    CHECK(access(path, F_OK) != 0);

    check_failed_writes(p, dir);
    CHECK_INT_EQ(count_entries(dir), 0);

    /* errors name the file */
    csf_error_clear(&err);
    CHECK(csf_colour_export(p, CSF_EXPORT_CLF, NULL, "/nonexistent/dir/x.clf", &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/dir");
    CHECK(csf_colour_export_eval("/nonexistent/y.clf", CSF_EXPORT_CLF, v, got, 1, &err) != CSF_OK);
    CHECK_INT_EQ(csf_export_format_from_name("icc"), CSF_EXPORT_ICC);
    CHECK_INT_EQ(csf_export_format_from_name("exr"), -1);
    rmdir(dir);
    free(v);
    free(got);
    csf_profile_free(p);
    return CHECK_RESULT();
}
