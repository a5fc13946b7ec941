/* Stimulus presenter: GL context (EGL surfaceless or GLFW+EGL window), the luminance shader,
 * validation, frame timing and trials. See presenter.h for the pipeline and the contract. */
#define GL_GLEXT_PROTOTYPES 1
#include "stimuli/presenter.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/rng.h"
#include "stimuli/context.h"

#define DEG (M_PI / 180.0)
#define INV_TABLE_N 4096
#define RNG_STREAM_MISS 0x6d697373ULL /* "miss" */
#define MAX_INJECT 64

enum {
    MODE_BLANK = 0,
    MODE_GABOR = 1,
    MODE_GRATING = 2,
    MODE_IMAGE = 3,
    MODE_DISC = 4,
    MODE_TEXT = 5,
    MODE_PATCH = 6,
    MODE_CAPTION = 7
};

struct csf_presenter {
    csf_presenter_config cfg;
    csf_geometry geom;
    int headless;
    int rw, rh; /* render size */
    int bits, maxlevel;
    double refresh_hz;
    /* luminance model */
    csf_display_profile *own_profile;
    const csf_display_profile *profile;
    double lum_black, lum_max;
    double *level_lum; /* maxlevel+1 entries, cd/m2 */
    char profile_id[128];
    /* EGL headless */
    EGLDisplay dpy;
    EGLContext ctx;
    /* windowed */
    GLFWwindow *win;
    int glfw_inited;
    /* GL objects */
    GLuint prog, vao, fbo, color_tex, inv_tex, fwd_tex, img_tex, text_tex, chan_tex;
    /* two builds of the fragment shader: without and with the place-mark code. llvmpipe runs
     * a branch's body even when a uniform says skip it, and the mark loop made every frame
     * of a fade session 40 % slower; prog and u point at the one in use */
    GLuint prog_plain, prog_marks;
    GLint u_plain[48], u_marks[48];
    const csf_image *img_uploaded;
    GLint *u; /* uniform locations of prog, U_COUNT used */
    /* timing */
    long frame_index;
    double t_last, t0_real;
    int have_frame;
    struct {
        long frame;
        int periods;
    } inject[MAX_INJECT];
    int n_inject;
    double miss_prob;
    int last_rendered;
    /* place marks (csf_presenter_set_marks): centre directions from the eye, ring radius */
    int n_marks;
    float mark_c[CSF_PRESENTER_MAX_MARKS][3];
    double mark_radius_deg;
    /* the last frame of csf_presenter_draw / run_trial, as csf_presenter_readback_region
     * rasterises it again: stimulus (if any), fixation, marks and the dither's frame number */
    int last_kind; /* 0 none or a text/patch frame, 1 blank or stimulus frame */
    int last_has_stim, last_fix, last_n_marks;
    csf_stimulus last_stim;
    long last_frame_number;
    /* region target at full resolution (grown on demand) */
    GLuint region_fbo, region_tex;
    int region_w, region_h;
    csf_frame_hook frame_hook;
    void *frame_hook_ctx;
    /* caption line over stimulus and blank frames (csf_presenter_set_caption): its own coverage
     * texture, so that a text screen does not overwrite it */
    GLuint caption_tex;
    int caption_on;
};

/* Where a frame is rasterised: the main render target, or a region of the full-resolution
 * frame (origin_x/y: its lower-left pixel in GL's bottom-up frame coordinates). */
typedef struct {
    GLuint fbo;
    int vw, vh;           /* viewport */
    double frame_w, frame_h; /* pixels of the whole frame the viewport is part of */
    double origin_x, origin_y;
    long frame_number;    /* what the temporal dither keys on */
} target;

enum {
    U_RENDER, U_SCREEN, U_EYE, U_MODE, U_C, U_H, U_V, U_FIXC, U_FREQ, U_ORIENT, U_PHASE, U_SIGMA,
    U_RADIUS, U_EDGE, U_CONTRAST, U_MEAN, U_LUMRANGE, U_MAXLEVEL, U_FRAME, U_FIX, U_INV, U_FWD,
    U_IMG, U_TEXT, U_DITHER, U_IMGMEAN, U_CHAN, U_DRIVE, U_BGDRIVE, U_RECT, U_NMARKS, U_MARKC,
    U_MARKR, U_MARKHW, U_MARKFRAC, U_ORIGIN, U_COUNT
};
static const char *const uniform_names[U_COUNT] = {
    "u_render", "u_screen", "u_eye", "u_mode", "u_c", "u_h", "u_v", "u_fixc", "u_freq", "u_orient",
    "u_phase", "u_sigma", "u_radius", "u_edge", "u_contrast", "u_mean", "u_lumrange", "u_maxlevel",
    "u_frame", "u_fix", "u_inv", "u_fwd", "u_img", "u_text", "u_dither", "u_imgmean", "u_chan",
    "u_drive", "u_bgdrive", "u_rect", "u_nmarks", "u_markc", "u_markr", "u_markhw", "u_markfrac", "u_origin"};

static const char *const vs_src =
    "#version 330 core\n"
    "void main() {\n"
    "  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n"
    "  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
    "}\n";

/* Every fragment: screen mm -> direction from the eye -> stimulus angle space (azimuthal
 * equidistant around the patch centre) -> luminance in cd/m2 -> level via the profile tables. */
