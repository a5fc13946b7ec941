/* Matched-filter measurement of what is on screen at a place (see observer_view.h). */
#include "model/observer_view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct csf_view_place {
    int n_px;
    int *idx;        /* used pixels */
    float *bc, *bs;  /* E cos, E sin at each used pixel */
    int n_used;
    double minv[3][3]; /* inverse of the normal matrix of (1, E cos, E sin) */
    double acc[3];     /* sum over frames of sum_i L_i * basis_k(i) */
    int frames;
};

csf_status csf_view_display_init(csf_view_display *d, csf_view_lum_fn lum, void *ctx, int maxlevel,
                                 csf_error *err)
{
    memset(d, 0, sizeof *d);
    if (!lum || maxlevel < 1 || maxlevel > 65535)
        return csf_error_set(err, CSF_E_INVALID_ARG, "view display: no luminance function or max level %d "
                             "outside 1 to 65535", maxlevel);
    d->grey_cdm2 = malloc(sizeof(double) * (size_t)(maxlevel + 1));
    if (!d->grey_cdm2) return csf_error_set(err, CSF_E_NOMEM, "view display: out of memory");
    d->lum = lum;
    d->ctx = ctx;
    d->maxlevel = maxlevel;
    for (int k = 0; k <= maxlevel; k++) {
        double v = (double)k / maxlevel;
        d->grey_cdm2[k] = lum(ctx, v, v, v);
    }
    return CSF_OK;
}

void csf_view_display_free(csf_view_display *d)
{
    if (!d) return;
    free(d->grey_cdm2);
    d->grey_cdm2 = NULL;
}

double csf_view_display_pixel(const csf_view_display *d, const uint16_t rgb[3])
{
    int m = d->maxlevel;
    int r = rgb[0] > m ? m : rgb[0], g = rgb[1] > m ? m : rgb[1], b = rgb[2] > m ? m : rgb[2];
    if (r == g && g == b) return d->grey_cdm2[r];
    return d->lum(d->ctx, (double)r / m, (double)g / m, (double)b / m);
}

/* Inverse of a symmetric 3x3 matrix by cofactors; 0 when it is (numerically) singular. */
static int invert3(const double a[3][3], double out[3][3])
{
    double c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    double c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    double c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    double det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    double scale = fabs(a[0][0] * a[1][1] * a[2][2]);
    if (!(fabs(det) > 1e-12 * scale) || !isfinite(det)) return 0;
    out[0][0] = c00 / det;
    out[1][0] = c01 / det;
    out[2][0] = c02 / det;
    out[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
    out[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
    out[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
    out[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
    out[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
    out[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
    return 1;
}

csf_status csf_view_place_create(const float *u_deg, const float *v_deg, const unsigned char *use,
                                 int n_px, double freq_cpd, double orientation_deg, double sigma_deg,
                                 csf_view_place **out, csf_error *err)
{
    *out = NULL;
    if (!u_deg || !v_deg || n_px <= 0 || n_px > (1 << 24))
        return csf_error_set(err, CSF_E_INVALID_ARG, "view place: %d pixels (1 to %d)", n_px, 1 << 24);
    if (!(freq_cpd > 0 && freq_cpd <= 1000) || !(sigma_deg >= 0.02 && sigma_deg <= 30) ||
        !isfinite(orientation_deg))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "view place: frequency %g cpd (0 to 1000) / sigma %g deg (0.02 to 30) / "
                             "orientation %g deg out of range", freq_cpd, sigma_deg, orientation_deg);
    csf_view_place *pl = calloc(1, sizeof *pl);
    if (pl) {
        pl->idx = malloc(sizeof(int) * (size_t)n_px);
        pl->bc = malloc(sizeof(float) * (size_t)n_px);
        pl->bs = malloc(sizeof(float) * (size_t)n_px);
    }
    if (!pl || !pl->idx || !pl->bc || !pl->bs) {
        csf_view_place_free(pl);
        return csf_error_set(err, CSF_E_NOMEM, "view place: out of memory");
    }
    pl->n_px = n_px;
    double co = cos(orientation_deg * M_PI / 180), si = sin(orientation_deg * M_PI / 180);
    double m[3][3] = {{0}};
    for (int i = 0; i < n_px; i++) {
        double u = u_deg[i], v = v_deg[i];
        if (!isfinite(u) || !isfinite(v)) {
            csf_view_place_free(pl);
            return csf_error_set(err, CSF_E_INVALID_ARG, "view place: pixel %d has no finite angle", i);
        }
        if (use && !use[i]) continue;
        double e = exp(-(u * u + v * v) / (2 * sigma_deg * sigma_deg));
        double ph = 2 * M_PI * freq_cpd * (u * co + v * si);
        double b[3] = {1.0, e * cos(ph), e * sin(ph)};
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) m[r][c] += b[r] * b[c];
        pl->idx[pl->n_used] = i;
        pl->bc[pl->n_used] = (float)b[1];
        pl->bs[pl->n_used] = (float)b[2];
        pl->n_used++;
    }
    if (pl->n_used < 16 || !invert3(m, pl->minv)) {
        int n = pl->n_used;
        csf_view_place_free(pl);
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "view place: %d usable pixels cannot separate a %g cpd Gabor from the "
                             "mean (at least 16 and a non-singular fit needed)", n, freq_cpd);
    }
    *out = pl;
    return CSF_OK;
}

void csf_view_place_free(csf_view_place *pl)
{
    if (!pl) return;
    free(pl->idx);
    free(pl->bc);
    free(pl->bs);
    free(pl);
}

void csf_view_place_reset(csf_view_place *pl)
{
    pl->acc[0] = pl->acc[1] = pl->acc[2] = 0;
    pl->frames = 0;
}

void csf_view_place_add_frame(csf_view_place *pl, const csf_view_display *d, const uint16_t *rgb)
{
    double s0 = 0, s1 = 0, s2 = 0;
    for (int j = 0; j < pl->n_used; j++) {
        double L = csf_view_display_pixel(d, rgb + 3 * (size_t)pl->idx[j]);
        s0 += L;
        s1 += L * pl->bc[j];
        s2 += L * pl->bs[j];
    }
    pl->acc[0] += s0;
    pl->acc[1] += s1;
    pl->acc[2] += s2;
    pl->frames++;
}

int csf_view_place_frames(const csf_view_place *pl) { return pl->frames; }

double csf_view_place_contrast(const csf_view_place *pl, double *mean_cdm2)
{
    if (mean_cdm2) *mean_cdm2 = 0;
    if (pl->frames == 0) return 0.0;
    double y[3], c[3];
    for (int k = 0; k < 3; k++) y[k] = pl->acc[k] / pl->frames;
    for (int r = 0; r < 3; r++) c[r] = pl->minv[r][0] * y[0] + pl->minv[r][1] * y[1] + pl->minv[r][2] * y[2];
    if (mean_cdm2) *mean_cdm2 = c[0];
    if (!(c[0] > 0)) return 0.0; /* a black field: no contrast to speak of */
    return hypot(c[1], c[2]) / c[0];
}
