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
    size_t n_kv; /* "# meta.KEY: value" pairs */
    char *kv_key[CSFLUT_MAX_META], *kv_val[CSFLUT_MAX_META];
} csv_meta;

struct csflut_grid {
    csflut_build build;
    double *pts[4];
    double *thr, *se;
    char *meta[CSFLUT_N_STRINGS];
    size_t n_kv;
    char *kv_key[CSFLUT_MAX_META], *kv_val[CSFLUT_MAX_META];
    csflut_meta kv[CSFLUT_MAX_META];
};

const csflut_meta *csflut_grid_meta(const csflut_grid *g, size_t *n)
{
    if (n) *n = g ? g->n_kv : 0;
    return g ? g->kv : NULL;
}

csflut_build *csflut_grid_build(csflut_grid *g) { return g ? &g->build : NULL; }

void csflut_grid_free(csflut_grid *g)
{
    if (!g) return;
    for (int a = 0; a < 4; a++) free(g->pts[a]);
    free(g->thr);
    free(g->se);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) free(g->meta[k]);
    for (size_t k = 0; k < g->n_kv; k++) {
        free(g->kv_key[k]);
        free(g->kv_val[k]);
    }
    free(g);
}

typedef struct {
    double v[N_COLS];
    size_t line;
} row;

/* A comment line [q, le) (q at the '#'): "# key: value" for a known key sets that field; other
 * comments are ignored. Returns CSFLUT_OK, CSFLUT_E_NOMEM or CSFLUT_E_CSV (msg filled). */
/* At most 24 bytes of a field for a message, with every byte outside printable ASCII (and the
 * quote and backslash) as \xNN, so a hostile file cannot put control codes on a terminal. (This
 * library links only libc, so it keeps its own copy of csf_quote_bytes.) */
static const char *quote_field(const char *f, size_t n, char *out, size_t cap)
{
    size_t o = 0;
    for (size_t i = 0; i < n && i < 24 && o + 5 < cap; i++) {
        unsigned char c = (unsigned char)f[i];
        if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') out[o++] = (char)c;
        else o += (size_t)snprintf(out + o, cap - o, "\\x%02x", c);
    }
    out[o < cap ? o : cap - 1] = 0;
    return out;
}

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, s, n);
    d[n] = 0;
    return d;
}