static const char *const fs_src =
    "#version 330 core\n"
    "out vec4 o;\n"
    "uniform vec2 u_render, u_screen;\n"
    "uniform vec3 u_eye, u_c, u_h, u_v, u_fixc;\n"
    "uniform int u_mode, u_fix, u_maxlevel, u_dither;\n"
    "uniform float u_freq, u_phase, u_sigma, u_radius, u_edge, u_contrast, u_mean, u_imgmean;\n"
    "uniform vec2 u_orient, u_lumrange;\n"
    "uniform uint u_frame;\n"
    "uniform sampler2D u_inv, u_fwd, u_img, u_text, u_chan;\n"
    "uniform vec3 u_drive, u_bgdrive;\n"
    "uniform vec4 u_rect;\n"
    "uniform int u_nmarks;\n"
    "uniform vec3 u_markc[8];\n"
    "uniform float u_markr, u_markhw, u_markfrac;\n"
    /* pixel offset of the viewport in the frame: 0 for a whole frame, the region's corner for
     * csf_presenter_readback_region, so a region's pixels are the frame's pixels there */
    "uniform vec2 u_origin;\n"
    "const float RAD2DEG = 57.29577951308232;\n"
    "vec2 local_uv(vec3 d, vec3 c, vec3 h, vec3 v) {\n"
    "  float a = atan(length(cross(d, c)), dot(d, c));\n"
    "  vec2 xy = vec2(dot(d, h), dot(d, v));\n"
    "  float s = length(xy);\n"
    "  return (s > 1e-12 ? a / s : 1.0) * xy * RAD2DEG;\n"
    "}\n"
    "float window(float r) {\n"
    "  if (r <= u_radius) return 1.0;\n"
    "  if (r >= u_radius + u_edge) return 0.0;\n"
    "  return 0.5 + 0.5 * cos(3.141592653589793 * (r - u_radius) / u_edge);\n"
    "}\n"
    "void main() {\n"
    "  vec2 fc = gl_FragCoord.xy + u_origin;\n"
    /* measurement patch (csf_presenter_draw_patch): drive values in framebuffer levels per
     * channel, bypassing the luminance mapping; the same R2 mask and per-frame offset choose
     * between levels k and k+1 with probability frac(drive), channel by channel */
    "  if (u_mode == 6) {\n"
    "    bool inside = all(greaterThanEqual(fc, u_rect.xy)) && all(lessThan(fc, u_rect.zw));\n"
    "    vec3 dv = inside ? u_drive : u_bgdrive;\n"
    "    vec3 kk = clamp(floor(dv), vec3(0.0), vec3(float(u_maxlevel - 1)));\n"
    "    vec3 pp = clamp(dv - kk, vec3(0.0), vec3(1.0));\n"
    "    uvec2 q0 = uvec2(fc);\n"
    "    uint h0 = q0.x * 3242174889u + q0.y * 2447445414u + u_frame * 2654435769u;\n"
    "    float t0 = (float(h0 >> 8) + 0.5) / 16777216.0;\n"
    "    vec3 lp = (u_dither == 1) ? kk + step(vec3(0.5), pp) : kk + vec3(lessThan(vec3(t0), pp));\n"
    "    o = vec4(lp / float(u_maxlevel), 1.0);\n"
    "    return;\n"
    "  }\n"
    "  vec2 pmm = (fc / u_render - 0.5) * u_screen;\n"
    "  vec3 d = normalize(vec3(pmm - u_eye.xy, -u_eye.z));\n"
    "  float L = u_mean;\n"
    "  if (u_mode == 1 || u_mode == 2) {\n"
    "    vec2 uv = local_uv(d, u_c, u_h, u_v);\n"
    "    float w = dot(uv, u_orient);\n"
    "    float carrier = cos(6.283185307179586 * u_freq * w + u_phase);\n"
    "    float env = (u_mode == 1) ? exp(-dot(uv, uv) / (2.0 * u_sigma * u_sigma)) : window(length(uv));\n"
    "    L = u_mean * (1.0 + u_contrast * env * carrier);\n"
    "  } else if (u_mode == 4) {\n"
    "    vec2 uv = local_uv(d, u_c, u_h, u_v);\n"
    "    L = u_mean * (1.0 + u_contrast * window(length(uv)));\n"
    "  } else if (u_mode == 3) {\n"
    "    vec2 uv = local_uv(d, u_c, u_h, u_v);\n"
    "    vec2 isz = vec2(textureSize(u_img, 0));\n"
    "    vec2 half_deg = vec2(u_radius, u_radius * isz.y / isz.x);\n"
    "    vec2 tc = vec2(0.5 + 0.5 * uv.x / half_deg.x, 0.5 - 0.5 * uv.y / half_deg.y);\n"
    "    if (all(greaterThanEqual(tc, vec2(0.0))) && all(lessThanEqual(tc, vec2(1.0)))) {\n"
    "      vec2 la = texture(u_img, tc).rg;\n"
    "      float li = u_mean * (1.0 + u_contrast * (la.r - u_imgmean) / max(u_imgmean, 1e-3));\n"
    "      L = mix(u_mean, li, la.g);\n"
    "    }\n"
    "  } else if (u_mode == 5) {\n"
    "    float cov = texture(u_text, vec2(fc.x / u_render.x, 1.0 - fc.y / u_render.y)).r;\n"
    "    L = mix(u_mean, u_lumrange.x + 0.05 * (u_lumrange.y - u_lumrange.x), cov);\n"
    /* caption pass over a drawn frame: only the text's own pixels are written, the rest of the
     * frame (stimulus, marks, fixation) stays as the first pass drew it */
    "  } else if (u_mode == 7) {\n"
    "    float cov = texture(u_text, vec2(fc.x / u_render.x, 1.0 - fc.y / u_render.y)).r;\n"
    "    if (cov <= 0.0) discard;\n"
    "    L = mix(u_mean, u_lumrange.x + 0.05 * (u_lumrange.y - u_lumrange.x), cov);\n"
    "  }\n"
    /* place marks: thin dark rings of radius u_markr (angular distance from each place's centre
     * direction, exact), half-width u_markhw but at least 1 px (so every cross-section of the
     * line has a fully dark pixel), antialiased over one pixel; luminance u_markfrac x mean,
     * through the same profile inverse and dithering as everything else */
    "#ifdef CSF_MARKS\n"
    "  if (u_nmarks > 0) {\n"
    /* size of this pixel in degrees, for the minimum width and the antialiasing; derivatives
     * are defined here because the branch depends on a uniform only (dynamically uniform
     * control flow), and frames without marks (every fade frame) skip their cost */
    "    float pxdeg = RAD2DEG * max(length(dFdx(d)), length(dFdy(d)));\n"
    "    float hw = max(u_markhw, pxdeg), cov = 0.0;\n"
    "    for (int i = 0; i < 8; i++) {\n"
    "      if (i >= u_nmarks) break;\n"
    "      float r = RAD2DEG * atan(length(cross(d, u_markc[i])), dot(d, u_markc[i]));\n"
    "      cov = max(cov, clamp((hw - abs(r - u_markr)) / max(pxdeg, 1e-6) + 0.5, 0.0, 1.0));\n"
    "    }\n"
    "    L = mix(L, u_markfrac * u_mean, cov);\n"
    "  }\n"
    "#endif\n"
    "  if (u_fix != 0) {\n"
    "    if (dot(d, u_fixc) > 0.9999978068) L = u_lumrange.x + 0.1 * (u_mean - u_lumrange.x);\n"
    "  }\n"
    /* luminance -> level k and probability p of k+1, exact in expectation */
    "  float ln = clamp((L - u_lumrange.x) / (u_lumrange.y - u_lumrange.x), 0.0, 1.0);\n"
    "  float n = float(textureSize(u_inv, 0).x);\n"
    "  float drive = texture(u_inv, vec2((ln * (n - 1.0) + 0.5) / n, 0.5)).r;\n"
    "  int k = clamp(int(floor(drive * float(u_maxlevel))), 0, u_maxlevel - 1);\n"
    /* the inverse table is accurate to far below one level: one correction step each way
     * (no loops: llvmpipe runs divergent loops slowly) */
    "  float lk = texelFetch(u_fwd, ivec2(k, 0), 0).r, lk1 = texelFetch(u_fwd, ivec2(k + 1, 0), 0).r;\n"
    "  if (ln < lk && k > 0) { k -= 1; lk1 = lk; lk = texelFetch(u_fwd, ivec2(k, 0), 0).r; }\n"
    "  else if (ln > lk1 && k < u_maxlevel - 1) { k += 1; lk = lk1; lk1 = texelFetch(u_fwd, ivec2(k + 1, 0), "
    "0).r; }\n"
    "  float p = clamp((ln - lk) / max(lk1 - lk, 1e-9), 0.0, 1.0);\n"
    /* R2 low-discrepancy mask in 32-bit integer arithmetic (exact fract), golden-ratio step per frame */
    "  uvec2 q = uvec2(fc);\n"
    "  uint hsh = q.x * 3242174889u + q.y * 2447445414u + u_frame * 2654435769u;\n"
    "  float thr = (float(hsh >> 8) + 0.5) / 16777216.0;\n"
    "  vec3 lv;\n"
    "  if (u_dither == 1) {\n"
    "    lv = vec3(float(k) + (p >= 0.5 ? 1.0 : 0.0));\n"
    "  } else if (u_dither == 2) {\n"
    /* bit-stealing: the 8 mixes of k and k+1 per channel are sub-levels between grey k and k+1,
     * placed by the channels' own luminance steps (scaled so that k+1 on all three is grey
     * k+1); dither between the two sub-levels that bracket L */
    "    vec3 dc = texelFetch(u_chan, ivec2(k + 1, 0), 0).rgb - texelFetch(u_chan, ivec2(k, 0), 0).rgb;\n"
    "    float tot = max(dc.r + dc.g + dc.b, 1e-12);\n"
    "    float lo = lk, hi = lk1; vec3 dlo = vec3(0.0), dhi = vec3(1.0);\n"
    "    for (int m = 1; m < 7; m++) {\n"
    "      vec3 d = vec3(float(m & 1), float((m >> 1) & 1), float((m >> 2) & 1));\n"
    "      float v = lk + (lk1 - lk) * dot(d, dc) / tot;\n"
    "      if (v <= ln && v > lo) { lo = v; dlo = d; }\n"
    "      if (v >= ln && v < hi) { hi = v; dhi = d; }\n"
    "    }\n"
    "    float ps = clamp((ln - lo) / max(hi - lo, 1e-12), 0.0, 1.0);\n"
    "    lv = vec3(float(k)) + (thr < ps ? dhi : dlo);\n"
    "  } else {\n"
    "    lv = vec3(float(k) + (thr < p ? 1.0 : 0.0));\n"
    "  }\n"
    "  o = vec4(lv / float(u_maxlevel), 1.0);\n"
    "}\n";

static double now_monotonic(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void csf_presenter_config_defaults(csf_presenter_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->headless = 1;
    cfg->refresh_hz = 60.0;
    cfg->framebuffer_bits = 8;
    cfg->seed = 1;
    csf_geometry_init(&cfg->geometry, 531.0, 299.0, 1920, 1080, 570.0, 0.0, 0.0, NULL);
}

/* ---------------- luminance model ---------------- */

static double fwd_lum(const csf_presenter *p, double drive01)
{
    if (p->cfg.grey_lum_fn) return p->cfg.grey_lum_fn(p->cfg.grey_lum_ctx, drive01);
    return csf_profile_grey_lum(p->profile, drive01);
}

static double inv_drive(const csf_presenter *p, double lum)
{
    if (!p->cfg.grey_lum_fn) return csf_profile_grey_drive(p->profile, lum);
    double lo = 0.0, hi = 1.0;
    if (lum <= p->lum_black) return 0.0;
    if (lum >= p->lum_max) return 1.0;
    for (int i = 0; i < 50; i++) {
        double mid = 0.5 * (lo + hi);
        if (fwd_lum(p, mid) < lum) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

static csf_status setup_luminance(csf_presenter *p, csf_error *err)
{
    if (!p->cfg.grey_lum_fn) {
        if (p->cfg.profile) {
            p->profile = p->cfg.profile;
            snprintf(p->profile_id, sizeof p->profile_id, "%s", csf_profile_id(p->profile));
        } else {
            p->own_profile = csf_profile_default();
            if (!p->own_profile) return csf_error_set(err, CSF_E_NOMEM, "out of memory (default profile)");
            p->profile = p->own_profile;
            snprintf(p->profile_id, sizeof p->profile_id, "%s (default display, no profile given)",
                     csf_profile_id(p->profile));
        }
    } else {
        snprintf(p->profile_id, sizeof p->profile_id, "%s",
                 p->cfg.grey_lum_name ? p->cfg.grey_lum_name : "custom-luminance-function");
    }
    p->lum_black = fwd_lum(p, 0.0);
    p->lum_max = fwd_lum(p, 1.0);
    if (!(p->lum_max > p->lum_black) || !isfinite(p->lum_max) || p->lum_black < 0)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "display luminance range [%g, %g] cd/m2 is not increasing",
                             p->lum_black, p->lum_max);
    p->level_lum = malloc(sizeof(double) * (size_t)(p->maxlevel + 1));
    if (!p->level_lum) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (int k = 0; k <= p->maxlevel; k++) p->level_lum[k] = fwd_lum(p, (double)k / p->maxlevel);
    for (int k = 1; k <= p->maxlevel; k++)
        if (!(p->level_lum[k] >= p->level_lum[k - 1]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "display luminance decreases between levels %d and %d "
                                 "(%g > %g cd/m2); the profile must be monotone",
                                 k - 1, k, p->level_lum[k - 1], p->level_lum[k]);
    return CSF_OK;
}

/* ---------------- GL setup ---------------- */

static csf_status gl_compile(GLenum type, const char *src, GLuint *out, csf_error *err)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        glDeleteShader(s);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "shader compile failed: %s", log);
    }
    *out = s;
    return CSF_OK;
}

/* Compiles and links one build of the shaders; the fragment source gets `defines` after its
 * #version line. */
