#include "questplus.h"

#include <math.h>
#include <stdlib.h>

#include "core/rng.h"
#include "model/csf_model.h"

enum { N_SMAX = 8, N_FMAX = 7, N_BW = 3, N_DELTA = 2, N_A = 4, N_B = 4, N_SLOPE = 3, N_X = 23 };
enum { N_STATIC = N_SMAX * N_FMAX * N_BW * N_DELTA * N_A * N_B };
_Static_assert((int)N_STATIC == (int)QP_N_STATIC, "questplus.h names the static grid's size");
/* P(correct) tabulated over d = x - t */
#define D_MIN (-6.0)
#define D_STEP 0.005
enum { N_D = 2401 };

static const double SLOPES[N_SLOPE] = {2.0, 3.2, 5.0};

struct questplus {
    int n_cells, n_surf, n_hyp;
    const int *n_alt;
    double lcmin, lcmax;
    float *t;                  /* [surf * n_cells + cell] log10 threshold */
    double *w;                 /* [surf * N_SLOPE + slope] posterior, max 1 */
    double p[2][N_SLOPE][N_D]; /* [four places?][slope][d] P(correct) */
    double lp[2][N_SLOPE][N_D], lq[2][N_SLOPE][N_D];
    int *act; /* scratch for next(): active hypotheses and their log weights */
    double *lw;
};

static int d_index(double d)
{
    int i = (int)lround((d - D_MIN) / D_STEP);
    return i < 0 ? 0 : i >= N_D ? N_D - 1 : i;
}

csf_model_params questplus_static_surface(int s, double *prior)
{
    static const double bw[N_BW] = {2.0, 3.0, 4.5}, dl[N_DELTA] = {0.25, 0.75};
    static const double ea[N_A] = {0.0, 0.02, 0.04, 0.07}, eb[N_B] = {0.0, 0.012, 0.025, 0.045};
    int i5 = s % N_B, i4 = s / N_B % N_A, i3 = s / (N_B * N_A) % N_DELTA;
    int i2 = s / (N_B * N_A * N_DELTA) % N_BW, i1 = s / (N_B * N_A * N_DELTA * N_BW) % N_FMAX;
    int i0 = s / (N_B * N_A * N_DELTA * N_BW * N_FMAX);
    double ls = 1.5 + 0.2 * i0, lf = -0.1 + 0.15 * i1;
    double zs = (ls - 2.25) / 0.35, zf = (lf - 0.45) / 0.25;
    *prior = exp(-0.5 * (zs * zs + zf * zf));
    csf_model_params p = {.smax = pow(10.0, ls),
                          .fmax_cpd = pow(10.0, lf),
                          .beta_oct = bw[i2],
                          .delta_log10 = dl[i3],
                          .ecc_a = ea[i4],
                          .ecc_b = eb[i5]};
    return p;
}

static double static_surface(void *ctx, int s, const csf_cell *cells, int n_cells, float *t_log10)
{
    (void)ctx;
    double prior;
    csf_model_params p = questplus_static_surface(s, &prior);
    for (int c = 0; c < n_cells; c++)
        t_log10[c] = (float)-csf_model_log10_sensitivity(&p, cells[c].freq_cpd, cells[c].ecc_deg);
    return prior;
}

questplus *questplus_create_family(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                                   double log10_cmin, double log10_cmax, int n_surf,
                                   questplus_surface_fn surface, void *ctx)
{
    questplus *q = calloc(1, sizeof *q);
    if (!q) return NULL;
    q->n_surf = n_surf, q->n_hyp = n_surf * N_SLOPE;
    q->t = malloc(sizeof *q->t * (size_t)n_surf * (size_t)n_cells);
    q->w = malloc(sizeof *q->w * (size_t)q->n_hyp);
    q->act = malloc(sizeof *q->act * (size_t)q->n_hyp);
    q->lw = malloc(sizeof *q->lw * (size_t)q->n_hyp);
    if (!q->t || !q->w || !q->act || !q->lw) {
        questplus_free(q);
        return NULL;
    }
    q->n_cells = n_cells, q->n_alt = n_alt, q->lcmin = log10_cmin, q->lcmax = log10_cmax;
    for (int s = 0; s < n_surf; s++) {
        double prior = surface(ctx, s, cells, n_cells, &q->t[(size_t)s * (size_t)n_cells]);
        for (int k = 0; k < N_SLOPE; k++) q->w[(size_t)s * N_SLOPE + (size_t)k] = prior;
    }
    lapse = lapse < 0.001 ? 0.001 : lapse;
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < N_SLOPE; k++)
            for (int i = 0; i < N_D; i++) {
                double g = f ? 0.25 : 0.5, d = D_MIN + D_STEP * i;
                double pc = g + (1.0 - g - lapse) * (1.0 - exp(-pow(10.0, SLOPES[k] * d)));
                q->p[f][k][i] = pc, q->lp[f][k][i] = log(pc), q->lq[f][k][i] = log(1.0 - pc);
            }
    return q;
}

questplus *questplus_create(const csf_cell *cells, int n_cells, const int *n_alt, double lapse,
                            double log10_cmin, double log10_cmax)
{
    return questplus_create_family(cells, n_cells, n_alt, lapse, log10_cmin, log10_cmax, N_STATIC,
                                   static_surface, NULL);
}

