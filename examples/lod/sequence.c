#define _POSIX_C_SOURCE 200809L
#include "sequence.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "imgdiff.h"
#include "judge.h"
#include "outfile.h"
#include "pngout.h"

enum { K_STATIC, K_MOVING, K_COARSE, N_KINDS };
static const char *const kind_name[N_KINDS] = {"static", "moving", "coarse"};

/* what the sequence adds up per kind of simplification */
typedef struct {
    long triangles;
    double win_sum; /* peak visibility summed over the frames of the current window */
    int win_n;
    double vis4; /* sum over finished windows of (mean peak visibility)^4 */
    double peak; /* largest over frames */
    lod_judgement judge;
} kind_total;

typedef struct {
    const lod_sequence *q;
    float *vel, *node_lo, *node_hi, *still; /* per node: centre, range over its vertices, zeros */
    float *vel_lo, *vel_hi;                 /* per pixel */
    uint32_t *tri;
    uint8_t *full, *img;
    float *all_vel; /* every frame's vertex velocities, for the median */
    long n_all_vel, full_tri, cull_tri;
    int frames_per_window;
    kind_total kind[N_KINDS];
    FILE *csv;
} seq_state;

static int fail(const char *what)
{
    fprintf(stderr, "lod: %s\n", what);
    return 1;
}

