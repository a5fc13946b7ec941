/* Exports of a csflut table: CSV (re-importable, every axis, raw values, %.17g so a round trip is
 * bit-exact), JSON, a self-contained C header and a GLSL function. The C and GLSL forms hold the
 * 2-D (frequency, eccentricity) view at the table's default velocity and luminance and reproduce
 * csflut_threshold: same nodes (C: 17-digit decimals, bit-exact), same cell search, same nested lerp. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csflut.h"
#include "csflut_internal.h"

typedef struct {
    char *s;
    size_t len, cap;
    int oom;
} sbuf;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void sb_printf(sbuf *b, const char *fmt, ...)
{
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        size_t room = b->cap - b->len;
        int n = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? room : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->oom = 1;
            return;
        }
        if ((size_t)n < room && b->s) {
            b->len += (size_t)n;
            return;
        }
        size_t nc = b->cap ? b->cap * 2 : 4096;
        while (nc < b->len + (size_t)n + 1) nc *= 2;
        char *ns = realloc(b->s, nc);
        if (!ns) {
            b->oom = 1;
            return;
        }
        b->s = ns;
        b->cap = nc;
    }
}

/* The shortest decimal that reads back as the same double (exact, and 0.3 prints as 0.3). */
static void sb_real(sbuf *b, double v)
{
    char buf[40];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (strtod(buf, NULL) == v) break;
    }
    sb_printf(b, "%s", buf);
}

/* Exact numbers, with inf/nan spelled the way the CSV importer reads them. */
static void sb_num(sbuf *b, double v)
{
    if (v != v) sb_printf(b, "nan");
    else if (isinf(v)) sb_printf(b, v > 0 ? "inf" : "-inf");
    else sb_real(b, v);
}

static void sb_json_str(sbuf *b, const char *s)
{
    sb_printf(b, "\"");
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') sb_printf(b, "\\%c", *p);
        else if (*p < 0x20) sb_printf(b, "\\u%04x", *p);
        else sb_printf(b, "%c", *p);
    }
    sb_printf(b, "\"");
}

/* JSON has no infinity or NaN: null stands for "never visible" in thresholds and "unknown" in
 * stderr and metadata numbers. */
static void sb_json_num(sbuf *b, double v)
{
    if (!isfinite(v)) sb_printf(b, "null");
    else sb_real(b, v);
}

static const char *const csv_cols[4] = {"freq_cpd", "ecc_deg", "velocity_dps", "lum_cdm2"};

/* Comment text may not break out of its comment: newlines become spaces. */
static void sb_comment_str(sbuf *b, const char *s)
{
    for (; *s; s++) sb_printf(b, "%c", (*s == '\n' || *s == '\r') ? ' ' : *s);
}

static void export_csv(const csflut_table *t, sbuf *b)
{
    const char *keys[5] = {"observer", "display_profile_id", "method", "date_utc", "tool_version"};
    const char *vals[5] = {csflut_observer(t), csflut_display_profile_id(t), csflut_method(t),
                           csflut_date_utc(t), csflut_tool_version(t)};
    sb_printf(b, "# csflut %d.%d threshold table\n", t->vmaj, t->vmin);
    for (int k = 0; k < 5; k++) {
        sb_printf(b, "# %s: ", keys[k]);
        sb_comment_str(b, vals[k]);
        sb_printf(b, "\n");
    }
    sb_printf(b, "# viewing_distance_mm: ");
    sb_num(b, t->dist_mm);
    sb_printf(b, "\n# mean_lum_cdm2: ");
    sb_num(b, t->mean_lum);
    sb_printf(b, "\n# trials: %d\n", t->trials);
    for (int k = 0; k < t->n_meta; k++) /* keys and values hold no line break (csflut_check_meta) */
        sb_printf(b, "# meta.%s: %s\n", t->meta_key[k], t->meta_val[k]);
    for (int a = 0; a < 4; a++)
        if (t->n[a] > 0) sb_printf(b, "%s,", csv_cols[a]);
    sb_printf(b, "threshold%s\n", t->se ? ",stderr_log10" : "");
    size_t nf = (size_t)t->n[0], ne = (size_t)t->n[1], nv = t->n[2] > 0 ? (size_t)t->n[2] : 1;
    for (size_t k = 0; k < t->n_nodes; k++) {
        size_t idx[4] = {k % nf, (k / nf) % ne, (k / nf / ne) % nv, k / nf / ne / nv};
        for (int a = 0; a < 4; a++)
            if (t->n[a] > 0) {
                sb_num(b, t->pts[a][idx[a]]);
                sb_printf(b, ",");
            }
        sb_num(b, t->raw[k]);
        if (t->se) {
            sb_printf(b, ",");
            if (t->se[k] == t->se[k]) sb_num(b, t->se[k]);
        }
        sb_printf(b, "\n");
    }
}

