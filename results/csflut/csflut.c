/* csflut reader: parses and validates .csflut files (docs/csflut.md), derives the conservative
 * view, and answers threshold / perceptibility / inverse queries by multilinear interpolation.
 * libc + libm only. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csflut.h"
#include "csflut_internal.h"

static const char *const axis_names[4] = {"freq", "ecc", "velocity", "luminance"};
static const char *const axis_units[4] = {"cpd", "deg", "deg/s", "cd/m2"};

const char *csflut_strerror(csflut_status s)
{
    switch (s) {
    case CSFLUT_OK: return "success";
    case CSFLUT_E_ARG: return "invalid argument";
    case CSFLUT_E_NOMEM: return "out of memory";
    case CSFLUT_E_IO: return "cannot read or write the file";
    case CSFLUT_E_TRUNCATED: return "file is truncated";
    case CSFLUT_E_BAD_MAGIC: return "not a csflut threshold table (bad magic number)";
    case CSFLUT_E_BAD_VERSION: return "unsupported csflut format version";
    case CSFLUT_E_BAD_CHECKSUM: return "checksum mismatch: the file is corrupted";
    case CSFLUT_E_BAD_HEADER: return "inconsistent header or section layout";
    case CSFLUT_E_BAD_AXIS: return "absurd axis (count, id, scale or number of points)";
    case CSFLUT_E_NONMONOTONE: return "grid points are not strictly increasing";
    case CSFLUT_E_BAD_VALUE: return "non-finite, zero or negative value";
    case CSFLUT_E_BAD_METADATA: return "bad metadata";
    case CSFLUT_E_CSV: return "CSV input refused";
    }
    return "unknown csflut status";
}

/* The version this file was compiled as, so a program can tell which library it runs against
 * (the macros in its own csflut.h say which one it was built against). */
const char *csflut_version(void) { return CSFLUT_LIB_VERSION; }
int csflut_version_number(void) { return CSFLUT_LIB_VERSION_NUMBER; }

const char *csflut_axis_name(csflut_axis a) { return (unsigned)a < 4 ? axis_names[a] : "?"; }
const char *csflut_axis_unit(csflut_axis a) { return (unsigned)a < 4 ? axis_units[a] : "?"; }

void csflut_diag_set(csflut_diag *d, csflut_status code, size_t where, const char *fmt, ...)
{
    if (!d) return;
    d->code = code;
    d->where = where;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof d->message, fmt, ap);
    va_end(ap);
}

/* Bitwise CRC-32 (IEEE 802.3, reflected, poly 0xEDB88320): tables are small, a lookup table
 * would buy nothing measurable and would need initialisation. */
uint32_t csflut_crc32(const unsigned char *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

/* log2 of a frequency, -inf for x <= 0 (below every grid): the interpolation coordinate. */
static inline double log2_guarded(double x) { return csflut_log2i(x); }
double csflut_log2(double x) { return csflut_log2i(x); }

/* ---- little-endian reading with bounds checks ---------------------------------------------- */
typedef struct {
    const unsigned char *p;
    size_t len, pos;
} rd;

static int rd_has(const rd *r, size_t n) { return n <= r->len - r->pos; }
static uint32_t get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t get_u64(const unsigned char *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}
static double get_f64(const unsigned char *p)
{
    uint64_t u = get_u64(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* ---- validation shared with the writer ------------------------------------------------------ */
/* With the velocity warp, neighbouring grid points must stay apart in log2(v + v0). */
static csflut_status check_vel_warp(int n, const double *pts, double v0, csflut_diag *diag, size_t where)
{
    for (int i = 1; i < n; i++)
        if (!(csflut_vel_coord(pts[i], v0, 1) > csflut_vel_coord(pts[i - 1], v0, 1))) {
            csflut_diag_set(diag, CSFLUT_E_NONMONOTONE, where,
                            "velocity grid points %d and %d are too close to tell apart in the "
                            "warp log(v + %g)",
                            i - 1, i, v0);
            return CSFLUT_E_NONMONOTONE;
        }
    return CSFLUT_OK;
}

csflut_status csflut_check_axis(int which, int n, const double *pts, int scale, double vel_v0,
                                csflut_diag *diag, size_t where)
{
    const char *nm = axis_names[which];
    int required = which < 2;
    if (n < (required ? 1 : 0) || n > CSFLUT_MAX_POINTS) {
        csflut_diag_set(diag, CSFLUT_E_BAD_AXIS, where,
                        "%s axis has %d points (allowed %d to %d)", nm, n, required ? 1 : 0,
                        CSFLUT_MAX_POINTS);
        return CSFLUT_E_BAD_AXIS;
    }
    int want_scale = which == 1 ? CSFLUT_SCALE_LINEAR : CSFLUT_SCALE_LOG;
    if (scale != want_scale && !(which == 2 && scale == CSFLUT_SCALE_LINEAR)) {
        csflut_diag_set(diag, CSFLUT_E_BAD_AXIS, where, "%s axis has scale %d (must be %s)", nm,
                        scale, want_scale ? "log" : "linear");
        return CSFLUT_E_BAD_AXIS;
    }
    for (int i = 0; i < n; i++) {
        double v = pts[i];
        int bad = !isfinite(v) || v < 0 || (scale == CSFLUT_SCALE_LOG && v <= 0);
        if (bad) {
            csflut_diag_set(diag, CSFLUT_E_BAD_VALUE, where,
                            "%s grid point %d is %g (must be finite and %s 0)", nm, i, v,
                            scale == CSFLUT_SCALE_LOG ? ">" : ">=");
            return CSFLUT_E_BAD_VALUE;
        }
        if (i > 0 && !(v > pts[i - 1])) {
            csflut_diag_set(diag, CSFLUT_E_NONMONOTONE, where,
                            "%s grid point %d (%g) is not above point %d (%g): grids must be "
                            "strictly increasing", nm, i, v, i - 1, pts[i - 1]);
            return CSFLUT_E_NONMONOTONE;
        }
    }
    if (scale == CSFLUT_SCALE_LOG && n >= 2) {
        /* log2 spacing must be representable: neighbours closer than ~1e-12 relative would make
         * the interpolation weights meaningless. */
        for (int i = 1; i < n; i++)
            if (!(csflut_log2(pts[i]) > csflut_log2(pts[i - 1]))) {
                csflut_diag_set(diag, CSFLUT_E_NONMONOTONE, where,
                                "%s grid points %d and %d are too close to tell apart", nm, i - 1,
                                i);
                return CSFLUT_E_NONMONOTONE;
            }
    }
    if (which == CSFLUT_AXIS_VEL && vel_v0 == vel_v0) return check_vel_warp(n, pts, vel_v0, diag, where);
    return CSFLUT_OK;
}

csflut_status csflut_check_meta(const char *const *keys, const char *const *vals, size_t n, csflut_diag *diag,
                                size_t where)
{
    if (n > CSFLUT_MAX_META) {
        csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, where, "%zu metadata pairs (at most %d)", n,
                        CSFLUT_MAX_META);
        return CSFLUT_E_BAD_METADATA;
    }
    for (size_t i = 0; i < n; i++) {
        const char *k = keys[i], *v = vals[i];
        size_t kl = k ? strlen(k) : 0, vl = v ? strlen(v) : 0;
        int ok = kl >= 1 && kl <= CSFLUT_MAX_META_KEY;
        for (size_t c = 0; c < kl && ok; c++)
            ok = (k[c] >= 'a' && k[c] <= 'z') || (k[c] >= 'A' && k[c] <= 'Z') ||
                 (k[c] >= '0' && k[c] <= '9') || k[c] == '_' || k[c] == '.' || k[c] == '-';
        if (!ok) {
            csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, where,
                            "metadata key %zu is not 1 to %d of A-Z a-z 0-9 _ . -", i, CSFLUT_MAX_META_KEY);
            return CSFLUT_E_BAD_METADATA;
        }
        if (!v || vl > CSFLUT_MAX_STRING || strpbrk(v, "\r\n")) {
            csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, where,
                            "metadata value of %s is missing, over %d bytes, or contains a line "
                            "break",
                            k, CSFLUT_MAX_STRING);
            return CSFLUT_E_BAD_METADATA;
        }
        for (size_t j = 0; j < i; j++)
            if (strcmp(keys[j], k) == 0) {
                csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, where, "metadata key %s appears twice", k);
                return CSFLUT_E_BAD_METADATA;
            }
    }
    return CSFLUT_OK;
}

