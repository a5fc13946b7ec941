/* Place marks (csf_presenter_set_marks) read back through a simulated LCD: the ring of every mark
 * is dark (0.7 x the mean, through the display model) all the way round at the expected pixels
 * (exact visual angle: csf_geometry_move + csf_geometry_deg_to_px), every dark pixel lies on some
 * ring, the place centres and the field between rings stay at the mean, the rings stay on a
 * stimulus frame, clearing removes them, a bookkeeping-only presenter accepts them, and bad input
 * is refused with the limit in the message (and leaves the marks as they were). */
#include <math.h>
#include <string.h>

#include "stim_test.h"
#include "tests/check.h"

#define NF 8          /* frames averaged (temporal dither) */
#define RADIUS 3.0    /* ring radius, deg (3 sigma of the session's Gabor) */
#define NM 6

static const double mark_ecc[NM] = {8, 8, 8, 8, 18, 0};
static const double mark_polar[NM] = {30, 150, 210, 330, 0, 0};

typedef struct {
    csf_presenter *p;
    const csf_display_model *model;
    const csf_geometry *g;
    int rw, rh;
    uint16_t *lv;
    double *lum; /* frame-averaged luminance, cd/m2, top row first */
} ctx;

/* Draws NF frames (blank, or the stimulus) and averages the read-back luminance per pixel. */
static void draw_avg(ctx *c, const csf_stimulus *s)
{
    csf_error e;
    size_t n = (size_t)c->rw * c->rh;
    memset(c->lum, 0, sizeof(double) * n);
    for (int f = 0; f < NF; f++) {
        csf_frame_info fi;
        CHECK_MSG(csf_presenter_draw(c->p, s, 0, &fi, &e) == CSF_OK, "%s", e.msg);
        CHECK_INT_EQ(fi.rendered, 1);
        CHECK_INT_EQ(csf_presenter_readback_levels(c->p, c->lv, &e), CSF_OK);
        for (size_t i = 0; i < n; i++) {
            const uint16_t *px = c->lv + 3 * i;
            c->lum[i] += csf_display_model_lum(c->model, px[0] / 255.0, px[1] / 255.0, px[2] / 255.0) / NF;
        }
    }
}

/* Render pixel (column, row from the top) of the direction (ecc, polar). */
static int to_pixel(const ctx *c, double ecc, double polar, int *col, int *row)
{
    double x, y;
    if (!csf_geometry_deg_to_px(c->g, ecc, polar, &x, &y)) return 0;
    *col = (int)floor(x * c->rw / c->g->width_px);
    *row = (int)floor(y * c->rh / c->g->height_px);
    return *col >= 0 && *col < c->rw && *row >= 0 && *row < c->rh;
}

static double lum_at(const ctx *c, int col, int row) { return c->lum[(size_t)row * c->rw + col]; }

/* The point at angular distance dist from mark m's centre, in direction dir (deg). */
static int mark_point(const ctx *c, int m, double dir, double dist, int *col, int *row)
{
    double e2, p2;
    csf_geometry_move(c->g, mark_ecc[m], mark_polar[m], dir, dist, &e2, &p2);
    return to_pixel(c, e2, p2, col, row);
}

/* Every ring: the pixel under each of 72 points on it is darker than 0.9 x mean, and the darkest
 * pixel of its 3x3 neighbourhood is at the mark luminance (0.7 x mean, within 4 %). Returns the
 * number of points checked. */