static void sb_json_array(sbuf *b, const double *v, size_t n)
{
    sb_printf(b, "[");
    for (size_t i = 0; i < n; i++) {
        if (i) sb_printf(b, ",");
        sb_json_num(b, v[i]);
    }
    sb_printf(b, "]");
}

static void export_json(const csflut_table *t, sbuf *b)
{
    sb_printf(b, "{\n  \"format\": \"csflut\",\n  \"version\": \"%d.%d\",\n", t->vmaj, t->vmin);
    sb_printf(b, "  \"metadata\": {\"observer\": ");
    sb_json_str(b, csflut_observer(t));
    sb_printf(b, ", \"display_profile_id\": ");
    sb_json_str(b, csflut_display_profile_id(t));
    sb_printf(b, ", \"method\": ");
    sb_json_str(b, csflut_method(t));
    sb_printf(b, ", \"date_utc\": ");
    sb_json_str(b, csflut_date_utc(t));
    sb_printf(b, ", \"tool_version\": ");
    sb_json_str(b, csflut_tool_version(t));
    sb_printf(b, ", \"viewing_distance_mm\": ");
    sb_json_num(b, t->dist_mm);
    sb_printf(b, ", \"mean_lum_cdm2\": ");
    sb_json_num(b, t->mean_lum);
    sb_printf(b, ", \"trials\": %d},\n  \"meta\": {", t->trials);
    for (int k = 0; k < t->n_meta; k++) {
        sb_printf(b, k ? ", " : "");
        sb_json_str(b, t->meta_key[k]);
        sb_printf(b, ": ");
        sb_json_str(b, t->meta_val[k]);
    }
    sb_printf(b, "},\n  \"axes\": [");
    int first = 1;
    for (int a = 0; a < 4; a++) {
        if (t->n[a] == 0) continue;
        sb_printf(b, "%s\n    {\"name\": \"%s\", \"unit\": \"%s\", \"scale\": \"%s\", \"points\": ",
                  first ? "" : ",", csflut_axis_name((csflut_axis)a),
                  csflut_axis_unit((csflut_axis)a), t->scale[a] ? "log" : "linear");
        sb_json_array(b, t->pts[a], (size_t)t->n[a]);
        if (a == CSFLUT_AXIS_VEL && t->vel_v0 == t->vel_v0) {
            sb_printf(b, ", \"warp\": \"log(|v| + v0)\", \"warp_v0_dps\": ");
            sb_real(b, t->vel_v0);
        }
        sb_printf(b, "}");
        first = 0;
    }
    sb_printf(b, "\n  ],\n  \"index\": \"((lum*n_vel + vel)*n_ecc + ecc)*n_freq + freq\",\n");
    sb_printf(b, "  \"threshold\": ");
    sb_json_array(b, t->raw, t->n_nodes);
    sb_printf(b, ",\n  \"threshold_conservative\": ");
    sb_json_array(b, t->cons, t->n_nodes);
    sb_printf(b, ",\n  \"conservative_stderr_shift\": %.17g", t->k_shift);
    if (t->se) {
        sb_printf(b, ",\n  \"stderr_log10\": ");
        sb_json_array(b, t->se, t->n_nodes);
    }
    sb_printf(b, "\n}\n");
}

/* Appends tpl with every '@' replaced by the prefix (generated code names many prefixed
 * identifiers). */
static void sb_tpl(sbuf *b, const char *px, const char *tpl)
{
    for (const char *p = tpl; *p;) {
        const char *at = strchr(p, '@');
        size_t n = at ? (size_t)(at - p) : strlen(p);
        sb_printf(b, "%.*s", (int)n, p);
        if (!at) break;
        sb_printf(b, "%s", px);
        p = at + 1;
    }
}

/* Decimal with 17 significant digits: reads back as the same double in C and C++ (hex-float
 * literals are not C++ before C++17). All values are finite: invisible nodes hold the cap. */
