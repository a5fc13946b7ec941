/* CSV importer for threshold grids: a header row naming the columns, one row per grid node. The
 * grid is the set of distinct values in each axis column; every combination must appear once.
 * Outside input: every refusal names the line and the rule it broke. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csflut.h"
#include "csflut_internal.h"

enum { COL_FREQ, COL_ECC, COL_VEL, COL_LUM, COL_THR, COL_SE, N_COLS };
static const char *const col_names[N_COLS] = {"freq_cpd", "ecc_deg", "velocity_dps",
                                              "lum_cdm2", "threshold", "stderr_log10"};

/* The metadata comments `csflut_export` writes ("# observer: ...", "# trials: 240"), read back
 * so an export -> import round trip keeps them. */
static const char *const meta_keys[CSFLUT_N_STRINGS] = {"observer", "display_profile_id",
                                                         "method", "date_utc", "tool_version"};
typedef struct {
    char *str[CSFLUT_N_STRINGS];
    double dist_mm, mean_lum;
    long trials;
} csv_meta;

struct csflut_grid {
    csflut_build build;
    double *pts[4];
    double *thr, *se;
    char *meta[CSFLUT_N_STRINGS];
};

csflut_build *csflut_grid_build(csflut_grid *g) { return g ? &g->build : NULL; }

void csflut_grid_free(csflut_grid *g)
{
    if (!g) return;
    for (int a = 0; a < 4; a++) free(g->pts[a]);
    free(g->thr);
    free(g->se);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) free(g->meta[k]);
    free(g);
}

typedef struct {
    double v[N_COLS];
    size_t line;
} row;

/* A comment line [q, le) (q at the '#'): "# key: value" for a known key sets that field; other
 * comments are ignored. Returns CSFLUT_OK, CSFLUT_E_NOMEM or CSFLUT_E_CSV (msg filled). */
static csflut_status parse_meta(const char *q, const char *le, csv_meta *m, char *msg, size_t msz)
{
    q++;
    while (q < le && (*q == ' ' || *q == '\t')) q++;
    const char *colon = memchr(q, ':', (size_t)(le - q));
    if (!colon) return CSFLUT_OK;
    size_t kl = (size_t)(colon - q);
    const char *v = colon + 1, *ve = le;
    while (v < ve && (*v == ' ' || *v == '\t')) v++;
    while (ve > v && (ve[-1] == ' ' || ve[-1] == '\t')) ve--;
    size_t vl = (size_t)(ve - v);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) {
        if (strlen(meta_keys[k]) != kl || memcmp(q, meta_keys[k], kl) != 0) continue;
        if (vl > CSFLUT_MAX_STRING || memchr(v, 0, vl)) {
            snprintf(msg, msz, "%s is longer than %d bytes or contains a NUL byte", meta_keys[k],
                     CSFLUT_MAX_STRING);
            return CSFLUT_E_CSV;
        }
        free(m->str[k]);
        m->str[k] = malloc(vl + 1);
        if (!m->str[k]) return CSFLUT_E_NOMEM;
        memcpy(m->str[k], v, vl);
        m->str[k][vl] = 0;
        return CSFLUT_OK;
    }
    static const char *const num_keys[3] = {"viewing_distance_mm", "mean_lum_cdm2", "trials"};
    for (int k = 0; k < 3; k++) {
        if (strlen(num_keys[k]) != kl || memcmp(q, num_keys[k], kl) != 0) continue;
        char buf[64];
        double x = NAN;
        int ok = vl > 0 && vl < sizeof buf;
        if (ok) {
            memcpy(buf, v, vl);
            buf[vl] = 0;
            char *end;
            x = strtod(buf, &end);
            ok = *end == 0;
        }
        /* NaN = unknown for the two reals; the same limits as the file header */
        if (k < 2) ok = ok && (x != x || (isfinite(x) && x > 0));
        else ok = ok && x >= 0 && x <= 2147483647.0 && x == floor(x);
        if (!ok) {
            snprintf(msg, msz, "%s \"%.*s\" is not %s", num_keys[k], (int)(vl < 40 ? vl : 40), v,
                     k < 2 ? "a number > 0 (or nan for unknown)" : "a whole number 0 to 2147483647");
            return CSFLUT_E_CSV;
        }
        if (k == 0) m->dist_mm = x;
        else if (k == 1) m->mean_lum = x;
        else m->trials = (long)x;
        return CSFLUT_OK;
    }
    return CSFLUT_OK;
}

