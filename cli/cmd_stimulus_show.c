/* csfcal stimulus show: what a session draws at the given settings, in a window (fullscreen, or
 * --windowed), with keys that step the settings, or headless as PNG files (--png). The stimulus
 * is built as a session builds it (a Gabor of sigma 1 deg by default, fixation mark on, mean
 * luminance through the display profile) and drawn through the same presenter; a drifting
 * carrier's phase is set from each frame's predicted presentation time as csf_presenter_run_trial
 * sets it. The caption's contrast is measured on the frame (stimuli/selfcheck.h's phase meter),
 * not copied from the request. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <jansson.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cmd_stimulus.h"
#include "core/file_write.h"

#define SHOW_DEFAULT_FREQ_CPD 2.0
#define SHOW_DEFAULT_CONTRAST 0.5
#define SHOW_LOG_CONTRAST_STEP 0.1 /* log10 units per key press */
#define SHOW_KEYQ 32

typedef struct {
    stim_args a; /* the settings now shown */
    csf_presenter *p;
    const stim_truth *t;
    csf_stimulus s;
    double onset_s;    /* presenter time of the first frame: the drift's phase origin */
    double measured_c; /* Michelson contrast fitted on the frame (NAN until measured) */
    int need_measure, need_caption, quit, clean, json;
    long frames;
    char note[300];      /* why the last key's step was refused ("" when none) */
    int keyq[SHOW_KEYQ]; /* key presses from the window, as the --keys letters */
    int nkeys;
} show_state;

/* ---------------- settings and keys ---------------- */

/* 0 when a (drawn at this presenter) is a stimulus the presenter accepts and that does not
 * alias; else the reason in why. */
static int settings_ok(csf_presenter *p, const stim_args *a, char *why, size_t len)
{
    if (stim_check_aliasing(a, csf_presenter_refresh_hz(p), why, len)) return -1;
    csf_stimulus s;
    stim_from_args(a, &s);
    csf_error e;
    if (csf_presenter_validate(p, &s, &e) == CSF_OK) return 0;
    snprintf(why, len, "%.*s", len > 1 ? (int)len - 1 : 0, e.msg);
    return -1;
}

/* The settings after one key (the --keys letters); 0 when the key means nothing. */
static int step_settings(stim_args *a, int key)
{
    double cstep = pow(10.0, SHOW_LOG_CONTRAST_STEP);
    switch (key) {
    case 'f': a->freq_cpd *= 2; return 1;
    case 'F': a->freq_cpd /= 2; return 1;
    case 'c': a->contrast = fmin(1.0, a->contrast * cstep); return 1;
    case 'C': a->contrast /= cstep; return 1;
    case 'e': a->ecc_deg += 1; return 1;
    case 'E': a->ecc_deg = fmax(0.0, a->ecc_deg - 1); return 1;
    case 'v': a->velocity_dps += 1; return 1;
    case 'V': a->velocity_dps -= 1; return 1;
    default: return 0;
    }
}

/* One key press: quit, or a step that is taken when the presenter accepts the result (else the
 * settings stay and the caption says why). */
static void apply_key(show_state *st, int key)
{
    if (key == 'q') {
        st->quit = 1;
        return;
    }
    stim_args next = st->a;
    if (!step_settings(&next, key)) return;
    char why[300];
    if (next.freq_cpd == st->a.freq_cpd && next.contrast == st->a.contrast && next.ecc_deg == st->a.ecc_deg &&
        next.velocity_dps == st->a.velocity_dps) {
        /* a step clamped to where it already was: contrast 1, eccentricity 0 */
        snprintf(st->note, sizeof st->note, "refused: %s",
                 key == 'c' ? "contrast is at its limit of 1" : "eccentricity is at its limit of 0 deg");
        st->need_caption = 1;
        return;
    }
    if (settings_ok(st->p, &next, why, sizeof why)) {
        snprintf(st->note, sizeof st->note, "refused: %.280s", why);
        st->need_caption = 1;
        return;
    }
    st->a = next;
    st->note[0] = '\0';
    stim_from_args(&st->a, &st->s);
    st->need_measure = 1;
}

static show_state *key_target; /* the window's state for the GLFW key callback */