static void sb_c_double(sbuf *b, double v) { sb_printf(b, "%.17g", v); }

static void sb_c_array(sbuf *b, const char *px, const char *name, const double *v, int n,
                       int per_line)
{
    sb_printf(b, "static const double %s_%s[%d] = {", px, name, n);
    for (int i = 0; i < n; i++) {
        sb_printf(b, i % per_line ? ", " : (i ? ",\n    " : "\n    "));
        sb_c_double(b, v[i]);
    }
    sb_printf(b, "};\n");
}

/* First lines of every generated function body. At the start of a compound statement the
 * standard pragma holds to the end of that body only, so the header changes nothing in the code
 * that includes it. GCC ignores the pragma and warns about it under -Wall (unknown-pragmas), which
 * with -Werror stops the build: it is left out for GCC, whose contraction the header's comment
 * covers (-ffp-contract=off). */
#define C_NO_CONTRACT                                                                              \
    "#if defined(__clang__) || !defined(__GNUC__)\n"                                             \
    "#pragma STDC FP_CONTRACT OFF\n"                                                              \
    "#endif\n"

/* How the velocity axis is interpolated, for the generated comments. */
static void sb_vel_coord_name(sbuf *b, const csflut_table *t)
{
    if (t->vel_v0 == t->vel_v0) sb_printf(b, "log2(|v| + %.17g)", t->vel_v0);
    else sb_printf(b, "%s", t->scale[2] == CSFLUT_SCALE_LOG ? "log2 |v|" : "|v|");
}

/* The header's opening comment, include guard and the grid as constant arrays. */
static void export_c_data(const csflut_table *t, const char *px, sbuf *b)
{
    const csflut_axis_fast *F = &t->fx, *E = &t->ex;
    const double *v = t->conservative ? t->slice_cons : t->slice_raw;
    sb_printf(b, "/* Generated by csflut %s from a csfcal threshold table: do not edit.\n"
                 " * Observer: ", CSFLUT_LIB_VERSION);
    sb_comment_str(b, csflut_observer(t));
    sb_printf(b, "; display: ");
    sb_comment_str(b, csflut_display_profile_id(t));
    sb_printf(b, "; view: %s.\n"
                 " * double %s_threshold(double freq_cpd, double ecc_deg) returns the threshold\n"
                 " * Michelson contrast: log2 thresholds blended bilinearly in log2 frequency and\n"
                 " * linear eccentricity, clamped to the grid edges; a never-visible node enters as\n"
                 " * the cap, and HUGE_VAL (never visible) is returned only where the blend is the cap.\n"
                 " * int %s_perceptible(double freq_cpd, double ecc_deg, double contrast) is 1 when\n"
                 " * contrast >= that threshold: 0 where never visible, 0 for a NaN argument.\n"
                 " * A NaN frequency or eccentricity gives a NaN threshold (as csflut_threshold).\n"
                 " * Bit for bit csflut_threshold() with any libm, as long as the compiler does not\n"
                 " * fuse a * b + c into one FMA: each function says #pragma STDC FP_CONTRACT OFF,\n"
                 " * which clang honours (unless -ffp-contract=fast) but GCC ignores, so it is\n"
                 " * emitted for compilers other than GCC. gcc in GNU modes (gnu99, gnu11: its\n"
                 " * default) and g++ in every mode fuse on a target with FMA (-march=native on x86,\n"
                 " * aarch64): build with -ffp-contract=off there. Never -ffast-math.\n"
                 " * C99 or later, C++11 or later. */\n",
              t->conservative ? "conservative" : "raw", px, px);
    sb_printf(b, "#ifndef %s_H\n#define %s_H\n#include <math.h>\n\n", px, px);
    sb_printf(b, "#define %s_NF %d\n#define %s_NE %d\n", px, F->n, px, E->n);
    sb_printf(b, "static const double %s_cap_log2 = ", px);
    sb_c_double(b, t->cap_log2);
    sb_printf(b, ";\n");
    sb_c_array(b, px, "freq_log2", F->node, F->n, 4);
    sb_c_array(b, px, "freq_inv_step", F->inv_step, F->n - 1, 4);
    sb_c_array(b, px, "ecc_deg", E->node, E->n, 4);
    sb_c_array(b, px, "ecc_inv_step", E->inv_step, E->n - 1, 4);
    sb_printf(b, "/* log2 threshold, [ecc][freq] */\n");
    sb_c_array(b, px, "log2_thr", v, F->n * E->n, 4);
    if (t->n[2] > 0) {
        const csflut_axis_fast *V = &t->vx;
        sb_printf(b, "/* velocity in its interpolation coordinate, ");
        sb_vel_coord_name(b, t);
        sb_printf(b, " */\n#define %s_NV %d\n", px, V->n);
        sb_c_array(b, px, "vel_coord", V->node, V->n, 4);
        sb_c_array(b, px, "vel_inv_step", V->inv_step, V->n - 1, 4);
        sb_printf(b, "/* log2 threshold, [velocity][ecc][freq] */\n");
        sb_c_array(b, px, "log2_thr3", t->conservative ? t->slice3_cons : t->slice3_raw, V->n * E->n * F->n,
                   4);
    }
    sb_printf(b, "\n");
}