static int draw(seq_state *s, int n_tri, const float mvp[16], uint8_t *rgb, int frame, const char *kind)
{
    const options *o = s->q->o;
    char path[4096], err[512];
    if (lod_render_draw(s->q->r, s->tri, n_tri, mvp, &o->shade, rgb, err, sizeof err) != 0) return fail(err);
    snprintf(path, sizeof path, "%s/frame%03d_%s.png", o->out_dir, frame, kind);
    if (lod_png_write(path, rgb, o->width_px, o->height_px, err, sizeof err) != 0) return fail(err);
    return 0;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static double median_of(float *v, long n)
{
    if (n <= 0) return 0;
    qsort(v, (size_t)n, sizeof *v, cmp_float);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The eye integrates contrast over about 100 ms (Bloch's law; Watson 1986), so frames inside one
 * such window are one look at their mean difference, and separate windows are separate looks,
 * pooled by probability summation (Minkowski, beta 4; Watson 1979). */
#define LOD_INTEGRATION_S 0.1

static void close_window(kind_total *t)
{
    if (t->win_n == 0) return;
    t->vis4 += pow(t->win_sum / t->win_n, 4);
    t->win_sum = 0;
    t->win_n = 0;
}

/* One simplification of frame f: the cut, its render, and its difference from the full frame. */
static int frame_kind(seq_state *s, int f, int k, lod_view *v, const float mvp[16], const double gaze_px[2],
                      int *n_tri, lod_diff *d)
{
    const options *o = s->q->o;
    lod_cut_stats st;
    v->vel_lo_dps = k == K_STATIC ? s->still : s->node_lo;
    v->vel_hi_dps = k == K_STATIC ? s->still : s->node_hi;
    v->threshold_factor = k == K_COARSE ? o->coarse_factor : 1;
    *n_tri = lod_vtree_simplify(s->q->tree, s->q->tab, v, s->tri, &st);
    if (*n_tri < 0) return fail("out of memory");
    if (draw(s, *n_tri, mvp, s->img, f, kind_name[k])) return 1;
    if (lod_image_diff_moving(s->full, s->img, o->width_px, o->height_px, &o->shade, o->ppd, gaze_px,
                              s->q->tab, s->vel_lo, s->vel_hi, d) != 0)
        return fail("out of memory");
    kind_total *t = &s->kind[k];
    t->triangles += *n_tri;
    t->peak = fmax(t->peak, d->peak_visibility);
    t->win_sum += d->peak_visibility;
    if (++t->win_n >= s->frames_per_window) close_window(t);
    return 0;
}

static void frame_velocity_stats(seq_state *s, double *lo, double *med, double *hi)
{
    const lod_vtree *t = s->q->tree;
    long base = s->n_all_vel;
    *lo = INFINITY;
    *hi = 0;
    for (int v = 0; v < t->mesh->n_vert; v++) {
        float x = s->vel[t->leaf_of[v]];
        s->all_vel[s->n_all_vel++] = x;
        *lo = fmin(*lo, x);
        *hi = fmax(*hi, x);
    }
    float *mine = malloc((size_t)(s->n_all_vel - base + 1) * sizeof *mine); /* + 1: never a 0-byte request */
    *med = NAN;
    if (mine) {
        memcpy(mine, s->all_vel + base, (size_t)(s->n_all_vel - base) * sizeof *mine);
        *med = median_of(mine, s->n_all_vel - base);
        free(mine);
    }
}

static int run_frame(seq_state *s, int f)
{
    const lod_sequence *q = s->q;
    const options *o = q->o;
    double t_s = f / o->fps, gaze_px[2], eye_dps, v_lo, v_med, v_hi;
    lod_view v = {.width_px = o->width_px,
                  .height_px = o->height_px,
                  .dist_px = q->screen.dist_px,
                  .distance_factor = 1};
    float mvp[16];
    lod_path_frame(&q->path, t_s, v.view, mvp);
    if (lod_motion_velocities(q->tree, &q->path, &q->screen, t_s, 1 / o->fps, s->vel, gaze_px, &eye_dps) != 0)
        return fail("out of memory");
    lod_vtree_velocity_range(q->tree, s->vel, s->node_lo, s->node_hi);
    v.gaze_px[0] = gaze_px[0];
    v.gaze_px[1] = gaze_px[1];
    if (lod_motion_velocity_map(q->tree, v.view, &q->screen, s->vel, eye_dps, s->vel_lo, s->vel_hi) != 0)
        return fail("out of memory");
    frame_velocity_stats(s, &v_lo, &v_med, &v_hi);
    int n_full = lod_vtree_full(q->tree, s->tri);
    if (draw(s, n_full, mvp, s->full, f, "full")) return 1;
    lod_cut_stats st;
    v.cull_only = 1;
    int n_cull = lod_vtree_simplify(q->tree, q->tab, &v, s->tri, &st);
    v.cull_only = 0;
    if (n_cull < 0) return fail("out of memory");
    s->full_tri += n_full;
    s->cull_tri += n_cull;
    int n[N_KINDS];
    lod_diff d[N_KINDS];
    for (int k = 0; k < N_KINDS; k++)
        if (frame_kind(s, f, k, &v, mvp, gaze_px, &n[k], &d[k])) return 1;
    printf("frame %3d  t %.3f s  retinal %.2f/%.2f/%.2f deg/s (min/median/max)  triangles full %d culled %d  "
           "static %d  moving %d  coarse %d  peak visibility static %.3f moving %.3f (%.3g cpd, %.3g deg) "
           "coarse %.3f\n",
           f, t_s, v_lo, v_med, v_hi, n_full, n_cull, n[K_STATIC], n[K_MOVING], n[K_COARSE],
           d[K_STATIC].peak_visibility, d[K_MOVING].peak_visibility, d[K_MOVING].peak_freq_cpd,
           d[K_MOVING].peak_ecc_deg, d[K_COARSE].peak_visibility);
    fprintf(s->csv, "%d,%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", f, t_s,
            v_lo, v_med, v_hi, eye_dps, gaze_px[0], n_full, n_cull, n[K_STATIC], n[K_MOVING], n[K_COARSE],
            d[K_STATIC].peak_visibility, d[K_MOVING].peak_visibility, d[K_COARSE].peak_visibility,
            d[K_STATIC].rms_contrast, d[K_MOVING].rms_contrast, d[K_COARSE].rms_contrast);
    return 0;
}

/* The finest detail the table lets through at the fovea for a 10 % contrast step (a typical
 * shading change of a fold), static and at the sequence's median retinal velocity: the frequency
 * the simplifier compares each node's with (csflut_max_frequency4). */
static void finest_detail(const csflut_table *tab, double v_dps, double out_cpd[2])
{
    double lum = csflut_default_luminance(tab);
    out_cpd[0] = csflut_max_frequency4(tab, 0, 0, lum, 0.1);
    out_cpd[1] = csflut_max_frequency4(tab, 0, v_dps, lum, 0.1);
}

static void write_json_kinds(FILE *f, const seq_state *s, const lod_judgement *identical)
{
    fprintf(f,
            "  \"judge\": {\n    \"identical\": {\"visibility\": 0, \"dprime\": %.6g, \"trials\": %d, "
            "\"correct\": %d, "
            "\"p_correct\": %.6g, \"p_above_chance\": %.6g},\n",
            identical->dprime, identical->trials, identical->correct, identical->p_correct,
            identical->p_above_chance);
    for (int k = 0; k < N_KINDS; k++) {
        const kind_total *t = &s->kind[k];
        fprintf(
            f,
            "    \"%s\": {\"visibility\": %.6g, \"peak_visibility\": %.6g, \"dprime\": %.6g, \"trials\": %d, "
            "\"correct\": %d, \"p_correct\": %.6g, \"p_above_chance\": %.6g}%s\n",
            kind_name[k], pow(t->vis4, 0.25), t->peak, t->judge.dprime, t->judge.trials, t->judge.correct,
            t->judge.p_correct, t->judge.p_above_chance, k + 1 < N_KINDS ? "," : "");
    }
    fprintf(f, "  }\n");
}

/* a JSON string: quotes, backslashes and control characters escaped */
static void json_str(FILE *f, const char *str)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)str; *c; c++) {
        if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
        else if (*c < 0x20) fprintf(f, "\\u%04x", *c);
        else fputc(*c, f);
    }
    fputc('"', f);
}