static void key_cb(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)w;
    (void)scancode;
    if (!key_target || (action != GLFW_PRESS && action != GLFW_REPEAT)) return;
    int shift = (mods & GLFW_MOD_SHIFT) != 0, c = 0;
    switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: c = 'q'; break;
    case GLFW_KEY_RIGHT: c = 'f'; break;
    case GLFW_KEY_LEFT: c = 'F'; break;
    case GLFW_KEY_UP: c = 'c'; break;
    case GLFW_KEY_DOWN: c = 'C'; break;
    case GLFW_KEY_F: c = shift ? 'F' : 'f'; break;
    case GLFW_KEY_C: c = shift ? 'C' : 'c'; break;
    case GLFW_KEY_E: c = shift ? 'E' : 'e'; break;
    case GLFW_KEY_V: c = shift ? 'V' : 'v'; break;
    default: return;
    }
    if (key_target->nkeys < SHOW_KEYQ) key_target->keyq[key_target->nkeys++] = c;
}

/* ---------------- measuring and the caption ---------------- */

/* The Michelson contrast on the last frame (the region re-rendered without the caption). */
static csf_status measure(show_state *st, csf_error *err)
{
    csf_stimulus s = st->s;
    s.time_s = 0;
    csf_phase_meter *m = NULL;
    csf_status rc = csf_phase_meter_open(st->p, &s, 1, st->t->lum, st->t->lum_ctx, &m, err);
    csf_phase_reading r;
    if (!rc) rc = csf_phase_meter_read(m, &r, err);
    csf_phase_meter_close(m);
    if (rc) return rc;
    st->measured_c = r.contrast;
    st->need_measure = 0;
    return CSF_OK;
}

/* The caption: the values shown, led by the reason when the last key's step was not taken. The
 * values alone fill about 170 characters, wider than a 1920-pixel screen at the caption's font
 * (1/45 of the height), so a reason after them would never be seen. */
static csf_status update_caption(show_state *st, csf_error *err)
{
    if (st->clean) return CSF_OK;
    const stim_args *a = &st->a;
    double black, max;
    csf_presenter_lum_range(st->p, &black, &max);
    char line[1024]; /* cut to the caption's limit below (the tail is off any screen) */
    snprintf(line, sizeof line,
             "%.220s%s%s %.4g cpd  ecc %.3g  polar %.3g deg  contrast %.4g (on screen %.4g)  sigma %.3g  "
             "orient %.3g deg  %.3g deg/s (%.3g Hz)  mean %.4g cd/m2  [f/F c/C e/E v/V q]",
             st->note, st->note[0] ? "  |  " : "", a->grating ? "grating" : "Gabor", a->freq_cpd, a->ecc_deg,
             a->polar_deg, a->contrast, st->measured_c, a->sigma_deg, a->orientation_deg, a->velocity_dps,
             a->velocity_dps * a->freq_cpd,
             st->s.mean_lum_cdm2 > 0 ? st->s.mean_lum_cdm2 : 0.5 * (black + max));
    line[CSF_CAPTION_MAX_CHARS] = '\0';
    return csf_presenter_set_caption(st->p, line, err);
}

/* One frame at the drift phase of its predicted presentation time (as run_trial draws it). */
static csf_status draw_one(show_state *st, csf_error *err)
{
    double t = csf_presenter_next_frame_time(st->p);
    if (st->frames == 0) st->onset_s = t;
    st->s.time_s = t - st->onset_s;
    csf_frame_info fi;
    csf_status rc = csf_presenter_draw(st->p, &st->s, !st->a.no_fixation, &fi, err);
    if (rc) return rc;
    st->frames++;
    if (!st->need_measure) return CSF_OK;
    rc = measure(st, err);
    return rc ? rc : update_caption(st, err);
}

/* ---------------- PNG ---------------- */

/* The presenter's last frame as an 8-bit (16-bit for a 10-bit framebuffer) RGB PNG at path,
 * written through core/file_write. */
