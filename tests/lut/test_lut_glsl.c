/* The exported GLSL gives the library's numbers (PREFIX_threshold, and PREFIX_threshold3 of a
 * table with a velocity axis): each function is compiled into a fragment shader
 * on an EGL surfaceless context (Mesa llvmpipe on CI), evaluated for 64x64 queries read from a
 * float texture, written to a float framebuffer and read back; compared to csflut_threshold at
 * the same float inputs to 1e-5 relative (float32), never-visible as +inf. Twice: as GLSL 3.30
 * core on an OpenGL 3.3 core context, and as GLSL ES 3.00 on an OpenGL ES 3.0 context with the
 * export straight after #version (an ES fragment shader has no default float precision; the
 * export sets highp under #ifdef GL_ES). */
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/check.h"
#include "tests/lut/lut_fixture.h"

enum { W = 64, H = 64 };

static const char *vs_body = "void main() {\n"
                             "    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n"
                             "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
                             "}\n";

static GLuint compile(GLenum kind, const char *src)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "shader compile failed:\n%s\n", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

/* Renders prefix_threshold for the queries; out gets W*H floats. es: GLSL ES 3.00 on an ES
 * context, the export first after #version (nothing sets a precision before it); else GLSL 3.30
 * core. Returns 0 on success. */
static int run_shader(const char *glsl, const char *prefix, const float *q, float *out, int es, int three)
{
    size_t n = strlen(glsl) + 1024;
    char *fs = malloc(n), vs[512], call[128];
    /* q holds (freq, ecc, velocity, unused) per texel */
    if (three) snprintf(call, sizeof call, "%s_threshold3(fe.x, fe.y, fe.z)", prefix);
    else snprintf(call, sizeof call, "%s_threshold(fe.x, fe.y)", prefix);
    if (es)
        snprintf(fs, n,
                 "#version 300 es\n%s\nuniform highp sampler2D q;\nout vec4 o;\n"
                 "void main() {\n"
                 "    vec4 fe = texelFetch(q, ivec2(gl_FragCoord.xy), 0);\n"
                 "    o = vec4(%s, 0.0, 0.0, 1.0);\n"
                 "}\n",
                 glsl, call);
    else
        snprintf(fs, n,
                 "#version 330 core\nuniform sampler2D q;\nout vec4 o;\n%s\n"
                 "void main() {\n"
                 "    vec4 fe = texelFetch(q, ivec2(gl_FragCoord.xy), 0);\n"
                 "    o = vec4(%s, 0.0, 0.0, 1.0);\n"
                 "}\n",
                 glsl, call);
    snprintf(vs, sizeof vs, "%s\n%s", es ? "#version 300 es" : "#version 330 core", vs_body);
    GLuint v = compile(GL_VERTEX_SHADER, vs), f = compile(GL_FRAGMENT_SHADER, fs);
    free(fs);
    if (!v || !f) return -1;
    GLuint prog = glCreateProgram();
    glAttachShader(prog, v);
    glAttachShader(prog, f);
    glLinkProgram(prog);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) return -1;
    GLuint tex[2], fbo, vao;
    glGenTextures(2, tex);
    glBindTexture(GL_TEXTURE_2D, tex[0]);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, W, H, 0, GL_RGBA, GL_FLOAT, q);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, tex[1]);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, W, H, 0, GL_RGBA, GL_FLOAT, NULL);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex[1], 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return -1;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glViewport(0, 0, W, H);
    glUseProgram(prog);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tex[0]);
    glUniform1i(glGetUniformLocation(prog, "q"), 0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    /* RGBA/FLOAT: the one float read-back format OpenGL ES guarantees */
    float *rgba = malloc(sizeof(float) * 4 * W * H);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, rgba);
    for (int i = 0; i < W * H; i++) out[i] = rgba[4 * i];
    free(rgba);
    GLenum err = glGetError();
    glDeleteVertexArrays(1, &vao);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(2, tex);
    glDeleteProgram(prog);
    glDeleteShader(v);
    glDeleteShader(f);
    return err == GL_NO_ERROR ? 0 : -1;
}

/* Makes a surfaceless context current: OpenGL 3.3 core, or OpenGL ES 3.0. */
static EGLContext make_context(EGLDisplay dpy, int es)
{
    EGLContext ctx = EGL_NO_CONTEXT;
    if (eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API)) {
        EGLint gl_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
        EGLint es_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
        ctx = eglCreateContext(dpy, (EGLConfig)0, EGL_NO_CONTEXT, es ? es_attr : gl_attr);
    }
    if (ctx != EGL_NO_CONTEXT && !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        eglDestroyContext(dpy, ctx);
        ctx = EGL_NO_CONTEXT;
    }
    return ctx;
}

