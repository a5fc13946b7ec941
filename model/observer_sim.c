/* Simulated observer (see observer_sim.h for the model). */
#include "model/observer_sim.h"
#include "model/observer_sdt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/file_read.h"
#include "model/psychometric.h"
#include "core/rng.h"
#include "core/csv.h"
#include "core/spec.h"

/* RNG streams: one per kind of draw, so adding a draw of one kind never shifts another. */
enum {
    ST_ATTEND = 0x0b501, ST_DETECT, ST_RT, ST_SPONT, ST_SPONT_T, ST_ANTICIP, ST_ANTICIP_T,
    ST_CLICK_X, ST_CLICK_Y, ST_GUESS_R, ST_GUESS_A, ST_2AFC, ST_2AFC_RT, ST_RT_N,
    ST_AFC, ST_AFC_WRONG, ST_AFC_RT,
    /* added with the decision models and session effects: new streams only, so the default
     * observer's draws are unchanged */
    ST_DRAW, ST_SDT_Z, ST_SDT_LAPSE, ST_SDT_GUESS, ST_LOOK, ST_WALK_BLOCK, ST_WALK_STEP,
    ST_RUN_START, ST_RUN_LEN, ST_RUN_GUESS
};

#define FRAMES_PER_TRIAL 4096u

struct csf_observer_sim {
    csf_observer_sim_params p;
    csf_obs_table *table;
    uint64_t seed;
    char desc[768];
};

/* ---- CSV table ------------------------------------------------------------------------------ */

#define TABLE_MAX_AXIS 64
#define TABLE_MAX_VELOCITY_DPS 1000.0

void csf_obs_table_free(csf_obs_table *t)
{
    if (!t) return;
    free(t->freq_cpd);
    free(t->ecc_deg);
    free(t->velocity_dps);
    free(t->log10_threshold);
    free(t);
}