csflut_status csflut_check_values(const double *thr, const double *se, size_t n_nodes,
                                  csflut_diag *diag, size_t where_thr, size_t where_se)
{
    for (size_t i = 0; i < n_nodes; i++) {
        double v = thr[i];
        if (!(v > 0)) { /* NaN, zero, negative, -inf */
            csflut_diag_set(diag, CSFLUT_E_BAD_VALUE, where_thr + 8 * i,
                            "threshold at node %zu is %g (must be > 0, or +inf for never "
                            "visible)", i, v);
            return CSFLUT_E_BAD_VALUE;
        }
    }
    if (se)
        for (size_t i = 0; i < n_nodes; i++) {
            double v = se[i];
            if (v != v) continue; /* unknown */
            if (!isfinite(v) || v < 0) {
                csflut_diag_set(diag, CSFLUT_E_BAD_VALUE, where_se + 8 * i,
                                "stderr_log10 at node %zu is %g (must be finite and >= 0, or "
                                "NaN for unknown)", i, v);
                return CSFLUT_E_BAD_VALUE;
            }
        }
    return CSFLUT_OK;
}

/* ---- derived data --------------------------------------------------------------------------- */
static int bucket_of(const csflut_axis_fast *a, double x)
{
    return (int)((x - a->lo) * a->bucket_scale);
}

/* coord: 0 linear, 1 log2, 2 the velocity warp log2(v + v0) */
static csflut_status axis_fast_init(csflut_axis_fast *a, const double *pts, int n, int coord, double v0)
{
    a->n = n < 2 ? 2 : n;
    a->node = calloc((size_t)a->n, sizeof(double));
    a->inv_step = malloc(sizeof(double) * (size_t)(a->n - 1));
    a->next = malloc(sizeof(double) * (size_t)a->n);
    if (!a->node || !a->inv_step || !a->next) return CSFLUT_E_NOMEM;
    for (int i = 0; i < n; i++)
        a->node[i] =
            coord == 2 ? csflut_vel_coord(pts[i], v0, 1) : (coord == 1 ? csflut_log2(pts[i]) : pts[i]);
    if (n == 1) a->node[1] = a->node[0] + 1.0; /* padded node carries the same values */
    for (int i = 0; i + 1 < a->n; i++) a->inv_step[i] = 1.0 / (a->node[i + 1] - a->node[i]);
    /* On the last node the weight must be exactly 1 (edge queries return the stored value bit for
     * bit; inside the grid the cell search already guarantees x < node[i+1]). Nudge the last
     * reciprocal by an ulp if the product rounds below 1; if no neighbour works, locate() falls
     * back to an explicit comparison. */
    {
        int l = a->n - 2;
        double d = a->node[l + 1] - a->node[l], inv = a->inv_step[l];
        double cand[3] = {inv, nextafter(inv, HUGE_VAL), nextafter(inv, 0)};
        a->last_exact = 0;
        for (int k = 0; k < 3 && !a->last_exact; k++)
            if (d * cand[k] == 1.0) {
                a->inv_step[l] = cand[k];
                a->last_exact = 1;
            }
    }
    for (int s = 0; s < a->n; s++) a->next[s] = s + 1 <= a->n - 2 ? a->node[s + 1] : HUGE_VAL;
    a->lo = a->node[0];
    a->hi = a->node[a->n - 1];
    /* the fewest buckets (a power of two) that separate every interior node */
    for (int nb = 16; nb <= 32768; nb *= 2) {
        a->bucket_scale = nb / (a->hi - a->lo);
        if (!isfinite(a->bucket_scale)) break;
        int ok = 1;
        for (int k = 2; k <= a->n - 2 && ok; k++)
            if (bucket_of(a, a->node[k]) == bucket_of(a, a->node[k - 1])) ok = 0;
        if (!ok) continue;
        a->first = malloc(sizeof(unsigned short) * (size_t)(nb + 1));
        if (!a->first) return CSFLUT_E_NOMEM;
        /* first[b] = interior nodes certainly below every x of bucket b (their bucket is lower) */
        for (int b = 0; b <= nb; b++) {
            int s = 0;
            for (int k = 1; k <= a->n - 2; k++)
                if (bucket_of(a, a->node[k]) < b) s = k;
            a->first[b] = (unsigned short)s;
        }
        a->n_buckets = nb;
        return CSFLUT_OK;
    }
    a->n_buckets = 0;
    return CSFLUT_OK;
}

/* Finds the cell and weight of x (already in the interpolation coordinate, clamped). */
static inline int axis_fast_locate(const csflut_axis_fast *a, double x, double *w)
{
    int i;
    if (a->n_buckets) {
        int s = a->first[bucket_of(a, x)];
        i = s + (x >= a->next[s]);
    } else {
        i = 0;
        while (i < a->n - 2 && x >= a->node[i + 1]) i++;
    }
    /* exactly 1 on the last node, so edge queries return the stored value bit for bit */
    if (a->last_exact) *w = (x - a->node[i]) * a->inv_step[i];
    else *w = x >= a->node[i + 1] ? 1.0 : (x - a->node[i]) * a->inv_step[i];
    return i;
}

/* Clamp to [lo, hi]; NaN becomes lo, so the cell search never sees NaN (the batch path marks
 * NaN queries afterwards). */
static inline double clampd(double x, double lo, double hi)
{
    x = x > lo ? x : lo;
    return x < hi ? x : hi;
}

/* Interpolation runs on log2 thresholds (a geometric blend, never above the linear one). An
 * invisible (+inf) node enters as the finite cap t->cap_log2, so a query next to a visible node
 * gets a threshold close to that node's; only a result equal to the cap (every corner with a
 * non-zero weight invisible) is +inf. All values are finite here, so the plain blend is exact at
 * w = 0 and w = 1, and blending equal caps gives the cap exactly: cap_log2 is a power of two, and
 * fl(fl(1 - w) + w) == 1 for every w in [0, 1]. */
static inline double lerp(double a, double b, double w) { return (1 - w) * a + w * b; }

/* Finite thresholds above 2^500 (no contrast comes near) are held at 2^500, so every blend stays
 * in exp2's range: the cap is then at most 512. */
#define CSFLUT_LOG2_MAX_FINITE 500.0
static inline double to_log(const csflut_table *t, double v)
{
    if (isinf(v)) return t->cap_log2;
    double l = csflut_log2i(v);
    return l < CSFLUT_LOG2_MAX_FINITE ? l : CSFLUT_LOG2_MAX_FINITE;
}

static inline double from_log(double r, double cap_log2)
{
    return r >= cap_log2 ? HUGE_VAL : csflut_exp2i(r);
}

/* Generic locate on any axis (used by the N-D path): index i0, i1 and weight. */
static void axis_locate(const csflut_table *t, int ax, double x, int *i0, int *i1, double *w)
{
    int n = t->n[ax];
    if (n <= 1) {
        *i0 = *i1 = 0;
        *w = 0;
        return;
    }
    const double *p = t->pts[ax];
    if (ax == CSFLUT_AXIS_FREQ) { /* reuse the fast axis so 2-D and N-D agree bit for bit */
        double u = clampd(csflut_log2(x), t->fx.lo, t->fx.hi);
        *i0 = axis_fast_locate(&t->fx, u, w);
        *i1 = *i0 + 1;
        return;
    }
    if (ax == CSFLUT_AXIS_ECC) {
        double e = clampd(x, t->ex.lo, t->ex.hi);
        *i0 = axis_fast_locate(&t->ex, e, w);
        *i1 = *i0 + 1;
        return;
    }
    if (ax == CSFLUT_AXIS_VEL) { /* the fast axis too: csflut_threshold3 and 4 agree */
        double c =
            clampd(csflut_vel_coord(x, t->vel_v0, t->scale[ax] == CSFLUT_SCALE_LOG), t->vx.lo, t->vx.hi);
        *i0 = axis_fast_locate(&t->vx, c, w);
        *i1 = *i0 + 1;
        return;
    }
    int lg = t->scale[ax] == CSFLUT_SCALE_LOG;
    double lo = p[0], hi = p[n - 1];
    double xc = x < lo ? lo : (x > hi ? hi : x);
    int i = 0;
    while (i < n - 2 && xc >= p[i + 1]) i++;
    *i0 = i;
    *i1 = i + 1;
    if (lg) *w = (csflut_log2(xc) - csflut_log2(p[i])) / (csflut_log2(p[i + 1]) - csflut_log2(p[i]));
    else *w = (xc - p[i]) / (p[i + 1] - p[i]);
    if (*w < 0) *w = 0;
    if (*w > 1) *w = 1;
}

