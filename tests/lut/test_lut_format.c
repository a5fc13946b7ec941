/* The .csflut file format: writer/reader round trips (memory and file, 2-D and 4-D), metadata,
 * and every kind of bad file refused with its own error code, never an out-of-bounds read. */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "results/csflut/csflut_internal.h"
#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

/* Offsets in a 2-D (8 x 6) file, from the layout in docs/csflut.md. */
enum {
    OFF_VERSION = 8, OFF_FILESIZE = 16, OFF_NAXES = 24, OFF_FLAGS = 28, OFF_DIST = 32,
    OFF_AX0 = 64, OFF_AX0_PTS = 64 + 48, OFF_AX1 = OFF_AX0_PTS + 8 * 8,
    OFF_AX1_PTS = OFF_AX1 + 48, OFF_THR = OFF_AX1_PTS + 6 * 8, OFF_SE = OFF_THR + 48 * 8,
    OFF_META = OFF_SE + 48 * 8
};

static void put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void put64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void putf64(unsigned char *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    put64(p, u);
}
static void fix_crc(unsigned char *p, size_t len) { put32(p + len - 4, csflut_crc32(p, len - 4)); }

/* Opens a copy of buf[0..len) and expects the given status (and no table on failure). */
static csflut_status open_expect(const unsigned char *buf, size_t len, csflut_status want,
                                 const char *what)
{
    unsigned char *copy = malloc(len ? len : 1);
    memcpy(copy, buf, len);
    csflut_table *t = (csflut_table *)1;
    csflut_diag d;
    csflut_status st = csflut_open_memory_diag(copy, len, &t, &d);
    CHECK_MSG(st == want, "%s: got %d (%s) want %d", what, (int)st, d.message, (int)want);
    if (st) {
        CHECK(t == NULL);
        CHECK(d.code == st);
        CHECK(strlen(d.message) > 10);
    }
    csflut_close(st ? NULL : t);
    free(copy);
    return st;
}

static void test_round_trip_memory(void)
{
    fx_table fx;
    fx_make(&fx, 11, 0.08, 1.0);
    unsigned char *buf;
    size_t len;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &buf, &len), CSFLUT_OK);
    CHECK_INT_EQ(len, OFF_META + 5 * 4 + strlen("sim:seed=1") + strlen("lcd-test-0001") +
                          strlen("fade") + strlen("2026-11-22T06:00:00Z") + strlen("csfcal test") + 4);
    CHECK(memcmp(buf, "\x89" "CSFLUT\n", 8) == 0);
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_memory(buf, len, &t), CSFLUT_OK);
    CHECK(t != NULL);
    CHECK_INT_EQ(csflut_version_major(t), 1);
    CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_FREQ), 8);
    CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_ECC), 6);
    CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_VEL), 0);
    CHECK(csflut_axis_points(t, CSFLUT_AXIS_LUM) == NULL);
    CHECK_INT_EQ(csflut_axis_scale(t, CSFLUT_AXIS_FREQ), CSFLUT_SCALE_LOG);
    CHECK_INT_EQ(csflut_axis_scale(t, CSFLUT_AXIS_ECC), CSFLUT_SCALE_LINEAR);
    CHECK_INT_EQ(csflut_node_count(t), 48);
    const double *raw = csflut_raw_thresholds(t), *se = csflut_stderr_log10(t);
    int same = 1, n_inf = 0;
    for (int k = 0; k < 48; k++) {
        if (memcmp(&raw[k], &fx.thr[k], 8) != 0) same = 0;
        if (memcmp(&se[k], &fx.se[k], 8) != 0 && !(se[k] != se[k] && fx.se[k] != fx.se[k])) same = 0;
        n_inf += isinf(raw[k]);
    }
    CHECK(same);
    CHECK(n_inf > 5 && n_inf < 40); /* the fixture really has never-visible nodes */
    for (int k = 0; k < 8; k++) CHECK(csflut_axis_points(t, CSFLUT_AXIS_FREQ)[k] == fx_freq[k]);
    CHECK(strcmp(csflut_observer(t), "sim:seed=1") == 0);
    CHECK(strcmp(csflut_display_profile_id(t), "lcd-test-0001") == 0);
    CHECK(strcmp(csflut_method(t), "fade") == 0);
    CHECK(strcmp(csflut_date_utc(t), "2026-11-22T06:00:00Z") == 0);
    CHECK(strcmp(csflut_tool_version(t), "csfcal test") == 0);
    CHECK(csflut_viewing_distance_mm(t) == 600);
    CHECK(csflut_mean_lum_cdm2(t) == 80);
    CHECK_INT_EQ(csflut_trials(t), 240);
    /* writing the opened table again gives the same bytes */
    csflut_build b2;
    csflut_table_to_build(t, &b2);
    unsigned char *buf2;
    size_t len2;
    CHECK_INT_EQ(csflut_write_memory(&b2, &buf2, &len2), CSFLUT_OK);
    CHECK(len2 == len && memcmp(buf, buf2, len) == 0);
    free(buf2);
    csflut_close(t);
    free(buf);
}

