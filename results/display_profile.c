/* Display profile: monotone piecewise-cubic model of luminance vs drive, its exact inverse, and
 * the versioned text file that carries it (docs/display-profile.md).
 *
 * Why a transformed space: display curves are close to power laws, so interpolating
 * y = ((L - black)/top)^(1/g) instead of L makes the curve nearly straight, and a monotone cubic
 * through a few knots then reaches 0.1 %-level accuracy where a cubic in raw luminance would need
 * many more readings. g is fitted per curve and stored, so the model is fully determined by the
 * file and the inverse is exact on the same piecewise cubic. */
#include "results/display_profile.h"
#include "core/csv.h"
#include "core/file_write.h"
#include "core/file_read.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef CSF_VERSION
#define CSF_VERSION "unknown"
#endif

#define MAX_KNOTS 4096
#define MAX_READINGS 100000
#define MAX_FILE_BYTES (16u << 20)

typedef struct {
    int n;
    double *v;       /* drive01, strictly increasing, v[0] = 0, v[n-1] = 1 */
    double *lum;     /* cd/m2; grey includes black, channels exclude it */
    double *y;       /* transformed luminance in [0,1] */
    double *m;       /* slope dy/dv at each knot as the left end of the interval after it */
    double *ml;      /* slope at each knot as the right end of the interval before it; differs
                        from m only at a corner (see fc_slopes) */
    double base, top; /* lum = base + top * y^g */
    double g;        /* transform exponent */
} curve;

struct csf_display_profile {
    char id[160];
    char display[256];
    char instrument[256];
    char created_utc[32];
    char tool_version[32];
    double additivity_error;
    /* what the calibration states about the profile (NAN / -1 when not stated: older files, the
     * default display): max relative error above 10 % of peak per curve, the target, met or not */
    double stated_error_rel[CSF_CH_COUNT];
    double target_rel;
    int target_met;
    int has_channels;
    int has_primaries;
    double rgbw_xyz[4][3];
    curve c[CSF_CH_COUNT];
    csf_profile_reading *readings;
    size_t n_readings;
};

static const char *ch_names[CSF_CH_COUNT] = {"r", "g", "b", "grey"};

/* ---------- curve maths ---------- */

static void curve_free(curve *c)
{
    free(c->v);
    free(c->lum);
    free(c->y);
    free(c->m);
    free(c->ml);
    memset(c, 0, sizeof *c);
}

static int curve_alloc(curve *c, int n)
{
    c->n = n;
    c->v = calloc((size_t)n, sizeof(double));
    c->lum = calloc((size_t)n, sizeof(double));
    c->y = calloc((size_t)n, sizeof(double));
    c->m = calloc((size_t)n, sizeof(double));
    c->ml = calloc((size_t)n, sizeof(double));
    return c->v && c->lum && c->y && c->m && c->ml ? 0 : -1;
}

/* Corner test at interior knot k of (x, y), in the power-transformed space where a display curve
 * is nearly straight: the change of secant slope across k, per unit of its neighbouring interval
 * widths (a second-derivative estimate), is at least 4 times that at both neighbouring knots and
 * more than 8 % of the slope. A smooth curve gives similar estimates at neighbouring knots; a kink
 * in the panel's response (or a measured curve's slope break) concentrates at one knot. */
static int is_corner(const double *x, const double *y, int n, int k)
{
    if (k < 1 || k > n - 2 || n < 4) return 0;
    double d[4], D[3];
    int have[3] = {0, 0, 0};
    for (int j = -2; j <= 1; j++) {
        int a = k + j;
        d[j + 2] = (a >= 0 && a + 1 < n) ? (y[a + 1] - y[a]) / (x[a + 1] - x[a]) : NAN;
    }
    for (int j = 0; j < 3; j++) {
        int knot = k - 1 + j;
        if (knot < 1 || knot > n - 2 || isnan(d[j]) || isnan(d[j + 1])) continue;
        double hbar = 0.5 * (x[knot + 1] - x[knot - 1]);
        D[j] = fabs(d[j + 1] - d[j]) / hbar;
        have[j] = 1;
    }
    if (!have[1] || (!have[0] && !have[2])) return 0;
    /* a break of at least 8 % in slope, between intervals no narrower than 1/512 of the drive
     * range: below that, measurement noise on close levels would look like kinks */
    double jump = fabs(d[2] - d[1]);
    if (!(jump > 0.08 * 0.5 * (fabs(d[1]) + fabs(d[2])))) return 0;
    if (x[k] - x[k - 1] < 1.0 / 512 || x[k + 1] - x[k] < 1.0 / 512) return 0;
    for (int j = 0; j < 3; j += 2)
        if (have[j] && !(D[1] > 4 * D[j])) return 0;
    return 1;
}

/* One-sided slope at the end of a run of knots: derivative of the parabola through the end knot
 * and the next two (h0, d0 the nearer interval's width and secant), kept shape-preserving: never
 * against the secant's sign, and at most 3 times it when the secants disagree in sign. */
static double one_sided(double h0, double d0, double h1, double d1)
{
    double m = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (m * d0 <= 0) return 0;
    if (d0 * d1 <= 0 && fabs(m) > fabs(3 * d0)) return 3 * d0;
    return m;
}

/* Fritsch–Carlson (1980) slopes: a cubic Hermite with these slopes is monotone wherever the data
 * are. At a corner the two intervals get one-sided slopes (each its own secant), so a kink is
 * kept as a kink instead of being rounded over both intervals. */
static void fc_slopes(const double *x, const double *y, double *m, double *ml, int n)
{
    if (n < 2) {
        if (n == 1) m[0] = ml[0] = 0;
        return;
    }
    double d_prev = 0;
    for (int i = 0; i < n - 1; i++) {
        double d = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
        /* interior slope: the secant across both neighbouring intervals, i.e. the secants
         * weighted by their widths. Why not their plain mean: a short interval's secant carries
         * the instrument noise divided by its width, and the mean would pass that into the long
         * interval beside it */
        if (i == 0) m[0] = d;
        else m[i] = (d_prev * d <= 0) ? 0 : (y[i + 1] - y[i - 1]) / (x[i + 1] - x[i - 1]);
        d_prev = d;
    }
    m[n - 1] = d_prev;
#define SEC(a) ((y[(a) + 1] - y[(a)]) / (x[(a) + 1] - x[(a)]))
#define WID(a) (x[(a) + 1] - x[(a)])
    /* the ends (drive 0 and 1) and both sides of a corner: one-sided three-point slopes */
    if (n >= 3) {
        m[0] = one_sided(WID(0), SEC(0), WID(1), SEC(1));
        m[n - 1] = one_sided(WID(n - 2), SEC(n - 2), WID(n - 3), SEC(n - 3));
    }
    for (int i = 0; i < n; i++) ml[i] = m[i];
    for (int k = 1; k < n - 1; k++)
        if (is_corner(x, y, n, k)) {
            ml[k] = k >= 2 ? one_sided(WID(k - 1), SEC(k - 1), WID(k - 2), SEC(k - 2)) : SEC(k - 1);
            m[k] = k + 2 < n ? one_sided(WID(k), SEC(k), WID(k + 1), SEC(k + 1)) : SEC(k);
        }
#undef SEC
#undef WID
    for (int i = 0; i < n - 1; i++) {
        double d = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
        if (d == 0) {
            m[i] = ml[i + 1] = 0;
            continue;
        }
        double a = m[i] / d, b = ml[i + 1] / d;
        /* A slope against the secant (a one-sided end or corner slope can point back) takes the
         * cubic outside the Fritsch-Carlson region: it dips and the curve is no longer monotone
         * (found by fuzz_profile on a nearly flat segment beside a steep one). */
        if (!(a > 0)) a = 0;
        if (!(b > 0)) b = 0;
        double s = a * a + b * b;
        double t = s > 9 ? 3 / sqrt(s) : 1;
        m[i] = t * a * d;
        ml[i + 1] = t * b * d;
    }
    /* away from corners keep the curve smooth: the smaller slope satisfies both intervals'
     * monotonicity limits (shrinking a slope never leaves the Fritsch–Carlson region) */
    for (int k = 1; k < n - 1; k++)
        if (!is_corner(x, y, n, k)) {
            double v = fabs(m[k]) < fabs(ml[k]) ? m[k] : ml[k];
            m[k] = ml[k] = v;
        }
}