/* log2 and exp2 exactly as the library computes them (csflut_internal.h), so the header
 * gives the same bits with any libm: frexp and ldexp are exact. */
static void export_c_log2_exp2(const char *px, sbuf *b)
{
    sb_printf(b,
              "static inline double %s_log2_poly(double m, double e)\n"
              "{\n"
              C_NO_CONTRACT
              "    double s = (m - 1) / (m + 1), z = s * s, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;\n"
              "    double a0 = 2.8853900817779268 + 0.9617966939259757 * z;\n"
              "    double a1 = 0.5770780163555853 + 0.41219858311113244 * z;\n"
              "    double a2 = 0.3205988979753252 + 0.2623081892525388 * z;\n"
              "    double a3 = 0.2219530832136867 + 0.19235933878519512 * z;\n"
              "    double a4 = 0.16972882833987804 + 0.15186263588304877 * z;\n"
              "    double b0 = a0 + a1 * z2, b1 = a2 + a3 * z2, b2 = a4 + 0.1373995277037108 * z2;\n"
              "    double p = (b0 + b1 * z4) + b2 * z8;\n"
              "    return e + s * p;\n"
              "}\n"
              "\n", px);
    sb_printf(b,
              "static inline double %s_log2(double x)\n"
              "{\n"
              C_NO_CONTRACT
              "    int e;\n"
              "    x = x > 2.2250738585072014e-308 ? x : 2.2250738585072014e-308;\n"
              "    x = x < 1.7976931348623157e+308 ? x : 1.7976931348623157e+308;\n"
              "    double m = frexp(x, &e);\n"
              "    if (m < 0.70710678118654757) {\n"
              "        m *= 2;\n"
              "        e -= 1;\n"
              "    }\n"
              "    return %s_log2_poly(m, (double)e);\n"
              "}\n\n", px, px);
    sb_printf(b,
              "static inline double %s_exp2_poly(double f)\n"
              "{\n"
              C_NO_CONTRACT
              "    double f2 = f * f, f4 = f2 * f2, f8 = f4 * f4;\n"
              "    double a0 = 1.0 + 0.6931471805599453 * f;\n"
              "    double a1 = 0.2402265069591007 + 0.055504108664821576 * f;\n"
              "    double a2 = 0.009618129107628477 + 0.0013333558146428441 * f;\n"
              "    double a3 = 0.00015403530393381606 + 1.5252733804059838e-05 * f;\n"
              "    double a4 = 1.3215486790144305e-06 + 1.0178086009239696e-07 * f;\n"
              "    double a5 = 7.054911620801121e-09 + 4.44553827187081e-10 * f;\n"
              "    double a6 = 2.5678435993488196e-11 + 1.3691488853904124e-12 * f;\n"
              "    double b0 = a0 + a1 * f2, b1 = a2 + a3 * f2, b2 = a4 + a5 * f2;\n"
              "    double c0 = b0 + b1 * f4, c1 = b2 + a6 * f4;\n"
              "    return c0 + c1 * f8;\n"
              "}\n"
              "\n", px);
    sb_printf(b,
              "static inline double %s_exp2(double r)\n"
              "{\n"
              C_NO_CONTRACT
              "    double t = r + 6755399441055744.0;\n"
              "    double k = t - 6755399441055744.0;\n"
              "    return ldexp(%s_exp2_poly(r - k), (int)k);\n"
              "}\n\n", px, px);
}