static size_t node_index(const csflut_table *t, int f, int e, int v, int l)
{
    size_t nf = (size_t)t->n[0], ne = (size_t)t->n[1];
    size_t nv = t->n[2] > 0 ? (size_t)t->n[2] : 1;
    return (((size_t)l * nv + (size_t)v) * ne + (size_t)e) * nf + (size_t)f;
}

/* Full multilinear interpolation of log2 thresholds, nested freq, ecc, velocity, luminance;
 * returns the log2 result (the cap means never visible). */
static double interp_nd(const csflut_table *t, const double *vals, double f, double e, double v,
                        double l)
{
    if (f != f || e != e) return NAN;
    int f0, f1, e0, e1, v0 = 0, v1 = 0, l0 = 0, l1 = 0;
    double wf, we, wv = 0, wl = 0;
    axis_locate(t, CSFLUT_AXIS_FREQ, f, &f0, &f1, &wf);
    axis_locate(t, CSFLUT_AXIS_ECC, e, &e0, &e1, &we);
    if (t->n[2] > 0) {
        if (v != v) return NAN;
        axis_locate(t, CSFLUT_AXIS_VEL, v, &v0, &v1, &wv);
    }
    if (t->n[3] > 0) {
        if (l != l) return NAN;
        axis_locate(t, CSFLUT_AXIS_LUM, l, &l0, &l1, &wl);
    }
    if (t->n[0] == 1) f1 = f0;
    if (t->n[1] == 1) e1 = e0;
    double byl[2];
    for (int li = 0; li < 2; li++) {
        int L = li ? l1 : l0;
        double byv[2];
        for (int vi = 0; vi < 2; vi++) {
            int V = vi ? v1 : v0;
            double r0 = lerp(to_log(t, vals[node_index(t, f0, e0, V, L)]),
                             to_log(t, vals[node_index(t, f1, e0, V, L)]), wf);
            double r1 = lerp(to_log(t, vals[node_index(t, f0, e1, V, L)]),
                             to_log(t, vals[node_index(t, f1, e1, V, L)]), wf);
            byv[vi] = lerp(r0, r1, we);
        }
        byl[li] = lerp(byv[0], byv[1], wv);
    }
    return lerp(byl[0], byl[1], wl);
}

static void compute_conservative(csflut_table *t)
{
    size_t nf = (size_t)t->n[0], ne = (size_t)t->n[1];
    size_t slices = t->n_nodes / (nf * ne);
    for (size_t k = 0; k < t->n_nodes; k++) {
        double v = t->raw[k];
        if (t->se && t->k_shift > 0 && isfinite(t->se[k]) && isfinite(v))
            v *= pow(10.0, -t->k_shift * t->se[k]);
        t->cons[k] = v;
    }
    /* min over the quadrant of higher-or-equal frequency and eccentricity */
    for (size_t s = 0; s < slices; s++) {
        double *c = t->cons + s * nf * ne;
        for (size_t e = ne; e-- > 0;)
            for (size_t f = nf; f-- > 0;) {
                double m = c[e * nf + f];
                if (f + 1 < nf && c[e * nf + f + 1] < m) m = c[e * nf + f + 1];
                if (e + 1 < ne && c[(e + 1) * nf + f] < m) m = c[(e + 1) * nf + f];
                c[e * nf + f] = m;
            }
    }
}

/* The 2-D slice of log2 thresholds (invisible = cap) at the default velocity/luminance, padded to
 * >= 2 points per axis. */
static void compute_slice(csflut_table *t, const double *vals, double *slice)
{
    int nf = t->fx.n, ne = t->ex.n;
    for (int e = 0; e < ne; e++)
        for (int f = 0; f < nf; f++) {
            int fs = f < t->n[0] ? f : t->n[0] - 1, es = e < t->n[1] ? e : t->n[1] - 1;
            double r;
            if (t->n[2] == 0 && t->n[3] == 0) {
                r = to_log(t, vals[node_index(t, fs, es, 0, 0)]);
            } else {
                int v0 = 0, v1 = 0, l0 = 0, l1 = 0;
                double wv = 0, wl = 0;
                if (t->n[2] > 0) axis_locate(t, CSFLUT_AXIS_VEL, t->def_vel, &v0, &v1, &wv);
                if (t->n[3] > 0) axis_locate(t, CSFLUT_AXIS_LUM, t->def_lum, &l0, &l1, &wl);
                double a = lerp(to_log(t, vals[node_index(t, fs, es, v0, l0)]),
                                to_log(t, vals[node_index(t, fs, es, v1, l0)]), wv);
                double b = lerp(to_log(t, vals[node_index(t, fs, es, v0, l1)]),
                                to_log(t, vals[node_index(t, fs, es, v1, l1)]), wv);
                r = lerp(a, b, wl);
            }
            slice[(size_t)e * (size_t)nf + (size_t)f] = r;
        }
}

/* Per velocity node, the (frequency, eccentricity) slice of log2 thresholds at the default
 * luminance, padded like the 2-D slice (a one-point velocity axis repeats its slice). */
static void compute_slice3(csflut_table *t, const double *vals, double *slice)
{
    int nf = t->fx.n, ne = t->ex.n, nv = t->vx.n;
    int l0 = 0, l1 = 0;
    double wl = 0;
    if (t->n[3] > 0) axis_locate(t, CSFLUT_AXIS_LUM, t->def_lum, &l0, &l1, &wl);
    for (int v = 0; v < nv; v++)
        for (int e = 0; e < ne; e++)
            for (int f = 0; f < nf; f++) {
                int fs = f < t->n[0] ? f : t->n[0] - 1, es = e < t->n[1] ? e : t->n[1] - 1;
                int vs = v < t->n[2] ? v : t->n[2] - 1;
                double r = to_log(t, vals[node_index(t, fs, es, vs, l0)]);
                if (t->n[3] > 0) r = lerp(r, to_log(t, vals[node_index(t, fs, es, vs, l1)]), wl);
                slice[((size_t)v * (size_t)ne + (size_t)e) * (size_t)nf + (size_t)f] = r;
            }
}

/* Every derived slice of both views. */
static void compute_slices(csflut_table *t)
{
    compute_slice(t, t->raw, t->slice_raw);
    compute_slice(t, t->cons, t->slice_cons);
    if (t->n[2] > 0) {
        compute_slice3(t, t->raw, t->slice3_raw);
        compute_slice3(t, t->cons, t->slice3_cons);
    }
}

/* The cap for invisible nodes, in log2 units: at least one octave above both the highest
 * displayable Michelson contrast (1) and the highest finite threshold of the table, so it is
 * above every visible value and a blend towards it stays finite; rounded up to a power of two so
 * that blending caps gives the cap exactly. Derived, not stored (docs/csflut.md sec. 2). */
static double compute_cap_log2(const csflut_table *t)
{
    double m = 1.0;
    for (size_t k = 0; k < t->n_nodes; k++)
        if (isfinite(t->raw[k]) && t->raw[k] > m) m = t->raw[k];
    double l = csflut_log2(m);
    double want = (l < CSFLUT_LOG2_MAX_FINITE ? l : CSFLUT_LOG2_MAX_FINITE) + 1.0, cap = 1.0;
    while (cap < want) cap *= 2;
    return cap;
}

csflut_status csflut_table_finish(csflut_table *t)
{
    t->conservative = 1;
    t->def_vel = t->n[2] > 0 ? t->pts[2][0] : 0;
    t->def_lum = t->n[3] > 0 ? (isfinite(t->mean_lum) && t->mean_lum > 0 ? t->mean_lum : t->pts[3][0])
                             : (isfinite(t->mean_lum) ? t->mean_lum : 0);
    t->cons = malloc(sizeof(double) * t->n_nodes);
    if (!t->cons) return CSFLUT_E_NOMEM;
    t->cap_log2 = compute_cap_log2(t);
    csflut_status st = axis_fast_init(&t->fx, t->pts[0], t->n[0], 1, 0);
    if (st) return st;
    st = axis_fast_init(&t->ex, t->pts[1], t->n[1], 0, 0);
    if (st) return st;
    if (t->n[2] > 0) {
        int coord = t->vel_v0 == t->vel_v0 ? 2 : (t->scale[2] == CSFLUT_SCALE_LOG ? 1 : 0);
        st = axis_fast_init(&t->vx, t->pts[2], t->n[2], coord, t->vel_v0);
        if (st) return st;
    }
    size_t ns = (size_t)t->fx.n * (size_t)t->ex.n;
    t->slice_raw = malloc(sizeof(double) * ns);
    t->slice_cons = malloc(sizeof(double) * ns);
    if (!t->slice_raw || !t->slice_cons) return CSFLUT_E_NOMEM;
    if (t->n[2] > 0) {
        t->slice3_raw = malloc(sizeof(double) * ns * (size_t)t->vx.n);
        t->slice3_cons = malloc(sizeof(double) * ns * (size_t)t->vx.n);
        if (!t->slice3_raw || !t->slice3_cons) return CSFLUT_E_NOMEM;
    }
    compute_conservative(t);
    compute_slices(t);
    return CSFLUT_OK;
}