static void test_round_trip_file_and_absent_metadata(void)
{
    fx_table fx;
    fx_make(&fx, 12, 0.0, 1e30);
    fx.b.stderr_log10 = NULL;
    fx.b.observer = fx.b.display_profile_id = fx.b.method = fx.b.date_utc = fx.b.tool_version = NULL;
    fx.b.viewing_distance_mm = 0;
    fx.b.mean_lum_cdm2 = NAN;
    fx.b.trials = 0;
    char path[] = "/tmp/csflut-test-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    CHECK_INT_EQ(csflut_write_file(&fx.b, path), CSFLUT_OK);
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_file(path, &t), CSFLUT_OK);
    CHECK(csflut_stderr_log10(t) == NULL);
    CHECK(strcmp(csflut_observer(t), "") == 0);
    CHECK(isnan(csflut_viewing_distance_mm(t)));
    CHECK(isnan(csflut_mean_lum_cdm2(t)));
    CHECK(csflut_raw_thresholds(t)[17] == fx.thr[17]);
    csflut_close(t);
    unlink(path);
    CHECK_INT_EQ(csflut_open_file("/nonexistent/dir/x.csflut", &t), CSFLUT_E_IO);
    CHECK(t == NULL);
    /* a directory is not a table either */
    CHECK(csflut_open_file("/tmp", &t) != CSFLUT_OK);
    CHECK_INT_EQ(csflut_write_file(&fx.b, "/nonexistent/dir/x.csflut"), CSFLUT_E_IO);
}

static void test_4d_round_trip(void)
{
    const double vel[3] = {0, 2, 8}, lum[2] = {10, 100};
    double thr[8 * 6 * 3 * 2];
    csf_model_params p = csf_model_default();
    for (int l = 0; l < 2; l++)
        for (int v = 0; v < 3; v++)
            for (int e = 0; e < 6; e++)
                for (int f = 0; f < 8; f++)
                    thr[((l * 3 + v) * 6 + e) * 8 + f] = csf_model_threshold(&p, fx_freq[f], fx_ecc[e]) *
                                                         (1 + 0.3 * v) * (l ? 1.0 : 1.6);
    csflut_build b = {.n_freq = 8, .n_ecc = 6, .n_vel = 3, .n_lum = 2, .freq_cpd = fx_freq,
                      .ecc_deg = fx_ecc, .vel_dps = vel, .lum_cdm2 = lum, .threshold = thr,
                      .mean_lum_cdm2 = 50};
    csflut_table *t = fx_open(&b);
    CHECK(t != NULL);
    if (!t) return;
    CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_VEL), 3);
    CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_LUM), 2);
    /* velocity grid includes 0 deg/s, so it is stored on a linear scale */
    CHECK_INT_EQ(csflut_axis_scale(t, CSFLUT_AXIS_VEL), CSFLUT_SCALE_LINEAR);
    CHECK_INT_EQ(csflut_axis_scale(t, CSFLUT_AXIS_LUM), CSFLUT_SCALE_LOG);
    csflut_set_conservative(t, 0);
    /* nodes: the stored value (through log2 and exp2: a few ulp) */
    CHECK(rel_diff(csflut_threshold4(t, 4, 10, 8, 10), thr[((0 * 3 + 2) * 6 + 2) * 8 + 3]) < 2e-15);
    CHECK(rel_diff(csflut_threshold4(t, 4, 10, 2, 100), thr[((1 * 3 + 1) * 6 + 2) * 8 + 3]) < 2e-15);
    /* luminance is interpolated in log, thresholds geometrically: at the geometric mean of 10
     * and 100 the factor is the geometric mean of 1.6 and 1.0 */
    double base = thr[((1 * 3 + 0) * 6 + 2) * 8 + 3];
    CHECK_NEAR(csflut_threshold4(t, 4, 10, 0, sqrt(1000)) / base, sqrt(1.6), 1e-12);
    /* velocity in the warp log(v + 0.5): between 2 and 8 deg/s (grid points 1 and 2, factors
     * 1.3 and 1.6) the weight is log(5.5 / 2.5) / log(8.5 / 2.5) at 5 deg/s */
    CHECK(csflut_velocity_warp_v0(t) == 0.5);
    CHECK_INT_EQ(csflut_version_minor(t), 1);
    double wv = log(5.5 / 2.5) / log(8.5 / 2.5);
    CHECK_NEAR(csflut_threshold4(t, 4, 10, 5, 100) / base, pow(1.3, 1 - wv) * pow(1.6, wv), 1e-12);
    /* the 2-D query uses the default velocity (lowest) and luminance (metadata mean, 50) */
    CHECK(csflut_default_velocity(t) == 0);
    CHECK(csflut_default_luminance(t) == 50);
    CHECK(rel_diff(csflut_threshold(t, 3, 7), csflut_threshold4(t, 3, 7, 0, 50)) < 1e-14);
    /* max_frequency4 inverts threshold4 */
    double c = 0.3, mf = csflut_max_frequency4(t, 12, 3, 30, c);
    CHECK(mf > 0.5 && mf < 32);
    CHECK(rel_diff(csflut_threshold4(t, mf, 12, 3, 30), c) < 1e-12);
    csflut_close(t);
}

