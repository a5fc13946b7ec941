/* Private to the csflut library: file layout constants, the table structure, and helpers shared by
 * the reader, the writer, the CSV importer and the exporters. Not installed. */
#ifndef CSFLUT_INTERNAL_H
#define CSFLUT_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "csflut.h"

/* No a * b + c fused into one FMA anywhere in the library: a fused result differs in the last
 * place, so the numbers would depend on -march, and the C export (which keeps them unfused) would
 * no longer match bit for bit. Clang honours the standard pragma (from here to the end of each
 * file); GCC ignores it and warns under -Wall, so it gets -ffp-contract=off from the build
 * (results/meson.build; docs/csflut.md for vendoring). */
#if defined(__clang__) || !defined(__GNUC__)
#pragma STDC FP_CONTRACT OFF
#endif

/* File layout (docs/csflut.md): 64-byte header, axis records, thresholds, optional stderr,
 * metadata strings, CRC-32 trailer. All little-endian. */
#define CSFLUT_MAGIC "\x89" "CSFLUT\n"
#define CSFLUT_MAGIC_LEN 8
#define CSFLUT_HEADER_SIZE 64
#define CSFLUT_AXIS_RECORD_SIZE 48 /* id, scale, n, reserved (4 x u32) + name[16] + unit[16] */
#define CSFLUT_MAX_POINTS 4096     /* per axis: far beyond any measured grid */
#define CSFLUT_MAX_NODES (1u << 22) /* product of axis sizes (32 MiB of doubles) */
#define CSFLUT_MAX_STRING 4096     /* per metadata string */
#define CSFLUT_N_STRINGS 5
#define CSFLUT_FLAG_STDERR 1u
/* Format 1.1 header extension (bytes 64 to header_size): f64 velocity warp v0 (NaN = none), u32
 * number of key/value pairs, u32 reserved, then the pairs (u32 length + bytes, key then value). */
#define CSFLUT_EXT_FIXED 16
#define CSFLUT_MAX_META 256    /* key/value pairs */
#define CSFLUT_MAX_META_KEY 64 /* bytes per key */

/* One past the highest csflut_status code: the bound for walking every code (the enum itself
 * carries no such member, so a switch over it stays exhaustive and no caller can receive it).
 * Raise it when a code is added. */
#define CSFLUT_STATUS_END (CSFLUT_E_CSV + 1)

/* Precomputed 2-D (frequency, eccentricity) slice for the fast path. Axes with one point are
 * padded to two identical-valued nodes so every query has a cell. */
typedef struct {
    int n;              /* >= 2 */
    double lo, hi;      /* first/last node in the interpolation coordinate (log2 f, or deg) */
    double *node;       /* n nodes in the interpolation coordinate */
    double *inv_step;   /* n-1: 1/(node[i+1]-node[i]) */
    int last_exact;     /* (hi - node[n-2]) * inv_step[n-2] == 1 exactly */
    /* Branch-free cell search: bucket b = (int)((x - lo) * bucket_scale) holds at most one
     * interior node; first[b] is the cell of the bucket's lowest x, next[s] the interior node that
     * ends cell s (+inf after the last), so cell = first[b] + (x >= next[first[b]]). */
    int n_buckets;      /* 0: nodes too close together for buckets, search linearly */
    double bucket_scale;
    unsigned short *first; /* n_buckets + 1 */
    double *next;          /* n */
} csflut_axis_fast;

struct csflut_table {
    int vmaj, vmin;
    int n[4];            /* points per axis; 0 when absent */
    int scale[4];
    double *pts[4];
    size_t n_nodes;
    double *raw, *cons, *se; /* se NULL when absent */
    int conservative;
    double k_shift;
    char *str[CSFLUT_N_STRINGS]; /* observer, display, method, date, tool version */
    double dist_mm, mean_lum;
    int trials;
    double def_vel, def_lum;
    double vel_v0; /* velocity warp log2(|v| + vel_v0); NaN: the axis record's scale */
    int n_meta;
    char **meta_key, **meta_val;
    csflut_axis_fast fx, ex;  /* frequency (log2) and eccentricity (linear) */
    csflut_axis_fast vx;      /* velocity in its interpolation coordinate (when n[2] > 0) */
    double cap_log2;          /* log2 threshold an invisible node enters interpolation with */
    double *slice_raw, *slice_cons; /* ex.n * fx.n log2 thresholds (cap = never visible),
                                       freq fastest */
    double *slice3_raw, *slice3_cons; /* vx.n * ex.n * fx.n, at the default luminance (velocity
                                         axis only) */
};