void csflut_close(csflut_table *t)
{
    if (!t) return;
    for (int a = 0; a < 4; a++) free(t->pts[a]);
    free(t->raw);
    free(t->cons);
    free(t->se);
    for (int i = 0; i < CSFLUT_N_STRINGS; i++) free(t->str[i]);
    for (int k = 0; k < t->n_meta; k++) {
        free(t->meta_key[k]);
        free(t->meta_val[k]);
    }
    free(t->meta_key);
    free(t->meta_val);
    free(t->slice3_raw);
    free(t->slice3_cons);
    csflut_axis_fast *ax[3] = {&t->fx, &t->ex, &t->vx};
    for (int k = 0; k < 3; k++) {
        free(ax[k]->node);
        free(ax[k]->inv_step);
        free(ax[k]->first);
        free(ax[k]->next);
    }
    free(t->slice_raw);
    free(t->slice_cons);
    free(t);
}

/* ---- parsing -------------------------------------------------------------------------------- */
static csflut_status fail(csflut_diag *d, csflut_status code, size_t where, const char *msg)
{
    csflut_diag_set(d, code, where, "%s", msg);
    return code;
}

/* The envelope: magic, version, the sizes the header claims against the real one, the checksum.
 * *header_size: where the axis records start. */
static csflut_status parse_envelope(const unsigned char *p, size_t len, csflut_table *t, uint32_t *header_size,
                                    csflut_diag *d)
{
    if (len < CSFLUT_MAGIC_LEN) {
        if (memcmp(p, CSFLUT_MAGIC, len) == 0)
            return fail(d, CSFLUT_E_TRUNCATED, len, "file is shorter than the 8-byte magic number");
        return fail(d, CSFLUT_E_BAD_MAGIC, 0, "not a csflut file: the magic number is missing");
    }
    if (memcmp(p, CSFLUT_MAGIC, CSFLUT_MAGIC_LEN) != 0)
        return fail(d, CSFLUT_E_BAD_MAGIC, 0,
                    "not a csflut file: the first 8 bytes are not \\x89CSFLUT\\n");
    if (len < 12) return fail(d, CSFLUT_E_TRUNCATED, len, "file ends inside the version field");
    t->vmaj = (int)(p[8] | p[9] << 8);
    t->vmin = (int)(p[10] | p[11] << 8);
    if (t->vmaj != CSFLUT_FORMAT_VERSION_MAJOR) {
        csflut_diag_set(d, CSFLUT_E_BAD_VERSION, 8,
                        "format version %d.%d is not supported (this library reads %d.x)",
                        t->vmaj, t->vmin, CSFLUT_FORMAT_VERSION_MAJOR);
        return CSFLUT_E_BAD_VERSION;
    }
    if (len < CSFLUT_HEADER_SIZE + 4) {
        csflut_diag_set(d, CSFLUT_E_TRUNCATED, len,
                        "file is %zu bytes, shorter than the %d-byte header and checksum", len,
                        CSFLUT_HEADER_SIZE + 4);
        return CSFLUT_E_TRUNCATED;
    }
    *header_size = get_u32(p + 12);
    uint64_t file_size = get_u64(p + 16);
    if (file_size > len) {
        csflut_diag_set(d, CSFLUT_E_TRUNCATED, len,
                        "file is %zu bytes but its header says %llu: truncated", len,
                        (unsigned long long)file_size);
        return CSFLUT_E_TRUNCATED;
    }
    if (file_size < len) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, (size_t)file_size,
                        "file is %zu bytes but its header says %llu: trailing bytes", len,
                        (unsigned long long)file_size);
        return CSFLUT_E_BAD_HEADER;
    }
    uint32_t crc_file = get_u32(p + len - 4), crc = csflut_crc32(p, len - 4);
    if (crc != crc_file) {
        csflut_diag_set(d, CSFLUT_E_BAD_CHECKSUM, len - 4,
                        "CRC-32 is %08x but the file stores %08x: the file is corrupted",
                        (unsigned)crc, (unsigned)crc_file);
        return CSFLUT_E_BAD_CHECKSUM;
    }
    /* From here on the bytes are what the writer wrote, but a hostile writer can still lie. */
    if (*header_size < CSFLUT_HEADER_SIZE || *header_size > len - 4) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, 12, "header size %u is impossible (minimum %d)",
                        (unsigned)*header_size, CSFLUT_HEADER_SIZE);
        return CSFLUT_E_BAD_HEADER;
    }
    return CSFLUT_OK;
}

/* The fixed header fields after the sizes: axis count, flags, viewing distance, mean luminance,
 * trial count. */
static csflut_status parse_header_fields(const unsigned char *p, csflut_table *t, uint32_t *n_axes,
                                         uint32_t *flags, csflut_diag *d)
{
    *n_axes = get_u32(p + 24);
    *flags = get_u32(p + 28);
    if (*n_axes < 2 || *n_axes > 4) {
        csflut_diag_set(d, CSFLUT_E_BAD_AXIS, 24, "%u axes (allowed 2 to 4)", (unsigned)*n_axes);
        return CSFLUT_E_BAD_AXIS;
    }
    if (*flags & ~CSFLUT_FLAG_STDERR) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, 28, "unknown flags 0x%x", (unsigned)*flags);
        return CSFLUT_E_BAD_HEADER;
    }
    t->dist_mm = get_f64(p + 32);
    t->mean_lum = get_f64(p + 40);
    uint32_t trials = get_u32(p + 48);
    if (!(t->dist_mm != t->dist_mm || (isfinite(t->dist_mm) && t->dist_mm > 0)))
        return fail(d, CSFLUT_E_BAD_METADATA, 32,
                    "viewing distance must be finite and > 0 mm, or NaN for unknown");
    if (!(t->mean_lum != t->mean_lum || (isfinite(t->mean_lum) && t->mean_lum > 0)))
        return fail(d, CSFLUT_E_BAD_METADATA, 40,
                    "mean luminance must be finite and > 0 cd/m2, or NaN for unknown");
    if (trials > 0x7FFFFFFFu) return fail(d, CSFLUT_E_BAD_METADATA, 48, "trial count above 2^31-1");
    t->trials = (int)trials;
    return CSFLUT_OK;
}

/* One length-prefixed string of the header extension, at most max bytes, without NUL. */
static csflut_status ext_string(const unsigned char *p, rd *r, uint32_t max, char **out, csflut_diag *d)
{
    if (!rd_has(r, 4))
        return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "metadata pair runs past the header extension");
    uint32_t sl = get_u32(p + r->pos);
    if (sl > max) {
        csflut_diag_set(d, CSFLUT_E_BAD_METADATA, r->pos, "metadata key or value of %u bytes (at most %u)",
                        (unsigned)sl, (unsigned)max);
        return CSFLUT_E_BAD_METADATA;
    }
    r->pos += 4;
    if (!rd_has(r, sl))
        return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "metadata pair runs past the header extension");
    if (memchr(p + r->pos, 0, sl))
        return fail(d, CSFLUT_E_BAD_METADATA, r->pos, "metadata pair contains a NUL byte");
    *out = malloc(sl + 1);
    if (!*out) return CSFLUT_E_NOMEM;
    memcpy(*out, p + r->pos, sl);
    (*out)[sl] = 0;
    r->pos += sl;
    return CSFLUT_OK;
}

/* The format 1.1 header extension (bytes 64 to header_size): the velocity warp and the key/value
 * metadata. A 1.0 file's extension bytes are skipped, as 1.0 readers did; a file of a later
 * minor may carry more after the pairs, which this reader skips. */
