/* A real GLFW fullscreen window (OpenGL through EGL) under Xvfb: it renders a Gabor that reads
 * back correctly, the OS gamma ramp is identity while the presenter runs, and the user's ramp is
 * back after every way out: a normal exit without closing, SIGTERM, a SIGSEGV crash, and a SIGTERM
 * caught by the program's own handler (which must still run).
 * Run by test_window.sh inside xvfb-run. The parent sets a non-identity "user" ramp, runs itself
 * as a child in each mode, and compares the ramp after the child has died. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "stimuli/gamma_guard.h"
#include "stimuli/presenter.h"
#include "tests/check.h"

static void graceful(int sig)
{
    (void)sig;
    static const char msg[] = "graceful stop\n";
    (void)!write(1, msg, sizeof msg - 1);
    _exit(5);
}

static int child(const char *mode)
{
    if (strcmp(mode, "chain") == 0) signal(SIGTERM, graceful); /* a session's own handler */
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    csf_error e;
    cfg.headless = 0;
    csf_geometry_init(&cfg.geometry, 600, 337.5, 1280, 720, 570, 0, 0, &e);
    csf_presenter *p = NULL;
    if (strcmp(mode, "badmon") == 0) {
        cfg.monitor = "7";
        int st = csf_presenter_open(&cfg, &p, &e);
        printf("badmon status=%d msg=%s\n", st, e.msg);
        cfg.monitor = "no-such-monitor";
        st = csf_presenter_open(&cfg, &p, &e);
        printf("badname status=%d msg=%s\n", st, e.msg);
        return 0;
    }
    if (csf_presenter_open(&cfg, &p, &e) != CSF_OK) {
        printf("open failed: %s\n", e.msg);
        return 2;
    }
    GLFWmonitor *mon = glfwGetPrimaryMonitor();
    printf("identity=%d active=%d\n", csf_gamma_ramp_is_identity(mon), csf_gamma_guard_active());
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_GABOR;
    s.freq_cpd = 1;
    s.sigma_deg = 1.5;
    s.contrast = 0.5;
    int w, h, lo = 1 << 30, hi = -1;
    csf_presenter_render_size(p, &w, &h);
    uint16_t *lv = malloc(sizeof(uint16_t) * 3 * w * h);
    csf_frame_info fi;
    for (int i = 0; i < 3; i++)
        if (csf_presenter_draw(p, &s, 1, &fi, &e) != CSF_OK) printf("draw failed: %s\n", e.msg);
    if (csf_presenter_readback_levels(p, lv, &e) == CSF_OK)
        for (size_t i = 0; i < (size_t)w * h * 3; i++) {
            if (lv[i] < lo) lo = lv[i];
            if (lv[i] > hi) hi = lv[i];
        }
    printf("size=%dx%d range=%d..%d t=%.4f\n", w, h, lo, hi, fi.t_s);
    free(lv);
    fflush(stdout);
    if (strcmp(mode, "term") == 0 || strcmp(mode, "chain") == 0) raise(SIGTERM);
    if (strcmp(mode, "segv") == 0) {
        /* a real invalid store, not raise(); address 8 rather than NULL so that UBSan's null
         * check does not end the process first */
        volatile int *volatile bad = (volatile int *)(uintptr_t)8;
        *bad = 1;
    }
    if (strcmp(mode, "exit") == 0) exit(3); /* atexit restores; no presenter_close */
    csf_presenter_close(p);
    printf("closed identity=%d\n", csf_gamma_ramp_is_identity(mon));
    return 0;
}

static unsigned short user_ramp[3][4096];

static int ramp_equals_user(GLFWmonitor *mon, unsigned int size)
{
    const GLFWgammaramp *r = glfwGetGammaRamp(mon);
    if (!r || r->size != size) return 0;
    return memcmp(r->red, user_ramp[0], size * 2) == 0 && memcmp(r->green, user_ramp[1], size * 2) == 0 &&
           memcmp(r->blue, user_ramp[2], size * 2) == 0;
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "--child") == 0) return child(argv[2]);
    if (!glfwInit()) {
        fprintf(stderr, "no X display: run under xvfb-run\n");
        return 1;
    }
    GLFWmonitor *mon = glfwGetPrimaryMonitor();
    CHECK(mon != NULL);
    const GLFWgammaramp *r = mon ? glfwGetGammaRamp(mon) : NULL;
    unsigned int size = r ? r->size : 0;
    int have_ramp = size >= 2 && size <= 4096;
    if (!have_ramp) printf("this X server offers no gamma ramp: only rendering is tested\n");
    if (have_ramp) {
        glfwSetGamma(mon, 1.8); /* the "user's" ramp, clearly not identity */
        r = glfwGetGammaRamp(mon);
        memcpy(user_ramp[0], r->red, size * 2);
        memcpy(user_ramp[1], r->green, size * 2);
        memcpy(user_ramp[2], r->blue, size * 2);
        CHECK(!csf_gamma_ramp_is_identity(mon));
    }
    const char *modes[] = {"close", "exit", "term", "segv", "chain"};
    for (int i = 0; i < 5; i++) {
        char cmd[4200], line[256], out[2048] = "";
        snprintf(cmd, sizeof cmd, "exec '%s' --child %s", argv[0], modes[i]);
        FILE *f = popen(cmd, "r");
        CHECK(f != NULL);
        if (!f) continue;
        while (fgets(line, sizeof line, f)) strncat(out, line, sizeof out - strlen(out) - 1);
        int st = pclose(f);
        printf("[%s] %s", modes[i], out);
        CHECK_STR_CONTAINS(out, "size=1280x720");
        int lo = -1, hi = -1;
        const char *q = strstr(out, "range=");
        if (q) sscanf(q, "range=%d..%d", &lo, &hi);
        CHECK_MSG(lo >= 0 && hi - lo > 60, "window frame range %d..%d", lo, hi);
        if (have_ramp) {
            CHECK_STR_CONTAINS(out, "identity=1 active=1");
            CHECK_MSG(ramp_equals_user(mon, size), "[%s] user ramp not restored", modes[i]);
        }
        if (i == 0) CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0);
        if (i == 1) CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 3);
        if (i == 2) CHECK_MSG(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "status 0x%x", st);
        /* a crash ends by SIGSEGV, or by SIGABRT after the sanitizer's report (its handler was
         * installed first and is chained) */
        if (i == 3)
            CHECK_MSG(WIFSIGNALED(st) && (WTERMSIG(st) == SIGSEGV || WTERMSIG(st) == SIGABRT),
                      "status 0x%x", st);
        /* the program's own SIGTERM handler still runs after the ramp is restored */
        if (i == 4) {
            CHECK_MSG(WIFEXITED(st) && WEXITSTATUS(st) == 5, "status 0x%x", st);
            CHECK_STR_CONTAINS(out, "graceful stop");
        }
    }
    /* --monitor by index or name: unknown ones are refused with the count */
    {
        char cmd[4200], line[256], out[2048] = "";
        snprintf(cmd, sizeof cmd, "exec '%s' --child badmon", argv[0]);
        FILE *g = popen(cmd, "r");
        while (g && fgets(line, sizeof line, g)) strncat(out, line, sizeof out - strlen(out) - 1);
        if (g) pclose(g);
        CHECK_STR_CONTAINS(out, "there are 1 monitors (0 to 0)");
        CHECK_STR_CONTAINS(out, "no monitor with that name");
    }
    glfwTerminate();
    return CHECK_RESULT();
}
