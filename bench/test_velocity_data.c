/* The held-out velocity observers of bench_velocity (bench/data/velocity/observer_v_*.csv) are
 * usable truths and are not the prior's shape:
 *  - every (freq, ecc, velocity) cell is present exactly once, the grid holds 0, 4 and 12 deg/s
 *    and the session grid's frequencies and eccentricities, thresholds are positive or "inf";
 *  - the static slice (0 deg/s) is the static held-out person the README names, unchanged;
 *  - the log10 ratio drifting / static differs from the Kelly (1979) / Daly (1998) gain of
 *    model/csf_velocity.h (published knobs) by more than 0.1 log10 somewhere among the cells the
 *    benchmark scores (visible, f v below 60 Hz). The best fit over a grid of the model's knobs
 *    (c1, c2, steepness) is printed too: how far a prior with free knobs stays from each person.
 * Usage: test_velocity_data DIR (the folder bench/data; meson passes it). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/csf_velocity.h"
#include "tests/check.h"

enum { MAX_F = 32, MAX_E = 16, MAX_V = 16 };

typedef struct {
    int nf, ne, nv;
    double f[MAX_F], e[MAX_E], v[MAX_V];
    double lt[MAX_V][MAX_E][MAX_F]; /* log10 threshold; INFINITY never visible; NAN missing */
    int count[MAX_V][MAX_E][MAX_F];
} vtable;

static const char *const PEOPLE[] = {"robson", "older", "mkgp", "virsu", "mesopic", "dog", "mansak"};
enum { N_PEOPLE = sizeof PEOPLE / sizeof PEOPLE[0] };
static const double GRID_F[6] = {0.5, 1, 2, 4, 8, 16}, GRID_E[4] = {0, 5, 10, 20}, GRID_V[2] = {4, 12};

static int axis_index(double *axis, int *n, int max, double x)
{
    for (int i = 0; i < *n; i++)
        if (fabs(axis[i] - x) <= 1e-6 * fmax(1.0, fabs(x))) return i;
    if (*n == max) return -1;
    axis[*n] = x;
    return (*n)++;
}

/* Reads a 3- or 4-column table (velocity 0 when there are 3). Returns 0 on success. */
static int load(const char *path, int cols, vtable *t)
{
    memset(t, 0, sizeof *t);
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "cannot open %s\n", path);
        return -1;
    }
    char line[256];
    int bad = 0, rows = 0;
    while (fgets(line, sizeof line, fp)) {
        if (line[0] == '#' || line[0] == '\n' || !strncmp(line, "freq_cpd", 8)) continue;
        double f, e, v = 0.0;
        char th[64];
        int n = cols == 4 ? sscanf(line, "%lf,%lf,%lf,%63s", &f, &e, &v, th)
                          : sscanf(line, "%lf,%lf,%63s", &f, &e, th);
        int fi = axis_index(t->f, &t->nf, MAX_F, f), ei = axis_index(t->e, &t->ne, MAX_E, e);
        int vi = axis_index(t->v, &t->nv, MAX_V, v);
        if (n != cols || fi < 0 || ei < 0 || vi < 0) {
            fprintf(stderr, "%s: bad row: %s", path, line);
            bad++;
            continue;
        }
        double x = strcmp(th, "inf") ? strtod(th, NULL) : INFINITY;
        t->lt[vi][ei][fi] = x > 0.0 && x < 1.0 ? log10(x) : x >= 1.0 ? INFINITY : NAN;
        if (!(x > 0.0)) bad++;
        t->count[vi][ei][fi]++;
        rows++;
    }
    fclose(fp);
    return bad || rows == 0 ? -1 : 0;
}

static int find(const double *axis, int n, double x)
{
    for (int i = 0; i < n; i++)
        if (fabs(axis[i] - x) <= 1e-6 * fmax(1.0, x)) return i;
    return -1;
}

static void check_complete(const char *name, const vtable *t)
{
    int missing = 0, dup = 0;
    for (int v = 0; v < t->nv; v++)
        for (int e = 0; e < t->ne; e++)
            for (int f = 0; f < t->nf; f++) missing += t->count[v][e][f] == 0, dup += t->count[v][e][f] > 1;
    CHECK_MSG(missing == 0 && dup == 0, "%s: %d cells missing, %d duplicated (%d x %d x %d grid)", name,
              missing, dup, t->nf, t->ne, t->nv);
    CHECK_MSG(find(t->v, t->nv, 0) >= 0 && find(t->v, t->nv, 4) >= 0 && find(t->v, t->nv, 12) >= 0,
              "%s: velocities 0, 4 and 12 deg/s must all be in the grid", name);
    for (int i = 0; i < 6; i++)
        CHECK_MSG(find(t->f, t->nf, GRID_F[i]) >= 0, "%s: no %g cpd", name, GRID_F[i]);
    for (int i = 0; i < 4; i++)
        CHECK_MSG(find(t->e, t->ne, GRID_E[i]) >= 0, "%s: no %g deg", name, GRID_E[i]);
}

