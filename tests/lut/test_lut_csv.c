/* CSV import: round trips (import -> write -> read -> export CSV -> import) preserve every value
 * bit for bit, 2-D and 4-D, in any column and row order; bad CSV is refused with the line number. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

static csflut_status import(const char *text, csflut_grid **g, csflut_diag *d)
{
    return csflut_import_csv(text, strlen(text), g, d);
}

/* import -> binary -> table */
static csflut_table *csv_to_table(const char *text)
{
    csflut_grid *g;
    csflut_diag d;
    if (import(text, &g, &d) != CSFLUT_OK) {
        fprintf(stderr, "import failed: %s\n", d.message);
        return NULL;
    }
    csflut_table *t = fx_open(csflut_grid_build(g));
    csflut_grid_free(g);
    return t;
}

static int tables_identical(const csflut_table *a, const csflut_table *b)
{
    for (int ax = 0; ax < 4; ax++) {
        int n = csflut_axis_size(a, (csflut_axis)ax);
        if (n != csflut_axis_size(b, (csflut_axis)ax)) return 0;
        if (n && memcmp(csflut_axis_points(a, (csflut_axis)ax), csflut_axis_points(b, (csflut_axis)ax),
                        8 * (size_t)n) != 0)
            return 0;
    }
    size_t n = csflut_node_count(a);
    if (n != csflut_node_count(b)) return 0;
    if (memcmp(csflut_raw_thresholds(a), csflut_raw_thresholds(b), 8 * n) != 0) return 0;
    const double *sa = csflut_stderr_log10(a), *sb = csflut_stderr_log10(b);
    if (!sa != !sb) return 0;
    if (sa && memcmp(sa, sb, 8 * n) != 0) return 0;
    return 1;
}

static void test_round_trip_2d(void)
{
    fx_table fx;
    fx_make(&fx, 61, 0.1, 1.0);
    csflut_table *t0 = fx_open(&fx.b);
    char *csv;
    size_t len;
    CHECK_INT_EQ(csflut_export(t0, CSFLUT_FORMAT_CSV, NULL, &csv, &len), CSFLUT_OK);
    CHECK(strlen(csv) == len);
    CHECK_STR_CONTAINS(csv, "freq_cpd,ecc_deg,threshold,stderr_log10\n");
    CHECK_STR_CONTAINS(csv, ",inf,");
    CHECK_STR_CONTAINS(csv, "# observer: sim:seed=1");
    csflut_table *t1 = csv_to_table(csv);
    CHECK(t1 && tables_identical(t0, t1));
    /* and once more through the exported CSV of the re-imported table */
    char *csv2;
    CHECK_INT_EQ(csflut_export(t1, CSFLUT_FORMAT_CSV, NULL, &csv2, &len), CSFLUT_OK);
    csflut_table *t2 = csv_to_table(csv2);
    CHECK(t2 && tables_identical(t0, t2));
    free(csv);
    free(csv2);
    csflut_close(t0);
    csflut_close(t1);
    csflut_close(t2);
}

static void test_round_trip_4d_shuffled(void)
{
    /* rows in reverse order, columns permuted, CRLF line ends, comments and blank lines */
    const double vel[2] = {0.5, 4}, lum[3] = {1, 10, 100};
    char *text = malloc(1 << 16);
    size_t n = (size_t)sprintf(text, "# a 4-D grid\r\nthreshold, lum_cdm2 ,velocity_dps,ecc_deg,freq_cpd\r\n\r\n");
    csf_rng r;
    csf_rng_init(&r, 62, 0);
    double thr[4 * 3 * 2 * 3];
    const double fr[4] = {1, 2, 4, 8}, ec[3] = {0, 10, 20};
    for (int k = 0; k < 72; k++) thr[k] = 0.001 + 0.3 * csf_rng_next_uniform(&r);
    thr[5] = INFINITY;
    for (int k = 71; k >= 0; k--) {
        int f = k % 4, e = (k / 4) % 3, v = (k / 12) % 2, l = k / 24;
        n += (size_t)sprintf(text + n, "%.17g,%.17g,%.17g,%.17g,%.17g\r\n", thr[k], lum[l], vel[v],
                             ec[e], fr[f]);
    }
    csflut_table *t = csv_to_table(text);
    CHECK(t != NULL);
    if (t) {
        CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_VEL), 2);
        CHECK_INT_EQ(csflut_axis_size(t, CSFLUT_AXIS_LUM), 3);
        CHECK(memcmp(csflut_raw_thresholds(t), thr, sizeof thr) == 0);
        CHECK(csflut_stderr_log10(t) == NULL);
        char *csv;
        size_t len;
        CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_CSV, NULL, &csv, &len), CSFLUT_OK);
        CHECK_STR_CONTAINS(csv, "freq_cpd,ecc_deg,velocity_dps,lum_cdm2,threshold\n");
        csflut_table *t2 = csv_to_table(csv);
        CHECK(t2 && tables_identical(t, t2));
        csflut_close(t2);
        free(csv);
        csflut_close(t);
    }
    free(text);
}