static csf_status gl_program(const char *defines, GLuint *prog, GLint *u, csf_error *err)
{
    const char *nl = strchr(fs_src, '\n');
    size_t vlen = (size_t)(nl - fs_src) + 1, dlen = strlen(defines), rlen = strlen(nl + 1);
    char *src = malloc(vlen + dlen + rlen + 1);
    if (!src) return csf_error_set(err, CSF_E_NOMEM, "presenter: out of memory for the shader");
    memcpy(src, fs_src, vlen);
    memcpy(src + vlen, defines, dlen); // NOLINT(bugprone-not-null-terminated-result): the NUL comes next
    memcpy(src + vlen + dlen, nl + 1, rlen + 1); /* with its NUL */
    GLuint vs = 0, fs = 0;
    csf_status st = gl_compile(GL_VERTEX_SHADER, vs_src, &vs, err);
    if (st == CSF_OK) st = gl_compile(GL_FRAGMENT_SHADER, src, &fs, err);
    free(src);
    if (st) {
        if (vs) glDeleteShader(vs);
        return st;
    }
    *prog = glCreateProgram();
    glAttachShader(*prog, vs);
    glAttachShader(*prog, fs);
    glLinkProgram(*prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(*prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetProgramInfoLog(*prog, sizeof log, NULL, log);
        return csf_error_set(err, CSF_E_UNSUPPORTED, "shader link failed: %s", log);
    }
    for (int i = 0; i < U_COUNT; i++) u[i] = glGetUniformLocation(*prog, uniform_names[i]);
    return CSF_OK;
}

static csf_status gl_setup(csf_presenter *p, csf_error *err)
{
    csf_status st = gl_program("", &p->prog_plain, p->u_plain, err);
    if (st == CSF_OK) st = gl_program("#define CSF_MARKS 1\n", &p->prog_marks, p->u_marks, err);
    if (st) return st;
    p->prog = p->prog_plain;
    p->u = p->u_plain;
    glGenVertexArrays(1, &p->vao);

    /* offscreen colour target: both back ends render here, the window gets a blit */
    glGenTextures(1, &p->color_tex);
    glBindTexture(GL_TEXTURE_2D, p->color_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, p->bits == 10 ? GL_RGB10_A2 : GL_RGBA8, p->rw, p->rh, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenFramebuffers(1, &p->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, p->color_tex, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return csf_error_set(err, CSF_E_UNSUPPORTED,
                             "offscreen framebuffer %dx%d at %d bits is not supported", p->rw, p->rh,
                             p->bits);

    /* inverse profile: drive as a function of normalised luminance */
    float *tab = malloc(sizeof(float) * (INV_TABLE_N > p->maxlevel + 1 ? INV_TABLE_N : p->maxlevel + 1));
    if (!tab) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    double range = p->lum_max - p->lum_black;
    for (int i = 0; i < INV_TABLE_N; i++)
        tab[i] = (float)inv_drive(p, p->lum_black + range * i / (INV_TABLE_N - 1));
    glGenTextures(1, &p->inv_tex);
    glBindTexture(GL_TEXTURE_2D, p->inv_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, INV_TABLE_N, 1, 0, GL_RED, GL_FLOAT, tab);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    /* forward levels: normalised luminance of each framebuffer level */
    for (int k = 0; k <= p->maxlevel; k++) tab[k] = (float)((p->level_lum[k] - p->lum_black) / range);
    glGenTextures(1, &p->fwd_tex);
    glBindTexture(GL_TEXTURE_2D, p->fwd_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, p->maxlevel + 1, 1, 0, GL_RED, GL_FLOAT, tab);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    free(tab);
    /* channel curves (black excluded, normalised by the grey range) for bit-stealing */
    float *ch = calloc((size_t)(p->maxlevel + 1) * 3, sizeof(float));
    if (!ch) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    if (p->cfg.dither == CSF_DITHER_BITSTEAL)
        for (int k = 0; k <= p->maxlevel; k++)
            for (int c = 0; c < 3; c++)
                ch[3 * k + c] = (float)(csf_profile_channel_lum(p->profile, c, (double)k / p->maxlevel) / range);
    glGenTextures(1, &p->chan_tex);
    glBindTexture(GL_TEXTURE_2D, p->chan_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, p->maxlevel + 1, 1, 0, GL_RGB, GL_FLOAT, ch);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    free(ch);
    glGenTextures(1, &p->img_tex);
    glGenTextures(1, &p->text_tex);
    glGenTextures(1, &p->caption_tex);
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_UNSUPPORTED, "OpenGL setup failed (float textures?)");
    return CSF_OK;
}

static csf_status window_open(csf_presenter *p, csf_error *err)
{
    csf_glfw_context c = {.monitor = p->cfg.monitor,
                          .width_px = p->geom.width_px,
                          .height_px = p->geom.height_px,
                          .bits = p->bits,
                          .windowed = p->cfg.windowed};
    csf_status st = csf_context_glfw_open(&c, err);
    p->win = c.win;
    p->glfw_inited = c.glfw_inited;
    if (c.bits != p->bits) { /* 10-bit refused: 8, and bits says so */
        p->bits = c.bits;
        p->maxlevel = 255;
    }
    if (st != CSF_OK) return st;
    p->rw = c.fb_w;
    p->rh = c.fb_h;
    if (c.has_mode && p->cfg.refresh_hz <= 0) p->refresh_hz = c.mode_hz;
    return CSF_OK;
}

csf_status csf_presenter_open(const csf_presenter_config *cfg, csf_presenter **out, csf_error *err)
{
    /* One small shader: Mesa's on-disk shader cache buys nothing, and its background thread
     * outlives the context and crashes LeakSanitizer's stop-the-world at exit. The user's own
     * setting wins. */
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
    if (!cfg || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "presenter: NULL argument");
    *out = NULL;
    csf_geometry chk;
    const csf_geometry *g = &cfg->geometry;
    csf_status st = csf_geometry_init(&chk, g->width_mm, g->height_mm, g->width_px, g->height_px,
                                      g->distance_mm, g->eye_x_mm, g->eye_y_mm, err);
    if (st) return st;
    double hz = cfg->refresh_hz == 0 ? 60.0 : cfg->refresh_hz;
    if (!(hz >= 20 && hz <= 1000))
        return csf_error_set(err, CSF_E_INVALID_ARG, "refresh rate %g Hz is outside 20 to 1000 Hz", hz);
    int bits = cfg->framebuffer_bits == 0 ? 8 : cfg->framebuffer_bits;
    if (bits != 8 && bits != 10)
        return csf_error_set(err, CSF_E_INVALID_ARG, "framebuffer depth %d bits: only 8 or 10", bits);
    if (cfg->render_width_px < 0 || cfg->render_height_px < 0 || cfg->render_width_px > 16384 ||
        cfg->render_height_px > 16384)
        return csf_error_set(err, CSF_E_INVALID_ARG, "render size %dx%d is outside 0 to 16384 px",
                             cfg->render_width_px, cfg->render_height_px);
    if (!isfinite(cfg->fault_polar_offset_deg))
        return csf_error_set(err, CSF_E_INVALID_ARG, "injected polar offset is not finite");
    if (cfg->dither < 0 || cfg->dither > CSF_DITHER_BITSTEAL)
        return csf_error_set(err, CSF_E_INVALID_ARG, "dither mode %d is unknown", cfg->dither);
    if (cfg->dither == CSF_DITHER_BITSTEAL &&
        (cfg->grey_lum_fn || (cfg->profile && !csf_profile_has_channels(cfg->profile))))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "bit-stealing needs a display profile with per-channel (r, g, b) "
                             "curves; this one has only the grey curve");
    csf_presenter *p = calloc(1, sizeof *p);
    if (!p) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    p->cfg = *cfg;
    p->geom = chk;
    p->headless = cfg->headless;
    p->refresh_hz = hz;
    p->bits = bits;
    p->maxlevel = (1 << bits) - 1;
    p->dpy = EGL_NO_DISPLAY;
    p->ctx = EGL_NO_CONTEXT;
    p->rw = cfg->render_width_px ? cfg->render_width_px : chk.width_px;
    p->rh = cfg->render_height_px ? cfg->render_height_px : chk.height_px;
    st = setup_luminance(p, err);
    if (!st) st = p->headless ? csf_context_egl_open(&p->dpy, &p->ctx, err) : window_open(p, err);
    if (!st) st = gl_setup(p, err);
    if (st) {
        csf_presenter_close(p);
        return st;
    }
    *out = p;
    return CSF_OK;
}

void csf_presenter_close(csf_presenter *p)
{
    if (!p) return;
    int current = p->win ? 1 : (p->ctx != EGL_NO_CONTEXT);
    if (current && p->prog) {
        glDeleteProgram(p->prog_plain);
        glDeleteProgram(p->prog_marks);
        glDeleteVertexArrays(1, &p->vao);
        glDeleteFramebuffers(1, &p->fbo);
        GLuint t[7] = {p->color_tex, p->inv_tex,  p->fwd_tex,    p->img_tex,
                       p->text_tex,  p->chan_tex, p->caption_tex};
        glDeleteTextures(7, t);
        if (p->region_fbo) glDeleteFramebuffers(1, &p->region_fbo);
        if (p->region_tex) glDeleteTextures(1, &p->region_tex);
    }
    csf_context_egl_close(p->dpy, p->ctx);
    csf_context_glfw_close(p->win, p->glfw_inited);
    csf_profile_free(p->own_profile);
    free(p->level_lum);
    free(p);
}

/* ---------------- validation ---------------- */

static double stim_extent_deg(const csf_stimulus *s)
{
    double edge = s->edge_deg > 0 ? s->edge_deg : 0.25;
    double radius = s->radius_deg > 0 ? s->radius_deg : 2.0;
    switch (s->kind) {
    case CSF_STIM_GABOR: return 3.0 * s->sigma_deg; /* envelope below 1.2 % beyond */
    case CSF_STIM_GRATING:
    case CSF_STIM_DISC: return radius + edge;
    case CSF_STIM_IMAGE: {
        double r = radius;
        if (s->image && s->image->width > 0)
            r = hypot(radius, radius * s->image->height / (double)s->image->width);
        return r;
    }
    default: return 0;
    }
}

static double mean_lum_of(const csf_presenter *p, const csf_stimulus *s)
{
    return s && s->mean_lum_cdm2 > 0 ? s->mean_lum_cdm2 : 0.5 * (p->lum_black + p->lum_max);
}

/* Centre of the patch at the stimulus' own time_s (motion applied). */
static void stim_centre(const csf_presenter *p, const csf_stimulus *s, double *ecc, double *polar)
{
    *ecc = s->ecc_deg;
    *polar = s->polar_deg;
    if (s->velocity_dps != 0 && s->time_s != 0)
        csf_geometry_move(&p->geom, s->ecc_deg, s->polar_deg, s->motion_dir_deg,
                          s->velocity_dps * s->time_s, ecc, polar);
}

/* The luminances an image stimulus really spans, as the shader draws it: each pixel at
 * mean (1 + contrast (v - m) / max(m, 1e-3)), m the image's mean, composited over the mean by its
 * alpha (so the mean itself is always shown around and under the image). A contrast-1 image whose
 * pixels stay near m therefore spans far less than 0 to 2x the mean; one with a few bright pixels on
 * a dark mean spans more. */
static void image_lum_range(const csf_stimulus *s, double mean, double *lo, double *hi)
{
    const csf_image *im = s->image;
    double m = im->mean_lum, m_div = fmax(m, 1e-3), dmin = 0, dmax = 0;
    size_t n = (size_t)im->width * (size_t)im->height;
    for (size_t i = 0; i < n; i++) {
        double a = im->alpha ? im->alpha[i] : 1.0, d = a * (im->lum[i] - m) / m_div;
        dmin = fmin(dmin, d);
        dmax = fmax(dmax, d);
    }
    *lo = mean * (1 + s->contrast * dmin);
    *hi = mean * (1 + s->contrast * dmax);
}

/* The stimulus's own parameters: finite, in range, an image where one is drawn, a drift below the
 * temporal Nyquist limit. */
static csf_status validate_parameters(const csf_presenter *p, const csf_stimulus *s, csf_error *err)
{
    if (s->kind < CSF_STIM_GABOR || s->kind > CSF_STIM_DISC)
        return csf_error_set(err, CSF_E_INVALID_ARG, "stimulus kind %d is unknown (1 to 4)", s->kind);
    const double nums[] = {s->freq_cpd, s->orientation_deg, s->phase_deg, s->sigma_deg, s->ecc_deg,
                           s->polar_deg, s->contrast, s->mean_lum_cdm2, s->drift_hz,
                           s->velocity_dps, s->motion_dir_deg, s->radius_deg, s->edge_deg,
                           s->time_s};
    for (size_t i = 0; i < sizeof nums / sizeof nums[0]; i++)
        if (!isfinite(nums[i]))
            return csf_error_set(err, CSF_E_INVALID_ARG, "stimulus has a non-finite parameter");
    if (!(s->contrast >= 0 && s->contrast <= 1))
        return csf_error_set(err, CSF_E_INVALID_ARG, "contrast %g is outside 0 to 1 (Michelson)",
                             s->contrast);
    if (!(s->ecc_deg >= 0 && s->ecc_deg < 90))
        return csf_error_set(err, CSF_E_INVALID_ARG, "eccentricity %g deg is outside 0 to 90 deg",
                             s->ecc_deg);
    if ((s->kind == CSF_STIM_GABOR || s->kind == CSF_STIM_GRATING) &&
        !(s->freq_cpd > 0 && s->freq_cpd <= 1000))
        return csf_error_set(err, CSF_E_INVALID_ARG, "spatial frequency %g cpd is outside (0, 1000]",
                             s->freq_cpd);
    if (s->kind == CSF_STIM_GABOR && !(s->sigma_deg >= 0.02 && s->sigma_deg <= 30))
        return csf_error_set(err, CSF_E_INVALID_ARG, "Gabor sigma %g deg is outside 0.02 to 30 deg",
                             s->sigma_deg);
    if (s->radius_deg < 0 || s->radius_deg > 80 || s->edge_deg < 0 || s->edge_deg > 30)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "radius %g deg / edge %g deg outside 0 to 80 / 0 to 30 deg",
                             s->radius_deg, s->edge_deg);
    if (s->kind == CSF_STIM_IMAGE && (!s->image || !s->image->lum))
        return csf_error_set(err, CSF_E_INVALID_ARG, "image stimulus without an image");
    /* at half the refresh rate the carrier steps half a cycle per frame: a counterphase flicker
     * with no direction of motion, so the limit itself is refused too */
    if (fabs(s->drift_hz) >= 0.5 * p->refresh_hz)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "drift %g Hz is at or above the temporal Nyquist limit %g Hz (half the "
                             "refresh rate); the carrier would alias",
                             s->drift_hz, 0.5 * p->refresh_hz);
    if (fabs(s->velocity_dps) > 1000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "velocity %g deg/s is outside +-1000 deg/s",
                             s->velocity_dps);
    return CSF_OK;
}