static csflut_status parse_extension(const unsigned char *p, uint32_t header_size, csflut_table *t,
                                     csflut_diag *d)
{
    if (t->vmin < 1 || header_size == CSFLUT_HEADER_SIZE) return CSFLUT_OK;
    if (header_size < CSFLUT_HEADER_SIZE + CSFLUT_EXT_FIXED) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, 12,
                        "header extension of %u bytes is shorter than its %d fixed bytes",
                        (unsigned)(header_size - CSFLUT_HEADER_SIZE), CSFLUT_EXT_FIXED);
        return CSFLUT_E_BAD_HEADER;
    }
    double v0 = get_f64(p + CSFLUT_HEADER_SIZE);
    if (!(v0 != v0 || (isfinite(v0) && v0 > 0 && v0 <= 1e6))) {
        csflut_diag_set(d, CSFLUT_E_BAD_AXIS, CSFLUT_HEADER_SIZE,
                        "velocity warp v0 is %g deg/s (must be > 0 and at most 1e6, or NaN for "
                        "none)",
                        v0);
        return CSFLUT_E_BAD_AXIS;
    }
    t->vel_v0 = v0;
    uint32_t n = get_u32(p + CSFLUT_HEADER_SIZE + 8), reserved = get_u32(p + CSFLUT_HEADER_SIZE + 12);
    if (t->vmin == 1 && reserved != 0)
        return fail(d, CSFLUT_E_BAD_HEADER, CSFLUT_HEADER_SIZE + 12,
                    "reserved field of the header extension is not zero");
    if (n > CSFLUT_MAX_META) {
        csflut_diag_set(d, CSFLUT_E_BAD_METADATA, CSFLUT_HEADER_SIZE + 8, "%u metadata pairs (at most %d)",
                        (unsigned)n, CSFLUT_MAX_META);
        return CSFLUT_E_BAD_METADATA;
    }
    t->meta_key = calloc(n ? n : 1, sizeof(char *));
    t->meta_val = calloc(n ? n : 1, sizeof(char *));
    if (!t->meta_key || !t->meta_val) return CSFLUT_E_NOMEM;
    rd r = {p, header_size, CSFLUT_HEADER_SIZE + CSFLUT_EXT_FIXED};
    for (uint32_t i = 0; i < n; i++) {
        t->n_meta = (int)i + 1; /* so csflut_close frees what was read */
        csflut_status st = ext_string(p, &r, CSFLUT_MAX_META_KEY, &t->meta_key[i], d);
        if (!st) st = ext_string(p, &r, CSFLUT_MAX_STRING, &t->meta_val[i], d);
        if (st) return st;
    }
    csflut_status st = csflut_check_meta((const char *const *)t->meta_key, (const char *const *)t->meta_val,
                                         n, d, CSFLUT_HEADER_SIZE + CSFLUT_EXT_FIXED);
    if (st) return st;
    if (t->vmin == 1 && r.pos != header_size) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, r.pos,
                        "%zu unexplained bytes at the end of the header extension",
                        (size_t)header_size - r.pos);
        return CSFLUT_E_BAD_HEADER;
    }
    return CSFLUT_OK;
}

/* The axis records and their points: frequency and eccentricity first, then velocity and/or
 * luminance, each once, in order. */
static csflut_status parse_axes(const unsigned char *p, rd *r, uint32_t n_axes, csflut_table *t, csflut_diag *d)
{
    int prev_id = -1;
    for (uint32_t k = 0; k < n_axes; k++) {
        size_t at = r->pos;
        if (!rd_has(r, CSFLUT_AXIS_RECORD_SIZE))
            return fail(d, CSFLUT_E_BAD_HEADER, at, "axis record runs past the end of the file");
        uint32_t id = get_u32(p + at), scale = get_u32(p + at + 4), n = get_u32(p + at + 8);
        if (id > 3 || (int)id <= prev_id || (k < 2 && id != k)) {
            csflut_diag_set(d, CSFLUT_E_BAD_AXIS, at,
                            "axis record %u has id %u (frequency 0 and eccentricity 1 first, then "
                            "velocity 2 and/or luminance 3, each once, in order)",
                            (unsigned)k, (unsigned)id);
            return CSFLUT_E_BAD_AXIS;
        }
        prev_id = (int)id;
        if (n < 1 || n > CSFLUT_MAX_POINTS) {
            csflut_diag_set(d, CSFLUT_E_BAD_AXIS, at + 8, "%s axis has %u points (allowed 1 to %d)",
                            axis_names[id], (unsigned)n, CSFLUT_MAX_POINTS);
            return CSFLUT_E_BAD_AXIS;
        }
        if (scale > 1) {
            csflut_diag_set(d, CSFLUT_E_BAD_AXIS, at + 4, "%s axis has unknown scale %u",
                            axis_names[id], (unsigned)scale);
            return CSFLUT_E_BAD_AXIS;
        }
        r->pos += CSFLUT_AXIS_RECORD_SIZE;
        if (!rd_has(r, 8 * (size_t)n))
            return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "axis points run past the end of the file");
        t->n[id] = (int)n;
        t->scale[id] = (int)scale;
        t->pts[id] = malloc(sizeof(double) * n);
        if (!t->pts[id]) return CSFLUT_E_NOMEM;
        for (uint32_t i = 0; i < n; i++) t->pts[id][i] = get_f64(p + r->pos + 8 * (size_t)i);
        csflut_status st = csflut_check_axis((int)id, (int)n, t->pts[id], (int)scale, t->vel_v0, d, r->pos);
        if (st) return st;
        r->pos += 8 * (size_t)n;
    }
    return CSFLUT_OK;
}

/* The threshold per grid node and, when the flags say so, its standard error. */
static csflut_status parse_values(const unsigned char *p, rd *r, uint32_t flags, uint32_t header_size,
                                  csflut_table *t, csflut_diag *d)
{
    size_t nodes = 1;
    for (int a = 0; a < 4; a++) {
        if (t->n[a] > 0) nodes *= (size_t)t->n[a];
        if (nodes > CSFLUT_MAX_NODES) {
            csflut_diag_set(d, CSFLUT_E_BAD_AXIS, header_size,
                            "the grid has more than %u nodes", (unsigned)CSFLUT_MAX_NODES);
            return CSFLUT_E_BAD_AXIS;
        }
    }
    t->n_nodes = nodes;
    size_t where_thr = r->pos;
    if (!rd_has(r, 8 * nodes))
        return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "threshold values run past the end of the file");
    t->raw = malloc(sizeof(double) * nodes);
    if (!t->raw) return CSFLUT_E_NOMEM;
    for (size_t i = 0; i < nodes; i++) t->raw[i] = get_f64(p + r->pos + 8 * i);
    r->pos += 8 * nodes;
    size_t where_se = r->pos;
    if (flags & CSFLUT_FLAG_STDERR) {
        if (!rd_has(r, 8 * nodes))
            return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "stderr values run past the end of the file");
        t->se = malloc(sizeof(double) * nodes);
        if (!t->se) return CSFLUT_E_NOMEM;
        for (size_t i = 0; i < nodes; i++) t->se[i] = get_f64(p + r->pos + 8 * i);
        r->pos += 8 * nodes;
    }
    return csflut_check_values(t->raw, t->se, nodes, d, where_thr, where_se);
}

/* The metadata strings: length-prefixed, bounded, without NUL bytes. */
static csflut_status parse_strings(const unsigned char *p, rd *r, csflut_table *t, csflut_diag *d)
{
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) {
        if (!rd_has(r, 4))
            return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "metadata runs past the end of the file");
        uint32_t sl = get_u32(p + r->pos);
        if (sl > CSFLUT_MAX_STRING) {
            csflut_diag_set(d, CSFLUT_E_BAD_METADATA, r->pos,
                            "metadata string %d is %u bytes (at most %d)", k, (unsigned)sl,
                            CSFLUT_MAX_STRING);
            return CSFLUT_E_BAD_METADATA;
        }
        r->pos += 4;
        if (!rd_has(r, sl))
            return fail(d, CSFLUT_E_BAD_HEADER, r->pos, "metadata string runs past the end of the file");
        if (memchr(p + r->pos, 0, sl))
            return fail(d, CSFLUT_E_BAD_METADATA, r->pos, "metadata string contains a NUL byte");
        t->str[k] = malloc(sl + 1);
        if (!t->str[k]) return CSFLUT_E_NOMEM;
        memcpy(t->str[k], p + r->pos, sl);
        t->str[k][sl] = 0;
        r->pos += sl;
    }
    if (r->pos != r->len) {
        csflut_diag_set(d, CSFLUT_E_BAD_HEADER, r->pos,
                        "%zu unexplained bytes before the checksum", r->len - r->pos);
        return CSFLUT_E_BAD_HEADER;
    }
    return CSFLUT_OK;
}