static double hermite(const curve *c, int i, double t)
{
    double h = c->v[i + 1] - c->v[i];
    double t2 = t * t, t3 = t2 * t;
    /* Written as y0 plus increments, not as a weighted sum of y0 and y1: the weights of the usual
     * form add up to 1 only up to rounding, which made a flat segment wobble by an ulp and the
     * curve non-monotone there (found by fuzz_profile). Here a flat segment (equal ends, zero
     * slopes) is exactly y0, and the result is kept between the segment's ends, which is where a
     * monotone cubic lies. */
    /* The increment is summed before it meets y0: (y0 + a) + b rounds twice, and on a segment a
     * few hundred ulps tall that made the curve step down by an ulp near its end (fuzz_profile). */
    double inc = (3 * t2 - 2 * t3) * (c->y[i + 1] - c->y[i]) +
                 h * ((t3 - 2 * t2 + t) * c->m[i] + (t3 - t2) * c->ml[i + 1]);
    double y = c->y[i] + inc;
    double lo = c->y[i] < c->y[i + 1] ? c->y[i] : c->y[i + 1];
    double hi = c->y[i] < c->y[i + 1] ? c->y[i + 1] : c->y[i];
    return y < lo ? lo : y > hi ? hi : y;
}

static int find_seg(const curve *c, double v)
{
    int lo = 0, hi = c->n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (c->v[mid] <= v) lo = mid;
        else hi = mid;
    }
    return lo;
}

static double curve_y(const curve *c, double v)
{
    if (!(v > 0)) v = 0;
    if (v > 1) v = 1;
    int i = find_seg(c, v);
    if (i >= c->n - 1) return c->y[c->n - 1];
    double t = (v - c->v[i]) / (c->v[i + 1] - c->v[i]);
    double y = hermite(c, i, t);
    return y < 0 ? 0 : y;
}

static double curve_lum(const curve *c, double v)
{
    return c->base + c->top * pow(curve_y(c, v), c->g);
}

static double curve_drive(const curve *c, double lum)
{
    if (!(lum > c->base)) {
        /* lowest drive giving the black level (flat start of a cut-off display) */
        int i = 0;
        while (i + 1 < c->n && c->y[i + 1] <= 0) i++;
        return c->v[i];
    }
    if (lum >= c->base + c->top) return 1.0;
    double y = pow((lum - c->base) / c->top, 1.0 / c->g);
    /* first knot with y_k >= y: the segment before it holds the answer */
    int lo = 0, hi = c->n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (c->y[mid] < y) lo = mid;
        else hi = mid;
    }
    if (c->y[hi] == y) {
        int k = hi;
        while (k > 0 && c->y[k - 1] == y) k--;
        return c->v[k];
    }
    /* bisection on the monotone cubic: converges to the last bit of the double */
    double a = 0, b = 1;
    for (int it = 0; it < 80; it++) {
        double t = 0.5 * (a + b);
        if (hermite(c, lo, t) < y) a = t;
        else b = t;
        if (b - a < 1e-17) break;
    }
    return c->v[lo] + 0.5 * (a + b) * (c->v[lo + 1] - c->v[lo]);
}

/* Fills y/m from v/lum; base is lum[0] (grey) or 0 (channels); g fitted when g_fit <= 0. */
static int curve_finish(curve *c, int is_channel, double g_fixed)
{
    if (c->n < 2 || c->v[0] != 0.0 || c->v[c->n - 1] != 1.0) return -1;
    c->base = is_channel ? 0.0 : c->lum[0];
    c->top = c->lum[c->n - 1] - c->base;
    if (!(c->top > 0)) return -1;
    if (g_fixed > 0) {
        c->g = g_fixed;
    } else {
        /* log-log slope through knots in the upper part of the range, where relative accuracy
         * matters; clamped to a sane range */
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        int k = 0;
        for (int i = 1; i < c->n - 1; i++) {
            double r = (c->lum[i] - c->base) / c->top;
            if (r < 0.05 || c->v[i] <= 0) continue;
            double lx = log(c->v[i]), ly = log(r);
            sx += lx; sy += ly; sxx += lx * lx; sxy += lx * ly;
            k++;
        }
        double g = 2.2;
        /* fit through the origin of log-log (v=1 -> r=1) */
        if (k >= 1 && sxx > 0) g = sxy / sxx;
        (void)sx; (void)sy;
        if (!(g >= 1.0)) g = 1.0;
        if (g > 4.0) g = 4.0;
        c->g = g;
    }
    for (int i = 0; i < c->n; i++) {
        double r = (c->lum[i] - c->base) / c->top;
        if (r < 0) r = 0;
        if (r > 1) r = 1;
        c->y[i] = pow(r, 1.0 / c->g);
    }
    for (int i = 1; i < c->n; i++)
        if (c->y[i] < c->y[i - 1]) c->y[i] = c->y[i - 1]; /* rounding only: data are monotone */
    fc_slopes(c->v, c->y, c->m, c->ml, c->n);
    return 0;
}

/* ---------- accessors ---------- */

const char *csf_profile_id(const csf_display_profile *p) { return p->id; }
const char *csf_profile_display(const csf_display_profile *p) { return p->display; }
double csf_profile_lum_black(const csf_display_profile *p) { return p->c[CSF_CH_GREY].base; }
double csf_profile_lum_max(const csf_display_profile *p)
{
    return p->c[CSF_CH_GREY].base + p->c[CSF_CH_GREY].top;
}
double csf_profile_grey_lum(const csf_display_profile *p, double drive01)
{
    return curve_lum(&p->c[CSF_CH_GREY], drive01);
}
double csf_profile_rel_lum(const csf_display_profile *p, double drive01)
{
    double w = csf_profile_lum_max(p);
    return w > 0 ? csf_profile_grey_lum(p, drive01) / w : NAN;
}
double csf_profile_lum_from_rel(const csf_display_profile *p, double rel)
{
    return rel * csf_profile_lum_max(p);
}
double csf_profile_grey_drive(const csf_display_profile *p, double lum_cdm2)
{
    return curve_drive(&p->c[CSF_CH_GREY], lum_cdm2);
}
int csf_profile_has_channels(const csf_display_profile *p) { return p->has_channels; }
double csf_profile_channel_lum(const csf_display_profile *p, int ch, double drive01)
{
    if (!p->has_channels || ch < 0 || ch > 2) return NAN;
    return curve_lum(&p->c[ch], drive01);
}
double csf_profile_channel_drive(const csf_display_profile *p, int ch, double lum_cdm2)
{
    if (!p->has_channels || ch < 0 || ch > 2) return NAN;
    return curve_drive(&p->c[ch], lum_cdm2);
}
size_t csf_profile_knots(const csf_display_profile *p, int ch, const double **drive01,
                         const double **lum_cdm2)
{
    if (ch < 0 || ch >= CSF_CH_COUNT || (ch < 3 && !p->has_channels)) return 0;
    if (drive01) *drive01 = p->c[ch].v;
    if (lum_cdm2) *lum_cdm2 = p->c[ch].lum;
    return (size_t)p->c[ch].n;
}
size_t csf_profile_readings(const csf_display_profile *p, const csf_profile_reading **out)
{
    if (out) *out = p->readings;
    return p->n_readings;
}
int csf_profile_primaries_xyz(const csf_display_profile *p, double rgbw_xyz[4][3])
{
    if (!p->has_primaries) return 0;
    memcpy(rgbw_xyz, p->rgbw_xyz, sizeof p->rgbw_xyz);
    return 1;
}
double csf_profile_additivity_error(const csf_display_profile *p) { return p->additivity_error; }