static int check_rings(const ctx *c, int n_marks, double mean, const char *what)
{
    int checked = 0;
    double sum_min = 0;
    for (int m = 0; m < n_marks; m++) {
        for (int k = 0; k < 72; k++) {
            int col, row;
            if (!mark_point(c, m, 5.0 * k, RADIUS, &col, &row)) continue;
            double here = lum_at(c, col, row), lo = here;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int x = col + dx, y = row + dy;
                    if (x >= 0 && x < c->rw && y >= 0 && y < c->rh && lum_at(c, x, y) < lo) lo = lum_at(c, x, y);
                }
            CHECK_MSG(here < 0.9 * mean, "%s: mark %d, ring point at %g deg (px %d,%d): %.4g cd/m2, "
                      "mean %.4g: not darker", what, m, 5.0 * k, col, row, here, mean);
            CHECK_MSG(fabs(lo / (CSF_MARK_LUM_FRACTION * mean) - 1) < 0.04,
                      "%s: mark %d, ring at %g deg: darkest %.4g cd/m2, expected %.4g", what, m,
                      5.0 * k, lo, CSF_MARK_LUM_FRACTION * mean);
            sum_min += lo;
            checked++;
        }
    }
    if (checked)
        printf("%s: %d ring points, mean ring luminance %.4f cd/m2 (expected %.4f, field %.4f)\n",
               what, checked, sum_min / checked, CSF_MARK_LUM_FRACTION * mean, mean);
    return checked;
}

/* Pixel at (ecc, polar) is at the mean (within 3 %: one 8-bit step and the dither). */
static void check_mean_at(const ctx *c, double ecc, double polar, double mean, const char *what)
{
    int col, row;
    if (!to_pixel(c, ecc, polar, &col, &row)) {
        CHECK_MSG(0, "%s: (%g, %g) is off the render", what, ecc, polar);
        return;
    }
    double l = lum_at(c, col, row);
    CHECK_MSG(fabs(l / mean - 1) < 0.03, "%s at ecc %g polar %g (px %d,%d): %.4g cd/m2, mean %.4g",
              what, ecc, polar, col, row, l, mean);
}

/* Every pixel darker than 0.9 x mean lies within the line's half-width plus 0.8 pixel of some
 * ring (exact angular distance from the mark centres, csf_geometry_local_uv). */
static void check_dark_only_on_rings(const ctx *c, int n_marks, double mean)
{
    int dark = 0, stray = 0;
    for (int row = 0; row < c->rh; row++)
        for (int col = 0; col < c->rw; col++) {
            if (lum_at(c, col, row) >= 0.9 * mean) continue;
            dark++;
            double px = (col + 0.5) * c->g->width_px / c->rw, py = (row + 0.5) * c->g->height_px / c->rh;
            double x, y, ecc, polar, rad, tan_;
            csf_geometry_px_to_mm(c->g, px, py, &x, &y);
            csf_geometry_mm_to_deg(c->g, x, y, &ecc, &polar);
            csf_geometry_px_per_deg(c->g, ecc, polar, &rad, &tan_);
            double pxdeg = (double)c->g->width_px / c->rw / fmin(rad, tan_); /* render px, deg */
            double best = INFINITY;
            for (int m = 0; m < n_marks; m++) {
                double u, v;
                csf_geometry_local_uv(c->g, mark_ecc[m], mark_polar[m], x, y, &u, &v);
                best = fmin(best, fabs(hypot(u, v) - RADIUS));
            }
            if (best > fmax(0.5 * CSF_MARK_WIDTH_DEG, pxdeg) + 0.8 * pxdeg) {
                if (stray < 5)
                    printf("stray dark pixel %d,%d: %.4g cd/m2, %.3f deg from the nearest ring\n", col,
                           row, lum_at(c, col, row), best);
                stray++;
            }
        }
    CHECK_MSG(dark > 100, "only %d dark pixels", dark);
    CHECK_MSG(stray == 0, "%d of %d dark pixels are not on a ring", stray, dark);
    printf("%d dark pixels, all on the rings\n", dark);
}