/* A 2-D table is written byte for byte as before format 1.1: the bundled example (written by the
 * 1.0 writer) read and written again gives the same bytes. */
static void test_2d_bytes_unchanged(const char *example)
{
    FILE *f = fopen(example, "rb");
    CHECK(f != NULL);
    if (!f) return;
    static unsigned char old[1 << 16];
    size_t n = fread(old, 1, sizeof old, f);
    fclose(f);
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_memory(old, n, &t), CSFLUT_OK);
    if (!t) return;
    CHECK_INT_EQ(csflut_version_minor(t), 0);
    CHECK_INT_EQ(csflut_meta_count(t), 0);
    CHECK(isnan(csflut_velocity_warp_v0(t)));
    csflut_build b;
    csflut_table_to_build(t, &b);
    unsigned char *buf;
    size_t len;
    CHECK_INT_EQ(csflut_write_memory(&b, &buf, &len), CSFLUT_OK);
    CHECK_INT_EQ((long)len, (long)n);
    CHECK(len == n && memcmp(buf, old, n) == 0);
    free(buf);
    csflut_close(t);
}

/* A 3-D table: format 1.1, the warp and the metadata pairs in the header extension. */
static const double v3_vel[4] = {0, 2, 8, 32};
static double v3_thr[8 * 6 * 4], v3_se[8 * 6 * 4];
static const csflut_meta v3_meta[2] = {
    {"velocity_meaning", "retinal (fixation on the mark: screen velocity)"},
    {"cells_not_shown", "f=32 cpd v=8 deg/s; f=32 cpd v=32 deg/s"}};

static csflut_build v3_build(void)
{
    csf_model_params p = csf_model_default();
    for (int v = 0; v < 4; v++)
        for (int e = 0; e < 6; e++)
            for (int f = 0; f < 8; f++) {
                int k = (v * 6 + e) * 8 + f;
                v3_thr[k] = csf_model_threshold(&p, fx_freq[f], fx_ecc[e]) * (1 + 0.25 * v);
                v3_se[k] = 0.05;
            }
    csflut_build b = {.n_freq = 8,
                      .n_ecc = 6,
                      .n_vel = 4,
                      .freq_cpd = fx_freq,
                      .ecc_deg = fx_ecc,
                      .vel_dps = v3_vel,
                      .threshold = v3_thr,
                      .stderr_log10 = v3_se,
                      .observer = "sim",
                      .method = "bayes"};
    return b;
}