/* The bilinear blend over the grid and the visibility test built on it. */
static void export_c_lookup(const char *px, sbuf *b)
{
    sb_printf(b,
              "static inline double %s_lerp(double a, double b, double w)\n"
              "{\n"
              C_NO_CONTRACT
              "    return (1 - w) * a + w * b;\n"
              "}\n\n", px);
    sb_printf(b,
              "static inline double %s_threshold(double freq_cpd, double ecc_deg)\n"
              "{\n"
              C_NO_CONTRACT
              "    if (freq_cpd != freq_cpd || ecc_deg != ecc_deg) return NAN;\n"
              "    double u = %s_log2(freq_cpd);\n"
              "    u = u > %s_freq_log2[0] ? u : %s_freq_log2[0];\n"
              "    u = u < %s_freq_log2[%s_NF - 1] ? u : %s_freq_log2[%s_NF - 1];\n"
              "    double e = ecc_deg > %s_ecc_deg[0] ? ecc_deg : %s_ecc_deg[0];\n"
              "    e = e < %s_ecc_deg[%s_NE - 1] ? e : %s_ecc_deg[%s_NE - 1];\n"
              "    int i = 0, j = 0;\n"
              "    while (i < %s_NF - 2 && u >= %s_freq_log2[i + 1]) i++;\n"
              "    while (j < %s_NE - 2 && e >= %s_ecc_deg[j + 1]) j++;\n"
              "    double wf = u >= %s_freq_log2[i + 1] ? 1.0 : (u - %s_freq_log2[i]) * %s_freq_inv_step[i];\n"
              "    double we = e >= %s_ecc_deg[j + 1] ? 1.0 : (e - %s_ecc_deg[j]) * %s_ecc_inv_step[j];\n"
              "    const double *v = %s_log2_thr + j * %s_NF + i;\n"
              "    double r0 = %s_lerp(v[0], v[1], wf);\n"
              "    double r1 = %s_lerp(v[%s_NF], v[%s_NF + 1], wf);\n"
              "    double r = %s_lerp(r0, r1, we);\n"
              "    return r >= %s_cap_log2 ? HUGE_VAL : %s_exp2(r);\n"
              "}\n\n",
              px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px);
    sb_printf(b,
              "/* 1 if a pattern of this contrast at this frequency and eccentricity is visible. */\n"
              "static inline int %s_perceptible(double freq_cpd, double ecc_deg, double contrast)\n"
              "{\n" C_NO_CONTRACT "    return contrast >= %s_threshold(freq_cpd, ecc_deg);\n"
              "}\n\n",
              px, px);
}

/* The velocity coordinate as the library computes it (csflut_vel_coord). */
static void export_c_vel_coord(const csflut_table *t, const char *px, sbuf *b)
{
    sb_tpl(b, px,
           "static inline double @_vel_coord_of(double vel_dps)\n{\n" C_NO_CONTRACT
           "    double a = vel_dps < 0 ? -vel_dps : vel_dps;\n");
    if (t->vel_v0 == t->vel_v0) {
        sb_tpl(b, px, "    return @_log2(a + ");
        sb_c_double(b, t->vel_v0);
        sb_printf(b, ");\n}\n\n");
    } else if (t->scale[2] == CSFLUT_SCALE_LOG) {
        sb_tpl(b, px, "    return @_log2(a);\n}\n\n");
    } else {
        sb_printf(b, "    return a;\n}\n\n");
    }
}