/* "# meta.KEY: value": a key/value metadata pair, checked as the writer checks it. */
static csflut_status parse_meta_pair(const char *k, size_t kl, const char *v, size_t vl, csv_meta *m,
                                     char *msg, size_t msz)
{
    char shown[100];
    if (m->n_kv >= CSFLUT_MAX_META) {
        snprintf(msg, msz, "more than %d meta. pairs", CSFLUT_MAX_META);
        return CSFLUT_E_CSV;
    }
    if (memchr(v, 0, vl) || memchr(k, 0, kl)) {
        snprintf(msg, msz, "meta.%s contains a NUL byte", quote_field(k, kl, shown, sizeof shown));
        return CSFLUT_E_CSV;
    }
    char *key = dup_n(k, kl), *val = dup_n(v, vl);
    if (!key || !val) {
        free(key);
        free(val);
        return CSFLUT_E_NOMEM;
    }
    m->kv_key[m->n_kv] = key;
    m->kv_val[m->n_kv] = val;
    m->n_kv++;
    csflut_diag d;
    if (csflut_check_meta((const char *const *)m->kv_key, (const char *const *)m->kv_val, m->n_kv, &d, 0) !=
        CSFLUT_OK) {
        snprintf(msg, msz, "%.150s", d.message);
        return CSFLUT_E_CSV;
    }
    return CSFLUT_OK;
}

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
    if (kl > 5 && memcmp(q, "meta.", 5) == 0) return parse_meta_pair(q + 5, kl - 5, v, vl, m, msg, msz);
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
            char shown[100];
            snprintf(msg, msz, "%s \"%s\" is not %s", num_keys[k], quote_field(v, vl, shown, sizeof shown),
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

/* What has been read of the CSV: where each column sits, the data rows, the # metadata. */
typedef struct {
    int colmap[N_COLS]; /* field position of each column, -1 absent */
    int n_fields, have_header;
    row *rows;
    size_t n_rows, cap_rows;
    csv_meta meta;
} csv_read;

/* The header: known column names, each once, the required ones present. */
static csflut_status read_header(csv_read *cr, const char **fs, const size_t *fl, int nf, char *msg, size_t msz)
{
    if (nf < 0) {
        snprintf(msg, msz, "header has more than %d columns", N_COLS);
        return CSFLUT_E_CSV;
    }
    for (int k = 0; k < nf; k++) {
        int found = -1;
        for (int c = 0; c < N_COLS; c++)
            if (fl[k] == strlen(col_names[c]) && memcmp(fs[k], col_names[c], fl[k]) == 0) found = c;
        if (found < 0) {
            char shown[100];
            snprintf(msg, msz,
                     "unknown column \"%s\" (allowed: freq_cpd, ecc_deg, velocity_dps, "
                     "lum_cdm2, threshold, stderr_log10)", quote_field(fs[k], fl[k], shown, sizeof shown));
            return CSFLUT_E_CSV;
        }
        if (cr->colmap[found] >= 0) {
            snprintf(msg, msz, "column %s appears twice", col_names[found]);
            return CSFLUT_E_CSV;
        }
        cr->colmap[found] = k;
    }
    const int required[3] = {COL_FREQ, COL_ECC, COL_THR};
    for (int k = 0; k < 3; k++)
        if (cr->colmap[required[k]] < 0) {
            snprintf(msg, msz, "header lacks the required column %s", col_names[required[k]]);
            return CSFLUT_E_CSV;
        }
    cr->n_fields = nf;
    cr->have_header = 1;
    return CSFLUT_OK;
}

/* Why a column's value is out of its range (NULL: it is not). */
static const char *value_rule(int c, double v)
{
    switch (c) {
    case COL_FREQ: return isfinite(v) && v > 0 ? NULL : "must be finite and > 0 cpd";
    case COL_ECC: return isfinite(v) && v >= 0 ? NULL : "must be finite and >= 0 deg";
    case COL_VEL: return isfinite(v) && v >= 0 ? NULL : "must be finite and >= 0 deg/s";
    case COL_LUM: return isfinite(v) && v > 0 ? NULL : "must be finite and > 0 cd/m2";
    case COL_THR: return v > 0 ? NULL : "must be > 0 (inf = never visible)";
    case COL_SE: return v != v || (isfinite(v) && v >= 0) ? NULL : "must be >= 0, or empty/nan for unknown";
    }
    return NULL;
}

/* One data row: as many fields as the header, each a number in its column's range. */
static csflut_status read_row(csv_read *cr, size_t line, const char **fs, const size_t *fl, int nf, char *msg,
                              size_t msz)
{
    if (nf != cr->n_fields) {
        snprintf(msg, msz, "%s fields, the header has %d",
                 nf < 0 ? "too many" : (nf < cr->n_fields ? "too few" : "too many"), cr->n_fields);
        return CSFLUT_E_CSV;
    }
    if (cr->n_rows >= CSFLUT_MAX_NODES) {
        snprintf(msg, msz, "more than %u rows", (unsigned)CSFLUT_MAX_NODES);
        return CSFLUT_E_CSV;
    }
    if (cr->n_rows == cr->cap_rows) {
        size_t nc = cr->cap_rows ? cr->cap_rows * 2 : 64;
        row *nr = realloc(cr->rows, nc * sizeof *cr->rows);
        if (!nr) return CSFLUT_E_NOMEM;
        cr->rows = nr;
        cr->cap_rows = nc;
    }
    row *r = &cr->rows[cr->n_rows];
    r->line = line;
    for (int c = 0; c < N_COLS; c++) {
        r->v[c] = NAN;
        int k = cr->colmap[c];
        if (k < 0) continue;
        if (c == COL_SE && (fl[k] == 0)) continue; /* empty = unknown */
        if (parse_num(fs[k], fl[k], &r->v[c]) != 0) {
            char shown[100];
            snprintf(msg, msz, "%s \"%s\" is not a number", col_names[c], quote_field(fs[k], fl[k], shown, sizeof shown));
            return CSFLUT_E_CSV;
        }
        const char *rule = value_rule(c, r->v[c]);
        if (rule) {
            snprintf(msg, msz, "%s %g %s", col_names[c], r->v[c], rule);
            return CSFLUT_E_CSV;
        }
    }
    cr->n_rows++;
    return CSFLUT_OK;
}

/* Every line: # metadata, blank lines, the header, then the rows. *line ends as the number of
 * lines read (the line a failure names). */
static csflut_status read_lines(csv_read *cr, const char *text, size_t len, size_t *line, csflut_diag *diag)
{
    char msg[200];
    const char *p = text ? text : "", *end = p + len;
    for (const char *next; p < end; p = next) {
        const char *e = memchr(p, '\n', (size_t)(end - p));
        next = e ? e + 1 : end;
        if (!e) e = end;
        (*line)++;
        const char *le = e;
        if (le > p && le[-1] == '\r') le--;
        const char *q = p;
        while (q < le && (*q == ' ' || *q == '\t')) q++;
        if (q < le && *q == '#') {
            csflut_status st = parse_meta(q, le, &cr->meta, msg, sizeof msg);
            if (st == CSFLUT_E_CSV) return csv_fail(diag, *line, msg);
            if (st) return st;
        }
        if (q == le || *q == '#') continue;
        if (memchr(p, 0, (size_t)(le - p))) return csv_fail(diag, *line, "NUL byte in the line");
        const char *fs[N_COLS];
        size_t fl[N_COLS];
        int nf = split(p, le, fs, fl, N_COLS);
        csflut_status st = cr->have_header ? read_row(cr, *line, fs, fl, nf, msg, sizeof msg)
                                           : read_header(cr, fs, fl, nf, msg, sizeof msg);
        if (st == CSFLUT_E_CSV) return csv_fail(diag, *line, msg);
        if (st == CSFLUT_E_NOMEM) csflut_diag_set(diag, st, *line, "out of memory");
        if (st) return st;
    }
    if (!cr->have_header)
        return csv_fail(diag, *line ? *line : 1, "no header row (expected freq_cpd,ecc_deg,...,threshold)");
    if (cr->n_rows == 0) return csv_fail(diag, *line, "no data rows");
    return CSFLUT_OK;
}

/* The grid's axes: each present column's distinct values, sorted, into g->pts and n. */
static csflut_status grid_axes(csflut_grid *g, const csv_read *cr, int n[4], char *msg, size_t msz)
{
    for (int a = 0; a < 4; a++) {
        if (cr->colmap[a] < 0) continue;
        double *v = malloc(cr->n_rows * sizeof *v);
        if (!v) return CSFLUT_E_NOMEM;
        for (size_t i = 0; i < cr->n_rows; i++) v[i] = cr->rows[i].v[a];
        qsort(v, cr->n_rows, sizeof *v, cmp_double);
        size_t u = 0;
        for (size_t i = 0; i < cr->n_rows; i++)
            if (u == 0 || v[i] != v[u - 1]) v[u++] = v[i];
        if (u > CSFLUT_MAX_POINTS) {
            free(v);
            snprintf(msg, msz, "column %s has %zu distinct values (at most %d grid points)", col_names[a], u,
                     CSFLUT_MAX_POINTS);
            return CSFLUT_E_CSV;
        }
        g->pts[a] = v;
        n[a] = (int)u;
    }
    return CSFLUT_OK;
}

/* Names the grid point node k lacks a row for. */
static void missing_node(const csflut_grid *g, const int n[4], size_t k, char *msg, size_t msz)
{
    size_t nv = n[2] > 0 ? (size_t)n[2] : 1;
    size_t r = k;
    int fi = (int)(r % (size_t)n[0]);
    r /= (size_t)n[0];
    int ei = (int)(r % (size_t)n[1]);
    r /= (size_t)n[1];
    int vi = (int)(r % nv);
    int li = (int)(r / nv);
    int m = snprintf(msg, msz, "the grid is incomplete: no row for freq_cpd=%.17g ecc_deg=%.17g", g->pts[0][fi],
                     g->pts[1][ei]);
    if (n[2] && m > 0 && (size_t)m < msz) m += snprintf(msg + m, msz - (size_t)m, " velocity_dps=%.17g", g->pts[2][vi]);
    if (n[3] && m > 0 && (size_t)m < msz) snprintf(msg + m, msz - (size_t)m, " lum_cdm2=%.17g", g->pts[3][li]);
}

/* Every row's threshold (and standard error) into its grid node: each node exactly once. */
static csflut_status grid_nodes(csflut_grid *g, const csv_read *cr, const int n[4], size_t line, csflut_diag *diag)
{
    char msg[200];
    size_t nodes = 1;
    for (int a = 0; a < 4; a++) nodes *= n[a] > 0 ? (size_t)n[a] : 1;
    if (nodes > CSFLUT_MAX_NODES) {
        snprintf(msg, sizeof msg, "the grid would have %zu nodes (at most %u)", nodes, (unsigned)CSFLUT_MAX_NODES);
        return csv_fail(diag, line, msg);
    }
    g->thr = malloc(nodes * sizeof(double));
    size_t *node_line = calloc(nodes, sizeof *node_line);
    if (cr->colmap[COL_SE] >= 0) g->se = malloc(nodes * sizeof(double));
    csflut_status st = CSFLUT_OK;
    if (!g->thr || !node_line || (cr->colmap[COL_SE] >= 0 && !g->se)) st = CSFLUT_E_NOMEM;
    size_t nv = n[2] > 0 ? (size_t)n[2] : 1;
    for (size_t i = 0; st == CSFLUT_OK && i < cr->n_rows; i++) {
        const row *rw = &cr->rows[i];
        int idx[4] = {0, 0, 0, 0};
        for (int a = 0; a < 4; a++)
            if (n[a] > 0) idx[a] = find(g->pts[a], n[a], rw->v[a]);
        size_t k = (((size_t)idx[3] * nv + (size_t)idx[2]) * (size_t)n[1] + (size_t)idx[1]) * (size_t)n[0] +
                   (size_t)idx[0];
        if (node_line[k]) {
            snprintf(msg, sizeof msg, "duplicate grid point (same axis values as line %zu)", node_line[k]);
            st = csv_fail(diag, rw->line, msg);
            break;
        }
        node_line[k] = rw->line;
        g->thr[k] = rw->v[COL_THR];
        if (g->se) g->se[k] = rw->v[COL_SE];
    }
    for (size_t k = 0; st == CSFLUT_OK && k < nodes; k++)
        if (!node_line[k]) {
            missing_node(g, n, k, msg, sizeof msg);
            st = csv_fail(diag, line, msg);
        }
    free(node_line);
    return st;
}

/* The table's build: the axes, the values and the metadata (which g takes over from cr). */
static void grid_build(csflut_grid *g, csv_read *cr, const int n[4])
{
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
        g->meta[k] = cr->meta.str[k];
        cr->meta.str[k] = NULL;
    }
    b->observer = g->meta[0];
    b->display_profile_id = g->meta[1];
    b->method = g->meta[2];
    b->date_utc = g->meta[3];
    b->tool_version = g->meta[4];
    g->n_kv = cr->meta.n_kv;
    for (size_t k = 0; k < g->n_kv; k++) {
        g->kv_key[k] = cr->meta.kv_key[k];
        g->kv_val[k] = cr->meta.kv_val[k];
        g->kv[k] = (csflut_meta){g->kv_key[k], g->kv_val[k]};
    }
    cr->meta.n_kv = 0;
    b->viewing_distance_mm = cr->meta.dist_mm;
    b->mean_lum_cdm2 = cr->meta.mean_lum;
    b->trials = (int)cr->meta.trials;
}