static void test_velocity_extension(void)
{
    csflut_build b = v3_build();
    unsigned char *buf;
    size_t len;
    csflut_diag d;
    CHECK_INT_EQ(csflut_write_memory_meta(&b, v3_meta, 2, &buf, &len, &d), CSFLUT_OK);
    /* header: minor 1, header_size = 64 + 16 fixed bytes + the pairs; v0 0.5, 2 pairs */
    size_t want_hs = 64 + 16;
    for (int k = 0; k < 2; k++) want_hs += 8 + strlen(v3_meta[k].key) + strlen(v3_meta[k].value);
    CHECK_INT_EQ(buf[10], 1);
    CHECK_INT_EQ((long)(buf[12] | buf[13] << 8), (long)want_hs);
    double v0;
    memcpy(&v0, buf + 64, 8);
    CHECK(v0 == 0.5);
    CHECK_INT_EQ(buf[72], 2);
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_memory_diag(buf, len, &t, &d), CSFLUT_OK);
    if (!t) return;
    CHECK_INT_EQ(csflut_meta_count(t), 2);
    CHECK(strcmp(csflut_meta_key(t, 1), "cells_not_shown") == 0);
    CHECK(strcmp(csflut_meta_find(t, "velocity_meaning"), v3_meta[0].value) == 0);
    CHECK(csflut_meta_find(t, "nope") == NULL && csflut_meta_key(t, 2) == NULL);
    CHECK(csflut_velocity_warp_v0(t) == 0.5);
    /* table -> build + pairs -> the same bytes */
    csflut_build b2;
    csflut_meta m2[4];
    csflut_table_to_build(t, &b2);
    CHECK_INT_EQ((long)csflut_table_meta(t, m2, 4), 2);
    unsigned char *buf2;
    size_t len2;
    CHECK_INT_EQ(csflut_write_memory_meta(&b2, m2, 2, &buf2, &len2, NULL), CSFLUT_OK);
    CHECK(len2 == len && memcmp(buf, buf2, len) == 0);
    free(buf2);
    csflut_close(t);
    /* a 2-D table with pairs is 1.1 too; without velocity its warp is NaN */
    fx_table fx;
    fx_make(&fx, 5, 0.05, 1.0);
    CHECK_INT_EQ(csflut_write_memory_meta(&fx.b, v3_meta, 1, &buf2, &len2, NULL), CSFLUT_OK);
    t = NULL;
    CHECK_INT_EQ(csflut_open_memory(buf2, len2, &t), CSFLUT_OK);
    if (t) {
        CHECK_INT_EQ(csflut_version_minor(t), 1);
        CHECK(isnan(csflut_velocity_warp_v0(t)));
        CHECK_INT_EQ(csflut_meta_count(t), 1);
        csflut_close(t);
    }
    free(buf2);

    /* hostile extensions (checksum fixed so the parser proper sees them) */
    unsigned char *m = malloc(len);
    struct {
        size_t off;
        int width;
        uint64_t val;
        csflut_status want;
        const char *what;
    } cases[] = {
        {64, 8, 0xBFF0000000000000ull, CSFLUT_E_BAD_AXIS, "v0 = -1"},
        {64, 8, 0x7FF0000000000000ull, CSFLUT_E_BAD_AXIS, "v0 = inf"},
        {76, 4, 1, CSFLUT_E_BAD_HEADER, "reserved not zero"},
        {72, 4, 300, CSFLUT_E_BAD_METADATA, "300 pairs"},
        {72, 4, 3, CSFLUT_E_BAD_HEADER, "a pair past the extension"},
        {72, 4, 1, CSFLUT_E_BAD_HEADER, "unexplained bytes in the extension"},
        {80, 4, 65, CSFLUT_E_BAD_METADATA, "key of 65 bytes"},
        {84, 1, ':', CSFLUT_E_BAD_METADATA, "key with a colon"},
        {84, 1, 0, CSFLUT_E_BAD_METADATA, "key with a NUL"},
        {12, 4, 72, CSFLUT_E_BAD_HEADER, "extension shorter than its fixed bytes"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memcpy(m, buf, len);
        for (int i = 0; i < cases[k].width; i++)
            m[cases[k].off + (size_t)i] = (unsigned char)(cases[k].val >> (8 * i));
        fix_crc(m, len);
        open_expect(m, len, cases[k].want, cases[k].what);
    }
    /* a later minor may add bytes after the pairs: skipped */
    memcpy(m, buf, len);
    m[10] = 2;
    put32(m + 72, 1);
    fix_crc(m, len);
    t = NULL;
    CHECK_INT_EQ(csflut_open_memory(m, len, &t), CSFLUT_OK);
    if (t) {
        CHECK_INT_EQ(csflut_meta_count(t), 1);
        csflut_close(t);
    }
    /* the same bytes as format 1.0: the extension is skipped as 1.0 readers did, no warp, and
     * velocity is interpolated as the axis record says (linear: the grid includes 0) */
    memcpy(m, buf, len);
    m[10] = 0;
    fix_crc(m, len);
    t = NULL;
    CHECK_INT_EQ(csflut_open_memory(m, len, &t), CSFLUT_OK);
    if (t) {
        CHECK(isnan(csflut_velocity_warp_v0(t)));
        CHECK_INT_EQ(csflut_meta_count(t), 0);
        csflut_set_conservative(t, 0);
        double base = v3_thr[(1 * 6 + 0) * 8 + 3];
        CHECK_NEAR(csflut_threshold3(t, 4, 0, 5) / base, sqrt(1.25 * 1.5) / 1.25, 1e-12);
        csflut_close(t);
    }
    free(m);
    free(buf);
}