/* The luminances the stimulus needs lie within the display's range. */
static csf_status validate_luminance(const csf_presenter *p, const csf_stimulus *s, csf_error *err)
{
    double mean = mean_lum_of(p, s);
    double lo = mean * (1 - s->contrast), hi = mean * (1 + s->contrast);
    if (s->kind == CSF_STIM_DISC) lo = mean;
    if (s->kind == CSF_STIM_IMAGE) image_lum_range(s, mean, &lo, &hi);
    if (lo < p->lum_black - 1e-9 || hi > p->lum_max + 1e-9)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "luminance %.4g to %.4g cd/m2 (mean %.4g, contrast %.4g%s) is outside the "
                             "display's range %.4g to %.4g cd/m2",
                             lo, hi, mean, s->contrast,
                             s->kind == CSF_STIM_IMAGE ? ", the image's own pixel range" : "",
                             p->lum_black, p->lum_max);
    return CSF_OK;
}

/* The patch's centre and a ring of points at its extent are on screen; *ecc, *polar get the
 * centre and *extent the patch's radius. */
static csf_status validate_placement(const csf_presenter *p, const csf_stimulus *s, double *ecc_out,
                                     double *polar_out, double *extent_out, csf_error *err)
{
    double ecc, polar;
    stim_centre(p, s, &ecc, &polar);
    if (!(ecc < 89.0))
        return csf_error_set(err, CSF_E_INVALID_ARG, "stimulus centre at %.3g deg is off-screen", ecc);
    double extent = stim_extent_deg(s);
    double cx, cy;
    double reach = csf_geometry_max_ecc(&p->geom, polar);
    if (!csf_geometry_deg_to_mm(&p->geom, ecc, polar, &cx, &cy) || !csf_geometry_on_screen(&p->geom, cx, cy))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "stimulus centre at eccentricity %.3g deg, polar angle %.3g deg is "
                             "off-screen: the screen reaches %.3g deg in that direction",
                             ecc, polar, reach);
    /* ring of points at the patch extent: all must be on screen */
    const int nring = 24;
    for (int i = 0; i < nring; i++) {
        double dir = 360.0 * i / nring, e2, p2, x, y;
        csf_geometry_move(&p->geom, ecc, polar, dir, extent, &e2, &p2);
        if (!csf_geometry_deg_to_mm(&p->geom, e2, p2, &x, &y) || !csf_geometry_on_screen(&p->geom, x, y))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "stimulus at eccentricity %.3g deg, polar angle %.3g deg with "
                                 "radius %.3g deg leaves the screen: the screen reaches %.3g deg "
                                 "in that direction, so the largest eccentricity for this patch "
                                 "there is about %.3g deg",
                                 ecc, polar, extent, reach, fmax(0.0, reach - extent));
    }
    *ecc_out = ecc;
    *polar_out = polar;
    *extent_out = extent;
    return CSF_OK;
}

/* A grating's frequency is below the local Nyquist limit everywhere inside its patch. */
static csf_status validate_nyquist(const csf_presenter *p, const csf_stimulus *s, double ecc, double polar,
                                   double extent, csf_error *err)
{
    const int nring = 24;
    if (s->kind == CSF_STIM_GABOR || s->kind == CSF_STIM_GRATING) {
        double worst = INFINITY, worst_ecc = ecc;
        for (int ring = 0; ring <= 2; ring++) {
            int n = ring == 0 ? 1 : nring;
            for (int i = 0; i < n; i++) {
                double e2 = ecc, p2 = polar, x, y;
                if (ring) csf_geometry_move(&p->geom, ecc, polar, 360.0 * i / n, extent * ring / 2.0, &e2, &p2);
                if (!csf_geometry_deg_to_mm(&p->geom, e2, p2, &x, &y)) continue;
                double ny = csf_geometry_nyquist_at(&p->geom, ecc, polar, x, y, s->orientation_deg);
                if (ny < worst) {
                    worst = ny;
                    worst_ecc = e2;
                }
            }
        }
        if (s->freq_cpd > worst)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "spatial frequency %.4g cpd exceeds the local Nyquist limit of "
                                 "%.4g cpd (0.5 cycle/pixel at orientation %.3g deg, eccentricity "
                                 "%.3g deg inside the patch); lower the frequency or increase the "
                                 "viewing distance",
                                 s->freq_cpd, worst, s->orientation_deg, worst_ecc);
    }
    return CSF_OK;
}

csf_status csf_presenter_validate(csf_presenter *p, const csf_stimulus *s, csf_error *err)
{
    if (!p || !s) return csf_error_set(err, CSF_E_INVALID_ARG, "validate: NULL argument");
    double ecc = 0, polar = 0, extent = 0;
    csf_status st = validate_parameters(p, s, err);
    if (st == CSF_OK) st = validate_luminance(p, s, err);
    if (st == CSF_OK) st = validate_placement(p, s, &ecc, &polar, &extent, err);
    if (st == CSF_OK) st = validate_nyquist(p, s, ecc, polar, extent, err);
    return st;
}

/* ---------------- drawing ---------------- */

static target main_target(const csf_presenter *p)
{
    return (target){p->fbo, p->rw, p->rh, p->rw, p->rh, 0, 0, p->frame_index};
}