static int write_json(const seq_state *s, double v_med, const double fmax_cpd[2],
                      const lod_judgement *identical)
{
    const options *o = s->q->o;
    char err[512];
    lod_outfile f;
    if (lod_outfile_open(&f, o->json_path, err, sizeof err) != 0) return fail(err);
    long st = s->kind[K_STATIC].triangles, mv = s->kind[K_MOVING].triangles;
    fprintf(f.f, "{\n  \"table\": ");
    json_str(f.f, o->table);
    fprintf(
        f.f,
        ",\n  \"table_has_velocity_axis\": %s,\n  \"frames\": %d,\n  \"fps\": %g,\n"
        "  \"object_velocity_dps\": %g,\n  \"spin_dps\": %g,\n  \"eye\": \"%s\",\n  \"coarse_factor\": %g,\n"
        "  \"retinal_velocity_median_dps\": %.6g,\n",
        csflut_axis_size(s->q->tab, CSFLUT_AXIS_VEL) > 0 ? "true" : "false", o->frames, o->fps,
        o->object_velocity_dps, o->spin_dps, o->pursuit ? "pursuit" : "fixate", o->coarse_factor, v_med);
    fprintf(f.f,
            "  \"triangles\": {\"full\": %ld, \"cull_only\": %ld, \"static\": %ld, \"moving\": %ld, "
            "\"coarse\": %ld},\n"
            "  \"triangles_saved_vs_static\": %ld,\n  \"triangles_saved_percent\": %.6g,\n"
            "  \"finest_detail_cpd_at_10pct\": {\"static\": %.6g, \"moving\": %.6g},\n",
            s->full_tri, s->cull_tri, st, mv, s->kind[K_COARSE].triangles, st - mv,
            st ? 100.0 * (st - mv) / st : 0, fmax_cpd[0], fmax_cpd[1]);
    write_json_kinds(f.f, s, identical);
    fprintf(f.f, "}\n");
    if (lod_outfile_close(&f, 1, err, sizeof err) != 0) return fail(err);
    return 0;
}