static void test_meta_refused(void)
{
    csflut_build b = v3_build();
    static char longval[4100];
    memset(longval, 'x', sizeof longval - 1);
    struct {
        csflut_meta m[2];
        size_t n;
        const char *what;
    } bad[] = {
        {{{"a", "1"}, {"a", "2"}}, 2, "appears twice"},
        {{{"a:b", "1"}}, 1, "A-Z a-z"},
        {{{"", "1"}}, 1, "A-Z a-z"},
        {{{"a b", "1"}}, 1, "A-Z a-z"},
        {{{"a", "line\nbreak"}}, 1, "line break"},
        {{{"a", NULL}}, 1, "missing"},
        {{{"a", longval}}, 1, "over 4096 bytes"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        unsigned char *buf = (unsigned char *)1;
        size_t len;
        csflut_diag d;
        CHECK_INT_EQ(csflut_write_memory_meta(&b, bad[k].m, bad[k].n, &buf, &len, &d), CSFLUT_E_BAD_METADATA);
        CHECK(buf == NULL);
        CHECK_STR_CONTAINS(d.message, bad[k].what);
    }
    static csflut_meta many[257];
    static char keys[257][8];
    for (int k = 0; k < 257; k++) {
        snprintf(keys[k], sizeof keys[k], "k%d", k);
        many[k] = (csflut_meta){keys[k], "v"};
    }
    unsigned char *buf;
    size_t len;
    csflut_diag d;
    CHECK_INT_EQ(csflut_write_memory_meta(&b, many, 257, &buf, &len, &d), CSFLUT_E_BAD_METADATA);
    CHECK_STR_CONTAINS(d.message, "at most 256");
    CHECK_INT_EQ(csflut_write_memory_meta(&b, many, 256, &buf, &len, &d), CSFLUT_OK);
    free(buf);
    CHECK_INT_EQ(csflut_write_memory_meta(&b, NULL, 1, &buf, &len, &d), CSFLUT_E_ARG);
    /* velocity grid points that the warp cannot tell apart */
    const double vclose[2] = {0, 1e-17};
    b.vel_dps = vclose;
    b.n_vel = 2;
    b.stderr_log10 = NULL;
    CHECK_INT_EQ(csflut_write_memory_meta(&b, NULL, 0, &buf, &len, &d), CSFLUT_E_NONMONOTONE);
    CHECK_STR_CONTAINS(d.message, "warp");
}

static void test_single_point_axes(void)
{
    const double f1[1] = {4}, e1[1] = {0};
    double thr1[1] = {0.005};
    csflut_build b = {.n_freq = 1, .n_ecc = 1, .freq_cpd = f1, .ecc_deg = e1, .threshold = thr1};
    csflut_table *t = fx_open(&b);
    CHECK(t != NULL);
    if (!t) return;
    CHECK(rel_diff(csflut_threshold(t, 0.1, 0), 0.005) < 2e-15);
    CHECK(rel_diff(csflut_threshold(t, 100, 30), 0.005) < 2e-15);
    CHECK(isinf(csflut_max_frequency(t, 0, 0.01)));
    CHECK(csflut_max_frequency(t, 0, 0.001) == 0);
    csflut_close(t);
}

static void test_bad_files(void)
{
    fx_table fx;
    fx_make(&fx, 13, 0.05, 1.0);
    unsigned char *good;
    size_t len;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &good, &len), CSFLUT_OK);
    unsigned char *b = malloc(len + 16);
    open_expect(good, len, CSFLUT_OK, "good");

    /* truncated at every length: always TRUNCATED (every prefix carries the right magic) */
    int all_trunc = 1;
    for (size_t n = 0; n < len; n++) {
        csflut_table *t = NULL;
        csflut_status st = csflut_open_memory(good, n, &t);
        if (st != CSFLUT_E_TRUNCATED || t) all_trunc = 0;
    }
    CHECK(all_trunc);
    open_expect(good, 0, CSFLUT_E_TRUNCATED, "empty");
    /* trailing bytes */
    memcpy(b, good, len);
    b[len] = 0;
    open_expect(b, len + 1, CSFLUT_E_BAD_HEADER, "trailing byte");
    /* bad magic: a PNG, a text file, one flipped bit */
    open_expect((const unsigned char *)"\x89PNG\r\n\x1a\n0000000000000000", 24, CSFLUT_E_BAD_MAGIC, "png");
    open_expect((const unsigned char *)"freq_cpd,ecc_deg,threshold\n", 27, CSFLUT_E_BAD_MAGIC, "csv");
    memcpy(b, good, len);
    b[3] ^= 0x20;
    open_expect(b, len, CSFLUT_E_BAD_MAGIC, "magic bit flip");
    open_expect((const unsigned char *)"XY", 2, CSFLUT_E_BAD_MAGIC, "2 bytes");
    /* bad version (with a valid checksum: the version is checked first anyway) */
    memcpy(b, good, len);
    b[OFF_VERSION] = 2;
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_VERSION, "version 2");
    memcpy(b, good, len);
    b[OFF_VERSION] = 0;
    open_expect(b, len, CSFLUT_E_BAD_VERSION, "version 0");
    /* a newer minor version is read */
    memcpy(b, good, len);
    b[OFF_VERSION + 2] = 7;
    fix_crc(b, len);
    CHECK(open_expect(b, len, CSFLUT_OK, "minor 7") == CSFLUT_OK);
    /* checksum: any flipped byte in the body or in the stored CRC */
    int all_crc = 1;
    for (size_t off = 12; off < len; off += 37) {
        memcpy(b, good, len);
        b[off] ^= 0x01;
        csflut_table *t = NULL;
        csflut_status st = csflut_open_memory(b, len, &t);
        /* the file-size field is checked before the CRC: flipping it reads as truncation or
         * trailing bytes */
        int size_field = off >= OFF_FILESIZE && off < OFF_FILESIZE + 8;
        if (!size_field && st != CSFLUT_E_BAD_CHECKSUM) all_crc = 0;
        csflut_close(t);
    }
    CHECK(all_crc);
    /* absurd axis sizes and counts */
    memcpy(b, good, len);
    put32(b + OFF_AX0 + 8, 0);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "0 frequency points");
    memcpy(b, good, len);
    put32(b + OFF_AX1 + 8, 0xFFFFFFFFu);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "4 billion eccentricity points");
    memcpy(b, good, len);
    put32(b + OFF_AX0 + 8, 5000);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "5000 frequency points");
    memcpy(b, good, len);
    put32(b + OFF_NAXES, 7);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "7 axes");
    memcpy(b, good, len);
    put32(b + OFF_NAXES, 1);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "1 axis");
    memcpy(b, good, len);
    put32(b + OFF_AX1, 3); /* second record claims to be luminance: eccentricity missing */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "axis ids");
    memcpy(b, good, len);
    put32(b + OFF_AX0 + 4, 0); /* frequency on a linear scale */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "linear frequency");
    memcpy(b, good, len);
    put32(b + OFF_AX0 + 8, 7); /* 7 points: the next record is read from the wrong place */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_AXIS, "layout mismatch");
    memcpy(b, good, len);
    put32(b + 12, 10); /* header shorter than the fixed header */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_HEADER, "header size");
    memcpy(b, good, len);
    put32(b + OFF_META + (4 + 10) + (4 + 13) + (4 + 4) + (4 + 20), 12); /* tool version 1 byte longer */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_HEADER, "string runs into the checksum");
    memcpy(b, good, len);
    put32(b + OFF_FLAGS, 0x10);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_HEADER, "unknown flag");
    /* non-monotone grids */
    memcpy(b, good, len);
    putf64(b + OFF_AX0_PTS + 8 * 3, 1.5); /* 0.5 1 2 1.5 8 ... */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_NONMONOTONE, "frequency order");
    memcpy(b, good, len);
    putf64(b + OFF_AX1_PTS + 8 * 2, 5); /* 0 5 5 20 ...: repeated point */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_NONMONOTONE, "repeated eccentricity");
    /* non-finite and negative values */
    const struct { size_t off; double v; const char *what; } bad_vals[] = {
        {OFF_AX0_PTS, NAN, "NaN frequency"}, {OFF_AX0_PTS, 0.0, "zero frequency (log axis)"},
        {OFF_AX1_PTS, -1.0, "negative eccentricity"}, {OFF_AX1_PTS + 40, INFINITY, "infinite eccentricity"},
        {OFF_THR + 8 * 5, NAN, "NaN threshold"}, {OFF_THR + 8 * 5, -0.01, "negative threshold"},
        {OFF_THR + 8 * 5, 0.0, "zero threshold"}, {OFF_THR + 8 * 5, -INFINITY, "-inf threshold"},
        {OFF_SE + 8 * 2, -0.1, "negative stderr"}, {OFF_SE + 8 * 2, INFINITY, "infinite stderr"},
    };
    for (size_t i = 0; i < sizeof bad_vals / sizeof bad_vals[0]; i++) {
        memcpy(b, good, len);
        putf64(b + bad_vals[i].off, bad_vals[i].v);
        fix_crc(b, len);
        open_expect(b, len, CSFLUT_E_BAD_VALUE, bad_vals[i].what);
    }
    /* +inf threshold and NaN stderr are legal */
    memcpy(b, good, len);
    putf64(b + OFF_THR, INFINITY);
    putf64(b + OFF_SE, NAN);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_OK, "inf threshold");
    /* metadata */
    memcpy(b, good, len);
    putf64(b + OFF_DIST, -600);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_METADATA, "negative distance");
    memcpy(b, good, len);
    b[OFF_META + 4 + 2] = 0; /* NUL inside the observer string */
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_METADATA, "NUL in observer");
    memcpy(b, good, len);
    put32(b + OFF_META, 100000);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_METADATA, "huge string");
    memcpy(b, good, len);
    put32(b + OFF_META, 4000);
    fix_crc(b, len);
    open_expect(b, len, CSFLUT_E_BAD_HEADER, "string past end");
    /* a lying file-size field: bigger than the buffer is truncation */
    memcpy(b, good, len);
    put64(b + OFF_FILESIZE, (uint64_t)len * 1000);
    open_expect(b, len, CSFLUT_E_TRUNCATED, "file size too big");

    /* every code has a distinct message */
    for (int s = 0; s < CSFLUT_STATUS_END; s++)
        for (int u = s + 1; u < CSFLUT_STATUS_END; u++)
            CHECK(strcmp(csflut_strerror((csflut_status)s), csflut_strerror((csflut_status)u)) != 0);
    CHECK(csflut_strerror((csflut_status)999) != NULL);
    /* the bound covers every real code and nothing past it */
    for (int s = 0; s < CSFLUT_STATUS_END; s++)
        CHECK_MSG(strcmp(csflut_strerror((csflut_status)s), "unknown csflut status") != 0,
                  "status %d has no message", s);
    CHECK(strcmp(csflut_strerror((csflut_status)CSFLUT_STATUS_END), "unknown csflut status") == 0);
    CHECK_INT_EQ(csflut_open_memory(NULL, 10, NULL), CSFLUT_E_ARG);
    free(b);
    free(good);
}