static void set_common_uniforms(csf_presenter *p, int with_marks, const target *t)
{
    p->prog = with_marks ? p->prog_marks : p->prog_plain;
    p->u = with_marks ? p->u_marks : p->u_plain;
    glUseProgram(p->prog);
    glUniform2f(p->u[U_RENDER], (float)t->frame_w, (float)t->frame_h);
    glUniform2f(p->u[U_ORIGIN], (float)t->origin_x, (float)t->origin_y);
    glUniform2f(p->u[U_SCREEN], (float)p->geom.width_mm, (float)p->geom.height_mm);
    glUniform3f(p->u[U_EYE], (float)p->geom.eye_x_mm, (float)p->geom.eye_y_mm, (float)p->geom.distance_mm);
    glUniform2f(p->u[U_LUMRANGE], (float)p->lum_black, (float)p->lum_max);
    glUniform1i(p->u[U_MAXLEVEL], p->maxlevel);
    glUniform1i(p->u[U_DITHER], p->cfg.dither == CSF_DITHER_NONE ? 1
                                : p->cfg.dither == CSF_DITHER_BITSTEAL ? 2 : 0);
    /* per-frame offset: frame index plus a seed-derived start, so runs with different seeds
     * use different (but reproducible) temporal dither phases */
    glUniform1ui(p->u[U_FRAME], (GLuint)(t->frame_number + (long)(p->cfg.seed & 0xffff)));
    double c[3], h[3], v[3];
    csf_geometry_centre_basis(&p->geom, 0.0, 0.0, c, h, v);
    glUniform3f(p->u[U_FIXC], (float)c[0], (float)c[1], (float)c[2]);
    /* texture unit k holds textures[k], and its sampler uniform is told so */
    const struct {
        GLuint tex;
        int uniform;
    } textures[] = {{p->inv_tex, U_INV}, {p->fwd_tex, U_FWD}, {p->img_tex, U_IMG},
                    {p->text_tex, U_TEXT}, {p->chan_tex, U_CHAN}};
    for (int k = 0; k < (int)(sizeof textures / sizeof textures[0]); k++) {
        glActiveTexture((GLenum)(GL_TEXTURE0 + k));
        glBindTexture(GL_TEXTURE_2D, textures[k].tex);
        glUniform1i(p->u[textures[k].uniform], k);
    }
}

static void upload_image(csf_presenter *p, const csf_image *img)
{
    if (p->img_uploaded == img) return;
    size_t n = (size_t)img->width * img->height;
    float *rg = malloc(sizeof(float) * 2 * n);
    if (!rg) return;
    for (size_t i = 0; i < n; i++) {
        rg[2 * i] = img->lum[i];
        rg[2 * i + 1] = img->alpha ? img->alpha[i] : 1.0f;
    }
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, p->img_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, img->width, img->height, 0, GL_RG, GL_FLOAT, rg);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    free(rg);
    p->img_uploaded = img;
}

static void render_to(csf_presenter *p, const csf_stimulus *s, int fixation, int text_mode,
                      int n_marks, const target *t)
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->vw, t->vh);
    set_common_uniforms(p, !text_mode && n_marks > 0, t);
    int mode = MODE_BLANK;
    double mean = mean_lum_of(p, s);
    if (text_mode) {
        mode = MODE_TEXT;
    } else if (s) {
        double ecc, polar, c[3], h[3], v[3];
        stim_centre(p, s, &ecc, &polar);
        polar += p->cfg.fault_polar_offset_deg;
        csf_geometry_centre_basis(&p->geom, ecc, polar, c, h, v);
        glUniform3f(p->u[U_C], (float)c[0], (float)c[1], (float)c[2]);
        glUniform3f(p->u[U_H], (float)h[0], (float)h[1], (float)h[2]);
        glUniform3f(p->u[U_V], (float)v[0], (float)v[1], (float)v[2]);
        double phase = s->phase_deg + 360.0 * s->drift_hz * s->time_s;
        phase = fmod(phase, 360.0);
        glUniform1f(p->u[U_FREQ], (float)s->freq_cpd);
        glUniform2f(p->u[U_ORIENT], (float)cos(s->orientation_deg * DEG), (float)sin(s->orientation_deg * DEG));
        glUniform1f(p->u[U_PHASE], (float)(phase * DEG));
        glUniform1f(p->u[U_SIGMA], (float)s->sigma_deg);
        glUniform1f(p->u[U_RADIUS], (float)(s->radius_deg > 0 ? s->radius_deg : 2.0));
        glUniform1f(p->u[U_EDGE], (float)(s->edge_deg > 0 ? s->edge_deg : 0.25));
        glUniform1f(p->u[U_CONTRAST], p->cfg.fault_blank ? 0.0f : (float)s->contrast);
        mode = s->kind == CSF_STIM_GABOR ? MODE_GABOR
             : s->kind == CSF_STIM_GRATING ? MODE_GRATING
             : s->kind == CSF_STIM_DISC ? MODE_DISC : MODE_IMAGE;
        if (mode == MODE_IMAGE) {
            upload_image(p, s->image);
            glUniform1f(p->u[U_IMGMEAN], (float)s->image->mean_lum);
        }
    }
    glUniform1f(p->u[U_MEAN], (float)mean);
    glUniform1i(p->u[U_MODE], mode);
    glUniform1i(p->u[U_FIX], fixation ? 1 : 0);
    /* place marks on every stimulus and blank frame while set, never on text screens */
    int nm = text_mode ? 0 : n_marks;
    glUniform1i(p->u[U_NMARKS], nm);
    if (nm > 0) {
        glUniform3fv(p->u[U_MARKC], nm, &p->mark_c[0][0]);
        glUniform1f(p->u[U_MARKR], (float)p->mark_radius_deg);
        glUniform1f(p->u[U_MARKHW], (float)(0.5 * CSF_MARK_WIDTH_DEG));
        glUniform1f(p->u[U_MARKFRAC], (float)CSF_MARK_LUM_FRACTION);
    }
    glBindVertexArray(p->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* The caption's text pixels over the frame just drawn in t (plain program: no marks, no
 * fixation), through the same luminance mapping and dither as the frame. */
static void render_caption(csf_presenter *p, const csf_stimulus *s, const target *t)
{
    set_common_uniforms(p, 0, t);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, p->caption_tex);
    glUniform1f(p->u[U_MEAN], (float)mean_lum_of(p, s));
    glUniform1i(p->u[U_MODE], MODE_CAPTION);
    glUniform1i(p->u[U_FIX], 0);
    glUniform1i(p->u[U_NMARKS], 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

static void render(csf_presenter *p, const csf_stimulus *s, int fixation, int text_mode)
{
    target t = main_target(p);
    render_to(p, s, fixation, text_mode, p->n_marks, &t);
    if (p->caption_on && !text_mode) render_caption(p, s, &t);
}

static int injected_periods(csf_presenter *p, long frame)
{
    int extra = 0;
    for (int i = 0; i < p->n_inject; i++)
        if (p->inject[i].frame == frame) extra += p->inject[i].periods;
    if (p->miss_prob > 0 && csf_rng_uniform(p->cfg.seed, RNG_STREAM_MISS, (uint64_t)frame) < p->miss_prob)
        extra += 1;
    return extra;
}

/* When the next frame will be on screen: exact on the virtual clock (injected misses included),
 * one period after the last frame in a window (vsync). */
static double next_frame_time(csf_presenter *p)
{
    if (!p->have_frame) return 0.0;
    if (p->headless) return p->t_last + (1 + injected_periods(p, p->frame_index)) / p->refresh_hz;
    return p->t_last + 1.0 / p->refresh_hz;
}

double csf_presenter_next_frame_time(csf_presenter *p)
{
    return p ? next_frame_time(p) : 0.0;
}

long csf_presenter_frame_index(const csf_presenter *p)
{
    return p ? p->frame_index : 0;
}

/* Presents the rendered frame (or only the clock when nothing was rendered) and fills fi. */
static void present(csf_presenter *p, int rendered, csf_frame_info *fi)
{
    double t;
    if (p->headless) {
        if (rendered) glFinish();
        t = next_frame_time(p);
    } else {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, p->fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glBlitFramebuffer(0, 0, p->rw, p->rh, 0, 0, p->rw, p->rh, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glfwSwapBuffers(p->win);
        glFinish();
        glfwPollEvents();
        double now = now_monotonic();
        if (!p->have_frame) p->t0_real = now;
        t = now - p->t0_real;
    }
    fi->frame_index = p->frame_index;
    fi->t_s = t;
    fi->interval_s = p->have_frame ? t - p->t_last : 0.0;
    fi->missed = p->have_frame && fi->interval_s > 1.5 / p->refresh_hz;
    fi->rendered = rendered;
    p->t_last = t;
    p->have_frame = 1;
    p->frame_index++;
    p->last_rendered = rendered;
}

static int should_render(const csf_presenter *p)
{
    if (!p->headless) return 1;
    int every = p->cfg.render_every;
    if (every < 0) return 0;
    if (every <= 1) return 1;
    return p->frame_index % every == 0;
}

static csf_status draw_frame(csf_presenter *p, const csf_stimulus *s, int fixation,
                             csf_frame_info *out, csf_error *err);

csf_status csf_presenter_draw(csf_presenter *p, const csf_stimulus *s, int fixation,
                              csf_frame_info *out, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "draw: NULL presenter");
    if (s) {
        csf_status st = csf_presenter_validate(p, s, err);
        if (st) return st;
    }
    return draw_frame(p, s, fixation, out, err);
}

/* Draws without validation: run_trial validates the whole trial once (contrast never exceeds the
 * validated peak, and a moving patch's path is checked at both ends). */
static csf_status draw_frame(csf_presenter *p, const csf_stimulus *s, int fixation,
                             csf_frame_info *out, csf_error *err)
{
    if (!p->headless && glfwWindowShouldClose(p->win))
        return csf_error_set(err, CSF_E_ABORTED, "the stimulus window was closed");
    int r = should_render(p);
    p->last_kind = 1;
    p->last_has_stim = s != NULL;
    if (s) p->last_stim = *s;
    p->last_fix = fixation;
    p->last_n_marks = p->n_marks;
    p->last_frame_number = p->frame_index;
    if (r) render(p, s, fixation, 0);
    csf_frame_info fi;
    present(p, r, &fi);
    fi.contrast_shown = s ? s->contrast : 0.0;
    if (r && glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error while drawing frame %ld",
                             fi.frame_index);
    if (out) *out = fi;
    if (p->frame_hook) p->frame_hook(p->frame_hook_ctx, p, &fi);
    return CSF_OK;
}

csf_status csf_presenter_draw_clear(csf_presenter *p, csf_frame_info *out, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "draw_clear: NULL presenter");
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
    glViewport(0, 0, p->rw, p->rh);
    glClearColor(0.5f, 0.5f, 0.5f, 1.0f); /* a cost baseline, not a calibrated grey */
    p->last_kind = 0;
    glClear(GL_COLOR_BUFFER_BIT);
    csf_frame_info fi;
    present(p, 1, &fi);
    fi.contrast_shown = 0;
    if (out) *out = fi;
    return glGetError() == GL_NO_ERROR ? CSF_OK
                                       : csf_error_set(err, CSF_E_DEVICE, "OpenGL error in a clear frame");
}