static int find_or_add(double *axis, int *n, double v)
{
    for (int i = 0; i < *n; i++)
        if (axis[i] == v) return i;
    if (*n >= TABLE_MAX_AXIS) return -1;
    axis[(*n)++] = v;
    return *n - 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One number field (trimmed by the splitter); "inf" is accepted for the threshold column. */
static int parse_field(const char *f, double *out, int allow_inf)
{
    if (allow_inf && (strcmp(f, "inf") == 0 || strcmp(f, "INF") == 0 || strcmp(f, "Inf") == 0)) {
        *out = INFINITY;
        return 0;
    }
    return csf_number_parse(f, -INFINITY, INFINITY, out) == CSF_NUM_OK ? 0 : -1;
}

typedef struct {
    double f, e, v, th;
    int line;
} table_row;

/* Columns of the table, by the header's names (without a header: the three of a 2-D table). */
enum { COL_FREQ, COL_ECC, COL_VEL, COL_TH, N_COLS };
static const char *const col_names[N_COLS] = {"freq_cpd", "ecc_deg", "velocity_dps", "threshold"};

/* The rows read so far and the distinct axis values they use. */
typedef struct {
    table_row *rows;
    size_t n_rows, cap;
    double fax[TABLE_MAX_AXIS], eax[TABLE_MAX_AXIS], vax[TABLE_MAX_AXIS];
    int nf, ne, nv;
    int n_cols;
    int col_of[N_COLS]; /* field index of each column, -1 where absent */
    char fields[N_COLS][CSF_CSV_FIELD_MAX];
} table_read;

/* The header line: each known column name once, freq_cpd, ecc_deg and threshold required. */
static csf_status read_table_header(table_read *tr, const char *l, int line, csf_error *err)
{
    const char *why;
    int n = csf_csv_split(l, tr->fields, N_COLS, &why);
    for (int c = 0; c < N_COLS; c++) tr->col_of[c] = -1;
    for (int i = 0; i < n; i++) {
        int c = 0;
        while (c < N_COLS && strcmp(tr->fields[i], col_names[c]) != 0) c++;
        if (c == N_COLS || tr->col_of[c] >= 0) n = -1;
        else tr->col_of[c] = i;
    }
    if (n < 0 || tr->col_of[COL_FREQ] < 0 || tr->col_of[COL_ECC] < 0 || tr->col_of[COL_TH] < 0)
        return csf_error_set(err, CSF_E_FORMAT,
                             "observer table line %d: header must name the columns freq_cpd, ecc_deg, "
                             "threshold and optionally velocity_dps, each once, e.g. "
                             "'freq_cpd,ecc_deg,threshold' or 'freq_cpd,ecc_deg,velocity_dps,threshold'",
                             line);
    tr->n_cols = n;
    return CSF_OK;
}

/* The fields of one data line as numbers in range; velocity 0 where the table has none. */
static csf_status read_row_values(table_read *tr, const char *l, int line, table_row *row, csf_error *err)
{
    const char *why;
    if (csf_csv_split(l, tr->fields, N_COLS, &why) != tr->n_cols)
        return tr->col_of[COL_VEL] < 0
                   ? csf_error_set(err, CSF_E_FORMAT,
                                   "observer table line %d: expected 3 comma-separated numbers "
                                   "freq_cpd,ecc_deg,threshold (a table with a velocity_dps column needs a "
                                   "header naming its columns)",
                                   line)
                   : csf_error_set(err, CSF_E_FORMAT,
                                   "observer table line %d: expected 4 comma-separated "
                                   "numbers, as the header names",
                                   line);
    double val[N_COLS] = {0};
    for (int c = 0; c < N_COLS; c++) {
        int i = tr->col_of[c];
        if (i >= 0 && parse_field(tr->fields[i], &val[c], c == COL_TH))
            return csf_error_set(err, CSF_E_FORMAT, "observer table line %d: not a number", line);
    }
    if (!(val[COL_FREQ] > 0 && val[COL_FREQ] <= 1000))
        return csf_error_set(err, CSF_E_FORMAT, "observer table line %d: freq_cpd %g outside (0, 1000]", line,
                             val[COL_FREQ]);
    if (!(val[COL_ECC] >= 0 && val[COL_ECC] <= 180))
        return csf_error_set(err, CSF_E_FORMAT, "observer table line %d: ecc_deg %g outside [0, 180]", line,
                             val[COL_ECC]);
    if (!(val[COL_VEL] >= 0 && val[COL_VEL] <= TABLE_MAX_VELOCITY_DPS))
        return csf_error_set(err, CSF_E_FORMAT, "observer table line %d: velocity_dps %g outside [0, %g]",
                             line, val[COL_VEL], TABLE_MAX_VELOCITY_DPS);
    if (!(val[COL_TH] > 0))
        return csf_error_set(err, CSF_E_FORMAT,
                             "observer table line %d: threshold %g must be > 0 (>= 1 or inf = never visible)",
                             line, val[COL_TH]);
    *row = (table_row){val[COL_FREQ], val[COL_ECC], val[COL_VEL], val[COL_TH], line};
    return CSF_OK;
}

/* One data line s..e (trimmed, without its comment): numbers in range, on a grid of at most
 * TABLE_MAX_AXIS values per axis. */
static csf_status read_table_row(table_read *tr, const char *l, int line, csf_error *err)
{
    table_row row;
    csf_status st = read_row_values(tr, l, line, &row, err);
    if (st != CSF_OK) return st;
    if (find_or_add(tr->fax, &tr->nf, row.f) < 0 || find_or_add(tr->eax, &tr->ne, row.e) < 0 ||
        find_or_add(tr->vax, &tr->nv, row.v) < 0)
        return csf_error_set(err, CSF_E_FORMAT,
                             "observer table line %d: more than %d distinct frequencies, eccentricities or "
                             "velocities",
                             line, TABLE_MAX_AXIS);
    size_t max_rows =
        (size_t)TABLE_MAX_AXIS * TABLE_MAX_AXIS * (tr->col_of[COL_VEL] >= 0 ? TABLE_MAX_AXIS : 1);
    if (tr->n_rows >= max_rows)
        return csf_error_set(err, CSF_E_FORMAT, "observer table line %d: more than %zu rows", line, max_rows);
    if (tr->n_rows == tr->cap) {
        tr->cap *= 2;
        table_row *nr = realloc(tr->rows, tr->cap * sizeof *tr->rows);
        if (!nr) return csf_error_set(err, CSF_E_NOMEM, "observer table: out of memory");
        tr->rows = nr;
    }
    tr->rows[tr->n_rows++] = row;
    return CSF_OK;
}

/* A header is a line before the first row that starts with a letter (a row starts with a number;
 * "inf" is only ever a threshold, which no header-less row has first). */
static int is_header(const table_read *tr, const char *s)
{
    return tr->n_rows == 0 && ((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z'));
}

/* Every line: comments (#, also after a row) and blank lines skipped, an optional header, then the
 * rows. */
static csf_status read_table_lines(table_read *tr, const char *text, size_t len, csf_error *err)
{
    csf_lines lines;
    if (csf_lines_open(&lines, text, len, 65535))
        return csf_error_set(err, CSF_E_NOMEM, "observer table: out of memory");
    lines.hash_comments = 1;
    char *l;
    int got;
    csf_status st = CSF_OK;
    while (st == CSF_OK && (got = csf_lines_next(&lines, &l)) != 0)
        st = got < 0 ? csf_error_set(err, CSF_E_FORMAT, "observer table line %d: %s", lines.line, lines.why)
             : is_header(tr, l) ? read_table_header(tr, l, lines.line, err)
                                : read_table_row(tr, l, lines.line, err);
    csf_lines_close(&lines);
    if (st == CSF_OK && tr->n_rows == 0)
        return csf_error_set(err, CSF_E_FORMAT, "observer table: no data rows");
    return st;
}

static int axis_index(const double *axis, double v)
{
    int i = 0;
    while (axis[i] != v) i++;
    return i;
}

/* Sorted axes and the node array (NAN = no row yet), sized from the rows read. */
static csf_status alloc_table(const table_read *tr, csf_obs_table **out, csf_error *err)
{
    int nf = tr->nf, ne = tr->ne, nv = tr->col_of[COL_VEL] >= 0 ? tr->nv : 0;
    size_t nodes = (size_t)nf * (size_t)ne * (size_t)(nv > 0 ? nv : 1);
    csf_obs_table *t = *out = calloc(1, sizeof *t);
    if (t) {
        t->n_freq = nf;
        t->n_ecc = ne;
        t->n_vel = nv;
        t->freq_cpd = malloc((size_t)nf * sizeof(double));
        t->ecc_deg = malloc((size_t)ne * sizeof(double));
        t->velocity_dps = malloc((size_t)(nv > 0 ? nv : 1) * sizeof(double));
        /* zeroed, although every cell is set to NAN below: the analyzer cannot follow that loop */
        t->log10_threshold = calloc(nodes, sizeof(double));
    }
    if (!t || !t->freq_cpd || !t->ecc_deg || !t->velocity_dps || !t->log10_threshold)
        return csf_error_set(err, CSF_E_NOMEM, "observer table: out of memory");
    memcpy(t->freq_cpd, tr->fax, (size_t)nf * sizeof(double));
    memcpy(t->ecc_deg, tr->eax, (size_t)ne * sizeof(double));
    if (nv > 0) memcpy(t->velocity_dps, tr->vax, (size_t)nv * sizeof(double));
    else t->velocity_dps[0] = 0;
    for (size_t i = 0; i < nodes; i++) t->log10_threshold[i] = NAN;
    return CSF_OK;
}

/* The first node without a row, named; CSF_OK when the grid is full. */
static csf_status check_full(const csf_obs_table *t, csf_error *err)
{
    int nv = t->n_vel > 0 ? t->n_vel : 1, nf = t->n_freq, ne = t->n_ecc;
    for (int vi = 0; vi < nv; vi++)
        for (int ei = 0; ei < ne; ei++)
            for (int fi = 0; fi < nf; fi++) {
                if (!isnan(t->log10_threshold[((size_t)vi * ne + ei) * nf + fi])) continue;
                if (t->n_vel > 0)
                    return csf_error_set(
                        err, CSF_E_FORMAT,
                        "observer table: no row for %g cpd at %g deg moving at %g deg/s (the "
                        "table must be a full frequency x eccentricity x velocity grid)",
                        t->freq_cpd[fi], t->ecc_deg[ei], t->velocity_dps[vi]);
                return csf_error_set(err, CSF_E_FORMAT,
                                     "observer table: no row for %g cpd at %g deg (the table "
                                     "must be a full frequency x eccentricity grid)",
                                     t->freq_cpd[fi], t->ecc_deg[ei]);
            }
    return CSF_OK;
}

/* The grid from the rows: sorted axes, every (frequency, eccentricity[, velocity]) node exactly
 * once; thresholds >= 1 become 1 (never visible). */
static csf_status build_table(table_read *tr, csf_obs_table **out, csf_error *err)
{
    /* read_table_lines refuses a table without rows, and every row puts its values on the axes:
     * said again here, where the sizes are used. */
    if (tr->nf < 1 || tr->ne < 1 || tr->nv < 1)
        return csf_error_set(err, CSF_E_FORMAT, "observer table: no data rows");
    qsort(tr->fax, (size_t)tr->nf, sizeof tr->fax[0], cmp_double);
    qsort(tr->eax, (size_t)tr->ne, sizeof tr->eax[0], cmp_double);
    qsort(tr->vax, (size_t)tr->nv, sizeof tr->vax[0], cmp_double);
    csf_status st = alloc_table(tr, out, err);
    if (st != CSF_OK) return st;
    csf_obs_table *t = *out;
    int nf = t->n_freq, ne = t->n_ecc;
    for (size_t r = 0; r < tr->n_rows; r++) {
        const table_row *row = &tr->rows[r];
        int fi = axis_index(t->freq_cpd, row->f), ei = axis_index(t->ecc_deg, row->e);
        int vi = t->n_vel > 0 ? axis_index(t->velocity_dps, row->v) : 0;
        double *cell = &t->log10_threshold[((size_t)vi * ne + ei) * nf + fi];
        if (!isnan(*cell))
            return t->n_vel > 0 ? csf_error_set(err, CSF_E_FORMAT,
                                                "observer table line %d: duplicate row for %g cpd at "
                                                "%g deg moving at %g deg/s",
                                                row->line, row->f, row->e, row->v)
                                : csf_error_set(err, CSF_E_FORMAT,
                                                "observer table line %d: duplicate row for %g cpd at %g deg",
                                                row->line, row->f, row->e);
        *cell = row->th >= 1 ? 1.0 : log10(row->th);
    }
    return check_full(t, err);
}

csf_status csf_obs_table_parse(const char *text, size_t len, csf_obs_table **out, csf_error *err)
{
    *out = NULL;
    if (!text) return csf_error_set(err, CSF_E_INVALID_ARG, "observer table: no text");
    table_read tr;
    memset(&tr, 0, sizeof tr);
    tr.n_cols = 3;
    tr.col_of[COL_FREQ] = 0, tr.col_of[COL_ECC] = 1, tr.col_of[COL_VEL] = -1, tr.col_of[COL_TH] = 2;
    tr.cap = 64;
    tr.rows = malloc(tr.cap * sizeof *tr.rows);
    if (!tr.rows) return csf_error_set(err, CSF_E_NOMEM, "observer table: out of memory");
    csf_obs_table *t = NULL;
    csf_status st = read_table_lines(&tr, text, len, err);
    if (st == CSF_OK) st = build_table(&tr, &t, err);
    free(tr.rows);
    if (st != CSF_OK) {
        csf_obs_table_free(t);
        return st;
    }
    *out = t;
    return CSF_OK;
}

csf_status csf_obs_table_load(const char *path, csf_obs_table **out, csf_error *err)
{
    *out = NULL;
    char *buf;
    size_t n;
    csf_status rs = csf_read_file(path, "observer table", (size_t)1 << 20, &buf, &n, err);
    if (rs != CSF_OK) return rs;
    csf_status st = csf_obs_table_parse(buf, n, out, err);
    free(buf);
    if (st != CSF_OK && err) {
        char tmp[sizeof err->msg];
        snprintf(tmp, sizeof tmp, "%s", err->msg);
        csf_error_set(err, st, "%s (%s)", tmp, path);
    }
    return st;
}

static int bracket(const double *axis, int n, double v, int *i0, double *w)
{
    if (n == 1 || v <= axis[0]) { *i0 = 0; *w = 0; return 0; }
    if (v >= axis[n - 1]) { *i0 = n - 2; *w = 1; return 0; }
    int i = 0;
    while (i < n - 2 && v > axis[i + 1]) i++;
    *i0 = i;
    *w = (v - axis[i]) / (axis[i + 1] - axis[i]);
    return 0;
}

/* Bilinear in (log10 f, ecc) on log10 threshold within one velocity slice. */
static double slice_log10(const csf_obs_table *t, int vi, double freq_cpd, double ecc_deg)
{
    double lf[TABLE_MAX_AXIS];
    for (int i = 0; i < t->n_freq; i++) lf[i] = log10(t->freq_cpd[i]);
    int fi, ei;
    double wf, we;
    bracket(lf, t->n_freq, log10(freq_cpd), &fi, &wf);
    bracket(t->ecc_deg, t->n_ecc, ecc_deg, &ei, &we);
    int fi1 = t->n_freq > 1 ? fi + 1 : fi, ei1 = t->n_ecc > 1 ? ei + 1 : ei;
    int nf = t->n_freq;
    const double *v = t->log10_threshold + (size_t)vi * (size_t)t->n_ecc * (size_t)nf;
    double a = v[ei * nf + fi] * (1 - wf) + v[ei * nf + fi1] * wf;
    double b = v[ei1 * nf + fi] * (1 - wf) + v[ei1 * nf + fi1] * wf;
    return a * (1 - we) + b * we;
}

double csf_obs_table_threshold_v(const csf_obs_table *t, double freq_cpd, double ecc_deg, double velocity_dps)
{
    if (!(freq_cpd > 0) || !(ecc_deg >= 0) || isnan(velocity_dps)) return NAN;
    if (t->n_freq < 1 || t->n_ecc < 1) return NAN; /* build_table never makes such a table */
    double x;
    if (t->n_vel < 1) {
        x = slice_log10(t, 0, freq_cpd, ecc_deg);
    } else {
        /* Along velocity, linear in the warp log10(|v| + 0.5) (model/csf_velocity.h), where
         * sensitivity changes by octaves of velocity and v = 0 is finite. */
        double wax[TABLE_MAX_AXIS];
        for (int i = 0; i < t->n_vel; i++) wax[i] = csf_velocity_warp(t->velocity_dps[i]);
        int vi;
        double wv;
        bracket(wax, t->n_vel, csf_velocity_warp(velocity_dps), &vi, &wv);
        int vi1 = t->n_vel > 1 ? vi + 1 : vi;
        x = slice_log10(t, vi, freq_cpd, ecc_deg) * (1 - wv) + slice_log10(t, vi1, freq_cpd, ecc_deg) * wv;
    }
    return x >= 0 ? INFINITY : pow(10.0, x);
}

double csf_obs_table_threshold(const csf_obs_table *t, double freq_cpd, double ecc_deg)
{
    return csf_obs_table_threshold_v(t, freq_cpd, ecc_deg, 0.0);
}
/* ---- spec parsing ---------------------------------------------------------------------------- */

typedef struct {
    const char *key;
    double lo, hi;
    size_t off; /* offset in csf_observer_sim_params */
} param_key;

#define PK(k, lo, hi, field) {k, lo, hi, offsetof(csf_observer_sim_params, field)}
static const param_key keys[] = {
    PK("smax", 2, 5000, model.smax),
    PK("fmax", 0.1, 60, model.fmax_cpd),
    PK("beta", 0.5, 12, model.beta_oct),
    PK("delta", 0, 4, model.delta_log10),
    PK("ecc_a", 0, 0.5, model.ecc_a),
    PK("ecc_b", 0, 0.5, model.ecc_b),
    PK("ecc_scale", 0, 2, model.ecc_scale_per_deg),
    PK("slope", 0.5, 20, slope),
    PK("lapse", 0, 0.5, lapse),
    PK("guess", 0, 0.9, guess_2afc),
    PK("fa", 0, 1, fa),
    PK("anticip", 0, 1, anticip),
    PK("rt_mu", 0.05, 3, rt_mu_s),
    PK("rt_sigma", 0, 1, rt_sigma_s),
    PK("rt_tau", 0, 2, rt_tau_s),
    PK("click_sd", 0, 20, click_sd_deg),
    PK("click_sd_ecc", 0, 1, click_sd_ecc),
    PK("click_range", 0, 90, click_range_deg),
    PK("k", 0.5, 8, k_transducer),
    PK("criterion", 0, 6, criterion_dprime),
    PK("look", 0.02, 1, look_s),
    PK("fatigue", 0, 0.5, fatigue_log10_per_100),
    PK("drift", 0, 0.1, drift_log10),
    PK("lapse_runs", 0, 0.2, lapse_run_rate),
    PK("run_max", 2, 20, lapse_run_max),
    PK("pieron_k", 0, 2, pieron_k_s),
    PK("pieron_beta", 0.1, 2, pieron_beta),
    PK("display_gamma", 1, 4, display_gamma),
    PK("frame_step", 1, 30, frame_step),
    PK("vc1", 0.2, 2, velocity.c1),
    PK("vc2", 0.5, 5, velocity.c2),
    PK("vsteep", 0, 3, velocity.steepness),
    PK("vmin", 0.05, 0.5, velocity.v_min_dps),
};

/* Per-observer draws (slope=draw, lapse=draw, k=draw), from the seed: slope log-uniform over
 * 1.5-6, lapse uniform over 0-0.08, k log-uniform over 1.25-5 (a Weibull fitted to the sdt
 * observer's 2AFC function has slope about 1.21 k, so 1.5-6 again). */
#define DRAW_SLOPE_LO 1.5
#define DRAW_SLOPE_HI 6.0
#define DRAW_LAPSE_HI 0.08
#define DRAW_K_LO 1.25
#define DRAW_K_HI 5.0
/* vsteep=draw: uniform over 0.5-1.5, i.e. the fall of sensitivity with speed half to one and a
 * half times Kelly's (measured curves differ from the model by about 0.2 log10). */
#define DRAW_VSTEEP_LO 0.5
#define DRAW_VSTEEP_HI 1.5

static void params_default(csf_observer_sim_params *p)
{
    memset(p, 0, sizeof *p);
    p->model = csf_model_default();
    p->slope = 3.5;
    p->lapse = 0.02;
    p->guess_2afc = 0.5;
    p->fa = 0.02;
    p->anticip = 0.01;
    p->rt_mu_s = 0.30;
    p->rt_sigma_s = 0.04;
    p->rt_tau_s = 0.10;
    p->click_sd_deg = 0.4;
    p->click_sd_ecc = 0.08;
    p->click_range_deg = 20;
    p->decision = CSF_SIM_WEIBULL;
    p->k_transducer = 2.5;
    p->criterion_dprime = 3.0;
    p->look_s = 0.1;
    p->lapse_run_max = 4;
    p->pieron_beta = 0.67;
    p->frame_step = 3;
    p->velocity = csf_velocity_default();
}

static double draw_log_uniform(uint64_t seed, uint64_t which, double lo, double hi)
{
    return lo * pow(hi / lo, csf_rng_uniform(seed, ST_DRAW, which));
}

/* The default observer's description is unchanged; the newer keys appear only when set. */
static void describe(csf_observer_sim *o, const char *table_path)
{
    const csf_observer_sim_params *p = &o->p;
    int n;
    if (o->table) {
        const char *base = strrchr(table_path, '/');
        n = snprintf(o->desc, sizeof o->desc, "sim(table=%.200s,slope=%g,lapse=%g,fa=%g",
                     base ? base + 1 : table_path, p->slope, p->lapse, p->fa);
    } else {
        n = snprintf(o->desc, sizeof o->desc,
                     "sim(smax=%g,fmax=%g,beta=%g,delta=%g,ecc_a=%g,ecc_b=%g,slope=%g,lapse=%g,fa=%g",
                     p->model.smax, p->model.fmax_cpd, p->model.beta_oct, p->model.delta_log10,
                     p->model.ecc_a, p->model.ecc_b, p->slope, p->lapse, p->fa);
    }
    char extra[512] = "";
    size_t e = 0;
#define ADD(...) e += (size_t)snprintf(extra + e, e < sizeof extra ? sizeof extra - e : 0, __VA_ARGS__)
    if (!o->table && p->model.ecc_scale_per_deg > 0) ADD(",ecc_scale=%g", p->model.ecc_scale_per_deg);
    if (p->decision == CSF_SIM_SDT)
        ADD(",decision=sdt,k=%g,criterion=%g,look=%g", p->k_transducer, p->criterion_dprime, p->look_s);
    if (p->fatigue_log10_per_100 > 0) ADD(",fatigue=%g", p->fatigue_log10_per_100);
    if (p->drift_log10 > 0) ADD(",drift=%g", p->drift_log10);
    if (p->lapse_run_rate > 0) ADD(",lapse_runs=%g,run_max=%g", p->lapse_run_rate, p->lapse_run_max);
    if (p->pieron_k_s > 0) ADD(",pieron_k=%g,pieron_beta=%g", p->pieron_k_s, p->pieron_beta);
    if (p->view_frame)
        ADD(",view=frame,display=%.100s,frame_step=%g", p->display[0] ? p->display : "(profile's)",
            p->frame_step);
    if (p->display_gamma > 0) ADD(",display_gamma=%g", p->display_gamma);
    csf_velocity_params vd = csf_velocity_default();
    if (vd.c1 != p->velocity.c1 || vd.c2 != p->velocity.c2 || vd.steepness != p->velocity.steepness ||
        vd.v_min_dps != p->velocity.v_min_dps)
        ADD(",vc1=%g,vc2=%g,vsteep=%g,vmin=%g", p->velocity.c1, p->velocity.c2, p->velocity.steepness,
            p->velocity.v_min_dps);
    if (p->slope_drawn || p->lapse_drawn || p->k_drawn || p->vsteep_drawn)
        ADD(",drawn:%s%s%s%s", p->slope_drawn ? "slope" : "", p->lapse_drawn ? " lapse" : "",
            p->k_drawn ? " k" : "", p->vsteep_drawn ? " vsteep" : "");
#undef ADD
    if (n > 0 && (size_t)n < sizeof o->desc)
        snprintf(o->desc + n, sizeof o->desc - (size_t)n, "%s)", extra);
}

/* What the spec says besides the parameters it sets directly. */
typedef struct {
    double rt_mean;        /* rt_mean= (NaN: not given); sets rt_mu from rt_tau at the end */
    int view_keys;         /* display_gamma= or frame_step= given */
    char table_path[1024]; /* table= */
} spec_extras;

/* A numeric key: rt_mean, or one of keys[] within its range (whole numbers where it counts
 * frames or trials). */
static csf_status parse_spec_number(csf_observer_sim *o, const char *tok, const char *val, spec_extras *x,
                                   csf_error *err)
{
    const param_key *k = NULL;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (strcmp(keys[i].key, tok) == 0) k = &keys[i];
    double v = 0;
    if (strcmp(tok, "rt_mean") == 0) {
        if (csf_number_parse(val, 0.1, 5, &v) != CSF_NUM_OK)
            return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: rt_mean=%s outside 0.1 to 5 s", val);
        x->rt_mean = v;
        return CSF_OK;
    }
    if (!k)
        return csf_error_set(
            err, CSF_E_INVALID_ARG,
            "--observer: unknown key '%s' (known: smax fmax beta delta ecc_a ecc_b ecc_scale "
            "field table decision slope lapse k criterion look guess fa anticip "
            "rt_mean rt_mu rt_sigma rt_tau pieron_k pieron_beta fatigue drift "
            "lapse_runs run_max click_sd click_sd_ecc click_range view display "
            "display_gamma frame_step vc1 vc2 vsteep vmin)",
            tok);
    if (csf_number_parse(val, k->lo, k->hi, &v) != CSF_NUM_OK)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: %s=%s outside %g to %g", tok, val, k->lo, k->hi);
    int counts = k->off == offsetof(csf_observer_sim_params, lapse_run_max) ||
                 k->off == offsetof(csf_observer_sim_params, frame_step);
    if (counts && v != floor(v))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: %s=%s must be a whole number", tok, val);
    *(double *)((char *)&o->p + k->off) = v;
    if (k->off == offsetof(csf_observer_sim_params, display_gamma) ||
        k->off == offsetof(csf_observer_sim_params, frame_step))
        x->view_keys = 1;
    if (k->off == offsetof(csf_observer_sim_params, slope)) o->p.slope_drawn = 0;
    if (k->off == offsetof(csf_observer_sim_params, lapse)) o->p.lapse_drawn = 0;
    if (k->off == offsetof(csf_observer_sim_params, k_transducer)) o->p.k_drawn = 0;
    if (k->off == offsetof(csf_observer_sim_params, velocity.steepness)) o->p.vsteep_drawn = 0;
    return CSF_OK;
}

/* One key=value of the spec. */
static csf_status parse_spec_token(csf_observer_sim *o, const char *tok, const char *val, uint64_t seed,
                                   spec_extras *x, csf_error *err)
{
    if (!val) return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: '%s' is not key=value", tok);
    if (strcmp(tok, "field") == 0 && strcmp(val, "nasal") == 0) {
        csf_model_use_nasal_field(&o->p.model);
        return CSF_OK;
    }
    if (strcmp(tok, "table") == 0) {
        snprintf(x->table_path, sizeof x->table_path, "%s", val);
        return CSF_OK;
    }
    if (strcmp(tok, "view") == 0) {
        if (strcmp(val, "plan") == 0) o->p.view_frame = 0;
        else if (strcmp(val, "frame") == 0) o->p.view_frame = 1;
        else return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: view=%s: must be plan or frame", val);
        return CSF_OK;
    }
    if (strcmp(tok, "display") == 0) {
        int known = !strcmp(val, "crt") || !strcmp(val, "lcd") || !strcmp(val, "oled") || !strcmp(val, "profile") ||
                    (!strncmp(val, "file=", 5) && val[5]);
        if (!known || strlen(val) >= sizeof o->p.display)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--observer: display=%.100s: must be crt, lcd, oled, profile or "
                                 "file=PATH.csv (at most %zu characters)", val, sizeof o->p.display - 1);
        snprintf(o->p.display, sizeof o->p.display, "%s", val);
        return CSF_OK;
    }
    if (strcmp(tok, "decision") == 0) {
        if (strcmp(val, "weibull") == 0) o->p.decision = CSF_SIM_WEIBULL;
        else if (strcmp(val, "sdt") == 0) o->p.decision = CSF_SIM_SDT;
        else return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: decision=%s: must be weibull or sdt", val);
        return CSF_OK;
    }
    if (strcmp(val, "draw") == 0 && !strcmp(tok, "vsteep")) {
        o->p.velocity.steepness =
            DRAW_VSTEEP_LO + (DRAW_VSTEEP_HI - DRAW_VSTEEP_LO) * csf_rng_uniform(seed, ST_DRAW, 3);
        o->p.vsteep_drawn = 1;
        return CSF_OK;
    }
    if (strcmp(val, "draw") == 0 && (!strcmp(tok, "slope") || !strcmp(tok, "lapse") || !strcmp(tok, "k"))) {
        if (!strcmp(tok, "slope")) {
            o->p.slope = draw_log_uniform(seed, 0, DRAW_SLOPE_LO, DRAW_SLOPE_HI);
            o->p.slope_drawn = 1;
        } else if (!strcmp(tok, "lapse")) {
            o->p.lapse = DRAW_LAPSE_HI * csf_rng_uniform(seed, ST_DRAW, 1);
            o->p.lapse_drawn = 1;
        } else {
            o->p.k_transducer = draw_log_uniform(seed, 2, DRAW_K_LO, DRAW_K_HI);
            o->p.k_drawn = 1;
        }
        return CSF_OK;
    }
    if (strcmp(tok, "field") == 0)
        return strcmp(val, "temporal") != 0
                   ? csf_error_set(err, CSF_E_INVALID_ARG, "--observer: field must be temporal or nasal")
                   : CSF_OK;
    return parse_spec_number(o, tok, val, x, err);
}

/* The checks that need the whole spec. */
static csf_status check_spec(csf_observer_sim *o, const spec_extras *x, csf_error *err)
{
    if (!isnan(x->rt_mean)) {
        o->p.rt_mu_s = x->rt_mean - o->p.rt_tau_s;
        if (o->p.rt_mu_s < 0.05)
            return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: rt_mean=%g is below rt_tau + 0.05 s = %g s",
                                 x->rt_mean, o->p.rt_tau_s + 0.05);
    }
    if (!o->p.view_frame && (o->p.display[0] || x->view_keys))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--observer: display=, display_gamma= and frame_step= need view=frame "
                             "(the person looks at the screen only then)");
    if (o->p.display_gamma > 0 && strcmp(o->p.display, "crt") && strcmp(o->p.display, "lcd") &&
        strcmp(o->p.display, "oled"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: display_gamma= applies to display=crt, lcd or oled only");
    if (o->p.lapse + o->p.guess_2afc >= 1)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: guess + lapse must be below 1");
    return CSF_OK;
}

csf_status csf_observer_sim_create(const char *spec, uint64_t seed, csf_observer_sim **out,
                                   csf_error *err)
{
    *out = NULL;
    if (!spec) spec = "sim";
    if (strncmp(spec, "sim", 3) != 0 || (spec[3] != '\0' && spec[3] != ':'))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--observer: '%s' is not a simulated observer (expected sim or sim:key=value,...)",
                             spec);
    const size_t max_chars = 1399;
    if (strlen(spec) > max_chars)
        return csf_error_set(err, CSF_E_INVALID_ARG, "--observer: spec longer than %zu characters",
                             max_chars);
    csf_spec *items = malloc(sizeof *items);
    if (!items) return csf_error_set(err, CSF_E_NOMEM, "observer: out of memory");
    csf_status st = csf_spec_split(spec[3] == ':' ? spec + 4 : "", "--observer", items, err);
    if (st != CSF_OK) {
        free(items);
        return st;
    }
    csf_observer_sim *o = calloc(1, sizeof *o);
    if (!o) {
        free(items);
        return csf_error_set(err, CSF_E_NOMEM, "observer: out of memory");
    }
    params_default(&o->p);
    o->seed = seed;
    spec_extras x = {.rt_mean = NAN};
    for (int i = 0; i < items->n && st == CSF_OK; i++)
        st = parse_spec_token(o, items->item[i].key, items->item[i].value, seed, &x, err);
    free(items);
    if (st == CSF_OK) st = check_spec(o, &x, err);
    if (st == CSF_OK && x.table_path[0]) st = csf_obs_table_load(x.table_path, &o->table, err);
    if (st != CSF_OK) {
        csf_observer_sim_free(o);
        return st;
    }
    describe(o, x.table_path);
    *out = o;
    return CSF_OK;
}

void csf_observer_sim_free(csf_observer_sim *o)
{
    if (!o) return;
    csf_obs_table_free(o->table);
    free(o);
}

const csf_observer_sim_params *csf_observer_sim_params_get(const csf_observer_sim *o)
{
    return &o->p;
}

const char *csf_observer_sim_describe(const csf_observer_sim *o)
{
    return o->desc;
}

double csf_observer_sim_threshold(const csf_observer_sim *o, double freq_cpd, double ecc_deg)
{
    double th = o->table ? csf_obs_table_threshold(o->table, freq_cpd, ecc_deg)
                         : csf_model_threshold(&o->p.model, freq_cpd, ecc_deg);
    return th >= 1 ? INFINITY : th;
}

double csf_observer_sim_threshold_v(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                    double velocity_dps)
{
    if (isnan(velocity_dps)) return NAN;
    if (o->table && o->table->n_vel > 0) {
        double th = csf_obs_table_threshold_v(o->table, freq_cpd, ecc_deg, velocity_dps);
        return th >= 1 ? INFINITY : th;
    }
    double th = csf_observer_sim_threshold(o, freq_cpd, ecc_deg);
    double gain = csf_velocity_log10_gain(&o->p.velocity, freq_cpd, velocity_dps);
    if (!isfinite(th) || gain == 0) return th; /* static (or slower than fixational drift): as is */
    th /= pow(10.0, gain);
    return th >= 1 ? INFINITY : th;
}

double csf_observer_sim_velocity_log10_gain(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                            double velocity_dps)
{
    if (!(o->table && o->table->n_vel > 0))
        return csf_velocity_log10_gain(&o->p.velocity, freq_cpd, velocity_dps);
    /* A 3-D table: the ratio of its own thresholds, taken before the never-visible clamp (a node
     * stored as 1 is as far as the table knows). */
    double t0 = csf_obs_table_threshold_v(o->table, freq_cpd, ecc_deg, 0.0);
    double tv = csf_obs_table_threshold_v(o->table, freq_cpd, ecc_deg, velocity_dps);
    if (isnan(t0) || isnan(tv)) return NAN;
    if (!isfinite(t0) && !isfinite(tv)) return 0.0;
    if (!isfinite(t0)) return log10(1.0 / tv);
    if (!isfinite(tv)) return log10(t0);
    return log10(t0 / tv);
}

/* ---- over a session: fatigue, criterion drift, lapse runs --------------------------------------- */

static uint64_t session_trial(uint64_t trial_index)
{
    return trial_index >= CSF_SIM_PRACTICE_INDEX ? 0 : trial_index;
}

double csf_observer_sim_trial_threshold(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                        uint64_t trial_index)
{
    return csf_observer_sim_trial_threshold_v(o, freq_cpd, ecc_deg, 0.0, trial_index);
}

double csf_observer_sim_trial_threshold_v(const csf_observer_sim *o, double freq_cpd, double ecc_deg,
                                          double velocity_dps, uint64_t trial_index)
{
    double th = csf_observer_sim_threshold_v(o, freq_cpd, ecc_deg, velocity_dps);
    if (!isfinite(th) || o->p.fatigue_log10_per_100 == 0) return th;
    th *= pow(10.0, o->p.fatigue_log10_per_100 * (double)session_trial(trial_index) / 100.0);
    return th >= 1 ? INFINITY : th;
}

/* Gaussian random walk W(n) = sum of n steps, computed in O(n / 64 + 64) as a pure function of
 * (seed, n): whole blocks of 64 steps are drawn as one normal each (sd 8), and the partial block
 * is a discrete Brownian bridge from the block's start to its drawn end, which has exactly the
 * law of the 64 individual steps given their sum. */
#define WALK_BLOCK 64
double csf_observer_sim_drift_log10(const csf_observer_sim *o, uint64_t trial_index)
{
    if (o->p.drift_log10 == 0) return 0.0;
    uint64_t n = session_trial(trial_index), nb = n / WALK_BLOCK, j = n % WALK_BLOCK;
    double w = 0;
    for (uint64_t b = 0; b < nb; b++) w += sqrt((double)WALK_BLOCK) * csf_rng_normal(o->seed, ST_WALK_BLOCK, b);
    if (j > 0) {
        double pj = 0, pall = 0;
        for (uint64_t i = 0; i < WALK_BLOCK; i++) {
            double z = csf_rng_normal(o->seed, ST_WALK_STEP, nb * WALK_BLOCK + i);
            if (i < j) pj += z;
            pall += z;
        }
        double end = sqrt((double)WALK_BLOCK) * csf_rng_normal(o->seed, ST_WALK_BLOCK, nb);
        w += pj - (double)j / WALK_BLOCK * (pall - end);
    }
    return o->p.drift_log10 * w;
}

/* A run starts at a trial with probability lapse_runs and lasts 2 .. run_max trials (uniform);
 * the trial is in a run when one started within the last run_max trials and still lasts. */
int csf_observer_sim_in_lapse_run(const csf_observer_sim *o, uint64_t trial_index)
{
    if (o->p.lapse_run_rate == 0 || trial_index >= CSF_SIM_PRACTICE_INDEX) return 0;
    int max = (int)o->p.lapse_run_max;
    for (int j = 0; j < max && (uint64_t)j <= trial_index; j++) {
        uint64_t s = trial_index - (uint64_t)j;
        if (csf_rng_uniform(o->seed, ST_RUN_START, s) >= o->p.lapse_run_rate) continue;
        int len = 2 + (int)(csf_rng_uniform(o->seed, ST_RUN_LEN, s) * (max - 1));
        if (len > max) len = max;
        if (len > j) return 1;
    }
    return 0;
}

/* ---- trials ---------------------------------------------------------------------------------- */

static double ex_gaussian(const csf_observer_sim *o, uint64_t idx)
{
    double z = csf_rng_normal(o->seed, ST_RT_N, idx);
    double u = csf_rng_uniform(o->seed, ST_RT, idx);
    double rt = o->p.rt_mu_s + o->p.rt_sigma_s * z - o->p.rt_tau_s * log(u);
    return rt < 0.1 ? 0.1 : rt; /* no one presses faster than ~100 ms after detecting */
}

/* Pieron's law: the extra time to respond to contrast c at threshold t, pieron_k (c/t)^-beta,
 * with c/t floored at 0.1 (a press on noise alone is slow, not endless). */
static double pieron_extra(const csf_observer_sim *o, double contrast, double t_log10)
{
    if (o->p.pieron_k_s == 0 || !isfinite(t_log10)) return 0.0;
    double ratio = contrast > 0 ? contrast / pow(10.0, t_log10) : 0;
    if (ratio < 0.1) ratio = 0.1;
    return o->p.pieron_k_s * pow(ratio, -o->p.pieron_beta);
}

void csf_observer_sim_fade_begin(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                                 double ecc_deg, double polar_deg, double onset_s,
                                 double duration_s, csf_sim_fade_trial *tr)
{
    csf_observer_sim_fade_begin_v(o, trial_index, freq_cpd, ecc_deg, 0.0, polar_deg, onset_s, duration_s, tr);
}

void csf_observer_sim_fade_begin_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                                   double ecc_deg, double velocity_dps, double polar_deg, double onset_s,
                                   double duration_s, csf_sim_fade_trial *tr)
{
    memset(tr, 0, sizeof *tr);
    uint64_t base = trial_index * FRAMES_PER_TRIAL;
    tr->trial = trial_index;
    tr->freq_cpd = freq_cpd;
    tr->ecc_deg = ecc_deg;
    tr->velocity_dps = velocity_dps;
    tr->polar_deg = polar_deg;
    double th = csf_observer_sim_trial_threshold_v(o, freq_cpd, ecc_deg, velocity_dps, trial_index);
    double drift = csf_observer_sim_drift_log10(o, trial_index);
    tr->t_sens_log10 = isfinite(th) ? log10(th) : INFINITY;
    /* Weibull: the latent threshold itself moves with the criterion; sdt: the criterion moves so
     * the contrast at which d' reaches it moves by the same log10 amount. */
    tr->t_log10 = tr->t_sens_log10 + drift;
    tr->criterion_dprime = o->p.criterion_dprime * pow(10.0, o->p.k_transducer * drift);
    tr->last_look = -1;
    tr->onset_s = onset_s;
    tr->attending = csf_rng_uniform(o->seed, ST_ATTEND, base) >= o->p.lapse &&
                    !csf_observer_sim_in_lapse_run(o, trial_index);
    tr->t_spont_s = INFINITY;
    if (csf_rng_uniform(o->seed, ST_SPONT, base) < o->p.fa)
        tr->t_spont_s = onset_s + duration_s * csf_rng_uniform(o->seed, ST_SPONT_T, base);
    if (csf_rng_uniform(o->seed, ST_ANTICIP, base) < o->p.anticip) {
        double ta = onset_s + 0.02 + 0.10 * csf_rng_uniform(o->seed, ST_ANTICIP_T, base);
        if (ta < tr->t_spont_s) tr->t_spont_s = ta;
    }
    tr->x_max = -INFINITY;
    tr->t_detect_s = INFINITY;
    tr->t_press_s = tr->t_spont_s;
    tr->press_spontaneous = isfinite(tr->t_spont_s);
}