static void test_writer_refuses(void)
{
    fx_table fx;
    fx_make(&fx, 14, 0.05, 1.0);
    unsigned char *buf = (unsigned char *)1;
    size_t len = 1;
    csflut_diag d;
    double fr[8];
    memcpy(fr, fx_freq, sizeof fr);
    fx.b.freq_cpd = fr;
    fr[4] = fr[3];
    CHECK_INT_EQ(csflut_write_memory_diag(&fx.b, &buf, &len, &d), CSFLUT_E_NONMONOTONE);
    CHECK(buf == NULL && len == 0);
    CHECK_STR_CONTAINS(d.message, "freq");
    fr[4] = 8;
    fx.thr[9] = NAN;
    CHECK_INT_EQ(csflut_write_memory_diag(&fx.b, &buf, &len, &d), CSFLUT_E_BAD_VALUE);
    CHECK_STR_CONTAINS(d.message, "node 9");
    fx.thr[9] = 0.01;
    fx.b.n_ecc = 0;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &buf, &len), CSFLUT_E_BAD_AXIS);
    fx.b.n_ecc = 6;
    fx.b.trials = -1;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &buf, &len), CSFLUT_E_BAD_METADATA);
    fx.b.trials = 3;
    fx.b.viewing_distance_mm = -5;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &buf, &len), CSFLUT_E_BAD_METADATA);
    fx.b.viewing_distance_mm = 500;
    fx.b.threshold = NULL;
    CHECK_INT_EQ(csflut_write_memory(&fx.b, &buf, &len), CSFLUT_E_ARG);
    CHECK_INT_EQ(csflut_write_memory(NULL, &buf, &len), CSFLUT_E_ARG);
}