/* ---------------- place marks ---------------- */

/* The shader declares its mark arrays with this size. */
_Static_assert(CSF_PRESENTER_MAX_MARKS == 8, "fs_src declares u_markc[8]: keep them equal");

csf_status csf_presenter_set_marks(csf_presenter *p, int n, const double *ecc_deg,
                                   const double *polar_deg, double radius_deg, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "place marks: NULL presenter");
    if (n < 0 || n > CSF_PRESENTER_MAX_MARKS)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "place marks: %d marks requested; the number must be 0 to %d", n,
                             CSF_PRESENTER_MAX_MARKS);
    if (n == 0) {
        p->n_marks = 0;
        return CSF_OK;
    }
    if (!ecc_deg || !polar_deg)
        return csf_error_set(err, CSF_E_INVALID_ARG, "place marks: NULL eccentricity or polar angle list");
    if (!(radius_deg > 0 && radius_deg <= CSF_MARK_MAX_RADIUS_DEG))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "place marks: ring radius %g deg is outside (0, %g] deg", radius_deg,
                             (double)CSF_MARK_MAX_RADIUS_DEG);
    float c[CSF_PRESENTER_MAX_MARKS][3];
    for (int i = 0; i < n; i++) {
        double e = ecc_deg[i], a = polar_deg[i];
        if (!isfinite(e) || !isfinite(a))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "place mark %d: eccentricity %g deg / polar angle %g deg must be finite",
                                 i, e, a);
        if (!(e >= 0 && e < 90))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "place mark %d: eccentricity %g deg is outside 0 to 90 deg", i, e);
        double x, y;
        if (!csf_geometry_deg_to_mm(&p->geom, e, a, &x, &y) || !csf_geometry_on_screen(&p->geom, x, y))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "place mark %d at eccentricity %.3g deg, polar angle %.3g deg is "
                                 "off-screen: the screen reaches %.3g deg in that direction",
                                 i, e, a, csf_geometry_max_ecc(&p->geom, a));
        double cd[3], h[3], v[3];
        csf_geometry_centre_basis(&p->geom, e, a, cd, h, v);
        for (int k = 0; k < 3; k++) c[i][k] = (float)cd[k];
    }
    /* all checked: replace the set (a refused call leaves the previous marks as they were) */
    memcpy(p->mark_c, c, sizeof(float) * 3 * (size_t)n);
    p->mark_radius_deg = radius_deg;
    p->n_marks = n;
    return CSF_OK;
}

int csf_presenter_mark_count(const csf_presenter *p) { return p ? p->n_marks : 0; }

/* ---------------- measurement patches ---------------- */

/* Patch rectangle in render pixels, GL convention (x0, y0 from the bottom-left; x1, y1 exclusive). */
static csf_status patch_rect_gl(const csf_presenter *p, const csf_patch *m, int r[4], csf_error *err)
{
    if (!m) return csf_error_set(err, CSF_E_INVALID_ARG, "patch: NULL patch");
    for (int c = 0; c < 3; c++)
        if (!(m->drive01[c] >= 0 && m->drive01[c] <= 1) || !(m->bg_drive01[c] >= 0 && m->bg_drive01[c] <= 1))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "patch: drive values must lie in [0, 1] (patch %g %g %g, background %g %g %g)",
                                 m->drive01[0], m->drive01[1], m->drive01[2], m->bg_drive01[0],
                                 m->bg_drive01[1], m->bg_drive01[2]);
    if (!(m->size_deg >= 0 && m->size_deg < 180) || !(m->screen_fraction >= 0 && m->screen_fraction <= 1))
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "patch: size %g deg / screen fraction %g out of range (0 to 180 deg, 0 to 1)",
                             m->size_deg, m->screen_fraction);
    double side_mm;
    if (m->size_deg > 0) {
        side_mm = 2.0 * p->geom.distance_mm * tan(0.5 * m->size_deg * DEG);
        double fit = fmin(p->geom.width_mm, p->geom.height_mm);
        if (side_mm > fit * (1 + 1e-9))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "patch: %g deg is %.1f mm at %.0f mm, larger than the screen's %.1f mm "
                                 "(use a smaller size or the full field)",
                                 m->size_deg, side_mm, p->geom.distance_mm, fit);
    } else if (m->screen_fraction > 0) {
        side_mm = m->screen_fraction * p->geom.height_mm;
    } else {
        r[0] = 0, r[1] = 0, r[2] = p->rw, r[3] = p->rh; /* full field */
        return CSF_OK;
    }
    int w = (int)lround(side_mm / p->geom.width_mm * p->rw);
    int h = (int)lround(side_mm / p->geom.height_mm * p->rh);
    if (w < 1) w = 1;
    if (h < 1) h = 1;
    if (w > p->rw) w = p->rw;
    if (h > p->rh) h = p->rh;
    r[0] = (p->rw - w) / 2;
    r[1] = (p->rh - h) / 2;
    r[2] = r[0] + w;
    r[3] = r[1] + h;
    return CSF_OK;
}

csf_status csf_presenter_patch_rect(const csf_presenter *p, const csf_patch *m, int *x, int *y, int *w,
                                    int *h, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "patch_rect: NULL presenter");
    int r[4] = {0, 0, 0, 0};
    csf_status st = patch_rect_gl(p, m, r, err);
    if (st) return st;
    if (x) *x = r[0];
    if (y) *y = p->rh - r[3]; /* top row first, as the readback */
    if (w) *w = r[2] - r[0];
    if (h) *h = r[3] - r[1];
    return CSF_OK;
}

void csf_presenter_set_frame_index(csf_presenter *p, long frame_index)
{
    if (p && frame_index >= 0) p->frame_index = frame_index;
}

/* The patch pass of a measurement frame (no present). */
static void patch_pass(csf_presenter *p, const csf_patch *m, const int r[4])
{
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
    glViewport(0, 0, p->rw, p->rh);
    target t = main_target(p);
    set_common_uniforms(p, 0, &t);
    p->last_kind = 0;
    double ml = (double)p->maxlevel;
    glUniform3f(p->u[U_DRIVE], (float)(m->drive01[0] * ml), (float)(m->drive01[1] * ml),
                (float)(m->drive01[2] * ml));
    glUniform3f(p->u[U_BGDRIVE], (float)(m->bg_drive01[0] * ml), (float)(m->bg_drive01[1] * ml),
                (float)(m->bg_drive01[2] * ml));
    glUniform4f(p->u[U_RECT], (float)r[0], (float)r[1], (float)r[2], (float)r[3]);
    glUniform1i(p->u[U_MODE], MODE_PATCH);
    glUniform1i(p->u[U_FIX], 0);
    glBindVertexArray(p->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

csf_status csf_presenter_draw_patch(csf_presenter *p, const csf_patch *m, csf_frame_info *out, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "draw_patch: NULL presenter");
    int r[4] = {0, 0, 0, 0};
    csf_status st = patch_rect_gl(p, m, r, err);
    if (st) return st;
    if (!p->headless && glfwWindowShouldClose(p->win))
        return csf_error_set(err, CSF_E_ABORTED, "the stimulus window was closed");
    patch_pass(p, m, r);
    csf_frame_info fi;
    present(p, 1, &fi);
    fi.contrast_shown = 0;
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error while drawing patch frame %ld",
                             fi.frame_index);
    if (out) *out = fi;
    return CSF_OK;
}

static cairo_t *text_canvas(const csf_presenter *p, double size, cairo_surface_t **surf);
static void upload_coverage(csf_presenter *p, GLuint tex, cairo_t *cr, cairo_surface_t *surf);

/* The placement overlay's coverage: a target mark at the patch centre (a ring and a cross, sized
 * to the patch so it stays inside it) and the text lines at the top left. */
static cairo_t *placement_canvas(const csf_presenter *p, const int r[4], const char *text,
                                 cairo_surface_t **surf)
{
    double size = fmax(10.0, p->rh / 24.0);
    cairo_t *cr = text_canvas(p, size, surf);
    if (!cr) return NULL;
    double cx = 0.5 * (r[0] + r[2]), cy = p->rh - 0.5 * (r[1] + r[3]); /* cairo: y down */
    double half = 0.5 * fmin(r[2] - r[0], r[3] - r[1]);
    double lw = fmax(1.0, half / 25);
    cairo_set_line_width(cr, lw);
    cairo_arc(cr, cx, cy, 0.35 * half, 0, 2 * M_PI);
    cairo_stroke(cr);
    cairo_move_to(cr, cx - 0.6 * half, cy);
    cairo_line_to(cr, cx + 0.6 * half, cy);
    cairo_move_to(cr, cx, cy - 0.6 * half);
    cairo_line_to(cr, cx, cy + 0.6 * half);
    cairo_stroke(cr);
    const char *line = text ? text : "";
    for (int i = 0; *line && i < 8; i++) {
        const char *nl = strchr(line, '\n');
        size_t len = nl ? (size_t)(nl - line) : strlen(line);
        char buf[256];
        if (len >= sizeof buf) len = sizeof buf - 1;
        memcpy(buf, line, len);
        buf[len] = 0;
        cairo_move_to(cr, 0.6 * size, (1.3 + 1.4 * i) * size);
        cairo_show_text(cr, buf);
        line = nl ? nl + 1 : line + len;
    }
    return cr;
}

csf_status csf_presenter_draw_placement(csf_presenter *p, const csf_patch *m, const char *text,
                                        csf_frame_info *out, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "draw_placement: NULL presenter");
    int r[4] = {0, 0, 0, 0};
    csf_status st = patch_rect_gl(p, m, r, err);
    if (st) return st;
    if (!p->headless && glfwWindowShouldClose(p->win))
        return csf_error_set(err, CSF_E_ABORTED, "the stimulus window was closed");
    cairo_surface_t *surf;
    cairo_t *cr = placement_canvas(p, r, text, &surf);
    if (!cr)
        return csf_error_set(err, CSF_E_NOMEM, "cairo could not create a %dx%d placement surface", p->rw,
                             p->rh);
    upload_coverage(p, p->text_tex, cr, surf);
    patch_pass(p, m, r);
    /* the overlay in the caption's dark ink, over the patch and its surround alike */
    target t = main_target(p);
    set_common_uniforms(p, 0, &t);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, p->text_tex);
    glUniform1f(p->u[U_MEAN], (float)mean_lum_of(p, NULL));
    glUniform1i(p->u[U_MODE], MODE_CAPTION);
    glUniform1i(p->u[U_FIX], 0);
    glUniform1i(p->u[U_NMARKS], 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    csf_frame_info fi;
    present(p, 1, &fi);
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error drawing the placement screen");
    if (out) *out = fi;
    return CSF_OK;
}

