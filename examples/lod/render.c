#define GL_GLEXT_PROTOTYPES 1
#include "render.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

struct lod_renderer {
    EGLDisplay dpy;
    EGLContext ctx;
    int w, h;
    GLuint prog, vao, vbo, ibo;
    GLuint fbo_ms, rb_color_ms, rb_depth_ms, fbo, rb_color;
    GLint u_mvp, u_light, u_albedo, u_ambient;
};

static const char *vs_src =
    "#version 330 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec3 nrm;\n"
    "uniform mat4 mvp;\n"
    "uniform vec3 light_dir;\n"
    "uniform float albedo, ambient;\n"
    "out float intensity;\n"
    /* Gouraud, in linear light: the same formula as lod_shade_intensity */
    "void main() {\n"
    "  intensity = albedo * (ambient + (1.0 - ambient) * max(dot(nrm, light_dir), 0.0));\n"
    "  gl_Position = mvp * vec4(pos, 1.0);\n"
    "}\n";
static const char *fs_src =
    "#version 330 core\n"
    "in float intensity;\n"
    "out vec4 color;\n"
    "void main() {\n"
    "  float v = pow(clamp(intensity, 0.0, 1.0), 1.0 / 2.2);\n" /* the display decodes gamma 2.2 */
    "  color = vec4(v, v, v, 1.0);\n"
    "}\n";

static GLuint compile(GLenum kind, const char *src, char *err, size_t err_len)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(err, err_len, "shader does not compile: %s", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static int make_program(lod_renderer *r, char *err, size_t err_len)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_src, err, err_len);
    GLuint fs = vs ? compile(GL_FRAGMENT_SHADER, fs_src, err, err_len) : 0;
    if (!fs) { glDeleteShader(vs); return -1; }
    r->prog = glCreateProgram();
    glAttachShader(r->prog, vs);
    glAttachShader(r->prog, fs);
    glLinkProgram(r->prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok;
    glGetProgramiv(r->prog, GL_LINK_STATUS, &ok);
    if (!ok) { snprintf(err, err_len, "shader program does not link"); return -1; }
    r->u_mvp = glGetUniformLocation(r->prog, "mvp");
    r->u_light = glGetUniformLocation(r->prog, "light_dir");
    r->u_albedo = glGetUniformLocation(r->prog, "albedo");
    r->u_ambient = glGetUniformLocation(r->prog, "ambient");
    return 0;
}

/* A 4x multisampled colour+depth target resolved into a single-sampled one for reading. */
static int make_targets(lod_renderer *r, char *err, size_t err_len)
{
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    GLsizei samples = max_samples >= 4 ? 4 : max_samples;
    glGenFramebuffers(1, &r->fbo_ms);
    glGenRenderbuffers(1, &r->rb_color_ms);
    glGenRenderbuffers(1, &r->rb_depth_ms);
    glBindRenderbuffer(GL_RENDERBUFFER, r->rb_color_ms);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, r->w, r->h);
    glBindRenderbuffer(GL_RENDERBUFFER, r->rb_depth_ms);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, r->w, r->h);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_ms);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r->rb_color_ms);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, r->rb_depth_ms);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, err_len, "multisampled %dx%d framebuffer incomplete", r->w, r->h);
        return -1;
    }
    glGenFramebuffers(1, &r->fbo);
    glGenRenderbuffers(1, &r->rb_color);
    glBindRenderbuffer(GL_RENDERBUFFER, r->rb_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, r->w, r->h);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r->rb_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, err_len, "%dx%d framebuffer incomplete", r->w, r->h);
        return -1;
    }
    return 0;
}