void questplus_free(questplus *q)
{
    if (!q) return;
    free(q->t);
    free(q->w);
    free(q->act);
    free(q->lw);
    free(q);
}

static double x_level(const questplus *q, int i)
{
    double x = -3.3 + 0.15 * i;
    return x < q->lcmin ? q->lcmin : x > q->lcmax ? q->lcmax : x;
}

/* A seeded random subset of the cells. */
static int pick_cells(const questplus *q, uint64_t seed, int trial, int *pick)
{
    int order[256], n_pick = 0, nc = q->n_cells < 256 ? q->n_cells : 256;
    for (int c = 0; c < nc; c++) order[c] = c;
    for (int c = 0; c < nc && n_pick < QP_CELLS_PER_TRIAL; c++) {
        int j = c + (int)(csf_rng_u64(seed, 0x51b, (uint64_t)trial * 256 + (uint64_t)c) % (uint64_t)(nc - c));
        int tmp = order[c];
        order[c] = order[j], order[j] = tmp;
        pick[n_pick++] = order[c];
    }
    return n_pick;
}

/* Expected entropy of the posterior after showing x at cell c:
 * E[H] = -(sum w P log(w P) + sum w Q log(w Q)) + A1 log A1 + A0 log A0. */
static double expected_entropy(const questplus *q, int n_act, double total, int c, double x)
{
    int f = q->n_alt[c] == 4;
    double a1 = 0.0, b = 0.0;
    for (int i = 0; i < n_act; i++) {
        int h = q->act[i], s = h / N_SLOPE, k = h % N_SLOPE;
        int di = d_index(x - q->t[(size_t)s * (size_t)q->n_cells + (size_t)c]);
        double w = q->w[h] / total, p = q->p[f][k][di];
        a1 += w * p;
        b += w * (p * (q->lw[i] + q->lp[f][k][di]) + (1.0 - p) * (q->lw[i] + q->lq[f][k][di]));
    }
    double a0 = 1.0 - a1;
    return -b + (a1 > 0 ? a1 * log(a1) : 0.0) + (a0 > 0 ? a0 * log(a0) : 0.0);
}

void questplus_next(questplus *q, uint64_t seed, int trial, int *cell, double *x_log10)
{
    int pick[QP_CELLS_PER_TRIAL] = {0}; /* a grid of no cells draws none */
    int n_pick = pick_cells(q, seed, trial, pick);
    double total = 0.0;
    int n_act = 0;
    for (int h = 0; h < q->n_hyp; h++)
        if (q->w[h] > 1e-7) total += q->w[h], q->act[n_act++] = h;
    for (int i = 0; i < n_act; i++) q->lw[i] = log(q->w[q->act[i]] / total);
    double best = INFINITY;
    *cell = pick[0], *x_log10 = q->lcmax;
    for (int pc = 0; pc < n_pick; pc++)
        for (int xi = 0; xi < N_X; xi++) {
            double x = x_level(q, xi);
            if (xi > 0 && x == x_level(q, xi - 1)) continue;
            double eh = expected_entropy(q, n_act, total, pick[pc], x);
            if (eh < best) best = eh, *cell = pick[pc], *x_log10 = x;
        }
}

void questplus_update(questplus *q, int cell, double x_log10, int correct)
{
    int f = q->n_alt[cell] == 4;
    double mx = 0.0;
    for (int h = 0; h < q->n_hyp; h++) {
        if (q->w[h] == 0.0) continue;
        int s = h / N_SLOPE, k = h % N_SLOPE;
        double p = q->p[f][k][d_index(x_log10 - q->t[(size_t)s * (size_t)q->n_cells + (size_t)cell])];
        q->w[h] *= correct ? p : 1.0 - p;
        if (q->w[h] > mx) mx = q->w[h];
    }
    for (int h = 0; h < q->n_hyp; h++) q->w[h] = q->w[h] / mx < 1e-12 ? 0.0 : q->w[h] / mx;
}

void questplus_estimate(const questplus *q, double *log10_t)
{
    for (int c = 0; c < q->n_cells; c++) {
        double tot = 0.0, inv = 0.0, m = 0.0;
        for (int h = 0; h < q->n_hyp; h++) {
            double w = q->w[h];
            if (w == 0.0) continue;
            double t = q->t[(size_t)(h / N_SLOPE) * (size_t)q->n_cells + (size_t)c];
            tot += w;
            if (t >= q->lcmax) inv += w, t = q->lcmax;
            m += w * t;
        }
        log10_t[c] = inv > 0.5 * tot ? INFINITY : m / tot;
    }
}

double questplus_best_fit_rms(const questplus *q, const double *truth_log10)
{
    double best = INFINITY;
    for (int s = 0; s < q->n_surf; s++) {
        double se = 0.0;
        int n = 0;
        for (int c = 0; c < q->n_cells; c++) {
            if (!(truth_log10[c] < q->lcmax)) continue;
            double t = q->t[(size_t)s * (size_t)q->n_cells + (size_t)c];
            t = t > q->lcmax ? q->lcmax : t;
            se += (t - truth_log10[c]) * (t - truth_log10[c]), n++;
        }
        if (n && sqrt(se / n) < best) best = sqrt(se / n);
    }
    return best;
}