/* Weibull: the latent-threshold hazard on the running maximum (observer_sim.h). */
static int weibull_detects(const csf_observer_sim *o, csf_sim_fade_trial *tr, uint64_t idx,
                           double contrast_shown)
{
    if (!(contrast_shown > 0) || !isfinite(tr->t_log10)) return 0;
    double x = log10(contrast_shown);
    double h = csf_psy_fade_hazard(tr->x_max, x, tr->t_log10, o->p.slope);
    if (x > tr->x_max) tr->x_max = x;
    return h > 0 && csf_rng_uniform(o->seed, ST_DETECT, idx) < h;
}

/* sdt yes/no: one look every look_s from onset at what is on screen then (blank screens too):
 * yes when d'(c) + N(0, 1) exceeds the criterion. */
static int sdt_detects(const csf_observer_sim *o, csf_sim_fade_trial *tr, double t_s,
                       double contrast_shown)
{
    int look = (int)floor((t_s - tr->onset_s) / o->p.look_s + 1e-9);
    if (look <= tr->last_look || look < 0) return 0;
    tr->last_look = look;
    if (look > (int)FRAMES_PER_TRIAL - 1) look = (int)FRAMES_PER_TRIAL - 1;
    double d = csf_sdt_dprime(contrast_shown, pow(10.0, tr->t_sens_log10), o->p.k_transducer);
    double z = csf_rng_normal(o->seed, ST_LOOK, tr->trial * FRAMES_PER_TRIAL + (uint64_t)look);
    return d + z > tr->criterion_dprime;
}