static void statement_unknown(csf_display_profile *p)
{
    for (int c = 0; c < CSF_CH_COUNT; c++) p->stated_error_rel[c] = NAN;
    p->target_rel = NAN;
    p->target_met = -1;
}

void csf_profile_set_statement(csf_display_profile *p, double target_rel,
                               const double stated_error_rel[CSF_CH_COUNT], int target_met)
{
    p->target_rel = target_rel;
    for (int c = 0; c < CSF_CH_COUNT; c++) p->stated_error_rel[c] = stated_error_rel[c];
    p->target_met = target_met ? 1 : 0;
}

int csf_profile_statement(const csf_display_profile *p, double *target_rel,
                          double stated_error_rel[CSF_CH_COUNT])
{
    if (target_rel) *target_rel = p->target_rel;
    if (stated_error_rel)
        for (int c = 0; c < CSF_CH_COUNT; c++) stated_error_rel[c] = p->stated_error_rel[c];
    return p->target_met;
}
const char *csf_profile_instrument(const csf_display_profile *p) { return p->instrument; }
const char *csf_profile_created_utc(const csf_display_profile *p) { return p->created_utc; }

static int parse_utc(const char *s, time_t *out)
{
    struct tm tm;
    memset(&tm, 0, sizeof tm);
    /* exactly YYYY-MM-DDTHH:MM:SSZ: sscanf alone would skip whitespace inside the fields */
    static const char shape[] = "dddd-dd-ddTdd:dd:ddZ";
    if (strlen(s) != sizeof shape - 1) return -1;
    for (size_t i = 0; i < sizeof shape - 1; i++)
        if (shape[i] == 'd' ? !isdigit((unsigned char)s[i]) : s[i] != shape[i]) return -1;
    int Y, M, D, h, mi, se;
    if (sscanf(s, "%4d-%2d-%2dT%2d:%2d:%2dZ", &Y, &M, &D, &h, &mi, &se) != 6) return -1;
    if (Y < 1970 || Y > 9999 || M < 1 || M > 12 || D < 1 || D > 31 || h > 23 || mi > 59 || se > 60 ||
        h < 0 || mi < 0 || se < 0)
        return -1;
    tm.tm_year = Y - 1900; tm.tm_mon = M - 1; tm.tm_mday = D;
    tm.tm_hour = h; tm.tm_min = mi; tm.tm_sec = se;
    *out = timegm(&tm);
    return 0;
}

double csf_profile_age_days(const csf_display_profile *p)
{
    time_t t;
    if (parse_utc(p->created_utc, &t)) return NAN;
    return difftime(time(NULL), t) / 86400.0;
}

int csf_profile_age_warning(const csf_display_profile *p, double max_age_days, char *msg, size_t len)
{
    if (msg && len) msg[0] = 0;
    double age = csf_profile_age_days(p);
    if (!(max_age_days > 0) || !isfinite(age) || age <= max_age_days) return 0;
    if (msg && len)
        snprintf(msg, len, "display profile %s is %.0f days old (limit profile_max_age_days = %g): recalibrate the monitor",
                 p->id, age, max_age_days);
    return 1;
}

void csf_profile_free(csf_display_profile *p)
{
    if (!p) return;
    for (int c = 0; c < CSF_CH_COUNT; c++) curve_free(&p->c[c]);
    free(p->readings);
    free(p);
}

static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
    const unsigned char *b = data;
    /* make_id hashes the bytes of set doubles; the analyzer cannot split a double into bytes */
    for (size_t k = 0; k < len; k++) h = (h ^ b[k]) * 1099511628211ull; // NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult)
    return h;
}

#define FNV_OFFSET 1469598103934665603ull
#define ID_NAME_MAX 24 /* longest display name kept readable in an id */

/* The display part of an id: the name itself when it is short and holds no path (a name given
 * with --name, "sim:display=lcd"), else its first word and a hash of the whole name, so that a
 * photometer spec with a file path ("sim:display=file=/data/lab/kink.csv") gives "sim-1f0c2a9e":
 * ids go into table metadata, file names and reports, where a path is noise and may be private. */
static void id_name(const char *display, char *out, size_t cap)
{
    size_t len = strlen(display);
    int pathlike = strchr(display, '/') != NULL || strchr(display, '\\') != NULL;
    size_t j = 0;
    if (!pathlike && len <= ID_NAME_MAX) {
        for (const char *s = display; *s && j + 1 < cap; s++)
            out[j++] = (isalnum((unsigned char)*s) || *s == '.' || *s == '_') ? *s : '-';
        out[j] = 0;
        return;
    }
    for (const char *s = display; *s && j < 12 && j + 1 < cap && (isalnum((unsigned char)*s) || *s == '_'); s++)
        out[j++] = *s;
    uint64_t h = fnv1a(FNV_OFFSET, display, len);
    snprintf(out + j, cap - j, "%s%08x", j ? "-" : "", (unsigned)(h ^ (h >> 32)));
}

/* "<display>-<date>-<hash of the model>": the hash (FNV-1a over the knot values) changes when
 * the model does. */
static void make_id(csf_display_profile *p)
{
    uint64_t h = FNV_OFFSET;
    for (int c = 0; c < CSF_CH_COUNT; c++)
        for (int i = 0; i < p->c[c].n; i++) {
            double pair[2] = {p->c[c].v[i], p->c[c].lum[i]};
            h = fnv1a(h, pair, sizeof pair);
        }
    char disp[48];
    id_name(p->display, disp, sizeof disp);
    char date[16] = "undated";
    if (strlen(p->created_utc) >= 10)
        snprintf(date, sizeof date, "%.4s%.2s%.2s", p->created_utc, p->created_utc + 5,
                 p->created_utc + 8);
    snprintf(p->id, sizeof p->id, "%s-%s-%08x", disp[0] ? disp : "display", date,
             (unsigned)(h ^ (h >> 32)));
}

static void now_utc(char *buf, size_t len)
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

static void copy_str(char *dst, size_t cap, const char *src)
{
    snprintf(dst, cap, "%s", src ? src : "");
    for (char *s = dst; *s; s++)
        if (*s == '\n' || *s == '\r') *s = ' ';
}

/* ---------- default profile ---------- */

csf_display_profile *csf_profile_default(void)
{
    csf_display_profile *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    statement_unknown(p);
    copy_str(p->display, sizeof p->display, "default");
    copy_str(p->instrument, sizeof p->instrument, "none (documented default display)");
    copy_str(p->created_utc, sizeof p->created_utc, "2026-01-01T00:00:00Z");
    copy_str(p->tool_version, sizeof p->tool_version, CSF_VERSION);
    p->additivity_error = 0;
    p->has_channels = 1;
    static const double w[3] = {0.2126, 0.7152, 0.0722};
    const double black = 0.2, white = 100.0, g = 2.2;
    const int n = 17;
    for (int c = 0; c < CSF_CH_COUNT; c++) {
        if (curve_alloc(&p->c[c], n)) {
            csf_profile_free(p);
            return NULL;
        }
        for (int i = 0; i < n; i++) {
            double v = (double)i / (n - 1);
            double rel = pow(v, g);
            p->c[c].v[i] = v;
            p->c[c].lum[i] = c == CSF_CH_GREY ? black + (white - black) * rel : (white - black) * w[c] * rel;
        }
        curve_finish(&p->c[c], c != CSF_CH_GREY, g);
    }
    snprintf(p->id, sizeof p->id, "default-gamma2.2-100cdm2");
    return p;
}