static int open_context(lod_renderer *r, char *err, size_t err_len)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    r->dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)
                         : EGL_NO_DISPLAY;
    EGLint major, minor;
    if (r->dpy == EGL_NO_DISPLAY || !eglInitialize(r->dpy, &major, &minor)) {
        snprintf(err, err_len, "no EGL surfaceless display (Mesa's EGL_MESA_platform_surfaceless)");
        r->dpy = EGL_NO_DISPLAY;
        return -1;
    }
    const EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                           EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    if (eglBindAPI(EGL_OPENGL_API)) r->ctx = eglCreateContext(r->dpy, (EGLConfig)0, EGL_NO_CONTEXT, attr);
    if (r->ctx == EGL_NO_CONTEXT || !eglMakeCurrent(r->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->ctx)) {
        snprintf(err, err_len, "no OpenGL 3.3 core context without a surface (EGL error 0x%x)",
                 (unsigned)eglGetError());
        return -1;
    }
    return 0;
}

lod_renderer *lod_render_open(int width_px, int height_px, char *err, size_t err_len)
{
    lod_renderer *r = calloc(1, sizeof *r);
    if (!r) { snprintf(err, err_len, "out of memory"); return NULL; }
    r->w = width_px;
    r->h = height_px;
    r->ctx = EGL_NO_CONTEXT;
    if (open_context(r, err, err_len) != 0 || make_program(r, err, err_len) != 0 ||
        make_targets(r, err, err_len) != 0) {
        lod_render_close(r);
        return NULL;
    }
    glGenVertexArrays(1, &r->vao);
    glGenBuffers(1, &r->vbo);
    glGenBuffers(1, &r->ibo);
    return r;
}

void lod_render_close(lod_renderer *r)
{
    if (!r) return;
    if (r->ctx != EGL_NO_CONTEXT) {
        eglMakeCurrent(r->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(r->dpy, r->ctx);
    }
    /* no eglTerminate: it unloads the driver and LeakSanitizer then loses the driver's frames */
    free(r);
}

int lod_render_set_vertices(lod_renderer *r, const float *pos, const float *nrm, int n)
{
    float *buf = malloc((size_t)n * 6 * sizeof *buf);
    if (!buf) return -1;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            buf[6 * i + c] = pos[3 * i + c];
            buf[6 * i + 3 + c] = nrm[3 * i + c];
        }
    glBindVertexArray(r->vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)n * 6 * sizeof *buf), buf, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)(3 * sizeof(float)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    free(buf);
    return 0;
}

int lod_render_draw(lod_renderer *r, const uint32_t *tri, int n_tri, const float mvp[16],
                    const lod_shade *s, uint8_t *rgb, char *err, size_t err_len)
{
    uint8_t *rgba = malloc((size_t)r->w * r->h * 4);
    if (!rgba) { snprintf(err, err_len, "out of memory"); return -1; }
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_ms);
    glViewport(0, 0, r->w, r->h);
    float bg = powf(s->background, 1 / 2.2f);
    glClearColor(bg, bg, bg, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glUseProgram(r->prog);
    glUniformMatrix4fv(r->u_mvp, 1, GL_FALSE, mvp);
    glUniform3fv(r->u_light, 1, s->light_dir);
    glUniform1f(r->u_albedo, s->albedo);
    glUniform1f(r->u_ambient, s->ambient);
    glBindVertexArray(r->vao);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)((size_t)n_tri * 3 * sizeof *tri), tri, GL_STREAM_DRAW);
    glDrawElements(GL_TRIANGLES, n_tri * 3, GL_UNSIGNED_INT, (void *)0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo_ms);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->fbo);
    glBlitFramebuffer(0, 0, r->w, r->h, 0, 0, r->w, r->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, r->w, r->h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        snprintf(err, err_len, "OpenGL error 0x%x while drawing", (unsigned)e);
        free(rgba);
        return -1;
    }
    for (int y = 0; y < r->h; y++) /* GL's first row is the bottom one */
        for (int x = 0; x < r->w; x++)
            for (int c = 0; c < 3; c++)
                rgb[((size_t)y * r->w + x) * 3 + c] = rgba[((size_t)(r->h - 1 - y) * r->w + x) * 4 + c];
    free(rgba);
    return 0;
}