static int summarise(seq_state *s)
{
    const options *o = s->q->o;
    double v_med = median_of(s->all_vel, s->n_all_vel), fmax_cpd[2];
    for (int k = 0; k < N_KINDS; k++) close_window(&s->kind[k]);
    finest_detail(s->q->tab, v_med, fmax_cpd);
    lod_judgement identical;
    lod_judge_same_different(0, o->judge_trials, o->seed, 0, &identical);
    for (int k = 0; k < N_KINDS; k++)
        lod_judge_same_different(pow(s->kind[k].vis4, 0.25), o->judge_trials, o->seed, (uint64_t)k + 1,
                                 &s->kind[k].judge);
    long st = s->kind[K_STATIC].triangles, mv = s->kind[K_MOVING].triangles;
    printf("triangles over %d frames: full %ld, culling alone %ld, static table %ld, table at the real "
           "velocity %ld, "
           "coarse (thresholds x%g) %ld\n",
           o->frames, s->full_tri, s->cull_tri, st, mv, o->coarse_factor, s->kind[K_COARSE].triangles);
    printf(
        "saved versus the static table: %ld triangles (%.1f %%); median retinal velocity %.3g deg/s (%s)\n",
        st - mv, st ? 100.0 * (st - mv) / st : 0.0, v_med, o->pursuit ? "smooth pursuit" : "fixation");
    printf("finest detail visible at the fovea at 10 %% contrast: %.3g cpd static, %.3g cpd at %.3g deg/s\n",
           fmax_cpd[0], fmax_cpd[1], v_med);
    printf("judge identical: visibility 0      d' %.3f  correct %3d/%d (%.3f)  p(above chance) %.3g\n",
           identical.dprime, identical.correct, identical.trials, identical.p_correct,
           identical.p_above_chance);
    for (int k = 0; k < N_KINDS; k++) {
        const kind_total *t = &s->kind[k];
        printf("judge %-9s visibility %-6.3f d' %.3f  correct %3d/%d (%.3f)  p(above chance) %.3g\n",
               kind_name[k], pow(t->vis4, 0.25), t->judge.dprime, t->judge.correct, t->judge.trials,
               t->judge.p_correct, t->judge.p_above_chance);
    }
    return o->json_path ? write_json(s, v_med, fmax_cpd, &identical) : 0;
}

int lod_run_sequence(const lod_sequence *q)
{
    const options *o = q->o;
    size_t npx = (size_t)o->width_px * o->height_px, nn = (size_t)q->tree->n_node;
    seq_state s = {.q = q, .frames_per_window = (int)fmax(1, lround(LOD_INTEGRATION_S * o->fps))};
    s.vel = malloc(nn * sizeof *s.vel);
    s.still = calloc(nn, sizeof *s.still);
    s.node_lo = malloc(nn * sizeof *s.node_lo);
    s.node_hi = malloc(nn * sizeof *s.node_hi);
    s.vel_lo = malloc(npx * sizeof *s.vel_lo);
    s.vel_hi = malloc(npx * sizeof *s.vel_hi);
    s.tri = malloc((size_t)q->tree->mesh->n_tri * 3 * sizeof *s.tri);
    s.full = malloc(npx * 3);
    s.img = malloc(npx * 3);
    s.all_vel = malloc((size_t)o->frames * (size_t)q->tree->mesh->n_vert * sizeof *s.all_vel);
    char path[4096], err[512];
    lod_outfile csv = {0};
    int rc = 1;
    if (!s.vel || !s.still || !s.node_lo || !s.node_hi || !s.vel_lo || !s.vel_hi || !s.tri || !s.full ||
        !s.img || !s.all_vel) {
        fail("out of memory");
        goto done;
    }
    snprintf(path, sizeof path, "%s/motion_summary.csv", o->out_dir);
    if (lod_outfile_open(&csv, path, err, sizeof err) != 0) {
        fail(err);
        goto done;
    }
    s.csv = csv.f;
    fprintf(s.csv,
            "frame,t_s,retinal_min_dps,retinal_median_dps,retinal_max_dps,eye_dps,gaze_x_px,triangles_full,"
            "triangles_cull_only,triangles_static,triangles_moving,triangles_coarse,peak_visibility_static,"
            "peak_visibility_moving,peak_visibility_coarse,rms_contrast_static,rms_contrast_moving,"
            "rms_contrast_coarse\n");
    rc = 0;
    for (int f = 0; f < o->frames && rc == 0; f++) rc = run_frame(&s, f);
    if (rc == 0) rc = summarise(&s);
done:
    if (csv.f && lod_outfile_close(&csv, rc == 0, err, sizeof err) != 0 && rc == 0) rc = fail(err);
    free(s.vel);
    free(s.still);
    free(s.node_lo);
    free(s.node_hi);
    free(s.vel_lo);
    free(s.vel_hi);
    free(s.tri);
    free(s.full);
    free(s.img);
    free(s.all_vel);
    return rc;
}