/* The trilinear blend over the velocity slices: csflut_threshold3 operation for operation. */
static void export_c_lookup3(const csflut_table *t, const char *px, sbuf *b)
{
    export_c_vel_coord(t, px, b);
    sb_tpl(b, px,
           "/* Threshold at a velocity (deg/s; its sign does not matter), at the table's default\n"
           " * luminance: csflut_threshold3 bit for bit. */\n"
           "static inline double @_threshold3(double freq_cpd, double ecc_deg, double vel_dps)\n"
           "{\n" C_NO_CONTRACT
           "    if (freq_cpd != freq_cpd || ecc_deg != ecc_deg || vel_dps != vel_dps) return NAN;\n"
           "    double u = @_log2(freq_cpd);\n"
           "    u = u > @_freq_log2[0] ? u : @_freq_log2[0];\n"
           "    u = u < @_freq_log2[@_NF - 1] ? u : @_freq_log2[@_NF - 1];\n"
           "    double e = ecc_deg > @_ecc_deg[0] ? ecc_deg : @_ecc_deg[0];\n"
           "    e = e < @_ecc_deg[@_NE - 1] ? e : @_ecc_deg[@_NE - 1];\n"
           "    double c = @_vel_coord_of(vel_dps);\n"
           "    c = c > @_vel_coord[0] ? c : @_vel_coord[0];\n"
           "    c = c < @_vel_coord[@_NV - 1] ? c : @_vel_coord[@_NV - 1];\n"
           "    int i = 0, j = 0, k = 0;\n"
           "    while (i < @_NF - 2 && u >= @_freq_log2[i + 1]) i++;\n"
           "    while (j < @_NE - 2 && e >= @_ecc_deg[j + 1]) j++;\n"
           "    while (k < @_NV - 2 && c >= @_vel_coord[k + 1]) k++;\n"
           "    double wf = u >= @_freq_log2[i + 1] ? 1.0 : (u - @_freq_log2[i]) * @_freq_inv_step[i];\n"
           "    double we = e >= @_ecc_deg[j + 1] ? 1.0 : (e - @_ecc_deg[j]) * @_ecc_inv_step[j];\n"
           "    double wv = c >= @_vel_coord[k + 1] ? 1.0 : (c - @_vel_coord[k]) * @_vel_inv_step[k];\n"
           "    const double *v0 = @_log2_thr3 + (k * @_NE + j) * @_NF + i;\n"
           "    const double *v1 = v0 + @_NE * @_NF;\n"
           "    double b0 = @_lerp(@_lerp(v0[0], v0[1], wf), @_lerp(v0[@_NF], v0[@_NF + 1], wf), we);\n"
           "    double b1 = @_lerp(@_lerp(v1[0], v1[1], wf), @_lerp(v1[@_NF], v1[@_NF + 1], wf), we);\n"
           "    double r = @_lerp(b0, b1, wv);\n"
           "    return r >= @_cap_log2 ? HUGE_VAL : @_exp2(r);\n"
           "}\n\n"
           "/* 1 if a pattern of this contrast is visible at that frequency, eccentricity and\n"
           " * velocity. */\n"
           "static inline int @_perceptible3(double freq_cpd, double ecc_deg, double vel_dps,\n"
           "                                 double contrast)\n"
           "{\n" C_NO_CONTRACT "    return contrast >= @_threshold3(freq_cpd, ecc_deg, vel_dps);\n"
           "}\n\n");
}

static void export_c(const csflut_table *t, const char *px, sbuf *b)
{
    export_c_data(t, px, b);
    export_c_log2_exp2(px, b);
    export_c_lookup(px, b);
    if (t->n[2] > 0) export_c_lookup3(t, px, b);
    sb_printf(b, "#endif\n");
}

static void sb_glsl_array(sbuf *b, const char *px, const char *name, const double *v, int n)
{
    sb_printf(b, "const float %s_%s[%d] = float[%d](", px, name, n, n);
    for (int i = 0; i < n; i++) {
        sb_printf(b, i % 4 ? ", " : (i ? ",\n    " : "\n    "));
        sb_printf(b, "%.9e", v[i]);
    }
    sb_printf(b, ");\n");
}