int main(void)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLDisplay dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)
                                 : EGL_NO_DISPLAY;
    EGLint maj, min;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &maj, &min)) {
        fprintf(stderr, "no EGL surfaceless display: skipped\n");
        return 77;
    }
    EGLContext ctx = make_context(dpy, 0);
    if (ctx == EGL_NO_CONTEXT) {
        fprintf(stderr, "no OpenGL 3.3 core context: skipped\n");
        eglTerminate(dpy);
        return 77;
    }
    fx_table fx;
    fx_make(&fx, 81, 0.12, 1.0);
    csflut_table *t = fx_open(&fx.b);
    CHECK(t != NULL);
    static float q[W * H * 4], out[W * H];
    csf_rng r;
    csf_rng_init(&r, 81, 1);
    for (int i = 0; i < W * H; i++) {
        q[4 * i] = (float)(0.3 * pow(2, 7.0 * csf_rng_next_uniform(&r)));
        q[4 * i + 1] = (float)(-2 + 47 * csf_rng_next_uniform(&r));
        /* velocity: 0, between the nodes, negative (drift direction), beyond the grid */
        q[4 * i + 2] = i % 9 == 0 ? 0.0f : (float)(-4 + 26 * csf_rng_next_uniform(&r));
        q[4 * i + 3] = 0.0f;
    }
    /* a few edge cases: beyond both ends of both axes */
    q[0] = 100.0f, q[1] = 100.0f;
    q[4] = 0.01f, q[5] = -5.0f;
    /* NaN: the library gives NaN; GLSL leaves max/clamp of NaN undefined, so the shader's answer
     * is the driver's (reported, not compared; the generated comment and docs/csflut.md say so) */
    q[8] = NAN, q[9] = 5.0f;
    /* the same grid with a velocity axis, never visible at high velocity and frequency */
    static const double vel[5] = {0, 1, 4, 8, 16};
    static double thr3[8 * 6 * 5];
    for (int v = 0; v < 5; v++)
        for (int k = 0; k < 48; k++) {
            double x = fx.thr[k] * pow(1.4, v);
            thr3[v * 48 + k] = x > 1 ? INFINITY : x;
        }
    csflut_build b3 = fx.b;
    b3.n_vel = 5;
    b3.vel_dps = vel;
    b3.threshold = thr3;
    b3.stderr_log10 = NULL;
    csflut_table *t3 = fx_open(&b3);
    CHECK(t3 != NULL);
    /* the generated comment describes both functions and what NaN does on each side */
    {
        char *glsl;
        CHECK_INT_EQ(csflut_export(t, CSFLUT_FORMAT_GLSL, "lut", &glsl, NULL), CSFLUT_OK);
        CHECK_STR_CONTAINS(glsl, "// float lut_threshold(float freq_cpd, float ecc_deg)");
        CHECK_STR_CONTAINS(glsl, "// bool lut_perceptible(float freq_cpd, float ecc_deg, float contrast)");
        CHECK_STR_CONTAINS(glsl, "// NaN arguments: csflut_threshold gives NaN");
        CHECK_STR_CONTAINS(glsl, "#ifdef GL_ES\nprecision highp float;\nprecision highp int;\n#endif\n");
        free(glsl);
    }
    for (int es = 0; es < 2; es++) {
        if (es) {
            eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(dpy, ctx);
            ctx = make_context(dpy, 1);
            /* Mesa's surfaceless platform offers ES 3 wherever it offers GL 3.3 core */
            CHECK_MSG(ctx != EGL_NO_CONTEXT, "no OpenGL ES 3.0 context");
            if (ctx == EGL_NO_CONTEXT) break;
        }
        const char *api = es ? "GLSL ES 3.00" : "GLSL 3.30 core";
        for (int run = 0; run < 4; run++) {
            int view = run & 1, three = run >> 1;
            csflut_table *tt = three ? t3 : t;
            csflut_set_conservative(tt, view);
            char *glsl;
            CHECK_INT_EQ(csflut_export(tt, CSFLUT_FORMAT_GLSL, "lut", &glsl, NULL), CSFLUT_OK);
            int rc = run_shader(glsl, "lut", q, out, es, three);
            free(glsl);
            CHECK_MSG(rc == 0, "%s: GL rendering failed", api);
            if (rc) break;
            double worst = 0;
            int n_inf = 0, mismatch_inf = 0;
            for (int i = 0; i < W * H; i++) {
                double fq = (double)q[4 * i], eq = (double)q[4 * i + 1], vq = (double)q[4 * i + 2];
                double want = three ? csflut_threshold3(tt, fq, eq, vq) : csflut_threshold(tt, fq, eq);
                double got = (double)out[i];
                if (i == 2) {
                    CHECK(isnan(want));
                    fprintf(stderr, "%s, %s view: NaN frequency: library %g, shader %g\n", api,
                            view ? "conservative" : "raw", want, got);
                    continue;
                }
                if (isinf(want) || isinf(got)) {
                    if (!(isinf(want) && isinf(got) && got > 0)) {
                        mismatch_inf++;
                        fprintf(stderr, "query f=%g e=%g v=%g: lib %g glsl %g\n", fq, eq, vq, want, got);
                    }
                    n_inf++;
                    continue;
                }
                double d = rel_diff(got, want);
                if (d > worst) worst = d;
            }
            fprintf(stderr, "%s, %s view, %s: %d queries (%d never visible), worst rel diff %.3g\n", api,
                    view ? "conservative" : "raw", three ? "threshold3 (velocity)" : "2-D", W * H, n_inf,
                    worst);
            CHECK(n_inf > 100); /* the comparison covers infinities */
            CHECK_INT_EQ(mismatch_inf, 0);
            CHECK_MSG(worst < 1e-5, "%s: worst relative difference %g", api, worst);
        }
    }
    csflut_close(t);
    csflut_close(t3);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (ctx != EGL_NO_CONTEXT) eglDestroyContext(dpy, ctx);
    /* no eglTerminate: it unloads the driver, and LeakSanitizer could then no longer attribute
     * Mesa's own small leaks to their module (tests/lsan.supp matches them by module name) */
    return CHECK_RESULT();
}