static void check_static_slice(const char *name, const vtable *t, const vtable *st)
{
    int v0 = find(t->v, t->nv, 0), off = 0;
    for (int e = 0; e < st->ne && v0 >= 0; e++)
        for (int f = 0; f < st->nf; f++) {
            int fi = find(t->f, t->nf, st->f[f]), ei = find(t->e, t->ne, st->e[e]);
            double a = fi >= 0 && ei >= 0 ? t->lt[v0][ei][fi] : NAN, b = st->lt[0][e][f];
            off += !(a == b || fabs(a - b) < 1e-4);
        }
    CHECK_MSG(v0 >= 0 && off == 0, "%s: %d static cells differ from the static person's table", name, off);
}

/* Largest and RMS |person's log ratio - prior's log gain| over the scored cells. */
static void misfit(const vtable *t, const csf_velocity_params *p, double *max_abs, double *rms, double *where)
{
    double mx = 0.0, ss = 0.0;
    int n = 0, v0 = find(t->v, t->nv, 0);
    for (int vi = 0; vi < 2; vi++)
        for (int ei = 0; ei < 4; ei++)
            for (int fi = 0; fi < 6; fi++) {
                double f = GRID_F[fi], v = GRID_V[vi];
                if (f * v >= 60.0) continue; /* cannot be shown at 120 Hz */
                int a = find(t->f, t->nf, f), e = find(t->e, t->ne, GRID_E[ei]), b = find(t->v, t->nv, v);
                double moving = t->lt[b][e][a], still = t->lt[v0][e][a];
                if (!isfinite(moving) || !isfinite(still)) continue;
                double d = (still - moving) - csf_velocity_log10_gain(p, f, v);
                ss += d * d, n++;
                if (fabs(d) > mx)
                    mx = fabs(d), where[0] = f, where[1] = GRID_E[ei], where[2] = v, where[3] = d;
            }
    *max_abs = mx;
    *rms = n ? sqrt(ss / n) : NAN;
}

static void check_not_prior(const char *name, const vtable *t)
{
    csf_velocity_params p = csf_velocity_default();
    double mx, rms, at[4] = {0};
    misfit(t, &p, &mx, &rms, at);
    printf("%-8s published Kelly-Daly: RMS %.3f, max %.3f (%g cpd, %g deg, %g deg/s: person - prior %+.3f)\n",
           name, rms, mx, at[0], at[1], at[2], at[3]);
    CHECK_MSG(mx > 0.1, "%s: within 0.1 log10 of the prior's shape everywhere (max %.3f)", name, mx);
    double best = INFINITY, best_max = NAN, bc[3] = {0};
    for (double c1 = 0.3; c1 <= 1.5; c1 *= 1.15)
        for (double c2 = 0.5; c2 <= 4.0; c2 *= 1.15)
            for (double s = 0.3; s <= 2.0; s += 0.1) {
                csf_velocity_params q = {.c1 = c1, .c2 = c2, .v_min_dps = 0.15, .steepness = s};
                double m2, r2, w2[4];
                misfit(t, &q, &m2, &r2, w2);
                if (r2 < best) best = r2, best_max = m2, bc[0] = c1, bc[1] = c2, bc[2] = s;
            }
    printf("%-8s best knobs c1 %.2f c2 %.2f steepness %.1f: RMS %.3f, max %.3f\n", name, bc[0], bc[1], bc[2],
           best, best_max);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_velocity_data DIR (bench/data)\n");
        return 2;
    }
    static vtable t, st;
    for (int i = 0; i < N_PEOPLE; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/velocity/observer_v_%s.csv", argv[1], PEOPLE[i]);
        int ok = load(path, 4, &t) == 0;
        CHECK_MSG(ok, "%s: unreadable or bad rows", path);
        snprintf(path, sizeof path, "%s/observer_%s.csv", argv[1], PEOPLE[i]);
        int ok_static = load(path, 3, &st) == 0;
        CHECK_MSG(ok_static, "%s: unreadable or bad rows", path);
        if (!ok || !ok_static) continue;
        check_complete(PEOPLE[i], &t);
        check_static_slice(PEOPLE[i], &t, &st);
        check_not_prior(PEOPLE[i], &t);
    }
    return CHECK_RESULT();
}
