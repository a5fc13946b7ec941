/* The exported C header compiles on its own and in C99, C11, C++11, C++14 and C++17 with gcc and
 * clang (-Wall -Wextra -pedantic -Werror), also with the host's FMA instructions (-march=native),
 * and gives the same numbers as the library bit for bit, in both views, on a noisy table with
 * never-visible nodes, and so does PREFIX_threshold3 of a table with a velocity axis (queries at
 * every velocity node, at 0, between nodes, negative and beyond the grid); prefixes GLSL or C++
 * would refuse are refused; the JSON export carries the values. */
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
    /* a table with a velocity axis (0 to 16 deg/s, never-visible nodes at high velocity and
     * frequency), both views: PREFIX_threshold3 as well as the 2-D function */
    static const double vel[5] = {0, 1, 4, 8, 16};
    static double thr3[8 * 6 * 5];
    for (int v = 0; v < 5; v++)
        for (int k = 0; k < 48; k++) {
            double x = fx.thr[k] * pow(1.4, v) * (1 + 0.1 * csf_rng_normal(71, 5, (uint64_t)(v * 48 + k)));
            thr3[v * 48 + k] = x > 1 ? INFINITY : x;
        }
    csflut_build b3 = fx.b;
    b3.n_vel = 5;
    b3.vel_dps = vel;
    b3.threshold = thr3;
    b3.stderr_log10 = NULL;
    csflut_table *t3 = fx_open(&b3);
    CHECK(t3 != NULL);
    const char *prefixes3[2] = {"lut3_raw", "lut3_cons"};
    for (int view = 0; view < 2; view++) {
        csflut_set_conservative(t3, view);
        char *hdr;
        CHECK_INT_EQ(csflut_export(t3, CSFLUT_FORMAT_C, prefixes3[view], &hdr, NULL), CSFLUT_OK);
        CHECK_STR_CONTAINS(hdr, "log2(|v| + 0.5)");
        CHECK_STR_CONTAINS(hdr,
                           view ? "lut3_cons_threshold3(double freq_cpd, double ecc_deg, double vel_dps)"
                                : "lut3_raw_perceptible3(double freq_cpd, double ecc_deg, double vel_dps,");
        snprintf(path, sizeof path, "%s/%s.h", dir, prefixes3[view]);
        CHECK(write_text(path, hdr) == 0);
        free(hdr);
    }
    /* the 2-D export of a 2-D table has no velocity part */
    {
        char *hdr;
        CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_C, NULL, &hdr, NULL), CSFLUT_OK);
        CHECK(strstr(hdr, "threshold3") == NULL);
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
    static double qf[NQ], qe[NQ], qv[NQ];
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
    /* velocities: every node, 0, between nodes, negative (drift direction), beyond the grid */
    for (int i = 0; i < NQ; i++)
        qv[i] = i < 5 ? vel[i] : (i % 9 == 0 ? 0.0 : -4 + 26 * csf_rng_next_uniform(&r));
    /* the program: each header included in its own right; queries in decimal with 17 digits
     * (exact, and legal in C++11, which has no hex-float literals) */
    size_t cap = 100 * NQ + 4096, n = 0;
    char *src = malloc(cap);
    n += (size_t)snprintf(src + n, cap - n,
                          "#include <stdio.h>\n#include \"lut_raw.h\"\n#include \"lut_cons.h\"\n"
                          "#include \"lut3_raw.h\"\n#include \"lut3_cons.h\"\n"
                          "static const double qf[%d] = {",
                          NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%.17g", i ? "," : "", qf[i]);
    n += (size_t)snprintf(src + n, cap - n, "};\nstatic const double qe[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%.17g", i ? "," : "", qe[i]);
    n += (size_t)snprintf(src + n, cap - n, "};\nstatic const double qv[%d] = {", NQ);
    for (int i = 0; i < NQ; i++) n += (size_t)snprintf(src + n, cap - n, "%s%.17g", i ? "," : "", qv[i]);
    snprintf(src + n, cap - n,
             "};\nint main(void)\n{\n    for (int i = 0; i < %d; i++)\n"
             "        printf(\"%%a %%a %%d %%a %%a %%a %%d\\n\", lut_raw_threshold(qf[i], qe[i]),\n"
             "               lut_cons_threshold(qf[i], qe[i]), lut_cons_perceptible(qf[i], qe[i], 0.01),\n"
             "               lut3_raw_threshold3(qf[i], qe[i], qv[i]),\n"
             "               lut3_cons_threshold3(qf[i], qe[i], qv[i]), lut3_cons_threshold(qf[i], qe[i]),\n"
             "               lut3_cons_perceptible3(qf[i], qe[i], qv[i], 0.02));\n"
             "    return 0;\n}\n",
             NQ);
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
        int lines = 0, agree = 1, exact = 0, exact3 = 0;
        double worst = 0;
        if (p) {
            char line[512];
            while (fgets(line, sizeof line, p) && lines < NQ) {
                double got[2], got3[3];
                int vis, vis3;
                if (sscanf(line, "%la %la %d %la %la %la %d", &got[0], &got[1], &vis, &got3[0], &got3[1],
                           &got3[2], &vis3) != 7) {
                    agree = 0;
                    break;
                }
                for (int view = 0; view < 2; view++) {
                    csflut_set_conservative(t, view);
                    double want = csflut_threshold(t, qf[lines], qe[lines]);
                    double d = rel_diff(got[view], want);
                    if (d > worst) worst = d;
                    if (memcmp(&got[view], &want, sizeof want) == 0) exact++;
                    csflut_set_conservative(t3, view);
                    double want3 = csflut_threshold3(t3, qf[lines], qe[lines], qv[lines]);
                    if (memcmp(&got3[view], &want3, sizeof want3) == 0) exact3++;
                }
                double want2 = csflut_threshold(t3, qf[lines], qe[lines]);
                if (memcmp(&got3[2], &want2, sizeof want2) == 0) exact3++;
                if (vis != csflut_perceptible(t, qf[lines], qe[lines], 0.01)) agree = 0;
                if (vis3 != csflut_perceptible3(t3, qf[lines], qe[lines], qv[lines], 0.02)) agree = 0;
                lines++;
            }
            CHECK(pclose(p) == 0);
        }
        CHECK_INT_EQ(lines, NQ);
        CHECK(agree);
        CHECK_MSG(exact == 2 * NQ, "%s -std=%s %s: only %d of %d bit-identical (worst %g)",
                  builds[k][0], builds[k][1], builds[k][3], exact, 2 * NQ, worst);
        CHECK_MSG(exact3 == 3 * NQ, "%s -std=%s %s: velocity table: only %d of %d bit-identical",
                  builds[k][0], builds[k][1], builds[k][3], exact3, 3 * NQ);
        fprintf(stderr,
                "C header, %s -std=%s %s: %d queries x 2 views, %d bit-identical; "
                "velocity table %d of %d\n",
                builds[k][0], builds[k][1], builds[k][3], NQ, exact, exact3, 3 * NQ);
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
    /* the JSON export of the velocity table names the warp */
    CHECK_INT_EQ(csflut_export(t3, CSFLUT_FORMAT_JSON, NULL, &json, NULL), CSFLUT_OK);
    CHECK_STR_CONTAINS(json, "\"name\": \"velocity\"");
    CHECK_STR_CONTAINS(json, "\"warp_v0_dps\": 0.5");
    free(json);
    csflut_close(t3);
    csflut_close(t);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
    return CHECK_RESULT();
}