static int dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    closedir(d);
    return n;
}

/* csflut_write_file on a "full disk" (RLIMIT_FSIZE, SIGXFSZ ignored, fails the
 * write like ENOSPC) leaves the previous table intact and no temporary, and the diagnostic names
 * the OS error; file errors on open name theirs too. */
static void test_write_fails_cleanly(void)
{
    char dir[] = "/tmp/csflut-write-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[600];
    snprintf(path, sizeof path, "%s/t.csflut", dir);
    fx_table fx;
    fx_make(&fx, 3, 0.1, 1.0);
    csflut_diag d;
    CHECK_INT_EQ(csflut_write_file_diag(&fx.b, path, &d), CSFLUT_OK);
    CHECK_INT_EQ(dir_entries(dir), 1);
    /* a bigger table that does not fit under the limit */
    static double f[300], thr[300 * 6];
    for (int i = 0; i < 300; i++) f[i] = 0.5 * pow(1.02, i);
    for (int i = 0; i < 300 * 6; i++) thr[i] = 0.01;
    csflut_build big = fx.b;
    big.n_freq = 300;
    big.freq_cpd = f;
    big.threshold = thr;
    big.stderr_log10 = NULL;
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit old_lim, lim;
    getrlimit(RLIMIT_FSIZE, &old_lim);
    lim = old_lim;
    lim.rlim_cur = 4096;
    CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
    csflut_status st = csflut_write_file_diag(&big, path, &d);
    setrlimit(RLIMIT_FSIZE, &old_lim);
    CHECK_INT_EQ(st, CSFLUT_E_IO);
    CHECK_MSG(strstr(d.message, strerror(EFBIG)) && strstr(d.message, path), "message: %s",
              d.message);
    CHECK_INT_EQ(dir_entries(dir), 1); /* no temporary left */
    csflut_table *t = NULL;
    CHECK_INT_EQ(csflut_open_file_diag(path, &t, &d), CSFLUT_OK); /* the old table, whole */
    if (t) CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_FREQ), 8);
    csflut_close(t);
    /* a missing folder and a missing file: the OS error in the message */
    char bad[700];
    snprintf(bad, sizeof bad, "%s/no/t.csflut", dir);
    CHECK_INT_EQ(csflut_write_file_diag(&fx.b, bad, &d), CSFLUT_E_IO);
    CHECK_MSG(strstr(d.message, strerror(ENOENT)) != NULL, "message: %s", d.message);
    CHECK_INT_EQ(csflut_open_file_diag(bad, &t, &d), CSFLUT_E_IO);
    CHECK_MSG(strstr(d.message, strerror(ENOENT)) && strstr(d.message, bad), "message: %s",
              d.message);
    CHECK_INT_EQ(csflut_open_file_diag(dir, &t, &d), CSFLUT_E_IO);
    CHECK_MSG(strstr(d.message, strerror(EISDIR)) != NULL, "message: %s", d.message);
    remove(path);
    rmdir(dir);
}