int csf_observer_sim_fade_frame(const csf_observer_sim *o, csf_sim_fade_trial *tr, double t_s,
                                double contrast_shown, double *press_t_s)
{
    uint64_t idx = tr->trial * FRAMES_PER_TRIAL + (uint64_t)(tr->frame < (int)FRAMES_PER_TRIAL - 1
                                                                 ? tr->frame
                                                                 : (int)FRAMES_PER_TRIAL - 1);
    tr->frame++;
    if (!tr->detected && tr->attending) {
        int det = o->p.decision == CSF_SIM_SDT ? sdt_detects(o, tr, t_s, contrast_shown)
                                               : weibull_detects(o, tr, idx, contrast_shown);
        if (det) {
            tr->detected = 1;
            tr->t_detect_s = t_s;
            double tp = t_s + ex_gaussian(o, tr->trial) + pieron_extra(o, contrast_shown, tr->t_sens_log10);
            if (tp < tr->t_press_s) {
                tr->t_press_s = tp;
                tr->press_spontaneous = 0;
            }
        }
    }
    if (t_s >= tr->t_press_s) {
        if (press_t_s) *press_t_s = tr->t_press_s;
        return 1;
    }
    return 0;
}

void csf_observer_sim_click(const csf_observer_sim *o, const csf_sim_fade_trial *tr, double *x_deg,
                            double *y_deg)
{
    uint64_t base = tr->trial * FRAMES_PER_TRIAL;
    if (tr->detected && !tr->press_spontaneous) {
        double sd = o->p.click_sd_deg + o->p.click_sd_ecc * tr->ecc_deg;
        double a = tr->polar_deg * M_PI / 180;
        *x_deg = tr->ecc_deg * cos(a) + sd * csf_rng_normal(o->seed, ST_CLICK_X, base);
        *y_deg = tr->ecc_deg * sin(a) + sd * csf_rng_normal(o->seed, ST_CLICK_Y, base);
    } else {
        /* Nothing seen: a guess anywhere within click_range of fixation (uniform over the disc). */
        double r = o->p.click_range_deg * sqrt(csf_rng_uniform(o->seed, ST_GUESS_R, base));
        double a = 2 * M_PI * csf_rng_uniform(o->seed, ST_GUESS_A, base);
        *x_deg = r * cos(a);
        *y_deg = r * sin(a);
    }
}