csflut_status csflut_import_csv(const char *text, size_t len, csflut_grid **out, csflut_diag *diag)
{
    if (diag) memset(diag, 0, sizeof *diag);
    if (!out || (!text && len)) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL argument");
        return CSFLUT_E_ARG;
    }
    *out = NULL;
    csv_read cr;
    memset(&cr, 0, sizeof cr);
    for (int c = 0; c < N_COLS; c++) cr.colmap[c] = -1;
    cr.meta = (csv_meta){.dist_mm = NAN, .mean_lum = NAN};
    size_t line = 0;
    csflut_grid *g = NULL;
    int n[4] = {0, 0, 0, 0};
    char msg[200];
    csflut_status st = read_lines(&cr, text, len, &line, diag);
    if (st == CSFLUT_OK && !(g = calloc(1, sizeof *g))) st = CSFLUT_E_NOMEM;
    if (st == CSFLUT_OK) {
        st = grid_axes(g, &cr, n, msg, sizeof msg);
        if (st == CSFLUT_E_CSV) csv_fail(diag, line, msg);
    }
    if (st == CSFLUT_OK) st = grid_nodes(g, &cr, n, line, diag);
    if (st == CSFLUT_OK) {
        grid_build(g, &cr, n);
        csflut_diag vd;
        st = csflut_validate_build(&g->build, &vd);
        if (st) csflut_diag_set(diag, st, 0, "%s", vd.message);
    }
    free(cr.rows);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) free(cr.meta.str[k]);
    for (size_t k = 0; k < cr.meta.n_kv; k++) {
        free(cr.meta.kv_key[k]);
        free(cr.meta.kv_val[k]);
    }
    if (st) {
        if (st == CSFLUT_E_NOMEM) csflut_diag_set(diag, st, line, "out of memory");
        csflut_grid_free(g);
        return st;
    }
    *out = g;
    return CSFLUT_OK;
}