/* Splits the line [s, e) at commas into at most max fields (trimmed). Returns the count, or -1
 * if there are more. */
static int split(const char *s, const char *e, const char **fs, size_t *fl, int max)
{
    int n = 0;
    for (;;) {
        const char *c = s;
        while (c < e && *c != ',') c++;
        if (n == max) return -1;
        const char *a = s, *b = c;
        while (a < b && (*a == ' ' || *a == '\t')) a++;
        while (b > a && (b[-1] == ' ' || b[-1] == '\t')) b--;
        fs[n] = a;
        fl[n] = (size_t)(b - a);
        n++;
        if (c == e) return n;
        s = c + 1;
    }
}

static int parse_num(const char *f, size_t len, double *out)
{
    char buf[64];
    if (len == 0 || len >= sizeof buf) return -1;
    memcpy(buf, f, len);
    buf[len] = 0;
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    if (end != buf + len) return -1;
    if (errno == ERANGE && isfinite(v) && v != 0) return -1; /* not reached: overflow gives inf */
    *out = v;
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int find(const double *p, int n, double v)
{
    int lo = 0, hi = n - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (p[mid] < v) lo = mid + 1;
        else if (p[mid] > v) hi = mid - 1;
        else return mid;
    }
    return -1;
}

static csflut_status csv_fail(csflut_diag *d, size_t line, const char *what)
{
    csflut_diag_set(d, CSFLUT_E_CSV, line, "line %zu: %s", line, what);
    return CSFLUT_E_CSV;
}