/* sdt m-AFC: a lapse (probability lapse * m / (m - 1), so the upper asymptote is 1 - lapse as in
 * the Weibull) or a lapse run is a uniform guess; otherwise each place gives d'(c_k) + N(0, 1)
 * and the person picks the largest. */
static int sdt_choose(const csf_observer_sim *o, uint64_t trial_index, double t_log10,
                      const double *contrast_shown, int m, int in_run)
{
    uint64_t base = trial_index * FRAMES_PER_TRIAL;
    double th = isfinite(t_log10) ? pow(10.0, t_log10) : INFINITY;
    if (in_run || csf_rng_uniform(o->seed, ST_SDT_LAPSE, base) < o->p.lapse * m / (m - 1)) {
        int k = (int)(csf_rng_uniform(o->seed, ST_SDT_GUESS, base) * m);
        return k < m ? k : m - 1;
    }
    int best = 0;
    double best_r = -INFINITY;
    for (int k = 0; k < m; k++) {
        double r = csf_sdt_dprime(contrast_shown[k], th, o->p.k_transducer) +
                   csf_rng_normal(o->seed, ST_SDT_Z, base + (uint64_t)k);
        if (r > best_r) best_r = r, best = k;
    }
    return best;
}

static int run_guess(const csf_observer_sim *o, uint64_t trial_index, int m)
{
    int k = (int)(csf_rng_uniform(o->seed, ST_RUN_GUESS, trial_index) * m);
    return k < m ? k : m - 1;
}