static csf_status write_png(csf_presenter *p, const char *path, csf_error *err)
{
    int w, h;
    csf_presenter_render_size(p, &w, &h);
    int maxlevel = (1 << csf_presenter_bits(p)) - 1, depth = maxlevel > 255 ? 16 : 8;
    size_t n = (size_t)w * h * 3;
    uint16_t *lv = malloc(n * sizeof *lv);
    png_bytep rows = malloc(n * (size_t)(depth / 8));
    if (!lv || !rows) {
        free(lv);
        free(rows);
        return csf_error_set(err, CSF_E_NOMEM, "out of memory for a %dx%d PNG", w, h);
    }
    csf_status rc = csf_presenter_readback_levels(p, lv, err);
    for (size_t i = 0; i < n && !rc; i++) {
        if (depth == 8) rows[i] = (png_byte)lv[i];
        else {
            unsigned v = (unsigned)((lv[i] * 65535u + (unsigned)maxlevel / 2) / (unsigned)maxlevel);
            rows[2 * i] = (png_byte)(v >> 8);
            rows[2 * i + 1] = (png_byte)(v & 255);
        }
    }
    free(lv);
    csf_atomic_file af;
    if (!rc) rc = csf_atomic_open(&af, path, "PNG frame", err);
    if (rc) {
        free(rows);
        return rc;
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        csf_atomic_abort(&af);
        free(rows);
        return csf_error_set(err, CSF_E_IO, "libpng could not write %s", path);
    }
    png_init_io(png, af.fp);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, depth, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < h; y++) png_write_row(png, rows + (size_t)y * w * 3 * (size_t)(depth / 8));
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(rows);
    return csf_atomic_commit(&af, err);
}

static int is_folder_path(const char *path)
{
    size_t n = strlen(path);
    return n > 0 && path[n - 1] == '/';
}

/* --png FILE: one frame; --frames N --png DIR/: N frames DIR/frame_0000.png ... The caption's
 * measurement needs a frame, so a first frame is drawn (and measured) before the written ones. */
static int show_png(show_state *st, csf_error *err)
{
    int folder = is_folder_path(st->a.png);
    long n = st->a.frames_set ? st->a.frames : 1;
    char path[4096];
    csf_status rc = CSF_OK;
    for (long k = 0; k < n && !rc; k++) {
        if (folder) snprintf(path, sizeof path, "%sframe_%04ld.png", st->a.png, k);
        else snprintf(path, sizeof path, "%s", st->a.png);
        if (k == 0) rc = csf_check_output_path(path, "PNG frame", err);
        if (!rc && k == 0 && !st->clean) {
            /* measure and caption; then the same frame number again, so that the written frame
             * has the dither a --clean one has */
            long first = csf_presenter_frame_index(st->p);
            rc = draw_one(st, err);
            st->frames = 0;
            csf_presenter_set_frame_index(st->p, first);
        }
        if (!rc) rc = draw_one(st, err);
        if (!rc) rc = write_png(st->p, path, err);
    }
    return rc ? csf_cli_report("stimulus show", err) : 0;
}

/* ---------------- the window ---------------- */

static int show_window(show_state *st, csf_error *err)
{
    GLFWwindow *win = csf_presenter_window(st->p);
    key_target = st;
    GLFWkeyfun prev = glfwSetKeyCallback(win, key_cb);
    const char *script = st->a.keys ? st->a.keys : "";
    csf_status rc = CSF_OK;
    while (!st->quit) {
        if (st->a.quit_after_frames > 0 && st->frames >= st->a.quit_after_frames) break;
        if (*script) apply_key(st, *script++);
        for (int i = 0; i < st->nkeys; i++) apply_key(st, st->keyq[i]);
        st->nkeys = 0;
        if (st->need_caption && !st->need_measure) rc = update_caption(st, err); /* a refusal's note */
        st->need_caption = 0;
        if (!rc && !st->quit) rc = draw_one(st, err); /* polls the window's events */
        if (rc) break;
    }
    glfwSetKeyCallback(win, prev);
    key_target = NULL;
    if (rc == CSF_E_ABORTED) rc = CSF_OK; /* the window was closed: a way to quit */
    return rc ? csf_cli_report("stimulus show", err) : 0;
}

/* ---------------- the command ---------------- */