/* The velocity slices and PREFIX_threshold3 / PREFIX_perceptible3, in float32. */
static void export_glsl3(const csflut_table *t, const char *px, sbuf *b)
{
    const csflut_axis_fast *F = &t->fx, *E = &t->ex, *V = &t->vx;
    sb_printf(b, "\n// Velocity (deg/s; its sign does not matter) in the coordinate ");
    sb_vel_coord_name(b, t);
    sb_printf(b,
              ";\n// float %s_threshold3(float freq_cpd, float ecc_deg, float vel_dps) and\n"
              "// bool %s_perceptible3(..., float contrast): csflut_threshold3 in float32.\n",
              px, px);
    sb_printf(b, "const int %s_NV = %d;\n", px, V->n);
    sb_glsl_array(b, px, "vel_coord", V->node, V->n);
    sb_printf(b, "// log2 threshold, [velocity][ecc][freq]\n");
    sb_glsl_array(b, px, "log2_thr3", t->conservative ? t->slice3_cons : t->slice3_raw, V->n * E->n * F->n);
    sb_tpl(b, px, "\nfloat @_vel_coord_of(float vel_dps)\n{\n");
    if (t->vel_v0 == t->vel_v0) sb_printf(b, "    return log2(abs(vel_dps) + %.9e);\n", t->vel_v0);
    else if (t->scale[2] == CSFLUT_SCALE_LOG) sb_printf(b, "    return log2(max(abs(vel_dps), 1e-30));\n");
    else sb_printf(b, "    return abs(vel_dps);\n");
    sb_tpl(b, px,
           "}\n\n"
           "float @_threshold3(float freq_cpd, float ecc_deg, float vel_dps)\n"
           "{\n"
           "    float u = clamp(log2(max(freq_cpd, 1e-30)), @_freq_log2[0], @_freq_log2[@_NF - 1]);\n"
           "    float e = clamp(ecc_deg, @_ecc_deg[0], @_ecc_deg[@_NE - 1]);\n"
           "    float c = clamp(@_vel_coord_of(vel_dps), @_vel_coord[0], @_vel_coord[@_NV - 1]);\n"
           "    int i = 0, j = 0, k = 0;\n"
           "    while (i < @_NF - 2 && u >= @_freq_log2[i + 1]) i++;\n"
           "    while (j < @_NE - 2 && e >= @_ecc_deg[j + 1]) j++;\n"
           "    while (k < @_NV - 2 && c >= @_vel_coord[k + 1]) k++;\n"
           "    float wf = clamp((u - @_freq_log2[i]) / (@_freq_log2[i + 1] - @_freq_log2[i]), 0.0, 1.0);\n"
           "    float we = clamp((e - @_ecc_deg[j]) / (@_ecc_deg[j + 1] - @_ecc_deg[j]), 0.0, 1.0);\n"
           "    float wv = clamp((c - @_vel_coord[k]) / (@_vel_coord[k + 1] - @_vel_coord[k]), 0.0, 1.0);\n"
           "    int a = (k * @_NE + j) * @_NF + i, p = @_NE * @_NF;\n"
           "    float b0 = mix(mix(@_log2_thr3[a], @_log2_thr3[a + 1], wf),\n"
           "                   mix(@_log2_thr3[a + @_NF], @_log2_thr3[a + @_NF + 1], wf), we);\n"
           "    float b1 = mix(mix(@_log2_thr3[a + p], @_log2_thr3[a + p + 1], wf),\n"
           "                   mix(@_log2_thr3[a + p + @_NF], @_log2_thr3[a + p + @_NF + 1], wf), we);\n"
           "    float r = mix(b0, b1, wv);\n"
           "    return r >= @_cap_log2 - 1e-5 ? uintBitsToFloat(0x7f800000u) : exp2(r);\n"
           "}\n\n"
           "bool @_perceptible3(float freq_cpd, float ecc_deg, float vel_dps, float contrast)\n"
           "{\n"
           "    return contrast >= @_threshold3(freq_cpd, ecc_deg, vel_dps);\n"
           "}\n");
}