/* ---------------- envelopes and trials ---------------- */

double csf_envelope_contrast(const csf_envelope *e, double peak, double t)
{
    if (!e) return peak;
    if (t < 0 || t >= e->duration_s) return 0.0;
    switch (e->kind) {
    case CSF_ENV_RAISED_COSINE: {
        double r = e->ramp_s;
        if (r <= 0) return peak;
        if (2 * r > e->duration_s) r = 0.5 * e->duration_s;
        double w = 1.0;
        if (t < r) w = 0.5 - 0.5 * cos(M_PI * t / r);
        else if (t > e->duration_s - r) w = 0.5 - 0.5 * cos(M_PI * (e->duration_s - t) / r);
        return peak * w;
    }
    case CSF_ENV_FADE_LOG: {
        if (e->start_contrast <= 0 || peak <= 0) return peak;
        double l0 = log10(e->start_contrast), l1 = log10(peak);
        return pow(10.0, l0 + (l1 - l0) * t / e->duration_s);
    }
    default: return peak;
    }
}

void csf_trial_record_free(csf_trial_record *r)
{
    if (!r) return;
    free(r->contrast_per_period);
    free(r->interval_s);
    r->contrast_per_period = NULL;
    r->interval_s = NULL;
}

static int push_d(double **arr, int *n, int *cap, double v)
{
    if (*n == *cap) {
        int nc = *cap ? *cap * 2 : 64;
        double *a = realloc(*arr, sizeof(double) * (size_t)nc);
        if (!a) return -1;
        *arr = a;
        *cap = nc;
    }
    (*arr)[(*n)++] = v;
    return 0;
}

/* What a trial has drawn and recorded so far, carried from its stimulus frames to its blank
 * offset frame and into the record's summary. */
typedef struct {
    csf_presenter *p;
    csf_trial_record *out;
    int ncap, icap, nper, nint;
    double onset, last_c;
    int drawn, missed, stopped;
} trial_run;

/* The arguments and the whole path of a moving patch are checked before anything is shown. */
static csf_status check_trial(csf_presenter *p, const csf_stimulus *s, const csf_envelope *env,
                              csf_error *err)
{
    if (!(env->duration_s > 0 && env->duration_s <= 600))
        return csf_error_set(err, CSF_E_INVALID_ARG, "trial duration %g s is outside (0, 600] s",
                             env->duration_s);
    if (env->kind == CSF_ENV_FADE_LOG && !(env->start_contrast > 0 && env->start_contrast <= s->contrast))
        return csf_error_set(err, CSF_E_INVALID_ARG, "fade start contrast %g must be in (0, end contrast %g]",
                             env->start_contrast, s->contrast);
    csf_stimulus st = *s;
    st.time_s = 0;
    csf_status rc = csf_presenter_validate(p, &st, err);
    if (rc) return rc;
    if (s->velocity_dps != 0) {
        st.time_s = env->duration_s;
        rc = csf_presenter_validate(p, &st, err);
        if (rc) return rc;
    }
    return CSF_OK;
}

/* The image before frame fi stayed on screen for a whole number of periods at contrast last_c.
 * Returns -1 out of memory. */
static int record_held(trial_run *r, const csf_frame_info *fi)
{
    int held = (int)lround(fi->interval_s * r->p->refresh_hz);
    if (held < 1) held = 1;
    for (int k = 0; k < held; k++)
        if (push_d(&r->out->contrast_per_period, &r->nper, &r->ncap, r->last_c)) return -1;
    if (push_d(&r->out->interval_s, &r->nint, &r->icap, fi->interval_s)) return -1;
    if (fi->missed) r->missed++;
    return 0;
}

static csf_status trial_nomem(csf_error *err)
{
    return csf_error_set(err, CSF_E_NOMEM, "out of memory recording a trial");
}

/* The stimulus frames until the envelope's duration or the stop callback, then a blank frame
 * that ends the last of them. */
static csf_status draw_trial_frames(trial_run *r, const csf_stimulus *s, const csf_envelope *env,
                                    int fixation, csf_trial_stop_fn stop, void *stop_ctx, csf_error *err)
{
    csf_presenter *p = r->p;
    double period = 1.0 / p->refresh_hz;
    csf_stimulus st = *s;
    csf_status rc;
    for (;;) {
        /* predicted time of this frame on the presenter's clock */
        double t_pred = r->drawn == 0 ? 0.0 : next_frame_time(p) - r->onset;
        if (r->drawn > 0 && t_pred >= env->duration_s - 0.5 * period) break;
        st.time_s = t_pred;
        st.contrast = csf_envelope_contrast(env, s->contrast, t_pred);
        csf_frame_info fi;
        rc = draw_frame(p, &st, fixation, &fi, err);
        if (rc) return rc;
        if (r->drawn == 0) r->onset = fi.t_s;
        else if (record_held(r, &fi)) return trial_nomem(err);
        /* what is on screen is what was drawn for this frame's (predicted = actual) time */
        r->last_c = st.contrast;
        r->drawn++;
        if (stop && stop(stop_ctx, &(csf_frame_info){fi.frame_index, fi.t_s, fi.interval_s, fi.missed,
                                                     fi.rendered, r->last_c})) {
            r->stopped = 1;
            break;
        }
    }
    /* offset: a blank frame ends the last stimulus frame */
    csf_frame_info fi;
    rc = draw_frame(p, NULL, fixation, &fi, err);
    if (rc) return rc;
    if (record_held(r, &fi)) return trial_nomem(err);
    r->out->t_end_s = fi.t_s;
    return CSF_OK;
}

/* The record's figures and its deviation flags from the periods actually shown. */
static void summarise_trial(const trial_run *r, const csf_stimulus *s, const csf_envelope *env)
{
    csf_trial_record *out = r->out;
    double period = 1.0 / r->p->refresh_hz;
    int nper = r->nper;
    double sum = 0, maxc = 0, maxdev = 0;
    for (int j = 0; j < nper; j++) {
        double c = out->contrast_per_period[j];
        sum += c;
        if (c > maxc) maxc = c;
        double dev = fabs(c - csf_envelope_contrast(env, s->contrast, j * period));
        if (dev > maxdev) maxdev = dev;
    }
    out->frames_shown = nper;
    out->frames_drawn = r->drawn + 1;
    out->frames_missed = r->missed;
    out->contrast_shown_mean = nper ? sum / nper : 0;
    out->contrast_shown_max = maxc;
    out->contrast_shown_last = r->last_c;
    out->max_abs_deviation = maxdev;
    out->t_onset_s = r->onset;
    out->stopped_by_callback = r->stopped;
    out->flags[0] = '\0';
    if (r->missed > 0) {
        out->deviated = 1;
        snprintf(out->flags, sizeof out->flags, "missed_frames");
    }
    /* relative deviation against the planned contrast of the same period */
    for (int j = 0; j < nper; j++) {
        double planned = csf_envelope_contrast(env, s->contrast, j * period);
        double c = out->contrast_per_period[j];
        if (fabs(c - planned) > 0.01 * fmax(planned, 1e-6) && (planned > 0 || c > 0)) {
            /* the last planned period may legitimately be cut by a response */
            out->deviated = 1;
            size_t L = strlen(out->flags);
            snprintf(out->flags + L, sizeof out->flags - L, "%scontrast_dev", L ? "," : "");
            break;
        }
    }
    if (!r->stopped && nper != out->frames_planned) {
        out->deviated = 1;
        size_t L = strlen(out->flags);
        snprintf(out->flags + L, sizeof out->flags - L, "%sduration", L ? "," : "");
    }
}

csf_status csf_presenter_run_trial(csf_presenter *p, const csf_stimulus *s, const csf_envelope *env,
                                   int fixation, csf_trial_stop_fn stop, void *stop_ctx,
                                   csf_trial_record *out, csf_error *err)
{
    if (!p || !s || !env || !out) return csf_error_set(err, CSF_E_INVALID_ARG, "run_trial: NULL argument");
    memset(out, 0, sizeof *out);
    csf_status rc = check_trial(p, s, env, err);
    if (rc) return rc;
    out->frames_planned = (int)lround(env->duration_s * p->refresh_hz);
    trial_run r = {.p = p, .out = out};
    rc = draw_trial_frames(&r, s, env, fixation, stop, stop_ctx, err);
    if (rc) {
        csf_trial_record_free(out);
        return rc;
    }
    summarise_trial(&r, s, env);
    return CSF_OK;
}

csf_status csf_presenter_inject_missed(csf_presenter *p, long frame_index, int periods, csf_error *err)
{
    if (!p->headless)
        return csf_error_set(err, CSF_E_UNSUPPORTED, "missed frames can only be injected headless");
    if (periods < 1 || periods > 1000)
        return csf_error_set(err, CSF_E_INVALID_ARG, "injected delay %d periods is outside 1 to 1000", periods);
    if (p->n_inject >= MAX_INJECT)
        return csf_error_set(err, CSF_E_INVALID_ARG, "at most %d injected missed frames", MAX_INJECT);
    p->inject[p->n_inject].frame = frame_index;
    p->inject[p->n_inject].periods = periods;
    p->n_inject++;
    return CSF_OK;
}

void csf_presenter_set_miss_rate(csf_presenter *p, double probability)
{
    if (p && p->headless) p->miss_prob = probability < 0 ? 0 : probability > 1 ? 1 : probability;
}

/* ---------------- readback and properties ---------------- */

void csf_presenter_render_size(const csf_presenter *p, int *w, int *h)
{
    if (w) *w = p->rw;
    if (h) *h = p->rh;
}

int csf_presenter_bits(const csf_presenter *p) { return p->bits; }