/* The run-time version query returns the macros this test was built with (the library is built
 * from the same header), the number and the string agree, and the file format version is kept
 * apart: a table written now carries the format version, not the library's. */
static void test_versions(void)
{
    CHECK(csflut_version() != NULL);
    if (csflut_version()) CHECK(strcmp(csflut_version(), CSFLUT_LIB_VERSION) == 0);
    CHECK_INT_EQ(csflut_version_number(), CSFLUT_LIB_VERSION_NUMBER);
    CHECK_INT_EQ(csflut_version_number(), CSFLUT_LIB_VERSION_MAJOR * 10000 +
                                              CSFLUT_LIB_VERSION_MINOR * 100 +
                                              CSFLUT_LIB_VERSION_PATCH);
    char s[32];
    snprintf(s, sizeof s, "%d.%d.%d", CSFLUT_LIB_VERSION_MAJOR, CSFLUT_LIB_VERSION_MINOR,
             CSFLUT_LIB_VERSION_PATCH);
    CHECK(strcmp(s, CSFLUT_LIB_VERSION) == 0);
    CHECK_INT_EQ(CSFLUT_VERSION_MAJOR, CSFLUT_FORMAT_VERSION_MAJOR);
    CHECK_INT_EQ(CSFLUT_VERSION_MINOR, CSFLUT_FORMAT_VERSION_MINOR);
    fx_table fx;
    fx_make(&fx, 3, 0.05, 1.0);
    csflut_table *t = fx_open(&fx.b);
    CHECK(t != NULL);
    if (t) {
        /* a 2-D table without metadata pairs is still written as format 1.0 */
        CHECK_INT_EQ(csflut_version_major(t), CSFLUT_FORMAT_VERSION_MAJOR);
        CHECK_INT_EQ(csflut_version_minor(t), 0);
        csflut_close(t);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_lut_format EXAMPLE.csflut\n");
        return 2;
    }
    test_2d_bytes_unchanged(argv[1]);
    test_velocity_extension();
    test_meta_refused();
    test_versions();
    test_round_trip_memory();
    test_round_trip_file_and_absent_metadata();
    test_4d_round_trip();
    test_single_point_axes();
    test_bad_files();
    test_writer_refuses();
    test_write_fails_cleanly();
    return CHECK_RESULT();
}