static csflut_status parse(const unsigned char *p, size_t len, csflut_table *t, csflut_diag *d)
{
    uint32_t header_size = 0, n_axes = 0, flags = 0;
    t->vel_v0 = NAN;
    csflut_status st = parse_envelope(p, len, t, &header_size, d);
    if (st) return st;
    st = parse_header_fields(p, t, &n_axes, &flags, d);
    if (st) return st;
    st = parse_extension(p, header_size, t, d);
    if (st) return st;
    rd r = {p, len - 4, header_size};
    st = parse_axes(p, &r, n_axes, t, d);
    if (st) return st;
    st = parse_values(p, &r, flags, header_size, t, d);
    if (st) return st;
    st = parse_strings(p, &r, t, d);
    if (st) return st;
    return csflut_table_finish(t);
}

csflut_status csflut_open_memory_diag(const void *buf, size_t len, csflut_table **out,
                                      csflut_diag *diag)
{
    if (diag) memset(diag, 0, sizeof *diag);
    if (!out || (!buf && len)) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL argument");
        return CSFLUT_E_ARG;
    }
    *out = NULL;
    csflut_table *t = calloc(1, sizeof *t);
    if (!t) return CSFLUT_E_NOMEM;
    static const unsigned char empty[1] = {0};
    csflut_status st = parse(buf ? (const unsigned char *)buf : empty, len, t, diag);
    if (st == CSFLUT_E_NOMEM) csflut_diag_set(diag, st, 0, "out of memory");
    if (st) {
        csflut_close(t);
        return st;
    }
    *out = t;
    return CSFLUT_OK;
}

csflut_status csflut_open_memory(const void *buf, size_t len, csflut_table **out)
{
    return csflut_open_memory_diag(buf, len, out, NULL);
}

csflut_status csflut_open_file_diag(const char *path, csflut_table **out, csflut_diag *diag)
{
    if (diag) memset(diag, 0, sizeof *diag);
    if (!path || !out) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL argument");
        return CSFLUT_E_ARG;
    }
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot open %s: %s", path, strerror(errno));
        return CSFLUT_E_IO;
    }
    errno = 0; /* a failed fread below names its own error */
    /* Read in chunks rather than trusting fseek/ftell (pipes, /proc files); cap at a size no
     * valid table reaches so a huge file cannot exhaust memory. */
    const size_t cap = (size_t)CSFLUT_MAX_NODES * 16 + (size_t)4 * CSFLUT_MAX_POINTS * 8 + (1u << 20);
    size_t len = 0, alloc = 0;
    unsigned char *buf = NULL;
    for (;;) {
        if (len == alloc) {
            size_t na = alloc ? alloc * 2 : 65536;
            unsigned char *nb = realloc(buf, na);
            if (!nb) {
                free(buf);
                fclose(f);
                csflut_diag_set(diag, CSFLUT_E_NOMEM, 0, "out of memory reading %s", path);
                return CSFLUT_E_NOMEM;
            }
            buf = nb;
            alloc = na;
        }
        size_t got = fread(buf + len, 1, alloc - len, f);
        len += got;
        if (got == 0) break;
        if (len > cap) {
            free(buf);
            fclose(f);
            csflut_diag_set(diag, CSFLUT_E_BAD_HEADER, cap,
                            "%s is larger than any valid table (%zu bytes)", path, cap);
            return CSFLUT_E_BAD_HEADER;
        }
    }
    int err = ferror(f) ? (errno ? errno : EIO) : 0;
    fclose(f);
    if (err) {
        free(buf);
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot read %s: %s", path, strerror(err));
        return CSFLUT_E_IO;
    }
    csflut_status st = csflut_open_memory_diag(buf, len, out, diag);
    free(buf);
    return st;
}

csflut_status csflut_open_file(const char *path, csflut_table **out)
{
    return csflut_open_file_diag(path, out, NULL);
}

/* ---- views ------------------------------------------------------------------------------------ */
void csflut_set_conservative(csflut_table *t, int on)
{
    if (t) t->conservative = on != 0;
}
int csflut_get_conservative(const csflut_table *t) { return t ? t->conservative : 0; }

csflut_status csflut_set_stderr_shift(csflut_table *t, double k)
{
    if (!t || !isfinite(k) || k < 0 || k > 10) return CSFLUT_E_ARG;
    t->k_shift = k;
    compute_conservative(t);
    compute_slices(t);
    return CSFLUT_OK;
}
double csflut_get_stderr_shift(const csflut_table *t) { return t ? t->k_shift : 0; }

/* ---- queries ------------------------------------------------------------------------------------ */
/* Bilinear blend of the log2 slice; the caller turns the log2 result into a threshold. */
static inline double bilinear(const double *vals, int nf, int i, int j, double wf, double we)
{
    const double *v = vals + (size_t)j * (size_t)nf + i;
    double r0 = lerp(v[0], v[1], wf);
    double r1 = lerp(v[nf], v[nf + 1], wf);
    return lerp(r0, r1, we);
}

/* The 2-D fast path after the frequency's log2 is known: cell search on both axes, bilinear. */
static inline double q2_core(const csflut_axis_fast *fx, const csflut_axis_fast *ex,
                             const double *vals, double u, double ecc_deg)
{
    u = clampd(u, fx->lo, fx->hi);
    double e = clampd(ecc_deg, ex->lo, ex->hi);
    double wf, we;
    int i = axis_fast_locate(fx, u, &wf);
    int j = axis_fast_locate(ex, e, &we);
    return bilinear(vals, fx->n, i, j, wf, we);
}

static inline double q2(const csflut_table *t, double freq_cpd, double ecc_deg)
{
    if (freq_cpd != freq_cpd || ecc_deg != ecc_deg) return NAN;
    return from_log(q2_core(&t->fx, &t->ex, t->conservative ? t->slice_cons : t->slice_raw,
                            log2_guarded(freq_cpd), ecc_deg),
                    t->cap_log2);
}

double csflut_threshold(const csflut_table *t, double freq_cpd, double ecc_deg)
{
    return t ? q2(t, freq_cpd, ecc_deg) : NAN;
}

/* The 3-D fast path after the frequency's log2 and the velocity's coordinate are known: cell
 * search on three axes, a bilinear blend in each of the two velocity slices (nested frequency,
 * eccentricity, as the 2-D path), then the blend along velocity. */
static inline double q3_core(const csflut_table *t, const double *vals, double u, double ecc_deg, double vc)
{
    u = clampd(u, t->fx.lo, t->fx.hi);
    double e = clampd(ecc_deg, t->ex.lo, t->ex.hi), c = clampd(vc, t->vx.lo, t->vx.hi);
    double wf, we, wv;
    int i = axis_fast_locate(&t->fx, u, &wf);
    int j = axis_fast_locate(&t->ex, e, &we);
    int k = axis_fast_locate(&t->vx, c, &wv);
    size_t plane = (size_t)t->fx.n * (size_t)t->ex.n;
    const double *s0 = vals + (size_t)k * plane;
    double b0 = bilinear(s0, t->fx.n, i, j, wf, we);
    double b1 = bilinear(s0 + plane, t->fx.n, i, j, wf, we);
    return lerp(b0, b1, wv);
}

static inline double vel_coord_of(const csflut_table *t, double vel_dps)
{
    return csflut_vel_coord(vel_dps, t->vel_v0, t->scale[2] == CSFLUT_SCALE_LOG);
}

double csflut_threshold3(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps)
{
    if (!t) return NAN;
    if (t->n[2] == 0) return q2(t, freq_cpd, ecc_deg);
    if (freq_cpd != freq_cpd || ecc_deg != ecc_deg || vel_dps != vel_dps) return NAN;
    double r = q3_core(t, t->conservative ? t->slice3_cons : t->slice3_raw, log2_guarded(freq_cpd), ecc_deg,
                       vel_coord_of(t, vel_dps));
    return from_log(r, t->cap_log2);
}

int csflut_perceptible3(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps,
                        double contrast)
{
    return contrast >= csflut_threshold3(t, freq_cpd, ecc_deg, vel_dps);
}

double csflut_threshold4(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps,
                         double lum_cdm2)
{
    if (!t) return NAN;
    if (t->n[3] == 0) return csflut_threshold3(t, freq_cpd, ecc_deg, vel_dps);
    double r = interp_nd(t, t->conservative ? t->cons : t->raw, freq_cpd, ecc_deg, vel_dps,
                         lum_cdm2);
    return r != r ? NAN : from_log(r, t->cap_log2);
}

int csflut_perceptible(const csflut_table *t, double freq_cpd, double ecc_deg, double contrast)
{
    double th = csflut_threshold(t, freq_cpd, ecc_deg);
    return contrast >= th;
}

/* Highest frequency whose interpolated threshold is <= c, given the column of log2 thresholds at
 * the frequency nodes (already interpolated over the other axes; the cap = never visible). Solved
 * on the same piecewise-linear curve (log2 threshold against log2 frequency) the queries use. */