static void expect_refusal(const char *text, size_t line, const char *needle)
{
    csflut_grid *g = (csflut_grid *)1;
    csflut_diag d;
    csflut_status st = import(text, &g, &d);
    CHECK_MSG(st == CSFLUT_E_CSV, "status %d for %s", (int)st, needle);
    CHECK(g == NULL);
    CHECK_MSG(d.where == line, "line %zu, want %zu: %s", d.where, line, d.message);
    char want[32];
    snprintf(want, sizeof want, "line %zu", line);
    CHECK_STR_CONTAINS(d.message, want);
    CHECK_STR_CONTAINS(d.message, needle);
}

static void test_bad_csv(void)
{
    const char *hdr = "freq_cpd,ecc_deg,threshold\n";
    char buf[1024];
    expect_refusal("", 1, "no header");
    expect_refusal("# only a comment\n", 1, "no header");
    expect_refusal("freq_cpd,ecc_deg,threshold\n", 1, "no data rows");
    expect_refusal("freq_cpd,ecc,threshold\n1,0,0.1\n", 1, "unknown column \"ecc\"");
    /* outside bytes in a message are made printable: a terminal control sequence is shown, not
     * obeyed */
    expect_refusal("freq_cpd,\x1b[2J,threshold\n1,0,0.1\n", 1, "unknown column \"\\x1b[2J\"");
    expect_refusal("freq_cpd,ecc_deg,threshold\n1,0,0.1\xff\n", 2, "threshold \"0.1\\xff\" is not a number");
    expect_refusal("freq_cpd,threshold\n1,0.1\n", 1, "ecc_deg");
    expect_refusal("freq_cpd,ecc_deg,threshold,freq_cpd\n", 1, "appears twice");
    expect_refusal("a,b,c,d,e,f,g\n", 1, "more than 6 columns");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0\n", hdr);
    expect_refusal(buf, 3, "too few fields");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0,0.1,7\n", hdr);
    expect_refusal(buf, 3, "too many fields");
    snprintf(buf, sizeof buf, "%s# c\n1,0,0.1\n2,0,abc\n", hdr);
    expect_refusal(buf, 4, "threshold \"abc\" is not a number");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n-2,0,0.1\n", hdr);
    expect_refusal(buf, 3, "freq_cpd -2 must be finite and > 0");
    snprintf(buf, sizeof buf, "%s1,nan,0.1\n", hdr);
    expect_refusal(buf, 2, "ecc_deg");
    snprintf(buf, sizeof buf, "%s1,0,0\n", hdr);
    expect_refusal(buf, 2, "threshold 0 must be > 0");
    snprintf(buf, sizeof buf, "%s1,0,-inf\n", hdr);
    expect_refusal(buf, 2, "threshold");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0,0.2\n1,0,0.3\n", hdr);
    expect_refusal(buf, 4, "duplicate grid point (same axis values as line 2)");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0,0.2\n1,5,0.3\n", hdr);
    expect_refusal(buf, 4, "no row for freq_cpd=2 ecc_deg=5");
    snprintf(buf, sizeof buf, "freq_cpd,ecc_deg,threshold,stderr_log10\n1,0,0.1,-0.2\n");
    expect_refusal(buf, 2, "stderr_log10");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0,\"0.2\"\n", hdr);
    expect_refusal(buf, 3, "not a number");
    snprintf(buf, sizeof buf, "%s1,0,0.1\n2,0,0.%0100d\n", hdr, 1);
    expect_refusal(buf, 3, "not a number"); /* over-long field */
    /* NUL byte inside a line */
    const char nul[] = "freq_cpd,ecc_deg,threshold\n1,0\0,0.1\n";
    csflut_grid *g;
    csflut_diag d;
    CHECK_INT_EQ(csflut_import_csv(nul, sizeof nul - 1, &g, &d), CSFLUT_E_CSV);
    CHECK_INT_EQ(d.where, 2);
    /* accepted: empty stderr, inf threshold, whitespace, no trailing newline */
    CHECK_INT_EQ(import("freq_cpd,ecc_deg,threshold,stderr_log10\n 1 ,0,inf,\n2,0,0.1,nan\n1,5,0.2,0.1\n2,5,0.3,0", &g, &d),
                 CSFLUT_OK);
    csflut_build *b = csflut_grid_build(g);
    CHECK(b->n_freq == 2 && b->n_ecc == 2 && isinf(b->threshold[0]) && isnan(b->stderr_log10[0]));
    CHECK(b->stderr_log10[3] == 0);
    csflut_grid_free(g);
}

int main(void)
{
    test_round_trip_2d();
    test_round_trip_4d_shuffled();
    test_bad_csv();
    return CHECK_RESULT();
}