csflut_status csflut_import_csv(const char *text, size_t len, csflut_grid **out, csflut_diag *diag)
{
    if (diag) memset(diag, 0, sizeof *diag);
    if (!out || (!text && len)) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL argument");
        return CSFLUT_E_ARG;
    }
    *out = NULL;
    int colmap[N_COLS]; /* field position of each column, -1 absent */
    for (int c = 0; c < N_COLS; c++) colmap[c] = -1;
    int n_fields = 0, have_header = 0;
    row *rows = NULL;
    size_t n_rows = 0, cap_rows = 0, line = 0;
    csflut_status st = CSFLUT_OK;
    char msg[200];
    const char *p = text ? text : "", *end = p + len;
    csflut_grid *g = NULL;
    size_t *node_line = NULL;
    csv_meta meta = {.dist_mm = NAN, .mean_lum = NAN};

    while (p < end) {
        const char *e = memchr(p, '\n', (size_t)(end - p));
        const char *next = e ? e + 1 : end;
        if (!e) e = end;
        line++;
        const char *le = e;
        if (le > p && le[-1] == '\r') le--;
        const char *q = p;
        while (q < le && (*q == ' ' || *q == '\t')) q++;
        if (q < le && *q == '#') {
            st = parse_meta(q, le, &meta, msg, sizeof msg);
            if (st == CSFLUT_E_CSV) st = csv_fail(diag, line, msg);
            if (st) goto done;
        }
        if (q == le || *q == '#') {
            p = next;
            continue;
        }
        if (memchr(p, 0, (size_t)(le - p))) {
            st = csv_fail(diag, line, "NUL byte in the line");
            goto done;
        }
        const char *fs[N_COLS];
        size_t fl[N_COLS];
        int nf = split(p, le, fs, fl, N_COLS);
        if (!have_header) {
            if (nf < 0) {
                snprintf(msg, sizeof msg, "header has more than %d columns", N_COLS);
                st = csv_fail(diag, line, msg);
                goto done;
            }
            for (int k = 0; k < nf; k++) {
                int found = -1;
                for (int c = 0; c < N_COLS; c++)
                    if (fl[k] == strlen(col_names[c]) && memcmp(fs[k], col_names[c], fl[k]) == 0)
                        found = c;
                if (found < 0) {
                    snprintf(msg, sizeof msg,
                             "unknown column \"%.*s\" (allowed: freq_cpd, ecc_deg, velocity_dps, "
                             "lum_cdm2, threshold, stderr_log10)", (int)(fl[k] > 40 ? 40 : fl[k]), fs[k]);
                    st = csv_fail(diag, line, msg);
                    goto done;
                }
                if (colmap[found] >= 0) {
                    snprintf(msg, sizeof msg, "column %s appears twice", col_names[found]);
                    st = csv_fail(diag, line, msg);
                    goto done;
                }
                colmap[found] = k;
            }
            const int required[3] = {COL_FREQ, COL_ECC, COL_THR};
            for (int k = 0; k < 3; k++)
                if (colmap[required[k]] < 0) {
                    snprintf(msg, sizeof msg, "header lacks the required column %s",
                             col_names[required[k]]);
                    st = csv_fail(diag, line, msg);
                    goto done;
                }
            n_fields = nf;
            have_header = 1;
            p = next;
            continue;
        }
        if (nf != n_fields) {
            snprintf(msg, sizeof msg, "%s fields, the header has %d",
                     nf < 0 ? "too many" : (nf < n_fields ? "too few" : "too many"), n_fields);
            st = csv_fail(diag, line, msg);
            goto done;
        }
        if (n_rows >= CSFLUT_MAX_NODES) {
            snprintf(msg, sizeof msg, "more than %u rows", (unsigned)CSFLUT_MAX_NODES);
            st = csv_fail(diag, line, msg);
            goto done;
        }
        if (n_rows == cap_rows) {
            size_t nc = cap_rows ? cap_rows * 2 : 64;
            row *nr = realloc(rows, nc * sizeof *rows);
            if (!nr) {
                st = CSFLUT_E_NOMEM;
                csflut_diag_set(diag, st, line, "out of memory");
                goto done;
            }
            rows = nr;
            cap_rows = nc;
        }
        row *r = &rows[n_rows];
        r->line = line;
        for (int c = 0; c < N_COLS; c++) {
            r->v[c] = NAN;
            int k = colmap[c];
            if (k < 0) continue;
            if (c == COL_SE && (fl[k] == 0)) continue; /* empty = unknown */
            if (parse_num(fs[k], fl[k], &r->v[c]) != 0) {
                snprintf(msg, sizeof msg, "%s \"%.*s\" is not a number", col_names[c],
                         (int)(fl[k] > 40 ? 40 : fl[k]), fs[k]);
                st = csv_fail(diag, line, msg);
                goto done;
            }
            double v = r->v[c];
            const char *rule = NULL;
            switch (c) {
            case COL_FREQ: if (!(isfinite(v) && v > 0)) rule = "must be finite and > 0 cpd"; break;
            case COL_ECC: if (!(isfinite(v) && v >= 0)) rule = "must be finite and >= 0 deg"; break;
            case COL_VEL: if (!(isfinite(v) && v >= 0)) rule = "must be finite and >= 0 deg/s"; break;
            case COL_LUM: if (!(isfinite(v) && v > 0)) rule = "must be finite and > 0 cd/m2"; break;
            case COL_THR: if (!(v > 0)) rule = "must be > 0 (inf = never visible)"; break;
            case COL_SE: if (v == v && !(isfinite(v) && v >= 0)) rule = "must be >= 0, or empty/nan for unknown"; break;
            }
            if (rule) {
                snprintf(msg, sizeof msg, "%s %g %s", col_names[c], v, rule);
                st = csv_fail(diag, line, msg);
                goto done;
            }
        }
        n_rows++;
        p = next;
    }
    if (!have_header) {
        st = csv_fail(diag, line ? line : 1, "no header row (expected freq_cpd,ecc_deg,...,threshold)");
        goto done;
    }
    if (n_rows == 0) {
        st = csv_fail(diag, line, "no data rows");
        goto done;
    }

    g = calloc(1, sizeof *g);
    if (!g) {
        st = CSFLUT_E_NOMEM;
        goto done;
    }
    int n[4] = {0, 0, 0, 0};
    for (int a = 0; a < 4; a++) {
        if (colmap[a] < 0) continue;
        double *v = malloc(n_rows * sizeof *v);
        if (!v) {
            st = CSFLUT_E_NOMEM;
            goto done;
        }
        for (size_t i = 0; i < n_rows; i++) v[i] = rows[i].v[a];
        qsort(v, n_rows, sizeof *v, cmp_double);
        size_t u = 0;
        for (size_t i = 0; i < n_rows; i++)
            if (u == 0 || v[i] != v[u - 1]) v[u++] = v[i];
        if (u > CSFLUT_MAX_POINTS) {
            free(v);
            snprintf(msg, sizeof msg, "column %s has %zu distinct values (at most %d grid points)",
                     col_names[a], u, CSFLUT_MAX_POINTS);
            st = csv_fail(diag, line, msg);
            goto done;
        }
        g->pts[a] = v;
        n[a] = (int)u;
    }
    size_t nodes = 1;
    for (int a = 0; a < 4; a++) nodes *= n[a] > 0 ? (size_t)n[a] : 1;
    if (nodes > CSFLUT_MAX_NODES) {
        snprintf(msg, sizeof msg, "the grid would have %zu nodes (at most %u)", nodes,
                 (unsigned)CSFLUT_MAX_NODES);
        st = csv_fail(diag, line, msg);
        goto done;
    }
    g->thr = malloc(nodes * sizeof(double));
    node_line = calloc(nodes, sizeof *node_line);
    if (colmap[COL_SE] >= 0) g->se = malloc(nodes * sizeof(double));
    if (!g->thr || !node_line || (colmap[COL_SE] >= 0 && !g->se)) {
        st = CSFLUT_E_NOMEM;
        goto done;
    }
    size_t nv = n[2] > 0 ? (size_t)n[2] : 1;
    for (size_t i = 0; i < n_rows; i++) {
        int idx[4] = {0, 0, 0, 0};
        for (int a = 0; a < 4; a++)
            if (n[a] > 0) idx[a] = find(g->pts[a], n[a], rows[i].v[a]);
        size_t k = (((size_t)idx[3] * nv + (size_t)idx[2]) * (size_t)n[1] + (size_t)idx[1]) *
                       (size_t)n[0] + (size_t)idx[0];
        if (node_line[k]) {
            snprintf(msg, sizeof msg, "duplicate grid point (same axis values as line %zu)",
                     node_line[k]);
            st = csv_fail(diag, rows[i].line, msg);
            goto done;
        }
        node_line[k] = rows[i].line;
        g->thr[k] = rows[i].v[COL_THR];
        if (g->se) g->se[k] = rows[i].v[COL_SE];
    }
    for (size_t k = 0; k < nodes; k++)
        if (!node_line[k]) {
            size_t r = k;
            int fi = (int)(r % (size_t)n[0]);
            r /= (size_t)n[0];
            int ei = (int)(r % (size_t)n[1]);
            r /= (size_t)n[1];
            int vi = (int)(r % nv);
            int li = (int)(r / nv);
            int m = snprintf(msg, sizeof msg,
                             "the grid is incomplete: no row for freq_cpd=%.17g ecc_deg=%.17g",
                             g->pts[0][fi], g->pts[1][ei]);
            if (n[2] && m > 0 && (size_t)m < sizeof msg)
                m += snprintf(msg + m, sizeof msg - (size_t)m, " velocity_dps=%.17g", g->pts[2][vi]);
            if (n[3] && m > 0 && (size_t)m < sizeof msg)
                snprintf(msg + m, sizeof msg - (size_t)m, " lum_cdm2=%.17g", g->pts[3][li]);
            st = csv_fail(diag, line, msg);
            goto done;
        }
    csflut_build *b = &g->build;
    b->n_freq = n[0];
    b->n_ecc = n[1];
    b->n_vel = n[2];
    b->n_lum = n[3];
    b->freq_cpd = g->pts[0];
    b->ecc_deg = g->pts[1];
    b->vel_dps = g->pts[2];
    b->lum_cdm2 = g->pts[3];
    b->threshold = g->thr;
    b->stderr_log10 = g->se;
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) {
        g->meta[k] = meta.str[k];
        meta.str[k] = NULL;
    }
    b->observer = g->meta[0];
    b->display_profile_id = g->meta[1];
    b->method = g->meta[2];
    b->date_utc = g->meta[3];
    b->tool_version = g->meta[4];
    b->viewing_distance_mm = meta.dist_mm;
    b->mean_lum_cdm2 = meta.mean_lum;
    b->trials = (int)meta.trials;
    csflut_diag vd;
    st = csflut_validate_build(b, &vd);
    if (st) {
        csflut_diag_set(diag, st, 0, "%s", vd.message);
        goto done;
    }
done:
    free(rows);
    free(node_line);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) free(meta.str[k]);
    if (st) {
        if (st == CSFLUT_E_NOMEM) csflut_diag_set(diag, st, line, "out of memory");
        csflut_grid_free(g);
        return st;
    }
    *out = g;
    return CSFLUT_OK;
}