csf_status csf_presenter_readback_levels(csf_presenter *p, uint16_t *rgb, csf_error *err)
{
    if (!p || !rgb) return csf_error_set(err, CSF_E_INVALID_ARG, "readback: NULL argument");
    if (!p->last_rendered)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "readback: the last frame was not rasterised (render_every)");
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    size_t row = (size_t)p->rw * 3;
    uint16_t *tmp = malloc(sizeof(uint16_t) * row * (size_t)p->rh);
    if (!tmp) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    glReadPixels(0, 0, p->rw, p->rh, GL_RGB, GL_UNSIGNED_SHORT, tmp);
    for (int y = 0; y < p->rh; y++) {
        const uint16_t *src = tmp + (size_t)(p->rh - 1 - y) * row;
        uint16_t *dst = rgb + (size_t)y * row;
        for (size_t i = 0; i < row; i++)
            dst[i] = (uint16_t)((src[i] * (uint32_t)p->maxlevel + 32767u) / 65535u);
    }
    free(tmp);
    if (glGetError() != GL_NO_ERROR) return csf_error_set(err, CSF_E_DEVICE, "glReadPixels failed");
    return CSF_OK;
}

void csf_presenter_set_frame_hook(csf_presenter *p, csf_frame_hook fn, void *ctx)
{
    if (!p) return;
    p->frame_hook = fn;
    p->frame_hook_ctx = fn ? ctx : NULL;
}

/* Grows the full-resolution region target to at least w x h. */
static csf_status region_target(csf_presenter *p, int w, int h, csf_error *err)
{
    if (p->region_fbo && w <= p->region_w && h <= p->region_h) return CSF_OK;
    int nw = w > p->region_w ? w : p->region_w, nh = h > p->region_h ? h : p->region_h;
    if (!p->region_tex) glGenTextures(1, &p->region_tex);
    glBindTexture(GL_TEXTURE_2D, p->region_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, p->bits == 10 ? GL_RGB10_A2 : GL_RGBA8, nw, nh, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    if (!p->region_fbo) glGenFramebuffers(1, &p->region_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, p->region_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, p->region_tex, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return csf_error_set(err, CSF_E_UNSUPPORTED, "readback region: a %dx%d framebuffer is not supported",
                             nw, nh);
    p->region_w = nw;
    p->region_h = nh;
    return CSF_OK;
}

csf_status csf_presenter_readback_region(csf_presenter *p, int x, int y, int w, int h, uint16_t *rgb,
                                         csf_error *err)
{
    if (!p || !rgb) return csf_error_set(err, CSF_E_INVALID_ARG, "readback region: NULL argument");
    int W = p->geom.width_px, H = p->geom.height_px;
    if (w < 1 || h < 1 || w > CSF_REGION_MAX_PX || h > CSF_REGION_MAX_PX || x < 0 || y < 0 || x > W - w ||
        y > H - h)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "readback region %dx%d at (%d, %d) is not inside the %dx%d px screen or is "
                             "larger than %d px a side", w, h, x, y, W, H, CSF_REGION_MAX_PX);
    if (p->last_kind != 1)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "readback region: the last frame was not a stimulus or blank frame");
    csf_status st = region_target(p, w, h, err);
    if (st) return st;
    target t = {p->region_fbo, w, h, W, H, x, H - y - h, p->last_frame_number};
    render_to(p, p->last_has_stim ? &p->last_stim : NULL, p->last_fix, 0, p->last_n_marks, &t);
    glBindFramebuffer(GL_FRAMEBUFFER, p->region_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    size_t row = (size_t)w * 3;
    uint16_t *tmp = malloc(sizeof(uint16_t) * row * (size_t)h);
    if (!tmp) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_SHORT, tmp);
    for (int j = 0; j < h; j++) {
        const uint16_t *src = tmp + (size_t)(h - 1 - j) * row;
        uint16_t *dst = rgb + (size_t)j * row;
        for (size_t i = 0; i < row; i++)
            dst[i] = (uint16_t)((src[i] * (uint32_t)p->maxlevel + 32767u) / 65535u);
    }
    free(tmp);
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error reading back a region");
    return CSF_OK;
}

csf_status csf_presenter_readback_rgb8(csf_presenter *p, unsigned char *rgb, csf_error *err)
{
    size_t n = (size_t)p->rw * p->rh * 3;
    uint16_t *lv = calloc(n, sizeof(uint16_t)); /* zeroed: a failed read-back leaves no garbage */
    if (!lv) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = csf_presenter_readback_levels(p, lv, err);
    if (!st)
        for (size_t i = 0; i < n; i++)
            rgb[i] = (unsigned char)((lv[i] * 255u + (unsigned)p->maxlevel / 2) / (unsigned)p->maxlevel);
    free(lv);
    return st;
}

double csf_presenter_level_lum(const csf_presenter *p, int level)
{
    if (level < 0) level = 0;
    if (level > p->maxlevel) level = p->maxlevel;
    return p->level_lum[level];
}

void csf_presenter_lum_range(const csf_presenter *p, double *black, double *max)
{
    if (black) *black = p->lum_black;
    if (max) *max = p->lum_max;
}

const char *csf_presenter_profile_id(const csf_presenter *p) { return p->profile_id; }
const csf_geometry *csf_presenter_geometry(const csf_presenter *p) { return &p->geom; }
double csf_presenter_refresh_hz(const csf_presenter *p) { return p->refresh_hz; }

double csf_presenter_time(const csf_presenter *p)
{
    if (p->headless || !p->have_frame) return p->have_frame ? p->t_last : 0.0;
    return now_monotonic() - p->t0_real;
}

void *csf_presenter_window(csf_presenter *p) { return p ? (void *)p->win : NULL; }

void csf_presenter_show_cursor(csf_presenter *p, int show)
{
    if (p && p->win)
        glfwSetInputMode(p->win, GLFW_CURSOR, show ? GLFW_CURSOR_NORMAL : GLFW_CURSOR_HIDDEN);
}

/* A cairo A8 surface of the render size with a context set up for black text of the given size
 * (sans-serif); NULL when cairo cannot make one. */
static cairo_t *text_canvas(const csf_presenter *p, double size, cairo_surface_t **surf)
{
    *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, p->rw, p->rh);
    if (cairo_surface_status(*surf) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(*surf);
        *surf = NULL;
        return NULL;
    }
    cairo_t *cr = cairo_create(*surf);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_set_source_rgba(cr, 0, 0, 0, 1);
    return cr;
}

/* The surface's coverage as the R8 texture tex (nearest sampling); destroys cr and surf. */
static void upload_coverage(csf_presenter *p, GLuint tex, cairo_t *cr, cairo_surface_t *surf)
{
    cairo_destroy(cr);
    cairo_surface_flush(surf);
    int stride = cairo_image_surface_get_stride(surf);
    const unsigned char *data = cairo_image_surface_get_data(surf);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, stride);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, p->rw, p->rh, 0, GL_RED, GL_UNSIGNED_BYTE, data);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    cairo_surface_destroy(surf);
}

csf_status csf_presenter_text_screen(csf_presenter *p, const char *text, csf_error *err)
{
    if (!p || !text) return csf_error_set(err, CSF_E_INVALID_ARG, "text screen: NULL argument");
    /* Callers wait on text screens for a key: a closed window must end the wait as draw does. */
    if (!p->headless && glfwWindowShouldClose(p->win))
        return csf_error_set(err, CSF_E_ABORTED, "the stimulus window was closed");
    double size = p->rh / 30.0;
    if (size < 8) size = 8;
    cairo_surface_t *surf;
    cairo_t *cr = text_canvas(p, size, &surf);
    if (!cr)
        return csf_error_set(err, CSF_E_NOMEM, "cairo could not create a %dx%d text surface", p->rw, p->rh);
    /* count lines, then draw each centred */
    int nlines = 1;
    for (const char *c = text; *c; c++) nlines += *c == '\n';
    double lh = size * 1.4, y0 = 0.5 * p->rh - 0.5 * lh * (nlines - 1);
    const char *line = text;
    for (int i = 0; i < nlines; i++) {
        const char *nl = strchr(line, '\n');
        size_t len = nl ? (size_t)(nl - line) : strlen(line);
        char buf[512];
        if (len >= sizeof buf) len = sizeof buf - 1;
        memcpy(buf, line, len);
        buf[len] = '\0';
        cairo_text_extents_t ext;
        cairo_text_extents(cr, buf, &ext);
        cairo_move_to(cr, 0.5 * p->rw - (ext.width / 2 + ext.x_bearing), y0 + i * lh);
        cairo_show_text(cr, buf);
        line = nl ? nl + 1 : line + len;
    }
    upload_coverage(p, p->text_tex, cr, surf);
    render(p, NULL, 0, 1);
    p->last_kind = 0;
    csf_frame_info fi;
    present(p, 1, &fi);
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error drawing the text screen");
    return CSF_OK;
}

csf_status csf_presenter_set_caption(csf_presenter *p, const char *text, csf_error *err)
{
    if (!p) return csf_error_set(err, CSF_E_INVALID_ARG, "caption: NULL presenter");
    if (!text || !text[0]) {
        p->caption_on = 0;
        return CSF_OK;
    }
    if (strlen(text) > CSF_CAPTION_MAX_CHARS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "caption of %zu characters is longer than %d",
                             strlen(text), CSF_CAPTION_MAX_CHARS);
    if (strchr(text, '\n'))
        return csf_error_set(err, CSF_E_INVALID_ARG, "a caption is one line (no newline)");
    double size = fmax(8.0, p->rh / 45.0);
    cairo_surface_t *surf;
    cairo_t *cr = text_canvas(p, size, &surf);
    if (!cr)
        return csf_error_set(err, CSF_E_NOMEM, "cairo could not create a %dx%d caption surface", p->rw,
                             p->rh);
    cairo_move_to(cr, 0.5 * size, 1.2 * size);
    cairo_show_text(cr, text);
    upload_coverage(p, p->caption_tex, cr, surf);
    p->caption_on = 1;
    if (glGetError() != GL_NO_ERROR)
        return csf_error_set(err, CSF_E_DEVICE, "OpenGL reported an error setting the caption");
    return CSF_OK;
}