static void export_glsl(const csflut_table *t, const char *px, sbuf *b)
{
    const csflut_axis_fast *F = &t->fx, *E = &t->ex;
    const double *v = t->conservative ? t->slice_cons : t->slice_raw;
    sb_printf(b, "// Generated by csflut %s from a csfcal threshold table: do not edit.\n"
                 "// float %s_threshold(float freq_cpd, float ecc_deg): threshold Michelson\n"
                 "// contrast (float32); log2 thresholds blended in log2 frequency x linear\n"
                 "// eccentricity, clamped to the grid; a never-visible node enters as the cap;\n"
                 "// +inf = never visible.\n"
                 "// bool %s_perceptible(float freq_cpd, float ecc_deg, float contrast): true when\n"
                 "// contrast >= that threshold; false where never visible.\n"
                 "// NaN arguments: csflut_threshold gives NaN (and perceptible false); GLSL leaves\n"
                 "// max and clamp of NaN undefined, so here the result is the driver's (Mesa\n"
                 "// llvmpipe: a finite threshold). Keep NaN out, or test isnan() before the call.\n"
                 "// GLSL 3.30 / ES 3.00 or later (uintBitsToFloat). Include it after #version.\n"
                 "// Under GLSL ES it sets the default precision to highp for float and int (an ES\n"
                 "// fragment shader has no default float precision; mediump is too coarse for\n"
                 "// these numbers): code after it gets highp unless it says otherwise.\n"
                 "// View: %s.\n",
              CSFLUT_LIB_VERSION, px, px, t->conservative ? "conservative" : "raw");
    sb_printf(b, "#ifdef GL_ES\nprecision highp float;\nprecision highp int;\n#endif\n");
    sb_printf(b, "const int %s_NF = %d;\nconst int %s_NE = %d;\n", px, F->n, px, E->n);
    sb_printf(b, "const float %s_cap_log2 = %.9e;\n", px, t->cap_log2);
    sb_glsl_array(b, px, "freq_log2", F->node, F->n);
    sb_glsl_array(b, px, "ecc_deg", E->node, E->n);
    sb_printf(b, "// log2 threshold, [ecc][freq]\n");
    sb_glsl_array(b, px, "log2_thr", v, F->n * E->n);
    sb_printf(b, "\n");
    /* The cap test allows float rounding: cap_log2 is at least one log2 unit above every visible
     * value, so a blend within 1e-5 of it has at most that weight on visible corners. */
    sb_printf(b,
              "float %s_threshold(float freq_cpd, float ecc_deg)\n"
              "{\n"
              "    float u = clamp(log2(max(freq_cpd, 1e-30)), %s_freq_log2[0], %s_freq_log2[%s_NF - 1]);\n"
              "    float e = clamp(ecc_deg, %s_ecc_deg[0], %s_ecc_deg[%s_NE - 1]);\n"
              "    int i = 0, j = 0;\n"
              "    while (i < %s_NF - 2 && u >= %s_freq_log2[i + 1]) i++;\n"
              "    while (j < %s_NE - 2 && e >= %s_ecc_deg[j + 1]) j++;\n"
              "    float wf = clamp((u - %s_freq_log2[i]) / (%s_freq_log2[i + 1] - %s_freq_log2[i]), 0.0, 1.0);\n"
              "    float we = clamp((e - %s_ecc_deg[j]) / (%s_ecc_deg[j + 1] - %s_ecc_deg[j]), 0.0, 1.0);\n"
              "    int k = j * %s_NF + i;\n"
              "    float r0 = mix(%s_log2_thr[k], %s_log2_thr[k + 1], wf);\n"
              "    float r1 = mix(%s_log2_thr[k + %s_NF], %s_log2_thr[k + %s_NF + 1], wf);\n"
              "    float r = mix(r0, r1, we);\n"
              "    return r >= %s_cap_log2 - 1e-5 ? uintBitsToFloat(0x7f800000u) : exp2(r);\n"
              "}\n\n",
              px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px, px);
    sb_printf(b,
              "bool %s_perceptible(float freq_cpd, float ecc_deg, float contrast)\n"
              "{\n"
              "    return contrast >= %s_threshold(freq_cpd, ecc_deg);\n"
              "}\n", px, px);
    if (t->n[2] > 0) export_glsl3(t, px, b);
}

static int is_identifier(const char *s)
{
    if (!s || !*s || strlen(s) > 64) return 0;
    if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || *s == '_')) return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              *s == '_'))
            return 0;
    return 1;
}

/* The prefix starts every generated name (PREFIX_threshold, PREFIX_NF, ...), in C and in GLSL:
 * GLSL refuses names that start with "gl_", and reserves names containing "__" (so does C++, in
 * which the C header must also compile); a prefix ending in '_' puts "__" into PREFIX_threshold. */
static int is_usable_prefix(const char *s)
{
    if (!is_identifier(s)) return 0;
    if (strncmp(s, "gl_", 3) == 0) return 0;
    if (strstr(s, "__") || s[strlen(s) - 1] == '_') return 0;
    return 1;
}

csflut_status csflut_export(const csflut_table *t, csflut_format fmt, const char *prefix,
                            char **out, size_t *len)
{
    if (!t || !out) return CSFLUT_E_ARG;
    *out = NULL;
    if (len) *len = 0;
    const char *px = prefix ? prefix : "csflut_gen";
    if (!is_usable_prefix(px)) return CSFLUT_E_ARG;
    sbuf b = {0};
    switch (fmt) {
    case CSFLUT_FORMAT_CSV: export_csv(t, &b); break;
    case CSFLUT_FORMAT_JSON: export_json(t, &b); break;
    case CSFLUT_FORMAT_C: export_c(t, px, &b); break;
    case CSFLUT_FORMAT_GLSL: export_glsl(t, px, &b); break;
    default: return CSFLUT_E_ARG;
    }
    if (b.oom || !b.s) {
        free(b.s);
        return CSFLUT_E_NOMEM;
    }
    *out = b.s;
    if (len) *len = b.len;
    return CSFLUT_OK;
}