void csflut_diag_set(csflut_diag *d, csflut_status code, size_t where, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
uint32_t csflut_crc32(const unsigned char *p, size_t n);
/* log2 and exp2 for the interpolation, written out here (a polynomial, no table, no branch) so
 * the batch loops vectorise and the exported C header can carry the same arithmetic, operation
 * for operation, and so match the library bit for bit. Both are accurate to about 1 ulp on
 * normal numbers. log2 clamps its argument to [DBL_MIN, DBL_MAX] (NaN gives log2(DBL_MIN) =
 * -1022): frequencies that small are below every grid, and callers check NaN themselves. exp2
 * takes r in [-1022, 1023], so its result is p * 2^k with k a normal exponent (the same as
 * ldexp(p, k)). The coefficients (Estrin's scheme, spelled out so the exporter can copy them) are the Taylor series of 2^f for |f| <= 1/2 (degree 13) and of
 * log2 m = (2 / ln 2) atanh((m - 1) / (m + 1)) for m in [sqrt(1/2), sqrt(2)] (up to s^21;
 * the next term is below 1e-17 relative). */
static inline double csflut_log2_poly(double m, double e)
{
    /* Estrin's scheme: short dependency chains, so consecutive queries overlap */
    double s = (m - 1) / (m + 1), z = s * s, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
    double a0 = 2.8853900817779268 + 0.9617966939259757 * z;
    double a1 = 0.5770780163555853 + 0.41219858311113244 * z;
    double a2 = 0.3205988979753252 + 0.2623081892525388 * z;
    double a3 = 0.2219530832136867 + 0.19235933878519512 * z;
    double a4 = 0.16972882833987804 + 0.15186263588304877 * z;
    double b0 = a0 + a1 * z2, b1 = a2 + a3 * z2, b2 = a4 + 0.1373995277037108 * z2;
    double p = (b0 + b1 * z4) + b2 * z8;
    return e + s * p;
}

static inline double csflut_log2i(double x)
{
    x = x > 0x1p-1022 ? x : 0x1p-1022;
    x = x < 0x1.fffffffffffffp1023 ? x : 0x1.fffffffffffffp1023;
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    /* x = m * 2^e with m in [sqrt(1/2), sqrt(2)): big = 1 when the mantissa is >= sqrt(2)'s
     * (adding 2^52 - mantissa(sqrt 2) carries into bit 52); integer arithmetic only, so the loop
     * vectorises */
    uint64_t mant = b & 0x000FFFFFFFFFFFFFull;
    uint64_t big = (mant + 0x95F619980C433ull) >> 52;
    int32_t e = (int32_t)(b >> 52) - 1023 + (int32_t)big;
    uint64_t mb = mant | ((1023 - big) << 52);
    double m;
    memcpy(&m, &mb, sizeof m);
    return csflut_log2_poly(m, (double)e);
}

static inline double csflut_exp2_poly(double f)
{
    double f2 = f * f, f4 = f2 * f2, f8 = f4 * f4;
    double a0 = 1.0 + 0.6931471805599453 * f;
    double a1 = 0.2402265069591007 + 0.055504108664821576 * f;
    double a2 = 0.009618129107628477 + 0.0013333558146428441 * f;
    double a3 = 0.00015403530393381606 + 1.5252733804059838e-05 * f;
    double a4 = 1.3215486790144305e-06 + 1.0178086009239696e-07 * f;
    double a5 = 7.054911620801121e-09 + 4.44553827187081e-10 * f;
    double a6 = 2.5678435993488196e-11 + 1.3691488853904124e-12 * f;
    double b0 = a0 + a1 * f2, b1 = a2 + a3 * f2, b2 = a4 + a5 * f2;
    double c0 = b0 + b1 * f4, c1 = b2 + a6 * f4;
    return c0 + c1 * f8;
}

/* r must lie in [-1022, 1023]: every caller passes a blend of csflut_log2i values (>= -1022)
 * and the cap (<= 512, see csflut_table_finish), or clamps. */
static inline double csflut_exp2i(double r)
{
    double t = r + 0x1.8p52; /* rounds r to the nearest integer k, held in t's low bits */
    double k = t - 0x1.8p52;
    uint64_t tb, sb;
    memcpy(&tb, &t, sizeof tb);
    sb = (tb - 0x4338000000000000ull + 1023) << 52; /* 2^k */
    double scale;
    memcpy(&scale, &sb, sizeof scale);
    return csflut_exp2_poly(r - k) * scale;
}

/* Not exported: csflut_log2i as a function, for the writer's axis check. */
double csflut_log2(double x);
/* A velocity grid point or query in the interpolation coordinate: log2(|v| + v0) with the warp
 * (v0 finite), else log2 |v| on a log axis or |v| on a linear one. */
static inline double csflut_vel_coord(double v, double v0, int logscale)
{
    double a = v < 0 ? -v : v;
    if (v0 == v0) return csflut_log2i(a + v0);
    return logscale ? csflut_log2i(a) : a;
}
/* Checks the key/value metadata as the reader does (shared with the writer). */
csflut_status csflut_check_meta(const char *const *keys, const char *const *vals, size_t n, csflut_diag *diag,
                                size_t where);
/* Creates the derived data (conservative view, 2-D slices) of a table whose axes and values are
 * filled. */
csflut_status csflut_table_finish(csflut_table *t);
/* Checks axes and values as the reader does (shared with the writer). */
csflut_status csflut_check_axis(int which, int n, const double *pts, int scale, double vel_v0,
                                csflut_diag *diag, size_t where);
csflut_status csflut_check_values(const double *thr, const double *se, size_t n_nodes,
                                  csflut_diag *diag, size_t where_thr, size_t where_se);

#endif
