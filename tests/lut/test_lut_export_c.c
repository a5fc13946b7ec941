/* The exported C header compiles on its own and in C99, C11, C++11, C++14 and C++17 with gcc and
 * clang (-Wall -Wextra -pedantic -Werror), also with the host's FMA instructions (-march=native),
 * and gives the same numbers as the library bit for bit, in both views, on a noisy table with
 * never-visible nodes; prefixes GLSL or C++ would refuse are refused; the JSON export carries the
 * values. */
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
        /* no fused multiply-add: the standard pragma for the compilers that honour it, and the
         * GCC flag in the comment; both functions and NaN described */
        CHECK_STR_CONTAINS(hdr, "#if defined(__clang__) || !defined(__GNUC__)\n"
                                "#pragma STDC FP_CONTRACT OFF\n#endif\n");
        CHECK_STR_CONTAINS(hdr, "-ffp-contract=off");
        CHECK_STR_CONTAINS(hdr, view ? "int lut_cons_perceptible(double freq_cpd, double ecc_deg, "
                                       "double contrast) is 1 when"
                                     : "int lut_raw_perceptible(double freq_cpd, double ecc_deg, "
                                       "double contrast) is 1 when");
        CHECK_STR_CONTAINS(hdr, "NaN threshold");
        snprintf(path, sizeof path, "%s/%s.h", dir, prefixes[view]);
        CHECK(write_text(path, hdr) == 0);
        free(hdr);
    }
    /* a bad prefix is refused: not an identifier, or one GLSL refuses ("gl_") or GLSL and C++
     * reserve ("__", also made by a trailing '_' before "_threshold"), in every format */
    static const char *const bad_prefix[] = {"9abc", "a-b", "", "gl_x", "gl_", "a__b", "__x",
                                             "lut_"};
    for (size_t k = 0; k < sizeof bad_prefix / sizeof bad_prefix[0]; k++)
        for (int fmt = CSFLUT_FORMAT_C; fmt <= CSFLUT_FORMAT_GLSL; fmt++) {
            char *junk = (char *)1;
            CHECK_MSG(csflut_export(t, (csflut_format)fmt, bad_prefix[k], &junk, NULL) ==
                          CSFLUT_E_ARG, "prefix '%s' accepted", bad_prefix[k]);
            CHECK(junk == NULL);
        }
    /* near misses stay accepted: the rules are exactly "gl_" at the start and "__" */
    static const char *const good_prefix[] = {"GL_x", "glx", "a_gl_b", "a_b", "_a"};
    for (size_t k = 0; k < sizeof good_prefix / sizeof good_prefix[0]; k++) {
        char *text = NULL;
        CHECK_MSG(csflut_export(t, CSFLUT_FORMAT_GLSL, good_prefix[k], &text, NULL) == CSFLUT_OK,
                  "prefix '%s' refused", good_prefix[k]);
        free(text);
    }

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
    /* the program: each header included in its own right; queries in decimal with 17 digits
     * (exact, and legal in C++11, which has no hex-float literals) */
    size_t cap = 64 * NQ + 4096, n = 0;
    char *src = malloc(cap);
    n += (size_t)snprintf(src + n, cap - n,
                          "#include <stdio.h>\n#include \"lut_raw.h\"\n#include \"lut_cons.h\"\n"
                          "static const double qf[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%.17g", i ? "," : "", qf[i]);
    n += (size_t)snprintf(src + n, cap - n, "};\nstatic const double qe[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%.17g", i ? "," : "", qe[i]);
    snprintf(src + n, cap - n,
             "};\nint main(void)\n{\n    for (int i = 0; i < %d; i++)\n"
             "        printf(\"%%a %%a %%d\\n\", lut_raw_threshold(qf[i], qe[i]),\n"
             "               lut_cons_threshold(qf[i], qe[i]), lut_cons_perceptible(qf[i], qe[i], 0.01));\n"
             "    return 0;\n}\n", NQ);
    snprintf(path, sizeof path, "%s/main.c", dir);
    CHECK(write_text(path, src) == 0);
    snprintf(path, sizeof path, "%s/main.cpp", dir);
    CHECK(write_text(path, src) == 0);
    free(src);
    /* the header alone, as a translation unit of its own */
    snprintf(path, sizeof path, "%s/alone.c", dir);
    CHECK(write_text(path, "#include \"lut_cons.h\"\ndouble f(double a, double b);\n"
                           "double f(double a, double b) { return lut_cons_threshold(a, b); }\n") == 0);
    /* The exported source builds as C99, C11, C++11, C++14, C++17 under gcc and clang, strict,
     * and every value is bit-identical to the library's */
    /* and with the host's FMA instructions allowed (-march=native): clang keeps a * b + c unfused
     * because of the header's pragma; GCC ignores the pragma and fuses in GNU C modes and in
     * C++, so those builds carry -ffp-contract=off, as the header's comment says */
    static const char *const builds[][4] = {
        {"gcc", "c99", "main.c", ""},      {"gcc", "c11", "main.c", ""},
        {"clang", "c99", "main.c", ""},    {"clang", "c11", "main.c", ""},
        {"g++", "c++11", "main.cpp", ""},  {"g++", "c++14", "main.cpp", ""},
        {"g++", "c++17", "main.cpp", ""},  {"clang++", "c++11", "main.cpp", ""},
        {"clang++", "c++14", "main.cpp", ""}, {"clang++", "c++17", "main.cpp", ""},
        {"clang", "c11", "main.c", "-march=native"},
        {"clang", "gnu11", "main.c", "-march=native"},
        {"clang++", "c++17", "main.cpp", "-march=native"},
        {"gcc", "c11", "main.c", "-march=native"},
        {"gcc", "gnu11", "main.c", "-march=native -ffp-contract=off"},
        {"g++", "c++17", "main.cpp", "-march=native -ffp-contract=off"}};
    snprintf(cmd, sizeof cmd, "cd %s && cc -std=c99 -pedantic -Wall -Wextra -Werror -c alone.c -o alone.o",
             dir);
    CHECK_MSG(system(cmd) == 0, "compiling the exported header alone failed: %s", cmd);
    for (size_t k = 0; k < sizeof builds / sizeof builds[0]; k++) {
        snprintf(cmd, sizeof cmd,
                 "cd %s && %s -std=%s -O2 %s -Wall -Wextra -pedantic -Werror %s -o prog -lm", dir,
                 builds[k][0], builds[k][1], builds[k][3], builds[k][2]);
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
                    if (memcmp(&got[view], &want, sizeof want) == 0) exact++;
                }
                if (vis != csflut_perceptible(t, qf[lines], qe[lines], 0.01)) agree = 0;
                lines++;
            }
            CHECK(pclose(p) == 0);
        }
        CHECK_INT_EQ(lines, NQ);
        CHECK(agree);
        CHECK_MSG(exact == 2 * NQ, "%s -std=%s %s: only %d of %d bit-identical (worst %g)",
                  builds[k][0], builds[k][1], builds[k][3], exact, 2 * NQ, worst);
        fprintf(stderr, "C header, %s -std=%s %s: %d queries x 2 views, %d bit-identical\n",
                builds[k][0], builds[k][1], builds[k][3], NQ, exact);
        snprintf(cmd, sizeof cmd, "rm -f %s/prog", dir);
        CHECK(system(cmd) == 0);
    }

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