int csf_observer_sim_2afc(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                          double ecc_deg, const double contrast_shown[2], double *rt_s)
{
    return csf_observer_sim_2afc_v(o, trial_index, freq_cpd, ecc_deg, 0.0, contrast_shown, rt_s);
}

int csf_observer_sim_2afc_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd, double ecc_deg,
                            double velocity_dps, const double contrast_shown[2], double *rt_s)
{
    uint64_t base = trial_index * FRAMES_PER_TRIAL;
    double th = csf_observer_sim_trial_threshold_v(o, freq_cpd, ecc_deg, velocity_dps, trial_index);
    double t = isfinite(th) ? log10(th) : INFINITY;
    if (rt_s) *rt_s = exp(log(0.6) + 0.3 * csf_rng_normal(o->seed, ST_2AFC_RT, base));
    int in_run = csf_observer_sim_in_lapse_run(o, trial_index);
    if (o->p.decision == CSF_SIM_SDT) return sdt_choose(o, trial_index, t, contrast_shown, 2, in_run);
    if (in_run) return run_guess(o, trial_index, 2);
    int sig = contrast_shown[1] > contrast_shown[0] ? 1 : 0;
    double diff = fabs(contrast_shown[1] - contrast_shown[0]);
    double x = diff > 0 ? log10(diff) : -INFINITY;
    double p = csf_psy_p4(x, t, o->p.slope, o->p.guess_2afc, o->p.lapse);
    int correct = csf_rng_uniform(o->seed, ST_2AFC, base) < p;
    return correct ? sig : 1 - sig;
}