/* A kink that falls between two knots (k, k+1) is rounded by any smooth interpolant over that
 * interval, and neither knot looks like a corner (each carries half of the break). Detected in
 * the power-transformed space, where the curve is nearly straight: the lines through the knots on
 * either side (spans of at least 0.02 of drive, so one noisy knot does not tilt them) differ in
 * slope by more than 15 %, and that break per unit width is at least 3 times the change of slope
 * just outside (a smooth curve bends evenly). The kink is then where the two lines cross: that
 * point becomes a knot, which is_corner() keeps as a corner (when its intervals are at least
 * 1/512 wide; else it is still the vertex between two short intervals). Writes up to max
 * crossings (drive, transformed y) into xs/ys, returns how many. */
static int bracketed_corners(const curve *c, double *xs, double *ys, int max)
{
    const double span = 0.02, gap = 1.0 / 1024;
    enum { MAXC = 64 };
    int ck[MAXC];
    double cx[MAXC], cy[MAXC], ch[MAXC];
    int nc = 0;
    for (int k = 1; k + 2 < c->n && nc < MAXC; k++) {
        /* (a knot already taken for a corner may be one beside the kink: the crossing decides) */
        int a = k - 1, b = k + 2;
        while (a > 0 && c->v[k] - c->v[a] < span) a--;
        while (b < c->n - 1 && c->v[b] - c->v[k + 1] < span) b++;
        if (c->v[k] - c->v[a] < span || c->v[b] - c->v[k + 1] < span) continue;
        double sL = (c->y[k] - c->y[a]) / (c->v[k] - c->v[a]);
        double sR = (c->y[b] - c->y[k + 1]) / (c->v[b] - c->v[k + 1]);
        double brk = fabs(sR - sL);
        if (!(brk > 0.15 * 0.5 * (fabs(sL) + fabs(sR)))) continue;
        double here = brk / (0.5 * (c->v[b] - c->v[a]));
        /* the change of slope just outside, per unit width, on each side that has room */
        int a2 = a - 1, b2 = b + 1, sides = 0, smooth = 1;
        while (a2 > 0 && c->v[a] - c->v[a2] < span) a2--;
        while (b2 < c->n - 1 && c->v[b2] - c->v[b] < span) b2++;
        if (a2 >= 0 && c->v[a] - c->v[a2] >= span) {
            double sLL = (c->y[a] - c->y[a2]) / (c->v[a] - c->v[a2]);
            if (!(here > 3 * fabs(sL - sLL) / (0.5 * (c->v[k] - c->v[a2])))) smooth = 0;
            sides++;
        }
        if (b2 < c->n && c->v[b2] - c->v[b] >= span) {
            double sRR = (c->y[b2] - c->y[b]) / (c->v[b2] - c->v[b]);
            if (!(here > 3 * fabs(sRR - sR) / (0.5 * (c->v[b2] - c->v[k + 1])))) smooth = 0;
            sides++;
        }
        if (sides < 2 || !smooth) continue; /* both sides: near an end one side proves nothing */
        double x = (c->y[k + 1] - c->y[k] + sL * c->v[k] - sR * c->v[k + 1]) / (sL - sR);
        if (!(x >= c->v[k] + gap && x <= c->v[k + 1] - gap)) continue;
        double y = c->y[k] + sL * (x - c->v[k]);
        if (!(y > c->y[k] && y < c->y[k + 1])) continue;
        ck[nc] = k;
        cx[nc] = x;
        cy[nc] = y;
        ch[nc] = here;
        nc++;
    }
    /* one kink shows in neighbouring pairs too (a line that reaches across it is tilted and
     * crosses the other short of it): keep the pair with the sharpest break among those within
     * two knots of each other */
    int nf = 0;
    for (int i = 0; i < nc && nf < max; i++) {
        int keep = 1;
        for (int j = 0; j < nc; j++)
            if (j != i && abs(ck[j] - ck[i]) <= 2 && (ch[j] > ch[i] || (ch[j] == ch[i] && j < i))) keep = 0;
        if (!keep) continue;
        xs[nf] = cx[i];
        ys[nf] = cy[i];
        nf++;
    }
    return nf;
}

/* ---------- building from readings ---------- */

static int cmp_reading(const void *a, const void *b)
{
    const csf_profile_reading *x = a, *y = b;
    return (x->drive01 > y->drive01) - (x->drive01 < y->drive01);
}

/* The readings of channel ch in a fresh array, with the shared black point for a colour
 * channel (drive 0 of every channel is black). */
static csf_status select_readings(const csf_profile_reading *r, size_t n, int ch, csf_profile_reading **out,
                                  size_t *n_out, csf_error *err)
{
    csf_profile_reading *sel = malloc((n ? n : 1) * sizeof *sel);
    if (!sel) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (r[i].channel == ch && isfinite(r[i].lum_cdm2) && r[i].drive01 >= 0 && r[i].drive01 <= 1)
            sel[k++] = r[i];
    if (ch != CSF_CH_GREY) {
        /* channel curves include the shared black point (drive 0 of every channel is black) */
        for (size_t i = 0; i < n; i++)
            if (r[i].channel == CSF_CH_GREY && r[i].drive01 == 0 && isfinite(r[i].lum_cdm2)) {
                csf_profile_reading *grown = realloc(sel, (k + 1) * sizeof *sel);
                if (!grown) {
                    free(sel);
                    return csf_error_set(err, CSF_E_NOMEM, "out of memory");
                }
                sel = grown;
                sel[k] = r[i];
                sel[k].channel = ch;
                k++;
            }
    }
    *out = sel;
    *n_out = k;
    return CSF_OK;
}

/* Readings sorted by drive into one level per distinct drive: its mean luminance (less black
 * for a colour channel) weighted by the number of repeats. Returns the number of levels. */
static int average_repeats(const csf_profile_reading *sel, size_t k, int ch, double black, double *v,
                           double *L, double *wt)
{
    int m = 0;
    for (size_t i = 0; i < k;) {
        size_t j = i;
        double s = 0;
        while (j < k && sel[j].drive01 == sel[i].drive01) s += sel[j++].lum_cdm2;
        v[m] = sel[i].drive01;
        L[m] = s / (double)(j - i) - (ch == CSF_CH_GREY ? 0 : black);
        wt[m] = (double)(j - i);
        m++;
        i = j;
    }
    return m;
}

/* PAV: blocks of pooled values, then expanded back per knot */
static void pool_adjacent_violators(double *L, const double *wt, int m)
{
    double *bv = malloc((size_t)m * sizeof(double)), *bw = malloc((size_t)m * sizeof(double));
    int *bn = malloc((size_t)m * sizeof(int));
    int nb = 0;
    for (int i = 0; i < m; i++) {
        bv[nb] = L[i]; bw[nb] = wt[i]; bn[nb] = 1; nb++;
        while (nb > 1 && bv[nb - 2] > bv[nb - 1]) {
            double w2 = bw[nb - 2] + bw[nb - 1];
            bv[nb - 2] = (bv[nb - 2] * bw[nb - 2] + bv[nb - 1] * bw[nb - 1]) / w2;
            bw[nb - 2] = w2;
            bn[nb - 2] += bn[nb - 1];
            nb--;
        }
    }
    int idx = 0;
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < bn[b]; j++) L[idx++] = bv[b];
    free(bv); free(bw); free(bn);
}

/* The nk kinks found between the knots of a fitted c added as knots of their own, and c refitted
 * (g included). */
static csf_status add_kinks(curve *c, int ch, const double *xs, const double *ys, int nk, csf_error *err)
{
    csf_status st = CSF_OK;
    curve o = *c;
    memset(c, 0, sizeof *c);
    if (curve_alloc(c, o.n + nk)) {
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    } else {
        int j = 0, q = 0;
        for (int i = 0; i < o.n; i++) {
            c->v[j] = o.v[i];
            c->lum[j++] = o.lum[i];
            if (q < nk && i + 1 < o.n && xs[q] > o.v[i] && xs[q] < o.v[i + 1]) {
                c->v[j] = xs[q];
                c->lum[j++] = o.base + o.top * pow(ys[q], o.g);
                q++;
            }
        }
        c->n = j;
        if (curve_finish(c, ch != CSF_CH_GREY, 0))
            st = csf_error_set(err, CSF_E_INSUFFICIENT, "%s curve does not rise", ch_names[ch]);
    }
    curve_free(&o);
    return st;
}

