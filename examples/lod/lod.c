/* lod: perceptually driven simplification of a mesh with a csfcal threshold table, the way a
 * renderer would use one (Luebke & Hallen 2001), rendered offscreen to PNG pairs for a
 * same/different study. Uses nothing of csfcal but the csflut library (pkg-config csflut).
 * README.md in this folder describes the model, the options and the output files. */
#define _POSIX_C_SOURCE 200809L
#include <csflut.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "imgdiff.h"
#include "lod_args.h"
#include "mesh.h"
#include "motion.h"
#include "outfile.h"
#include "pngout.h"
#include "render.h"
#include "sequence.h"
#include "vtree.h"

/* The camera of view i: around the model at evenly spaced azimuths, elevation alternating +-25
 * deg, at the distance where the model's bounding sphere spans object_deg. */
static void camera(const options *o, int i, double radius, double dist_px, float view[16], float mvp[16])
{
    double az = 2 * LOD_PI * i / o->views + 0.3, el = (i % 2 ? -25 : 25) * LOD_PI / 180;
    double d = radius / sin(0.5 * o->object_deg * LOD_PI / 180);
    double eye[3] = {d * cos(el) * sin(az), d * sin(el), d * cos(el) * cos(az)};
    double f[3] = {-eye[0] / d, -eye[1] / d, -eye[2] / d}, up[3] = {0, 1, 0};
    double s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
    double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int k = 0; k < 3; k++) s[k] /= sl;
    double u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
    memset(view, 0, 16 * sizeof *view);
    for (int k = 0; k < 3; k++) {
        view[k * 4 + 0] = (float)s[k];
        view[k * 4 + 1] = (float)u[k];
        view[k * 4 + 2] = (float)-f[k];
    }
    view[12] = (float)-(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    view[13] = (float)-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    view[14] = (float)(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
    view[15] = 1;
    /* the frustum the viewer sees: the image plane dist_px pixels from the eye */
    double n = d - 1.5 * radius, fa = d + 1.5 * radius;
    float proj[16] = {0};
    proj[0] = (float)(2 * dist_px / o->width_px);
    proj[5] = (float)(2 * dist_px / o->height_px);
    proj[10] = (float)(-(fa + n) / (fa - n));
    proj[11] = -1;
    proj[14] = (float)(-2 * fa * n / (fa - n));
    lod_mat_mul(proj, view, mvp);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

typedef struct {
    const options *o;
    const lod_mesh *mesh;
    const lod_vtree *tree;
    const csflut_table *tab;
    lod_renderer *r;
    uint32_t *tri;
    uint8_t *full, *img;
    FILE *summary, *conditions; /* the .f of the two outfiles */
    double dist_px, image_deg, model_radius;
} run_ctx;

static int render_to(run_ctx *c, int n_tri, const float mvp[16], uint8_t *rgb, const char *name, double *ms)
{
    char path[4096], err[512];
    double t0 = now_ms();
    if (lod_render_draw(c->r, c->tri, n_tri, mvp, &c->o->shade, rgb, err, sizeof err) != 0) {
        fprintf(stderr, "lod: %s\n", err);
        return 1;
    }
    *ms = now_ms() - t0;
    snprintf(path, sizeof path, "%s/%s", c->o->out_dir, name);
    if (lod_png_write(path, rgb, c->o->width_px, c->o->height_px, err, sizeof err) != 0) {
        fprintf(stderr, "lod: %s\n", err);
        return 1;
    }
    return 0;
}

/* |full - simplified| x 8 on black, for looking at where a simplification changed the image */
static int write_diff(run_ctx *c, const char *name)
{
    size_t n = (size_t)c->o->width_px * c->o->height_px * 3;
    uint8_t *d = malloc(n);
    char path[4096], err[512];
    if (!d) { fprintf(stderr, "lod: out of memory\n"); return 1; }
    for (size_t i = 0; i < n; i++) {
        int v = 8 * abs((int)c->full[i] - (int)c->img[i]);
        d[i] = (uint8_t)(v > 255 ? 255 : v);
    }
    snprintf(path, sizeof path, "%s/diff_%s", c->o->out_dir, name);
    int rc = lod_png_write(path, d, c->o->width_px, c->o->height_px, err, sizeof err);
    if (rc) fprintf(stderr, "lod: %s\n", err);
    free(d);
    return rc ? 1 : 0;
}

static int run_view(run_ctx *c, int vi)
{
    const options *o = c->o;
    lod_view v = {.width_px = o->width_px, .height_px = o->height_px, .dist_px = c->dist_px,
                  .gaze_px = {o->gaze_px[0], o->gaze_px[1]}};
    float mvp[16];
    camera(o, vi, c->model_radius, c->dist_px, v.view, mvp);
    char name[64], full_name[64];
    double render_ms;
    int n_full = lod_vtree_full(c->tree, c->tri);
    snprintf(full_name, sizeof full_name, "view%d_full.png", vi);
    if (render_to(c, n_full, mvp, c->full, full_name, &render_ms)) return 1;
    lod_cut_stats st;
    v.distance_factor = v.threshold_factor = 1;
    v.cull_only = 1;
    int n_cull = lod_vtree_simplify(c->tree, c->tab, &v, c->tri, &st);
    v.cull_only = 0;
    if (n_cull < 0) { fprintf(stderr, "lod: out of memory\n"); return 1; }
    printf("view %d  %-6s %7d triangles; %d without what is off screen or faces away; render %.1f ms\n", vi,
           "full", n_full, n_cull, render_ms);
    fprintf(c->summary, "%d,%s,,,,%d,%d,%d,0,0,0,0,0,,,\n", vi, full_name, n_full, n_full, n_cull);
    fprintf(c->conditions, "view%d_identical,image,0,%s,%s,%.4g,identical\n", vi, full_name, full_name, c->image_deg);
    for (int li = 0; li < o->n_levels; li++) {
        const level *l = &o->levels[li];
        v.distance_factor = l->distance_factor;
        v.threshold_factor = l->threshold_factor;
        double t0 = now_ms();
        int n = lod_vtree_simplify(c->tree, c->tab, &v, c->tri, &st);
        double simplify_ms = now_ms() - t0;
        if (n < 0) { fprintf(stderr, "lod: out of memory\n"); return 1; }
        snprintf(name, sizeof name, "view%d_%s.png", vi, l->name);
        if (render_to(c, n, mvp, c->img, name, &render_ms)) return 1;
        if (o->diff_images && write_diff(c, name)) return 1;
        lod_diff d;
        if (lod_image_diff(c->full, c->img, o->width_px, o->height_px, &o->shade, o->ppd, o->gaze_px, c->tab, &d) != 0) {
            fprintf(stderr, "lod: out of memory\n");
            return 1;
        }
        printf("view %d  %-6s %7d triangles (%5.1f %% of full, %5.1f %% of culled)  rms %.4f  max %.4f  peak visibility %6.3f "
               "(%.3g cpd, %.3g deg)  pooled %7.3f  simplify %5.1f ms  render %6.1f ms\n",
               vi, l->name, n, 100.0 * n / n_full, 100.0 * n / n_cull, d.rms_contrast, d.max_contrast, d.peak_visibility,
               d.peak_freq_cpd, d.peak_ecc_deg, d.pooled_visibility, simplify_ms, render_ms);
        fprintf(c->summary, "%d,%s,%s,%g,%g,%d,%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.2f\n", vi, name, full_name,
                l->distance_factor, l->threshold_factor, n_full, n, n_cull, d.changed_pixels, d.rms_contrast,
                d.max_contrast, d.peak_visibility, d.pooled_visibility, d.peak_freq_cpd, d.peak_ecc_deg,
                simplify_ms);
        fprintf(c->conditions, "view%d_%s,image,0,%s,%s,%.4g,%s\n", vi, l->name, full_name, name, c->image_deg,
                l->distance_factor == 1 && l->threshold_factor == 1 ? "imperceptible" : l->name);
    }
    return 0;
}

/* A same/different study over the pairs, after Luebke & Hallen (2001) section 6.2, in the format
 * of csfcal study (docs/studies.md): 1 s presentations 500 ms apart, fixation, 20 practice trials,
 * about 200 trials. With the default factors each view has four conditions (identical,
 * imperceptible, two deliberately perceptible), so equal trials per condition give the paper's
 * mix: 25 % identical, 25 % imperceptible, 50 % perceptible. */
static int write_study(const options *o)
{
    char path[4096], err[512];
    lod_outfile f;
    snprintf(path, sizeof path, "%s/study.conf", o->out_dir);
    if (lod_outfile_open(&f, path, err, sizeof err) != 0) { fprintf(stderr, "lod: %s\n", err); return 1; }
    int conditions = o->views * (o->n_levels + 1);
    int per = 2 * (int)lround(100.0 / conditions);
    per = per < 2 ? 2 : per;
    fprintf(f.f, "# written by examples/lod: same/different judgements of full vs simplified renders\n"
                 "# (Luebke & Hallen 2001, sec. 6.2); %d conditions x %d trials\n"
                 "name = lod_same_different\ndesign = same_different\nconditions = conditions.csv\n"
                 "trials_per_condition = %d\nblocks = 1\npractice_trials = 20\nfixation_s = 0.5\n"
                 "stimulus_s = 1.0\nisi_s = 0.5\niti_s = 0.5\nsame_fraction = 0.5\nsd_model = differencing\n"
                 "feedback = no\nseed = 2001\n", conditions, per, per);
    if (lod_outfile_close(&f, 1, err, sizeof err) != 0) { fprintf(stderr, "lod: %s\n", err); return 1; }
    return 0;
}

static int open_out(const options *o, const char *name, lod_outfile *f)
{
    char path[4096], err[512];
    snprintf(path, sizeof path, "%s/%s", o->out_dir, name);
    if (lod_outfile_open(f, path, err, sizeof err) == 0) return 0;
    fprintf(stderr, "lod: %s\n", err);
    return -1;
}

static int close_out(lod_outfile *f, int ok)
{
    char err[512];
    if (!f->f) return ok ? 0 : 1;
    if (lod_outfile_close(f, ok, err, sizeof err) == 0) return 0;
    if (ok) fprintf(stderr, "lod: %s\n", err);
    return 1;
}

/* The moving sequence: view 0's camera, the object crossing the screen through its centre. */
static int run_sequence(const run_ctx *c)
{
    const options *o = c->o;
    lod_sequence q = {.o = o,
                      .tree = c->tree,
                      .tab = c->tab,
                      .r = c->r,
                      .path = {.object_dist = c->model_radius / sin(0.5 * o->object_deg * LOD_PI / 180),
                               .velocity_dps = o->object_velocity_dps,
                               .spin_dps = o->spin_dps,
                               .t_mid_s = 0.5 * (o->frames - 1) / o->fps,
                               .pursuit = o->pursuit},
                      .screen = {.width_px = o->width_px,
                                 .height_px = o->height_px,
                                 .dist_px = c->dist_px,
                                 .fixation_px = {o->gaze_px[0], o->gaze_px[1]}}};
    camera(o, 0, c->model_radius, c->dist_px, q.path.view, q.path.mvp);
    printf("sequence: %d frames at %g Hz, the object crossing at %g deg/s and turning at %g deg/s, eye %s; "
           "the table "
           "%s\n",
           o->frames, o->fps, o->object_velocity_dps, o->spin_dps,
           o->pursuit ? "in smooth pursuit (Daly 1998)" : "fixating",
           csflut_axis_size(c->tab, CSFLUT_AXIS_VEL) > 0 ? "has a velocity axis"
                                                         : "has no velocity axis (velocity ignored)");
    return lod_run_sequence(&q);
}

static int run(const options *o, const csflut_table *tab)
{
    lod_mesh mesh;
    lod_vtree tree;
    if (lod_mesh_bumpy_sphere(&mesh, o->subdiv, o->seed) != 0) { fprintf(stderr, "lod: out of memory\n"); return 1; }
    double t0 = now_ms();
    if (lod_vtree_build(&tree, &mesh, &o->shade) != 0) {
        lod_mesh_free(&mesh);
        fprintf(stderr, "lod: out of memory\n");
        return 1;
    }
    printf("mesh: %d vertices, %d triangles; vertex tree: %d nodes, built in %.1f ms\n", mesh.n_vert,
           mesh.n_tri, tree.n_node, now_ms() - t0);
    char err[512];
    run_ctx c = {.o = o, .mesh = &mesh, .tree = &tree, .tab = tab, .dist_px = o->ppd * 180 / LOD_PI};
    for (int i = 0; i < mesh.n_vert; i++) {
        const float *p = mesh.pos + 3 * i;
        c.model_radius = fmax(c.model_radius, sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
    }
    c.image_deg = 2 * atan(0.5 * o->width_px / c.dist_px) * 180 / LOD_PI;
    size_t npx = (size_t)o->width_px * o->height_px * 3;
    c.tri = malloc((size_t)mesh.n_tri * 3 * sizeof *c.tri);
    c.full = malloc(npx);
    c.img = malloc(npx);
    float *pos = malloc((size_t)tree.n_node * 3 * sizeof *pos), *nrm = malloc((size_t)tree.n_node * 3 * sizeof *nrm);
    lod_outfile summary = {0}, conditions = {0};
    int rc = 1;
    if (!c.tri || !c.full || !c.img || !pos || !nrm) { fprintf(stderr, "lod: out of memory\n"); goto done; }
    for (int i = 0; i < tree.n_node; i++) {
        memcpy(pos + 3 * i, mesh.pos + 3 * tree.node[i].proxy, 3 * sizeof *pos);
        memcpy(nrm + 3 * i, tree.node[i].normal, 3 * sizeof *nrm);
    }
    if (!(c.r = lod_render_open(o->width_px, o->height_px, err, sizeof err))) {
        fprintf(stderr, "lod: %s\n", err);
        goto done;
    }
    if (lod_render_set_vertices(c.r, pos, nrm, tree.n_node) != 0) { fprintf(stderr, "lod: out of memory\n"); goto done; }
    if (o->frames) {
        rc = run_sequence(&c);
        goto done;
    }
    if (open_out(o, "lod_summary.csv", &summary) != 0 || open_out(o, "conditions.csv", &conditions) != 0) goto done;
    c.summary = summary.f;
    c.conditions = conditions.f;
    fprintf(c.summary, "view,image,reference,distance_factor,threshold_factor,triangles_full,triangles,triangles_cull_only,"
                       "changed_pixels,rms_contrast,max_contrast,peak_visibility,pooled_visibility,"
                       "peak_freq_cpd,peak_ecc_deg,simplify_ms\n");
    fprintf(c.conditions, "label,stimulus,ecc_deg,image_a,image_b,size_deg,curve\n");
    rc = 0;
    for (int vi = 0; vi < o->views && rc == 0; vi++) rc = run_view(&c, vi);
    if (rc == 0) rc = write_study(o);
done:
    if (close_out(&summary, rc == 0)) rc = 1;
    if (close_out(&conditions, rc == 0)) rc = 1;
    lod_render_close(c.r);
    free(pos);
    free(nrm);
    free(c.tri);
    free(c.full);
    free(c.img);
    lod_vtree_free(&tree);
    lod_mesh_free(&mesh);
    return rc;
}

int main(int argc, char **argv)
{
    options o;
    lod_options_defaults(&o);
    int rc = lod_parse_args(argc, argv, &o);
    if (rc == 1) {
        lod_usage(stdout);
        return 0;
    }
    if (rc) return rc;
    struct stat sb;
    if (stat(o.out_dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        if (mkdir(o.out_dir, 0777) != 0) {
            fprintf(stderr, "lod: --out %s: cannot create the folder: %s\n", o.out_dir, strerror(errno));
            return 2;
        }
    }
    csflut_table *tab;
    csflut_diag diag;
    if (csflut_open_file_diag(o.table, &tab, &diag) != CSFLUT_OK) {
        fprintf(stderr, "lod: %s\n", diag.message);
        return 1;
    }
    printf("table %s; %dx%d px at %g px/deg (%.3g deg wide), gaze at (%g, %g) px, model %g deg\n", o.table,
           o.width_px, o.height_px, o.ppd, 2 * atan(0.5 * o.width_px / (o.ppd * 180 / LOD_PI)) * 180 / LOD_PI,
           o.gaze_px[0], o.gaze_px[1], o.object_deg);
    rc = run(&o, tab);
    csflut_close(tab);
    return rc;
}