int csf_observer_sim_afc(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd,
                         double ecc_deg, const double *contrast_shown, int n_alternatives,
                         double *rt_s)
{
    return csf_observer_sim_afc_v(o, trial_index, freq_cpd, ecc_deg, 0.0, contrast_shown, n_alternatives,
                                  rt_s);
}

int csf_observer_sim_afc_v(const csf_observer_sim *o, uint64_t trial_index, double freq_cpd, double ecc_deg,
                           double velocity_dps, const double *contrast_shown, int n_alternatives,
                           double *rt_s)
{
    int m = n_alternatives;
    if (m < 2 || m > CSF_SIM_AFC_MAX) m = 2;
    uint64_t base = trial_index * FRAMES_PER_TRIAL;
    double th = csf_observer_sim_trial_threshold_v(o, freq_cpd, ecc_deg, velocity_dps, trial_index);
    double t = isfinite(th) ? log10(th) : INFINITY;
    if (rt_s) *rt_s = exp(log(0.7) + 0.3 * csf_rng_normal(o->seed, ST_AFC_RT, base));
    int in_run = csf_observer_sim_in_lapse_run(o, trial_index);
    if (o->p.decision == CSF_SIM_SDT) return sdt_choose(o, trial_index, t, contrast_shown, m, in_run);
    if (in_run) return run_guess(o, trial_index, m);
    /* The signal is where the most contrast was shown (the first such place on a tie); the
     * others showed nothing or less, and only the difference is there to be seen. */
    int sig = 0;
    for (int k = 1; k < m; k++)
        if (contrast_shown[k] > contrast_shown[sig]) sig = k;
    double other = 0;
    for (int k = 0; k < m; k++)
        if (k != sig && contrast_shown[k] > other) other = contrast_shown[k];
    double diff = contrast_shown[sig] - other;
    double x = diff > 0 ? log10(diff) : -INFINITY;
    double p = csf_psy_p4(x, t, o->p.slope, 1.0 / m, o->p.lapse);
    int correct = csf_rng_uniform(o->seed, ST_AFC, base) < p;
    if (correct) return sig;
    /* a wrong answer: uniformly one of the other m - 1 places */
    int k = (int)(csf_rng_uniform(o->seed, ST_AFC_WRONG, base) * (m - 1));
    if (k > m - 2) k = m - 2;
    return (sig + 1 + k) % m;
}
