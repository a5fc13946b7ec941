/* The exported C header compiles on its own (cc -std=c99 -pedantic -Werror) and gives the same
 * numbers as the library, in both views, on a noisy table with never-visible nodes; the JSON
 * export carries the values. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

enum { NQ = 3000 };

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    int ok = fputs(text, f) >= 0;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

int main(void)
{
    char dir[] = "/tmp/csflut-export-c-XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    fx_table fx;
    fx_make(&fx, 71, 0.12, 1.0);
    csflut_table *t = fx_open(&fx.b);
    CHECK(t != NULL);
    char path[512], cmd[2048];
    /* both views, under two prefixes, in one program */
    const char *prefixes[2] = {"lut_raw", "lut_cons"};
    for (int view = 0; view < 2; view++) {
        csflut_set_conservative(t, view);
        char *hdr;
        size_t len;
        CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_C, prefixes[view], &hdr, &len), CSFLUT_OK);
        CHECK_STR_CONTAINS(hdr, view ? "view: conservative" : "view: raw");
        snprintf(path, sizeof path, "%s/%s.h", dir, prefixes[view]);
        CHECK(write_text(path, hdr) == 0);
        free(hdr);
    }
    /* a bad prefix is refused */
    char *junk;
    CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_C, "9abc", &junk, NULL), CSFLUT_E_ARG);
    CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_C, "a-b", &junk, NULL), CSFLUT_E_ARG);

    /* queries: random inside and outside the grid, plus every node and the edges */
    static double qf[NQ], qe[NQ];
    csf_rng r;
    csf_rng_init(&r, 71, 9);
    int nq = 0;
    for (int e = 0; e < 6; e++)
        for (int f = 0; f < 8; f++) {
            qf[nq] = fx_freq[f];
            qe[nq++] = fx_ecc[e];
        }
    qf[nq] = 100;
    qe[nq++] = 100;
    qf[nq] = 0.001;
    qe[nq++] = -1;
    while (nq < NQ) {
        qf[nq] = 0.3 * pow(2, 7.0 * csf_rng_next_uniform(&r));
        qe[nq++] = -2 + 47 * csf_rng_next_uniform(&r);
    }
    /* the program: each header included in its own right, queries as hex floats */
    size_t cap = 64 * NQ + 4096, n = 0;
    char *src = malloc(cap);
    n += (size_t)snprintf(src + n, cap - n,
                          "#include <stdio.h>\n#include \"lut_raw.h\"\n#include \"lut_cons.h\"\n"
                          "static const double qf[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%a", i ? "," : "", qf[i]);
    n += (size_t)snprintf(src + n, cap - n, "};\nstatic const double qe[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%a", i ? "," : "", qe[i]);
    snprintf(src + n, cap - n,
             "};\nint main(void)\n{\n    for (int i = 0; i < %d; i++)\n"
             "        printf(\"%%a %%a %%d\\n\", lut_raw_threshold(qf[i], qe[i]),\n"
             "               lut_cons_threshold(qf[i], qe[i]), lut_cons_perceptible(qf[i], 0.01, qe[i]));\n"
             "    return 0;\n}\n", NQ);
    snprintf(path, sizeof path, "%s/main.c", dir);
    CHECK(write_text(path, src) == 0);
    free(src);
    /* the header alone, as a translation unit of its own */
    snprintf(path, sizeof path, "%s/alone.c", dir);
    CHECK(write_text(path, "#include \"lut_cons.h\"\ndouble f(double a, double b);\n"
                           "double f(double a, double b) { return lut_cons_threshold(a, b); }\n") == 0);
    snprintf(cmd, sizeof cmd,
             "cd %s && cc -std=c99 -pedantic -Wall -Wextra -Werror -c alone.c -o alone.o && "
             "cc -std=c11 -O2 -Wall -Wextra -Werror main.c -o prog -lm", dir);
    int rc = system(cmd);
    CHECK_MSG(rc == 0, "compiling the exported header failed: %s", cmd);
    snprintf(cmd, sizeof cmd, "%s/prog", dir);
    FILE *p = rc == 0 ? popen(cmd, "r") : NULL;
    int lines = 0, agree = 1, exact = 0;
    double worst = 0;
    if (p) {
        char line[256];
        while (fgets(line, sizeof line, p) && lines < NQ) {
            double got[2];
            int vis;
            if (sscanf(line, "%la %la %d", &got[0], &got[1], &vis) != 3) {
                agree = 0;
                break;
            }
            for (int view = 0; view < 2; view++) {
                csflut_set_conservative(t, view);
                double want = csflut_threshold(t, qf[lines], qe[lines]);
                double d = rel_diff(got[view], want);
                if (d > worst) worst = d;
                if (got[view] == want) exact++;
            }
            if (vis != csflut_perceptible(t, qf[lines], 0.01, qe[lines])) agree = 0;
            lines++;
        }
        CHECK(pclose(p) == 0);
    }
    CHECK_INT_EQ(lines, NQ);
    CHECK(agree);
    CHECK_MSG(worst < 1e-13, "worst relative difference %g", worst);
    CHECK_MSG(exact > NQ, "only %d of %d bit-identical", exact, 2 * NQ);
    fprintf(stderr, "C header: %d queries x 2 views, %d bit-identical, worst rel diff %.3g\n", NQ,
            exact, worst);

    /* JSON export: the raw values appear exactly (the shortest digits that read back as the
     * same double); infinity as null */
    char *json;
    CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_JSON, NULL, &json, NULL), CSFLUT_OK);
    char num[64];
    snprintf(num, sizeof num, "%.17g", fx.thr[9]);
    const char *at = strstr(json, "\"threshold\": [");
    CHECK(at != NULL);
    if (at) {
        /* the 10th value of the raw threshold array */
        const char *q = at + strlen("\"threshold\": [");
        for (int k = 0; k < 9 && q; k++) {
            q = strchr(q, ',');
            if (q) q++;
        }
        CHECK(q != NULL);
        if (q) CHECK_MSG(strtod(q, NULL) == fx.thr[9], "JSON value %.20s is not %s", q, num);
    }
    CHECK_STR_CONTAINS(json, "\"name\": \"freq\", \"unit\": \"cpd\", \"scale\": \"log\"");
    CHECK_STR_CONTAINS(json, "null");
    CHECK_STR_CONTAINS(json, "\"observer\": \"sim:seed=1\"");
    free(json);
    csflut_close(t);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
    return CHECK_RESULT();
}