int main(void)
{
    csf_display_model *model = stim_test_model("lcd");
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg); /* 531 x 299 mm, 1920 x 1080, 570 mm */
    cfg.grey_lum_fn = stim_test_model_grey;
    cfg.grey_lum_ctx = model;
    cfg.render_width_px = 480; /* a quarter of the screen's pixels each way: ~9 px per degree */
    cfg.render_height_px = 270;
    csf_presenter *p = stim_test_open(&cfg);
    ctx c = {p, model, csf_presenter_geometry(p), 0, 0, NULL, NULL};
    csf_presenter_render_size(p, &c.rw, &c.rh);
    c.lv = malloc(sizeof(uint16_t) * 3 * (size_t)c.rw * c.rh);
    c.lum = malloc(sizeof(double) * (size_t)c.rw * c.rh);
    double black, max;
    csf_presenter_lum_range(p, &black, &max);
    double mean = 0.5 * (black + max); /* a blank frame's mean */
    csf_error e;

    /* no marks: nothing dark anywhere */
    CHECK_INT_EQ(csf_presenter_mark_count(p), 0);
    draw_avg(&c, NULL);
    int dark0 = 0;
    for (int i = 0; i < c.rw * c.rh; i++) dark0 += c.lum[i] < 0.9 * mean;
    CHECK_INT_EQ(dark0, 0);

    /* four places on the 8 deg ring (as a four-place trial), one at 18 deg (the ring is then
     * elongated radially on the screen: checked in visual angle), one around fixation */
    CHECK_MSG(csf_presenter_set_marks(p, NM, mark_ecc, mark_polar, RADIUS, &e) == CSF_OK, "%s", e.msg);
    CHECK_INT_EQ(csf_presenter_mark_count(p), NM);
    draw_avg(&c, NULL);
    CHECK_MSG(check_rings(&c, NM, mean, "blank frame") > 6 * 60, "too few ring points on the render");
    check_dark_only_on_rings(&c, NM, mean);
    for (int m = 0; m < NM; m++) {
        check_mean_at(&c, mark_ecc[m], mark_polar[m], mean, "place centre");
        for (int k = 0; k < 8; k++) {
            int col, row;
            double e2, p2;
            csf_geometry_move(c.g, mark_ecc[m], mark_polar[m], 45.0 * k, 0.5 * RADIUS, &e2, &p2);
            if (to_pixel(&c, e2, p2, &col, &row)) check_mean_at(&c, e2, p2, mean, "inside the ring");
        }
    }
    /* between the rings: on the 8 deg ring between neighbouring places, and farther out */
    check_mean_at(&c, 8, 0, mean, "between places 0 and 3");
    check_mean_at(&c, 8, 180, mean, "between places 1 and 2");
    check_mean_at(&c, 13, 45, mean, "outside the rings");

    /* a stimulus frame keeps the rings (a Gabor at place 0, its envelope 1 % at the ring) */
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = 2;
    s.sigma_deg = 0.75;
    s.ecc_deg = mark_ecc[0];
    s.polar_deg = mark_polar[0];
    s.contrast = 0.1;
    draw_avg(&c, &s);
    check_rings(&c, NM, mean, "stimulus frame");
    {
        int col, row;
        CHECK(to_pixel(&c, s.ecc_deg, s.polar_deg, &col, &row));
        /* phase 0: the carrier's peak is at the centre */
        CHECK_MSG(lum_at(&c, col, row) > 1.05 * mean, "Gabor centre %.4g, mean %.4g", lum_at(&c, col, row), mean);
    }

    /* clearing removes them from the next frame */
    CHECK_INT_EQ(csf_presenter_set_marks(p, 0, NULL, NULL, 0, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_mark_count(p), 0);
    draw_avg(&c, NULL);
    dark0 = 0;
    for (int i = 0; i < c.rw * c.rh; i++) dark0 += c.lum[i] < 0.9 * mean;
    CHECK_MSG(dark0 == 0, "%d dark pixels after clearing", dark0);
    for (int m = 0; m < NM; m++)
        for (int k = 0; k < 72; k += 9) {
            int col, row;
            if (mark_point(&c, m, 5.0 * k, RADIUS, &col, &row))
                CHECK_MSG(fabs(lum_at(&c, col, row) / mean - 1) < 0.03, "cleared ring %d still at %.4g",
                          m, lum_at(&c, col, row));
        }

    /* refusals: message names the limit; the marks set before stay */
    double ok_e[2] = {8, 8}, ok_p[2] = {30, 150};
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, RADIUS, &e), CSF_OK);
    double many_e[CSF_PRESENTER_MAX_MARKS + 1], many_p[CSF_PRESENTER_MAX_MARKS + 1];
    for (int i = 0; i <= CSF_PRESENTER_MAX_MARKS; i++) many_e[i] = 5, many_p[i] = 40.0 * i;
    CHECK_INT_EQ(csf_presenter_set_marks(p, CSF_PRESENTER_MAX_MARKS + 1, many_e, many_p, 1, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "0 to 8");
    CHECK_STR_CONTAINS(e.msg, "9 marks");
    CHECK_INT_EQ(csf_presenter_set_marks(p, CSF_PRESENTER_MAX_MARKS, many_e, many_p, 1, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_mark_count(p), CSF_PRESENTER_MAX_MARKS);
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, RADIUS, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_set_marks(p, -1, ok_e, ok_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "0 to 8");
    double nan_e[2] = {8, NAN};
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, nan_e, ok_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "place mark 1");
    CHECK_STR_CONTAINS(e.msg, "finite");
    double inf_p[2] = {30, INFINITY};
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, inf_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "finite");
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, -1.0, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "outside (0, 30] deg");
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, 0.0, &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, NAN, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "outside (0, 30] deg");
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, ok_e, ok_p, 31.0, &e), CSF_E_INVALID_ARG);
    double neg_e[2] = {-1, 8}, far_e[2] = {8, 95}, off_e[2] = {8, 40}, off_p[2] = {30, 90};
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, neg_e, ok_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "outside 0 to 90 deg");
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, far_e, ok_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "outside 0 to 90 deg");
    /* the screen is ~29.4 deg tall at 570 mm: 40 deg straight up is off it */
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, off_e, off_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "off-screen");
    CHECK_STR_CONTAINS(e.msg, "screen reaches");
    CHECK_INT_EQ(csf_presenter_set_marks(p, 2, NULL, ok_p, RADIUS, &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_presenter_set_marks(NULL, 0, NULL, NULL, 0, &e), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_presenter_mark_count(p), 2); /* every refusal left the two marks */
    CHECK_INT_EQ(csf_presenter_set_marks(p, 0, NULL, NULL, NAN, &e), CSF_OK); /* clearing ignores the rest */
    CHECK_INT_EQ(csf_presenter_mark_count(p), 0);

    free(c.lv);
    free(c.lum);
    csf_presenter_close(p);

    /* bookkeeping only (render_every = -1): marks are state, frames still counted */
    csf_presenter_config bk;
    csf_presenter_config_defaults(&bk);
    bk.render_width_px = 64;
    bk.render_height_px = 36;
    bk.render_every = -1;
    csf_presenter *q = stim_test_open(&bk);
    CHECK_MSG(csf_presenter_set_marks(q, 4, mark_ecc, mark_polar, RADIUS, &e) == CSF_OK, "%s", e.msg);
    for (int f = 0; f < 3; f++) {
        csf_frame_info fi;
        CHECK_INT_EQ(csf_presenter_draw(q, NULL, 1, &fi, &e), CSF_OK);
        CHECK_INT_EQ(fi.rendered, 0);
        CHECK_INT_EQ((int)fi.frame_index, f);
    }
    CHECK_INT_EQ(csf_presenter_set_marks(q, 0, NULL, NULL, 0, &e), CSF_OK);
    CHECK_INT_EQ(csf_presenter_mark_count(q), 0);
    csf_presenter_close(q);
    csf_display_model_free(model);
    return CHECK_RESULT();
}