/* The curve fitted through the m levels, then through the kinks between them as well. */
static csf_status fit_levels(curve *c, int ch, const double *v, const double *L, int m, csf_error *err)
{
    if (curve_alloc(c, m)) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = CSF_OK;
    memcpy(c->v, v, (size_t)m * sizeof(double));
    memcpy(c->lum, L, (size_t)m * sizeof(double));
    if (ch != CSF_CH_GREY && c->lum[0] < 0) c->lum[0] = 0;
    for (int i = 1; ch != CSF_CH_GREY && i < m; i++)
        if (c->lum[i] < 0) c->lum[i] = 0;
    if (curve_finish(c, ch != CSF_CH_GREY, 0))
        st = csf_error_set(err, CSF_E_INSUFFICIENT,
                           "%s curve does not rise: full drive is not brighter than drive 0 "
                           "(is the sensor on the patch?)",
                           ch_names[ch]);
    double xs[8], ys[8];
    int nk = st ? 0 : bracketed_corners(c, xs, ys, 8);
    if (nk > 0 && c->n + nk <= MAX_KNOTS) st = add_kinks(c, ch, xs, ys, nk, err);
    return st;
}

/* Averages repeats, then pool-adjacent-violators so the knots are non-decreasing (noise can make
 * two close levels cross; the display itself does not). */
static csf_status build_curve(curve *c, const csf_profile_reading *r, size_t n, int ch, double black,
                              csf_error *err)
{
    csf_profile_reading *sel = NULL;
    size_t k = 0;
    csf_status st = select_readings(r, n, ch, &sel, &k, err);
    if (st) return st;
    qsort(sel, k, sizeof *sel, cmp_reading);
    double *v = malloc((k ? k : 1) * sizeof(double)), *L = malloc((k ? k : 1) * sizeof(double)),
           *wt = malloc((k ? k : 1) * sizeof(double));
    if (!v || !L || !wt) {
        free(sel);
        free(v);
        free(L);
        free(wt);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    int m = average_repeats(sel, k, ch, black, v, L, wt);
    free(sel);
    if (m < 2 || v[0] != 0 || v[m - 1] != 1) {
        free(v);
        free(L);
        free(wt);
        return csf_error_set(err, CSF_E_INSUFFICIENT,
                             "%s curve needs readings at drive 0 and 1 (has %d distinct levels)",
                             ch_names[ch], m);
    }
    if (m > MAX_KNOTS) {
        free(v);
        free(L);
        free(wt);
        return csf_error_set(err, CSF_E_INSUFFICIENT, "%s curve has %d levels (limit %d)", ch_names[ch], m,
                             MAX_KNOTS);
    }
    pool_adjacent_violators(L, wt, m);
    st = fit_levels(c, ch, v, L, m, err);
    free(v); free(L); free(wt);
    return st;
}

csf_status csf_profile_build(const csf_profile_reading *readings, size_t n,
                             const csf_profile_meta *meta, csf_display_profile **out, csf_error *err)
{
    *out = NULL;
    if (n > MAX_READINGS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%zu readings (limit %d)", n, MAX_READINGS);
    csf_display_profile *p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    statement_unknown(p);
    copy_str(p->display, sizeof p->display, meta && meta->display_name ? meta->display_name : "display");
    copy_str(p->instrument, sizeof p->instrument, meta && meta->instrument ? meta->instrument : "unknown");
    if (meta && meta->created_utc) copy_str(p->created_utc, sizeof p->created_utc, meta->created_utc);
    else now_utc(p->created_utc, sizeof p->created_utc);
    copy_str(p->tool_version, sizeof p->tool_version,
             meta && meta->tool_version ? meta->tool_version : CSF_VERSION);
    p->additivity_error = meta ? meta->additivity_error : NAN;
    csf_status st = build_curve(&p->c[CSF_CH_GREY], readings, n, CSF_CH_GREY, 0, err);
    if (st) {
        csf_profile_free(p);
        return st;
    }
    double black = p->c[CSF_CH_GREY].lum[0];
    int have[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++)
        if (readings[i].channel >= 0 && readings[i].channel < 3 && readings[i].drive01 == 1) have[readings[i].channel] = 1;
    if (have[0] && have[1] && have[2]) {
        for (int c = 0; c < 3; c++) {
            st = build_curve(&p->c[c], readings, n, c, black, err);
            if (st) {
                csf_profile_free(p);
                return st;
            }
        }
        p->has_channels = 1;
    }
    /* primaries: mean XYZ at full drive minus black XYZ */
    double acc[5][3] = {{0}};
    int cnt[5] = {0};
    for (size_t i = 0; i < n; i++) {
        const csf_profile_reading *r = &readings[i];
        if (!r->has_xyz) continue;
        int slot = -1;
        if (r->drive01 == 1 && r->channel >= 0 && r->channel <= CSF_CH_GREY) slot = r->channel;
        else if (r->drive01 == 0 && r->channel == CSF_CH_GREY) slot = 4;
        if (slot < 0) continue;
        for (int k = 0; k < 3; k++) acc[slot][k] += r->xyz[k];
        cnt[slot]++;
    }
    if (cnt[0] && cnt[1] && cnt[2] && cnt[3]) {
        p->has_primaries = 1;
        for (int s = 0; s < 4; s++)
            for (int k = 0; k < 3; k++)
                p->rgbw_xyz[s][k] = acc[s][k] / cnt[s] - (cnt[4] ? acc[4][k] / cnt[4] : 0);
    }
    p->readings = malloc((n ? n : 1) * sizeof *p->readings);
    if (!p->readings) {
        csf_profile_free(p);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    if (n) memcpy(p->readings, readings, n * sizeof *readings);
    p->n_readings = n;
    make_id(p);
    *out = p;
    return CSF_OK;
}

csf_status csf_profile_set_channel_knots(csf_display_profile *p, int ch, const double *drive01,
                                         const double *lum_cdm2, size_t n, csf_error *err)
{
    if (!p || ch < 0 || ch > 2 || !p->has_channels)
        return csf_error_set(err, CSF_E_INVALID_ARG, "channel %d cannot be set: the profile has no channel curves", ch);
    if (n < 2 || n > MAX_KNOTS || drive01[0] != 0.0 || drive01[n - 1] != 1.0)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s curve needs 2 to %d knots from drive 0 to 1", ch_names[ch],
                             MAX_KNOTS);
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(lum_cdm2[i]) || lum_cdm2[i] < 0 || (i && !(drive01[i] > drive01[i - 1])) ||
            (i && lum_cdm2[i] < lum_cdm2[i - 1]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s knot %zu: drive must rise and luminance must be >= 0 and never fall",
                                 ch_names[ch], i);
    }
    curve nc;
    memset(&nc, 0, sizeof nc);
    if (curve_alloc(&nc, (int)n)) {
        curve_free(&nc);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    }
    memcpy(nc.v, drive01, n * sizeof(double));
    memcpy(nc.lum, lum_cdm2, n * sizeof(double));
    if (curve_finish(&nc, 1, 0)) {
        curve_free(&nc);
        return csf_error_set(err, CSF_E_INSUFFICIENT, "%s curve does not rise", ch_names[ch]);
    }
    curve_free(&p->c[ch]);
    p->c[ch] = nc;
    make_id(p);
    return CSF_OK;
}

/* The profile's curve model through bare (drive, luminance) points, for the procedure's
 * leave-one-out and corner checks. */
static csf_status curve_from_points(curve *c, const double *drive01, const double *lum_cdm2, size_t n,
                                    int is_channel, csf_error *err)
{
    memset(c, 0, sizeof *c);
    csf_profile_reading *r = calloc(n ? n : 1, sizeof *r);
    if (!r) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    int ch = is_channel ? CSF_CH_R : CSF_CH_GREY;
    for (size_t i = 0; i < n; i++) {
        r[i].channel = ch;
        r[i].drive01 = drive01[i];
        r[i].lum_cdm2 = lum_cdm2[i];
    }
    csf_status st = build_curve(c, r, n, ch, 0, err);
    free(r);
    if (st) curve_free(c); /* a curve that does not rise fails after its knots were allocated */
    return st;
}

csf_status csf_profile_fit_curve(const double *drive01, const double *lum_cdm2, size_t n,
                                 int is_channel, const double *eval_drive01, double *eval_lum_cdm2,
                                 size_t n_eval, csf_error *err)
{
    curve c;
    csf_status st = curve_from_points(&c, drive01, lum_cdm2, n, is_channel, err);
    if (st) return st;
    for (size_t i = 0; i < n_eval; i++) eval_lum_cdm2[i] = curve_lum(&c, eval_drive01[i]);
    curve_free(&c);
    return CSF_OK;
}

size_t csf_profile_fit_corners(const double *drive01, const double *lum_cdm2, size_t n, int is_channel,
                               double *corner_drive01, size_t max, csf_error *err)
{
    curve c;
    if (curve_from_points(&c, drive01, lum_cdm2, n, is_channel, err) != CSF_OK) return 0;
    size_t k = 0;
    for (int i = 1; i < c.n - 1; i++)
        if (is_corner(c.v, c.y, c.n, i) && k < max) corner_drive01[k++] = c.v[i];
    curve_free(&c);
    return k;
}

/* ---------- text format ---------- */

typedef struct {
    char *buf;
    size_t len, cap;
    int oom;
} sbuf;

static void sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(sbuf *b, const char *fmt, ...)
{
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(b->buf + b->len, b->cap - b->len, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->oom = 1;
            return;
        }
        if ((size_t)n < b->cap - b->len) {
            b->len += (size_t)n;
            return;
        }
        size_t nc = b->cap * 2 + (size_t)n + 256;
        char *nb = realloc(b->buf, nc);
        if (!nb) {
            b->oom = 1;
            return;
        }
        b->buf = nb;
        b->cap = nc;
    }
}

