/* `csfcal devices`: what csfcal can reach from this station — simulated devices, USB photometers it
 * recognises, HID devices usable as response boxes, monitors (GLFW) and the offscreen EGL renderer.
 * Enumeration only: nothing is opened for measuring here. */
#define GLFW_INCLUDE_NONE
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>
#include <getopt.h>
#include <hidapi/hidapi.h>
#include <libusb-1.0/libusb.h>
#include <stdio.h>
#include <string.h>
#include <wchar.h>

#include "calib/cli.h"
#include "calib/commands.h"

/* USB ids of instruments csfcal knows; drivers for them plug in behind devices/photometer.h. */
static const struct {
    unsigned short vid, pid;
    const char *name, *spec;
} known_photometers[] = {
    {0x0861, 0x1001, "CRS ColorCAL MkII", "colorcal2"},
    {0x273f, 0x1001, "Hughski ColorHug", "colorhug"},
    {0x273f, 0x1004, "Hughski ColorHug2", "colorhug2"},
};

typedef struct {
    int json;
    int first; /* for JSON commas */
} out_state;

static void json_str(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') printf("\\%c", c);
        else if (c < 0x20) printf("\\u%04x", c);
        else putchar(c);
    }
    putchar('"');
}

static void item(out_state *o, const char *kind, const char *name, const char *spec, const char *detail)
{
    if (o->json) {
        printf("%s\n  {\"kind\": ", o->first ? "" : ",");
        json_str(kind);
        printf(", \"name\": ");
        json_str(name);
        printf(", \"spec\": ");
        json_str(spec);
        printf(", \"detail\": ");
        json_str(detail);
        printf("}");
    } else {
        printf("  %-10s %-28s %-14s %s\n", kind, name, spec, detail);
    }
    o->first = 0;
}

static void list_usb(out_state *o)
{
    libusb_context *ctx = NULL;
    if (libusb_init(&ctx) != 0) {
        item(o, "photometer", "(USB unavailable)", "-", "libusb could not initialise");
        return;
    }
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(ctx, &list);
    int found = 0;
    for (ssize_t i = 0; i < n; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
        for (size_t k = 0; k < sizeof known_photometers / sizeof known_photometers[0]; k++) {
            if (d.idVendor == known_photometers[k].vid && d.idProduct == known_photometers[k].pid) {
                char detail[96];
                snprintf(detail, sizeof detail, "USB %04x:%04x bus %d address %d (driver not in this release)",
                         d.idVendor, d.idProduct, libusb_get_bus_number(list[i]),
                         libusb_get_device_address(list[i]));
                item(o, "photometer", known_photometers[k].name, known_photometers[k].spec, detail);
                found++;
            }
        }
    }
    if (n >= 0) libusb_free_device_list(list, 1);
    libusb_exit(ctx);
    if (!found && !o->json) printf("  %-10s %-28s %-14s %s\n", "photometer", "(no USB photometer found)", "-", "");
}

static void list_hid(out_state *o)
{
    if (hid_init() != 0) return;
    struct hid_device_info *devs = hid_enumerate(0, 0);
    for (struct hid_device_info *d = devs; d; d = d->next) {
        char name[128], detail[96];
        snprintf(name, sizeof name, "%ls", d->product_string ? d->product_string : L"(unnamed HID)");
        snprintf(detail, sizeof detail, "HID %04x:%04x usage page 0x%x", d->vendor_id, d->product_id,
                 d->usage_page);
        item(o, "hid", name, "-", detail);
    }
    hid_free_enumeration(devs);
    hid_exit();
}

static void list_monitors(out_state *o, int headless)
{
    if (headless || !glfwInit()) {
        item(o, "display", "(none)", "-", "no window system reachable: --headless rendering only");
        return;
    }
    int count = 0;
    GLFWmonitor **mons = glfwGetMonitors(&count);
    for (int i = 0; i < count; i++) {
        int wmm = 0, hmm = 0;
        glfwGetMonitorPhysicalSize(mons[i], &wmm, &hmm);
        const GLFWvidmode *m = glfwGetVideoMode(mons[i]);
        const GLFWgammaramp *ramp = glfwGetGammaRamp(mons[i]);
        char spec[24], detail[160];
        snprintf(spec, sizeof spec, "--monitor %d", i);
        snprintf(detail, sizeof detail, "%dx%d px @ %d Hz, EDID %dx%d mm (verify with a ruler), gamma ramp %u entries",
                 m ? m->width : 0, m ? m->height : 0, m ? m->refreshRate : 0, wmm, hmm,
                 ramp ? ramp->size : 0u);
        item(o, "display", glfwGetMonitorName(mons[i]), spec, detail);
    }
    glfwTerminate();
}

static void list_egl(out_state *o)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLDisplay dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)
                                 : EGL_NO_DISPLAY;
    EGLint major = 0, minor = 0;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) {
        item(o, "renderer", "(EGL unavailable)", "--headless", "no surfaceless EGL platform");
        return;
    }
    char detail[160];
    snprintf(detail, sizeof detail, "EGL %d.%d, %s", major, minor, eglQueryString(dpy, EGL_VENDOR));
    item(o, "renderer", "offscreen (surfaceless EGL)", "--headless", detail);
    eglTerminate(dpy);
}

int csf_cmd_devices(int argc, char **argv)
{
    static const struct option opts[] = {{"help", no_argument, 0, 'h'}, CSF_CLI_COMMON_OPTIONS, {0, 0, 0, 0}};
    csf_cli cli;
    int rc = csf_cli_init(&cli, argc, argv);
    if (rc) return rc;
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        if (c == 'h') {
            printf("usage: csfcal devices [--json] [--headless]\n\n"
                   "Lists the simulated devices, USB photometers csfcal recognises, HID devices that can\n"
                   "serve as response boxes, monitors (with their EDID size, which is often wrong: put\n"
                   "the measured size in the station configuration) and the offscreen renderer.\n\n%s",
                   csf_cli_common_help);
            return 0;
        }
        int r = csf_cli_common_option(&cli, c, optarg);
        if (r < 0) return 2;
        if (r == 0) {
            fprintf(stderr, "csfcal devices: unknown option (try --help)\n");
            return 2;
        }
    }
    out_state o = {.json = cli.json, .first = 1};
    if (o.json) printf("[");
    else printf("  %-10s %-28s %-14s %s\n", "KIND", "NAME", "SPEC", "DETAIL");
    item(&o, "photometer", "simulated photometer", "sim", "display=crt|lcd|oled|file=CSV, noise, drift, faults");
    item(&o, "observer", "simulated observer", "sim", "CSF surface or table=CSV, Weibull, lapses, reaction times");
    item(&o, "responder", "keyboard / mouse", "keyboard", "through the GLFW window");
    list_usb(&o);
    list_hid(&o);
    list_monitors(&o, csf_cli_want_headless(&cli));
    list_egl(&o);
    if (o.json) printf("\n]\n");
    return 0;
}