static double invert_column(const csflut_table *t, const double *col, double c)
{
    int n = t->fx.n;
    double cap = t->cap_log2;
    if (c != c) return NAN;
    if (!(c > 0)) return 0.0;
    double lc = csflut_log2(c);
    if (col[n - 1] < cap && col[n - 1] <= lc) return HUGE_VAL;
    for (int i = n - 2; i >= 0; i--) {
        if (col[i] < cap && col[i] <= lc) {
            double a = col[i], b = col[i + 1];
            /* the crossing is the node itself: return the stored grid point exactly */
            if (a == lc) return t->pts[0][i < t->n[0] ? i : t->n[0] - 1];
            /* a contrast above the cap is visible up to (not at) the invisible node i + 1 */
            double w = lc >= b ? 1.0 : (lc - a) / (b - a);
            return exp2(t->fx.node[i] + w * (t->fx.node[i + 1] - t->fx.node[i]));
        }
    }
    return 0.0;
}

double csflut_max_frequency(const csflut_table *t, double ecc_deg, double contrast)
{
    if (!t || ecc_deg != ecc_deg) return NAN;
    double col[CSFLUT_MAX_POINTS + 1];
    double e = clampd(ecc_deg, t->ex.lo, t->ex.hi), we;
    int j = axis_fast_locate(&t->ex, e, &we), nf = t->fx.n;
    const double *s = (t->conservative ? t->slice_cons : t->slice_raw) + (size_t)j * (size_t)nf;
    for (int i = 0; i < nf; i++) col[i] = lerp(s[i], s[i + nf], we);
    return invert_column(t, col, contrast);
}

/* The column of log2 thresholds at the frequency nodes for (ecc, velocity), from the 3-D slices:
 * the same blends csflut_threshold3 makes at a frequency node (weight 0 there). */
static double max_frequency3(const csflut_table *t, double ecc_deg, double vel_dps, double contrast)
{
    if (ecc_deg != ecc_deg || vel_dps != vel_dps) return NAN;
    double col[CSFLUT_MAX_POINTS + 1];
    double e = clampd(ecc_deg, t->ex.lo, t->ex.hi), we, wv;
    double c = clampd(vel_coord_of(t, vel_dps), t->vx.lo, t->vx.hi);
    int j = axis_fast_locate(&t->ex, e, &we), k = axis_fast_locate(&t->vx, c, &wv), nf = t->fx.n;
    size_t plane = (size_t)nf * (size_t)t->ex.n;
    const double *s0 =
        (t->conservative ? t->slice3_cons : t->slice3_raw) + (size_t)k * plane + (size_t)j * (size_t)nf;
    const double *s1 = s0 + plane;
    for (int i = 0; i < nf; i++) col[i] = lerp(lerp(s0[i], s0[i + nf], we), lerp(s1[i], s1[i + nf], we), wv);
    return invert_column(t, col, contrast);
}

double csflut_max_frequency4(const csflut_table *t, double ecc_deg, double vel_dps,
                             double lum_cdm2, double contrast)
{
    if (!t) return NAN;
    if (t->n[2] == 0 && t->n[3] == 0) return csflut_max_frequency(t, ecc_deg, contrast);
    if (t->n[3] == 0) return max_frequency3(t, ecc_deg, vel_dps, contrast);
    double col[CSFLUT_MAX_POINTS + 1];
    int nf = t->fx.n;
    for (int i = 0; i < nf; i++) {
        int fi = i < t->n[0] ? i : t->n[0] - 1;
        col[i] = interp_nd(t, t->conservative ? t->cons : t->raw, t->pts[0][fi], ecc_deg,
                           vel_dps, lum_cdm2);
        if (col[i] != col[i]) return NAN;
    }
    return invert_column(t, col, contrast);
}

double csflut_peak_frequency(const csflut_table *t, double ecc_deg)
{
    if (!t || ecc_deg != ecc_deg) return NAN;
    double e = clampd(ecc_deg, t->ex.lo, t->ex.hi), we;
    int j = axis_fast_locate(&t->ex, e, &we), nf = t->n[0];
    const double *s = (t->conservative ? t->slice_cons : t->slice_raw) + (size_t)j * (size_t)t->fx.n;
    int best = 0;
    double bv = HUGE_VAL;
    for (int i = 0; i < nf; i++) {
        double v = lerp(s[i], s[i + t->fx.n], we);
        if (v <= bv) {
            bv = v;
            best = i;
        }
    }
    return t->pts[0][best];
}

#define DEG_PER_RAD 57.295779513082320876798
double csflut_threshold_cpr(const csflut_table *t, double freq_cpr, double ecc_rad)
{
    return csflut_threshold(t, freq_cpr / DEG_PER_RAD, ecc_rad * DEG_PER_RAD);
}
double csflut_threshold_wavelength(const csflut_table *t, double wavelength_rad, double ecc_rad)
{
    return csflut_threshold(t, 1.0 / (wavelength_rad * DEG_PER_RAD), ecc_rad * DEG_PER_RAD);
}
int csflut_perceptible_cpr(const csflut_table *t, double freq_cpr, double ecc_rad, double contrast)
{
    return contrast >= csflut_threshold_cpr(t, freq_cpr, ecc_rad);
}
int csflut_perceptible_wavelength(const csflut_table *t, double wavelength_rad, double ecc_rad,
                                  double contrast)
{
    return contrast >= csflut_threshold_wavelength(t, wavelength_rad, ecc_rad);
}
double csflut_max_frequency_cpr(const csflut_table *t, double ecc_rad, double contrast)
{
    return csflut_max_frequency(t, ecc_rad * DEG_PER_RAD, contrast) * DEG_PER_RAD;
}
double csflut_min_wavelength(const csflut_table *t, double ecc_rad, double contrast)
{
    double f = csflut_max_frequency_cpr(t, ecc_rad, contrast);
    if (f != f) return f;
    return 1.0 / f; /* inf -> 0 (every wavelength visible), 0 -> inf (none) */
}

void csflut_threshold_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                            double *out, size_t n)
{
    if (!t || !freq_cpd || !ecc_deg || !out) return;
    /* Blocks: the arithmetic that needs no table (log2, clamps, bucket numbers; exp2 and the
     * infinity/NaN selects) in loops the compiler vectorises, the table look-ups in between with
     * the axes in locals. Same arithmetic as csflut_threshold, so the results are bit-identical. */
    const csflut_axis_fast fx = t->fx, ex = t->ex;
    const double *vals = t->conservative ? t->slice_cons : t->slice_raw;
    const double cap = t->cap_log2;
    const int plain = fx.n_buckets && fx.last_exact && ex.n_buckets && ex.last_exact;
    enum { BLOCK = 512 };
    double u[BLOCK], ec[BLOCK];
    int bu[BLOCK], be[BLOCK];
    for (size_t b0 = 0; b0 < n; b0 += BLOCK) {
        size_t m = n - b0 < BLOCK ? n - b0 : BLOCK;
        if (plain) {
            /* vectorised: log2, clamps and bucket numbers */
            for (size_t k = 0; k < m; k++) {
                u[k] = clampd(log2_guarded(freq_cpd[b0 + k]), fx.lo, fx.hi);
                ec[k] = clampd(ecc_deg[b0 + k], ex.lo, ex.hi);
                bu[k] = bucket_of(&fx, u[k]);
                be[k] = bucket_of(&ex, ec[k]);
            }
            /* scalar: the cell search and the blend (table look-ups) */
            for (size_t k = 0; k < m; k++) {
                int s = fx.first[bu[k]], i = s + (u[k] >= fx.next[s]);
                int r = ex.first[be[k]], j = r + (ec[k] >= ex.next[r]);
                double wf = (u[k] - fx.node[i]) * fx.inv_step[i];
                double we = (ec[k] - ex.node[j]) * ex.inv_step[j];
                u[k] = bilinear(vals, fx.n, i, j, wf, we);
            }
        } else {
            for (size_t k = 0; k < m; k++)
                u[k] = q2_core(&fx, &ex, vals, log2_guarded(freq_cpd[b0 + k]), ecc_deg[b0 + k]);
        }
        for (size_t k = 0; k < m; k++) { /* from_log, written so that it vectorises */
            double f = freq_cpd[b0 + k], e = ecc_deg[b0 + k], v = csflut_exp2i(u[k]);
            out[b0 + k] = (f != f || e != e) ? NAN : (u[k] >= cap ? HUGE_VAL : v);
        }
    }
}

/* One block of the 3-D batch with every axis bucketed: coordinates, clamps and bucket numbers
 * in a loop the compiler vectorises, then the cell search and the trilinear blend; u gets the
 * log2 results. Same arithmetic as q3_core. */