static void sb_num(sbuf *b, double x)
{
    if (isnan(x)) sb_printf(b, "nan");
    else sb_printf(b, "%.17g", x);
}

csf_status csf_profile_to_text(const csf_display_profile *p, char **out, csf_error *err)
{
    sbuf b = {malloc(4096), 0, 4096, 0};
    if (!b.buf) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    b.buf[0] = 0;
    sb_printf(&b, "csfcal-display-profile 1\n");
    sb_printf(&b, "# luminance per drive value of one monitor; see docs/display-profile.md\n");
    sb_printf(&b, "id = %s\ndisplay = %s\ninstrument = %s\ncreated_utc = %s\ntool_version = %s\n",
              p->id, p->display, p->instrument, p->created_utc, p->tool_version);
    sb_printf(&b, "lum_black_cdm2 = ");
    sb_num(&b, csf_profile_lum_black(p));
    sb_printf(&b, "\nlum_max_cdm2 = ");
    sb_num(&b, csf_profile_lum_max(p));
    sb_printf(&b, "\nadditivity_error = ");
    sb_num(&b, p->additivity_error);
    if (p->target_met >= 0) {
        sb_printf(&b, "\ntarget_rel = ");
        sb_num(&b, p->target_rel);
        sb_printf(&b, "\ntarget_met = %d", p->target_met);
        for (int c = 0; c < CSF_CH_COUNT; c++) {
            if (isnan(p->stated_error_rel[c])) continue;
            sb_printf(&b, "\nstated_error_%s = ", ch_names[c]);
            /* one that could not be estimated (too few levels) is written as 100: "useless" */
            sb_num(&b, fmin(p->stated_error_rel[c], 100));
        }
    }
    sb_printf(&b, "\nhas_channels = %d\n", p->has_channels);
    if (p->has_primaries) {
        static const char *pn[4] = {"primary_r_xyz", "primary_g_xyz", "primary_b_xyz", "white_xyz"};
        for (int s = 0; s < 4; s++) {
            sb_printf(&b, "%s = ", pn[s]);
            for (int k = 0; k < 3; k++) {
                sb_num(&b, p->rgbw_xyz[s][k]);
                sb_printf(&b, k < 2 ? "," : "\n");
            }
        }
    }
    for (int ch = CSF_CH_GREY; ch >= 0; ch--) {
        if (ch < 3 && !p->has_channels) break;
        const curve *c = &p->c[ch];
        sb_printf(&b, "\n[curve %s]\ntransform_gamma = ", ch_names[ch]);
        sb_num(&b, c->g);
        sb_printf(&b, "\ndrive01,lum_cdm2\n");
        for (int i = 0; i < c->n; i++) {
            sb_num(&b, c->v[i]);
            sb_printf(&b, ",");
            sb_num(&b, c->lum[i]);
            sb_printf(&b, "\n");
        }
    }
    sb_printf(&b, "\n[readings]\nchannel,drive01,lum_cdm2,X,Y,Z\n");
    for (size_t i = 0; i < p->n_readings; i++) {
        const csf_profile_reading *r = &p->readings[i];
        sb_printf(&b, "%s,", ch_names[r->channel >= 0 && r->channel < CSF_CH_COUNT ? r->channel : CSF_CH_GREY]);
        sb_num(&b, r->drive01);
        sb_printf(&b, ",");
        sb_num(&b, r->lum_cdm2);
        for (int k = 0; k < 3; k++) {
            sb_printf(&b, ",");
            if (r->has_xyz) sb_num(&b, r->xyz[k]);
        }
        sb_printf(&b, "\n");
    }
    if (b.oom) {
        free(b.buf);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory writing profile");
    }
    *out = b.buf;
    return CSF_OK;
}

csf_status csf_profile_save(const csf_display_profile *p, const char *path, csf_error *err)
{
    char *text;
    csf_status st = csf_profile_to_text(p, &text, err);
    if (st) return st;
    /* a crash or a full disk never leaves half a profile, and the old one stays */
    st = csf_write_file_atomic(path, "display profile", text, strlen(text), err);
    free(text);
    return st;
}

/* Parser state for one line-oriented pass. */
typedef struct {
    const char *name;
    int line;
    csf_error *err;
} pctx;