/* Option combinations show refuses. Returns 0, or 2 after a message. */
static int check_show_args(const csf_cli *cli, const stim_args *a)
{
    if (a->frames_set && a->frames > 1 && !(a->png && is_folder_path(a->png))) {
        fprintf(stderr,
                "csfcal: stimulus show: --frames %ld writes PNG frames: give --png DIR/ (a "
                "folder, ending in /)\n",
                a->frames);
        return 2;
    }
    if (a->png && !a->png[0]) {
        fprintf(stderr, "csfcal: stimulus show: --png needs a file name (or DIR/ with --frames)\n");
        return 2;
    }
    if (!a->png && csf_cli_want_headless(cli)) {
        fprintf(stderr, "csfcal: stimulus show: no window can be opened (--headless or no X/Wayland "
                        "display); write frames with --png FILE or --frames N --png DIR/\n");
        return 2;
    }
    if (a->png && csf_cli_refuse_monitor(cli, "stimulus show", "--png writes files")) return 2;
    for (const char *k = a->keys ? a->keys : ""; *k; k++)
        if (!strchr("fFcCeEvVq", *k)) {
            fprintf(stderr,
                    "csfcal: stimulus show: --keys '%c' is not a key show knows (f F c C e E v V q)\n", *k);
            return 2;
        }
    if (a->n_drops || a->miss_rate > 0) {
        fprintf(stderr, "csfcal: stimulus show: --drop-frame and --miss-rate belong to stimulus check\n");
        return 2;
    }
    return 0;
}

static void print_summary(const show_state *st)
{
    const stim_args *a = &st->a;
    if (!st->json) {
        printf("shown %ld frames: %s %.4g cpd, ecc %.3g deg, contrast %.4g (measured %.4g), %.3g deg/s\n",
               st->frames, a->grating ? "grating" : "Gabor", a->freq_cpd, a->ecc_deg, a->contrast,
               st->measured_c, a->velocity_dps);
        return;
    }
    json_t *o =
        json_pack("{s:i,s:s,s:f,s:f,s:f,s:f,s:f,s:f,s:f}", "frames", (int)st->frames, "kind",
                  a->grating ? "grating" : "gabor", "freq_cpd", a->freq_cpd, "ecc_deg", a->ecc_deg,
                  "polar_deg", a->polar_deg, "contrast", a->contrast, "velocity_dps", a->velocity_dps,
                  "drift_hz", a->velocity_dps * a->freq_cpd, "refresh_hz", csf_presenter_refresh_hz(st->p));
    json_object_set_new(o, "contrast_measured",
                        isnan(st->measured_c) ? json_null() : json_real(st->measured_c));
    json_object_set_new(o, "note", json_string(st->note));
    json_dumpf(o, stdout, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    fputc('\n', stdout);
    json_decref(o);
}

/* The presenter for show: headless for PNG frames, else a window. Returns -1 to go on, or the
 * exit status. */
static int open_show(const csf_cli *cli, const stim_args *a, stim_truth *t, csf_presenter **p)
{
    csf_error e;
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    if (csf_geometry_init(&pc.geometry, CSF_GEOMETRY_FROM_CONFIG(cli->cfg), &e))
        return csf_cli_report("stimulus show", &e);
    pc.headless = a->png != NULL;
    pc.windowed = a->windowed;
    pc.refresh_hz = cli->cfg.refresh_hz;
    pc.framebuffer_bits = a->bits ? (int)a->bits : cli->cfg.framebuffer_bits;
    pc.monitor = cli->cfg.monitor[0] ? cli->cfg.monitor : NULL;
    pc.seed = cli->seed;
    int status = stim_open_truth(cli, "stimulus show", &pc, t);
    if (status >= 0) return status;
    if (csf_presenter_open(&pc, p, &e)) {
        stim_close_truth(t);
        return csf_cli_report("stimulus show", &e);
    }
    return -1;
}

int csf_cmd_stimulus_show(csf_cli *cli, const stim_args *args)
{
    show_state st = {
        .a = *args, .measured_c = NAN, .need_measure = 1, .clean = args->clean, .json = cli->json};
    if (isnan(st.a.freq_cpd)) st.a.freq_cpd = SHOW_DEFAULT_FREQ_CPD;
    if (isnan(st.a.contrast)) st.a.contrast = SHOW_DEFAULT_CONTRAST;
    int status = check_show_args(cli, &st.a);
    if (status) return status;
    stim_truth t;
    status = open_show(cli, &st.a, &t, &st.p);
    if (status >= 0) return status;
    st.t = &t;
    char why[400];
    if (settings_ok(st.p, &st.a, why, sizeof why)) {
        fprintf(stderr, "csfcal: stimulus show: %s\n", why);
        status = 2;
    } else {
        stim_from_args(&st.a, &st.s);
        csf_error e;
        status = st.a.png ? show_png(&st, &e) : show_window(&st, &e);
        if (status == 0) print_summary(&st);
    }
    csf_presenter_close(st.p);
    stim_close_truth(&t);
    return status;
}