static void batch3_block(const csflut_table *t, const double *vals, const double *f, const double *e,
                         const double *v, size_t m, double *u)
{
    enum { BLOCK = 512 };
    const csflut_axis_fast fx = t->fx, ex = t->ex, vx = t->vx;
    const double v0 = t->vel_v0;
    const int lg = t->scale[2] == CSFLUT_SCALE_LOG;
    double ec[BLOCK], vc[BLOCK];
    int bu[BLOCK], be[BLOCK], bv[BLOCK];
    for (size_t k = 0; k < m; k++) {
        u[k] = clampd(log2_guarded(f[k]), fx.lo, fx.hi);
        ec[k] = clampd(e[k], ex.lo, ex.hi);
        bu[k] = bucket_of(&fx, u[k]);
        be[k] = bucket_of(&ex, ec[k]);
    }
    /* the velocity coordinate, one loop per kind of axis so each vectorises; fabs gives the
     * same sums as csflut_vel_coord's |v| (they differ only in the sign of a zero) */
    if (v0 == v0)
        for (size_t k = 0; k < m; k++) vc[k] = csflut_log2i(fabs(v[k]) + v0);
    else if (lg)
        for (size_t k = 0; k < m; k++) vc[k] = csflut_log2i(fabs(v[k]));
    else
        for (size_t k = 0; k < m; k++) vc[k] = fabs(v[k]);
    for (size_t k = 0; k < m; k++) {
        vc[k] = clampd(vc[k], vx.lo, vx.hi);
        bv[k] = bucket_of(&vx, vc[k]);
    }
    const size_t plane = (size_t)fx.n * (size_t)ex.n;
    for (size_t k = 0; k < m; k++) {
        int s = fx.first[bu[k]], i = s + (u[k] >= fx.next[s]);
        int r = ex.first[be[k]], j = r + (ec[k] >= ex.next[r]);
        int q = vx.first[bv[k]], l = q + (vc[k] >= vx.next[q]);
        double wf = (u[k] - fx.node[i]) * fx.inv_step[i];
        double we = (ec[k] - ex.node[j]) * ex.inv_step[j];
        double wv = (vc[k] - vx.node[l]) * vx.inv_step[l];
        const double *s0 = vals + (size_t)l * plane;
        double b0 = bilinear(s0, fx.n, i, j, wf, we);
        double b1 = bilinear(s0 + plane, fx.n, i, j, wf, we);
        u[k] = lerp(b0, b1, wv);
    }
}

void csflut_threshold3_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                             const double *vel_dps, double *out, size_t n)
{
    if (!t || !freq_cpd || !ecc_deg || !vel_dps || !out) return;
    if (t->n[2] == 0) {
        csflut_threshold_batch(t, freq_cpd, ecc_deg, out, n);
        return;
    }
    const double *vals = t->conservative ? t->slice3_cons : t->slice3_raw;
    const double cap = t->cap_log2;
    const int plain = t->fx.n_buckets && t->fx.last_exact && t->ex.n_buckets && t->ex.last_exact &&
                      t->vx.n_buckets && t->vx.last_exact;
    enum { BLOCK = 512 };
    double u[BLOCK];
    for (size_t b0 = 0; b0 < n; b0 += BLOCK) {
        size_t m = n - b0 < BLOCK ? n - b0 : BLOCK;
        if (plain) {
            batch3_block(t, vals, freq_cpd + b0, ecc_deg + b0, vel_dps + b0, m, u);
        } else {
            for (size_t k = 0; k < m; k++)
                u[k] = q3_core(t, vals, log2_guarded(freq_cpd[b0 + k]), ecc_deg[b0 + k],
                               vel_coord_of(t, vel_dps[b0 + k]));
        }
        for (size_t k = 0; k < m; k++) { /* from_log, written so that it vectorises */
            double f = freq_cpd[b0 + k], e = ecc_deg[b0 + k], v = vel_dps[b0 + k];
            double x = csflut_exp2i(u[k]);
            out[b0 + k] = (f != f || e != e || v != v) ? NAN : (u[k] >= cap ? HUGE_VAL : x);
        }
    }
}

void csflut_threshold4_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                             const double *vel_dps, const double *lum_cdm2, double *out, size_t n)
{
    if (!t || !freq_cpd || !ecc_deg || !out) return;
    if (t->n[3] == 0 && vel_dps) {
        csflut_threshold3_batch(t, freq_cpd, ecc_deg, vel_dps, out, n);
        return;
    }
    for (size_t i = 0; i < n; i++)
        out[i] = csflut_threshold4(t, freq_cpd[i], ecc_deg[i], vel_dps ? vel_dps[i] : t->def_vel,
                                   lum_cdm2 ? lum_cdm2[i] : t->def_lum);
}

void csflut_perceptible_batch(const csflut_table *t, const double *freq_cpd,
                              const double *ecc_deg, const double *contrast, unsigned char *out,
                              size_t n)
{
    if (!t || !freq_cpd || !contrast || !ecc_deg || !out) return;
    for (size_t i = 0; i < n; i++) out[i] = contrast[i] >= q2(t, freq_cpd[i], ecc_deg[i]);
}

/* ---- accessors -------------------------------------------------------------------------------- */
int csflut_axis_size(const csflut_table *t, csflut_axis a)
{
    return t && (unsigned)a < 4 ? t->n[a] : 0;
}
const double *csflut_axis_points(const csflut_table *t, csflut_axis a)
{
    return t && (unsigned)a < 4 ? t->pts[a] : NULL;
}
csflut_scale csflut_axis_scale(const csflut_table *t, csflut_axis a)
{
    return t && (unsigned)a < 4 ? (csflut_scale)t->scale[a] : CSFLUT_SCALE_LINEAR;
}
size_t csflut_node_count(const csflut_table *t) { return t ? t->n_nodes : 0; }
const double *csflut_raw_thresholds(const csflut_table *t) { return t ? t->raw : NULL; }
const double *csflut_conservative_thresholds(const csflut_table *t) { return t ? t->cons : NULL; }
const double *csflut_stderr_log10(const csflut_table *t) { return t ? t->se : NULL; }
int csflut_version_major(const csflut_table *t) { return t ? t->vmaj : 0; }
int csflut_version_minor(const csflut_table *t) { return t ? t->vmin : 0; }
static const char *str_or_empty(const csflut_table *t, int k)
{
    return t && t->str[k] ? t->str[k] : "";
}
const char *csflut_observer(const csflut_table *t) { return str_or_empty(t, 0); }
const char *csflut_display_profile_id(const csflut_table *t) { return str_or_empty(t, 1); }
const char *csflut_method(const csflut_table *t) { return str_or_empty(t, 2); }
const char *csflut_date_utc(const csflut_table *t) { return str_or_empty(t, 3); }
const char *csflut_tool_version(const csflut_table *t) { return str_or_empty(t, 4); }
double csflut_viewing_distance_mm(const csflut_table *t) { return t ? t->dist_mm : NAN; }
double csflut_mean_lum_cdm2(const csflut_table *t) { return t ? t->mean_lum : NAN; }
int csflut_trials(const csflut_table *t) { return t ? t->trials : 0; }
double csflut_default_velocity(const csflut_table *t) { return t ? t->def_vel : NAN; }
double csflut_default_luminance(const csflut_table *t) { return t ? t->def_lum : NAN; }
double csflut_velocity_warp_v0(const csflut_table *t)
{
    return t && t->n[2] > 0 ? t->vel_v0 : NAN;
}
int csflut_meta_count(const csflut_table *t)
{
    return t ? t->n_meta : 0;
}
const char *csflut_meta_key(const csflut_table *t, int i)
{
    return t && i >= 0 && i < t->n_meta ? t->meta_key[i] : NULL;
}
const char *csflut_meta_value(const csflut_table *t, int i)
{
    return t && i >= 0 && i < t->n_meta ? t->meta_val[i] : NULL;
}
const char *csflut_meta_find(const csflut_table *t, const char *key)
{
    if (!t || !key) return NULL;
    for (int i = 0; i < t->n_meta; i++)
        if (strcmp(t->meta_key[i], key) == 0) return t->meta_val[i];
    return NULL;
}
size_t csflut_table_meta(const csflut_table *t, csflut_meta *out, size_t cap)
{
    if (!t) return 0;
    for (size_t i = 0; i < (size_t)t->n_meta && i < cap && out; i++) {
        out[i].key = t->meta_key[i];
        out[i].value = t->meta_val[i];
    }
    return (size_t)t->n_meta;
}