static csf_status perr(pctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static csf_status perr(pctx *c, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return csf_error_set(c->err, CSF_E_FORMAT, "%s:%d: %s", c->name, c->line, msg);
}

static int parse_dbl(const char *s, double *out)
{
    char *end;
    errno = 0;
    while (*s == ' ') s++;
    if (strncmp(s, "nan", 3) == 0 && (s[3] == 0 || s[3] == ',' || s[3] == ' ')) {
        *out = NAN;
        return 3;
    }
    double v = strtod(s, &end);
    if (end == s || errno || !isfinite(v)) return -1;
    *out = v;
    return (int)(end - s);
}

/* Splits a CSV row of up to max doubles (empty fields = NAN). Returns count or -1. */
static int split_nums(char *s, double *out, int max, int *empty_mask)
{
    int n = 0;
    *empty_mask = 0;
    for (;;) {
        if (n >= max) return -1;
        char *comma = strchr(s, ',');
        if (comma) *comma = 0;
        char *t = s;
        while (*t == ' ') t++;
        if (!*t) {
            out[n] = NAN;
            *empty_mask |= 1 << n;
        } else {
            int used = parse_dbl(t, &out[n]);
            if (used < 0) return -1;
            t += used;
            while (*t == ' ') t++;
            if (*t) return -1;
        }
        n++;
        if (!comma) break;
        s = comma + 1;
    }
    return n;
}

static int channel_from_name(const char *s)
{
    for (int c = 0; c < CSF_CH_COUNT; c++)
        if (strcmp(s, ch_names[c]) == 0) return c;
    return -1;
}

/* What one pass over a profile's text has gathered besides the profile itself. */
typedef struct {
    pctx pc;
    csf_display_profile *p;
    int section;          /* -1 header keys, 0..3 curve, 4 readings */
    int section_line;     /* lines seen in this section */
    int seen_curve[CSF_CH_COUNT];
    int cap_k[CSF_CH_COUNT];
    size_t cap_r;
    int declared_channels; /* has_channels, -1 not given */
    int seen_prim;        /* bit per primary_r/g/b_xyz and white_xyz given */
    double gam[CSF_CH_COUNT];
} profile_parse;

/* Line 1: the format and its version. */
static csf_status parse_first_line(profile_parse *pp, const char *s)
{
    int ver;
    char extra;
    if (sscanf(s, "csfcal-display-profile %d%c", &ver, &extra) != 1)
        return perr(&pp->pc, "not a csfcal display profile (first line must be 'csfcal-display-profile 1')");
    if (ver != 1)
        return csf_error_set(pp->pc.err, CSF_E_UNSUPPORTED, "%s: profile format version %d; this csfcal reads version 1",
                             pp->pc.name, ver);
    return CSF_OK;
}

/* "[readings]" or "[curve r|g|b|grey]", each curve once. */
static csf_status parse_section_header(profile_parse *pp, char *s)
{
    char *close = strchr(s, ']');
    if (!close || close[1]) return perr(&pp->pc, "malformed section header");
    *close = 0;
    char q[200]; /* the name as the message quotes it: outside bytes, made printable */
    if (strcmp(s + 1, "readings") == 0) {
        pp->section = 4;
    } else if (strncmp(s + 1, "curve ", 6) == 0) {
        int c = channel_from_name(s + 7);
        csf_quote_bytes(s + 7, strlen(s + 7), q, sizeof q);
        if (c < 0) return perr(&pp->pc, "unknown curve '%s' (r, g, b, grey)", q);
        if (pp->seen_curve[c]) return perr(&pp->pc, "curve %s given twice", q);
        pp->seen_curve[c] = 1;
        pp->section = c;
    } else {
        csf_quote_bytes(s + 1, strlen(s + 1), q, sizeof q);
        return perr(&pp->pc, "unknown section [%s]", q);
    }
    pp->section_line = 0;
    return CSF_OK;
}

/* One "key = value" line before the first section. Unknown keys are allowed: later minor
 * additions must not break older readers. */
static csf_status parse_header_key(profile_parse *pp, char *s)
{
    csf_display_profile *p = pp->p;
    pctx *pc = &pp->pc;
    char *eq = strchr(s, '=');
    if (!eq) return perr(pc, "expected key = value");
    *eq = 0;
    char *k = csf_trim(s), *v = csf_trim(eq + 1);
    double x;
    if (strcmp(k, "id") == 0) copy_str(p->id, sizeof p->id, v);
    else if (strcmp(k, "display") == 0) copy_str(p->display, sizeof p->display, v);
    else if (strcmp(k, "instrument") == 0) copy_str(p->instrument, sizeof p->instrument, v);
    else if (strcmp(k, "created_utc") == 0) {
        time_t t;
        if (parse_utc(v, &t)) return perr(pc, "created_utc must be YYYY-MM-DDTHH:MM:SSZ");
        copy_str(p->created_utc, sizeof p->created_utc, v);
    } else if (strcmp(k, "tool_version") == 0) copy_str(p->tool_version, sizeof p->tool_version, v);
    else if (strcmp(k, "lum_black_cdm2") == 0 || strcmp(k, "lum_max_cdm2") == 0) {
        /* derived from the grey curve; checked for being a number only */
        if (parse_dbl(v, &x) < 0) return perr(pc, "%s is not a number", k);
    } else if (strcmp(k, "additivity_error") == 0) {
        if (parse_dbl(v, &x) < 0 || (isfinite(x) && fabs(x) > 10))
            return perr(pc, "additivity_error must be a number in -10..10 or nan");
        p->additivity_error = x;
    } else if (strcmp(k, "target_rel") == 0) {
        if (parse_dbl(v, &x) < 0 || !(x > 0 && x <= 0.5))
            return perr(pc, "target_rel must be a number in (0, 0.5]");
        p->target_rel = x;
    } else if (strcmp(k, "target_met") == 0) {
        if (strcmp(v, "0") && strcmp(v, "1")) return perr(pc, "target_met must be 0 or 1");
        p->target_met = v[0] - '0';
    } else if (strncmp(k, "stated_error_", 13) == 0) {
        int c = -1;
        for (int j = 0; j < CSF_CH_COUNT; j++)
            if (strcmp(k + 13, ch_names[j]) == 0) c = j;
        if (c < 0) return CSF_OK; /* an unknown key, ignored as any */
        if (parse_dbl(v, &x) < 0 || !(x >= 0 && x <= 100))
            return perr(pc, "%s must be a relative error from 0 to 100", k);
        p->stated_error_rel[c] = x;
    } else if (strcmp(k, "has_channels") == 0) {
        if (strcmp(v, "0") && strcmp(v, "1")) return perr(pc, "has_channels must be 0 or 1");
        pp->declared_channels = v[0] - '0';
    } else if (strcmp(k, "primary_r_xyz") == 0 || strcmp(k, "primary_g_xyz") == 0 ||
               strcmp(k, "primary_b_xyz") == 0 || strcmp(k, "white_xyz") == 0) {
        int slot = k[0] == 'w' ? 3 : (k[8] == 'r' ? 0 : k[8] == 'g' ? 1 : 2);
        double xyz[3];
        int em;
        if (split_nums(v, xyz, 3, &em) != 3 || em || !isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
            return perr(pc, "%s must be three numbers X,Y,Z", k);
        memcpy(p->rgbw_xyz[slot], xyz, sizeof xyz);
        pp->seen_prim |= 1 << slot;
    }
    return CSF_OK;
}

/* A curve section's line: its gamma, its header, then rising knots. */
static csf_status parse_curve_line(profile_parse *pp, char *s)
{
    int section = pp->section;
    curve *c = &pp->p->c[section];
    pctx *pc = &pp->pc;
    if (pp->section_line == 1) {
        char *eq = strchr(s, '=');
        if (!eq || (*eq = 0, strcmp(csf_trim(s), "transform_gamma") != 0) ||
            parse_dbl(csf_trim(eq + 1), &pp->gam[section]) < 0 ||
            !(pp->gam[section] >= 1 && pp->gam[section] <= 4))
            return perr(pc, "curve must start with transform_gamma = G (1 to 4)");
        return CSF_OK;
    }
    if (pp->section_line == 2)
        return strcmp(s, "drive01,lum_cdm2") != 0 ? perr(pc, "expected header drive01,lum_cdm2") : CSF_OK;
    double f[2];
    int em;
    if (split_nums(s, f, 2, &em) != 2 || em || isnan(f[0]) || isnan(f[1])) return perr(pc, "expected drive01,lum_cdm2");
    if (c->n >= MAX_KNOTS) return perr(pc, "more than %d knots in a curve", MAX_KNOTS);
    if (f[0] < 0 || f[0] > 1 || f[1] < 0 || f[1] > 1e5)
        return perr(pc, "drive %g or luminance %g out of range (0..1, 0..100000 cd/m2)", f[0], f[1]);
    if (c->n > 0 && (f[0] <= c->v[c->n - 1] || f[1] < c->lum[c->n - 1]))
        return perr(pc, "knots must rise: drive strictly, luminance never falling");
    if (c->n == pp->cap_k[section]) {
        int nc = pp->cap_k[section] ? pp->cap_k[section] * 2 : 32;
        double *a = realloc(c->v, (size_t)nc * sizeof(double));
        if (a) c->v = a;
        double *b2 = realloc(c->lum, (size_t)nc * sizeof(double));
        if (b2) c->lum = b2;
        if (!a || !b2) return csf_error_set(pc->err, CSF_E_NOMEM, "out of memory");
        pp->cap_k[section] = nc;
    }
    c->v[c->n] = f[0];
    c->lum[c->n] = f[1];
    c->n++;
    return CSF_OK;
}

/* A [readings] line: its header, then channel,drive01,lum_cdm2 with X,Y,Z all or none. */
static csf_status parse_reading_line(profile_parse *pp, char *s)
{
    csf_display_profile *p = pp->p;
    pctx *pc = &pp->pc;
    if (pp->section_line == 1)
        return strcmp(s, "channel,drive01,lum_cdm2,X,Y,Z") != 0 ? perr(pc, "expected header channel,drive01,lum_cdm2,X,Y,Z")
                                                                : CSF_OK;
    char *comma = strchr(s, ',');
    if (!comma) return perr(pc, "expected channel,drive01,lum_cdm2,X,Y,Z");
    *comma = 0;
    int ch = channel_from_name(s);
    double f[5];
    int em;
    if (ch < 0 || split_nums(comma + 1, f, 5, &em) != 5 || (em & 3) || (em && em != 0x1c))
        return perr(pc, "expected channel,drive01,lum_cdm2,X,Y,Z (X,Y,Z all or none)");
    if (!(f[0] >= 0 && f[0] <= 1)) return perr(pc, "reading drive %g out of range 0..1", f[0]);
    if (p->n_readings >= MAX_READINGS) return perr(pc, "more than %d readings", MAX_READINGS);
    if (p->n_readings == pp->cap_r) {
        size_t nc = pp->cap_r ? pp->cap_r * 2 : 64;
        csf_profile_reading *a = realloc(p->readings, nc * sizeof *a);
        if (!a) return csf_error_set(pc->err, CSF_E_NOMEM, "out of memory");
        p->readings = a;
        pp->cap_r = nc;
    }
    csf_profile_reading *r = &p->readings[p->n_readings++];
    r->channel = ch;
    r->drive01 = f[0];
    r->lum_cdm2 = f[1];
    r->has_xyz = em == 0;
    for (int k = 0; k < 3; k++) r->xyz[k] = r->has_xyz ? f[2 + k] : NAN;
    return CSF_OK;
}

/* One line of the text (NUL-free, trimmed), by where it stands. */
static csf_status parse_line(profile_parse *pp, char *s)
{
    if (pp->pc.line == 1) return parse_first_line(pp, s);
    if (!*s || *s == '#') return CSF_OK;
    if (*s == '[') return parse_section_header(pp, s);
    if (pp->section == -1) return parse_header_key(pp, s);
    pp->section_line++;
    return pp->section < 4 ? parse_curve_line(pp, s) : parse_reading_line(pp, s);
}

/* The checks that need the whole text: a grey curve, all three channel curves or none (as
 * has_channels says), and each curve usable. */
static csf_status finish_profile(profile_parse *pp)
{
    csf_display_profile *p = pp->p;
    const char *name = pp->pc.name;
    csf_error *err = pp->pc.err;
    csf_status st = CSF_OK;
    if (pp->pc.line == 0) return csf_error_set(err, CSF_E_FORMAT, "%s: empty file", name);
    if (!pp->seen_curve[CSF_CH_GREY]) return csf_error_set(err, CSF_E_FORMAT, "%s: no [curve grey] section", name);
    int chans = pp->seen_curve[0] + pp->seen_curve[1] + pp->seen_curve[2];
    if (chans != 0 && chans != 3)
        return csf_error_set(err, CSF_E_FORMAT, "%s: channel curves must be all of r, g, b or none", name);
    if (pp->declared_channels >= 0 && pp->declared_channels != (chans == 3))
        return csf_error_set(err, CSF_E_FORMAT, "%s: has_channels = %d but %d channel curves given", name,
                             pp->declared_channels, chans);
    /* a statement is a target and whether it was met: one without the other cannot be checked or
     * written back */
    if ((p->target_met >= 0) != !isnan(p->target_rel))
        return csf_error_set(err, CSF_E_FORMAT, "%s: target_met and target_rel must be given together", name);
    for (int c = 0; st == CSF_OK && c < CSF_CH_COUNT; c++) {
        if (!pp->seen_curve[c]) continue;
        curve *cv = &p->c[c];
        int n = cv->n;
        double *v = cv->v, *L = cv->lum;
        cv->v = NULL;
        cv->lum = NULL;
        if (n < 2 || v[0] != 0 || v[n - 1] != 1 || !(L[n - 1] > (c == CSF_CH_GREY ? L[0] : 0))) {
            st = csf_error_set(err, CSF_E_FORMAT, "%s: curve %s needs knots at drive 0 and 1 with luminance rising",
                               name, ch_names[c]);
        } else if (curve_alloc(cv, n)) {
            st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
        } else {
            memcpy(cv->v, v, (size_t)n * sizeof(double));
            memcpy(cv->lum, L, (size_t)n * sizeof(double));
            if (curve_finish(cv, c != CSF_CH_GREY, pp->gam[c]))
                st = csf_error_set(err, CSF_E_FORMAT, "%s: curve %s is not usable", name, ch_names[c]);
        }
        free(v);
        free(L);
    }
    if (st == CSF_OK) {
        p->has_channels = chans == 3;
        p->has_primaries = pp->seen_prim == 15;
    }
    return st;
}

static csf_status parse_named(const char *text, size_t len, const char *name,
                              csf_display_profile **out, csf_error *err)
{
    *out = NULL;
    if (len > MAX_FILE_BYTES)
        return csf_error_set(err, CSF_E_FORMAT, "%s: %zu bytes (limit %u)", name, len, MAX_FILE_BYTES);
    profile_parse pp = {.pc = {name, 0, err}, .section = -1, .declared_channels = -1};
    csf_display_profile *p = pp.p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    statement_unknown(p);
    p->additivity_error = NAN;
    csf_status st = CSF_OK;
    char line[1024];
    size_t pos = 0;
    while (pos < len && st == CSF_OK) {
        size_t start = pos;
        while (pos < len && text[pos] != '\n') pos++;
        size_t l = pos - start;
        if (pos < len) pos++;
        pp.pc.line++;
        if (l >= sizeof line) {
            st = perr(&pp.pc, "line longer than %zu characters", sizeof line - 1);
            break;
        }
        memcpy(line, text + start, l);
        line[l] = 0;
        if (strlen(line) != l) {
            st = perr(&pp.pc, "NUL byte in text");
            break;
        }
        st = parse_line(&pp, csf_trim(line));
    }
    if (st == CSF_OK) st = finish_profile(&pp);
    if (st) {
        csf_profile_free(p);
        return st;
    }
    if (!p->created_utc[0]) copy_str(p->created_utc, sizeof p->created_utc, "1970-01-01T00:00:00Z");
    if (!p->id[0]) make_id(p);
    *out = p;
    return CSF_OK;
}

csf_status csf_profile_parse(const char *text, size_t len, csf_display_profile **out, csf_error *err)
{
    return parse_named(text, len, "profile", out, err);
}

csf_status csf_profile_load(const char *path, csf_display_profile **out, csf_error *err)
{
    *out = NULL;
    char *buf;
    size_t n;
    csf_status st = csf_read_file(path, "display profile", MAX_FILE_BYTES, &buf, &n, err);
    if (st) return st;
    st = parse_named(buf, n, path, out, err);
    free(buf);
    return st;
}
