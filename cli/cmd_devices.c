/* `csfcal devices`: what csfcal can reach from this station -- photometers (simulated; USB ones by
 * VID:PID; serial ports that may be Minolta or Photo Research meters; ArgyllCMS spotread on PATH),
 * response devices (keyboard and mouse, HID boxes, gamepads), monitors and the offscreen renderer
 * -- and, for a device that is present but not usable, why (permissions, another program holding
 * it, no spotread).
 *
 * Linux only: devices are found through sysfs and /dev, never opened, so listing cannot disturb a
 * meter or detach a keyboard's driver. The environment variable CSFCAL_DEVICES_ROOT (tests only)
 * puts a prefix before /sys and /dev so a fake tree can stand in for the machine. --json writes an
 * array through jansson: each entry has kind, name, spec, status (ok, simulated, unusable), detail,
 * and where they apply why (status unusable), vid, pid, path. */
#define GLFW_INCLUDE_NONE
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>
#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <jansson.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/commands.h"

/* USB ids of instruments csfcal knows (docs/instruments.md). */
static const struct {
    unsigned short vid, pid;
    const char *name, *spec;
} known_photometers[] = {
    {0x0861, 0x1001, "CRS ColorCAL MkII", "colorcal2"},
    {0x273f, 0x1001, "Hughski ColorHug", "-"},
    {0x273f, 0x1004, "Hughski ColorHug2", "colorhug2"},
};

static const char UDEV_HINT[] = "install csfcal's udev rules (scripts/setup.sh does it; by hand: sudo cp "
                                "data/udev/70-csfcal.rules /etc/udev/rules.d/ && sudo udevadm control --reload, "
                                "then re-plug the device)";

typedef struct {
    const char *kind, *name, *spec, *status, *detail, *why, *path;
    int vid, pid; /* -1: not a USB device */
} entry;

typedef struct {
    int json;
    json_t *list;
    const char *root; /* "" or CSFCAL_DEVICES_ROOT */
} out_state;

/* jansson wants UTF-8; names from sysfs are bytes the device chose */
static json_t *jstr(const char *s)
{
    json_t *j = json_string(s ? s : "");
    if (j) return j;
    char buf[512];
    size_t k = 0;
    for (; s && *s && k + 1 < sizeof buf; s++) buf[k++] = (unsigned char)*s < 0x80 ? *s : '?';
    buf[k] = 0;
    return json_string(buf);
}

static void add(out_state *o, const entry *e)
{
    if (o->json) {
        json_t *j = json_object();
        json_object_set_new(j, "kind", jstr(e->kind));
        json_object_set_new(j, "name", jstr(e->name));
        json_object_set_new(j, "spec", jstr(e->spec));
        json_object_set_new(j, "status", jstr(e->status));
        json_object_set_new(j, "detail", jstr(e->detail));
        if (e->why) json_object_set_new(j, "why", jstr(e->why));
        if (e->path) json_object_set_new(j, "path", jstr(e->path));
        if (e->vid >= 0) {
            json_object_set_new(j, "vid", json_integer(e->vid));
            json_object_set_new(j, "pid", json_integer(e->pid));
        }
        json_array_append_new(o->list, j);
        return;
    }
    printf("  %-10s %-30s %-22s %-9s %s\n", e->kind, e->name, e->spec, e->status, e->detail);
    if (e->why) printf("  %-10s   why: %s\n", "", e->why);
}

static void simple(out_state *o, const char *kind, const char *name, const char *spec, const char *status,
                   const char *detail)
{
    entry e = {kind, name, spec, status, detail, NULL, NULL, -1, -1};
    add(o, &e);
}

/* a/b plus suffix into buf; -1 when it does not fit (such an entry is skipped) */
static int join(char *buf, size_t len, const char *a, const char *b, const char *suffix)
{
    int n = snprintf(buf, len, "%s/%s%s", a, b, suffix);
    return n < 0 || (size_t)n >= len ? -1 : 0;
}

/* Reads a one-line sysfs attribute into buf (trailing newline removed); 0 or -1. */
static int read_attr(const char *dir, const char *name, char *buf, size_t len)
{
    char p[PATH_MAX];
    if (join(p, sizeof p, dir, name, "")) return -1;
    FILE *f = fopen(p, "r");
    if (!f) return -1;
    if (!fgets(buf, (int)len, f)) buf[0] = 0;
    fclose(f);
    buf[strcspn(buf, "\r\n")] = 0;
    return 0;
}

static int read_hex(const char *dir, const char *name)
{
    char b[32];
    if (read_attr(dir, name, b, sizeof b)) return -1;
    char *end;
    long v = strtol(b, &end, 16);
    return end == b || v < 0 || v > 0xffff ? -1 : (int)v;
}

/* Whether the person running csfcal may open the node read-write (what libusb, hidapi and a
 * serial driver need). Returns 0, or -1 with the reason. */
static int may_open(const char *node, const char *hint, char *why, size_t len)
{
    if (access(node, R_OK | W_OK) == 0) return 0;
    int e = errno;
    /* a reason cut short at len is still a reason: the return values are not needed */
    int n = e == EACCES || e == EPERM
                ? snprintf(why, len, "found but not accessible: permission denied on %.300s; %s", node, hint)
                : snprintf(why, len, "found but %.300s cannot be opened: %s", node, strerror(e));
    (void)n;
    return -1;
}

/* The kernel driver bound to interface dir (basename of its driver link), "" when none. */
static void iface_driver(const char *iface_dir, char *buf, size_t len)
{
    char p[PATH_MAX], target[PATH_MAX];
    buf[0] = 0;
    if (join(p, sizeof p, iface_dir, "driver", "")) return;
    ssize_t n = readlink(p, target, sizeof target - 1);
    if (n <= 0) return;
    target[n] = 0;
    const char *base = strrchr(target, '/');
    base = base ? base + 1 : target;
    size_t bl = strlen(base);
    if (bl >= len) return; /* no driver name is that long */
    memcpy(buf, base, bl + 1);
}

typedef struct {
    char dir[PATH_MAX], id[64], product[128], driver[64];
    int vid, pid, bus, dev, hid_iface, hid_proto, usbfs_held;
} usb_dev;

static void scan_interfaces(usb_dev *u)
{
    DIR *d = opendir(u->dir);
    if (!d) return;
    struct dirent *de;
    u->hid_iface = 0;
    while ((de = readdir(d))) {
        if (!strchr(de->d_name, ':')) continue; /* interfaces are BUS-PORT:CONFIG.IFACE */
        char idir[PATH_MAX], drv[64];
        if (join(idir, sizeof idir, u->dir, de->d_name, "")) continue;
        iface_driver(idir, drv, sizeof drv);
        if (strcmp(drv, "usbfs") == 0) u->usbfs_held = 1; /* a program claimed it through libusb */
        else if (drv[0] && !u->driver[0]) snprintf(u->driver, sizeof u->driver, "%s", drv);
        if (read_hex(idir, "bInterfaceClass") == 3 && !u->hid_iface) {
            u->hid_iface = 1;
            u->hid_proto = read_hex(idir, "bInterfaceProtocol");
        }
    }
    closedir(d);
}

static void usb_node(const out_state *o, const usb_dev *u, char *node, size_t len)
{
    snprintf(node, len, "%s/dev/bus/usb/%03d/%03d", o->root, u->bus, u->dev);
}

static void list_usb_photometer(out_state *o, const usb_dev *u, size_t k)
{
    char node[PATH_MAX], why[600], detail[300];
    usb_node(o, u, node, sizeof node);
    entry e = {"photometer", known_photometers[k].name, known_photometers[k].spec, "ok", detail, NULL,
               node + strlen(o->root), u->vid, u->pid};
    snprintf(detail, sizeof detail, "USB %04x:%04x bus %d device %d%s%s%s", u->vid, u->pid, u->bus, u->dev,
             u->driver[0] ? ", kernel driver " : "", u->driver,
             u->driver[0] ? " bound (csfcal detaches it while measuring and re-attaches it after)" : "");
    if (strcmp(known_photometers[k].spec, "-") == 0) {
        e.status = "unusable";
        e.why = "csfcal has no driver for the first ColorHug (a ColorHug2 is 273f:1004); spotread can drive it";
    } else if (u->usbfs_held) {
        e.status = "unusable";
        snprintf(why, sizeof why, "another program holds it (an interface is claimed through usbfs: colord, "
                 "ArgyllCMS, a second csfcal); close that program");
        e.why = why;
    } else if (may_open(node, UDEV_HINT, why, sizeof why)) {
        e.status = "unusable";
        e.why = why;
    }
    add(o, &e);
}

static void list_usb_hid(out_state *o, const usb_dev *u)
{
    char node[PATH_MAX], why[600], detail[300], spec[32], name[160];
    usb_node(o, u, node, sizeof node);
    snprintf(name, sizeof name, "%s", u->product[0] ? u->product : "(unnamed HID device)");
    snprintf(spec, sizeof spec, "hid:%04x:%04x", u->vid, u->pid);
    entry e = {"responder", name, spec, "ok", detail, NULL, node + strlen(o->root), u->vid, u->pid};
    if (u->hid_proto == 1 || u->hid_proto == 2) {
        /* a boot keyboard or mouse answers through the window: no device access needed */
        e.spec = u->hid_proto == 1 ? "keyboard" : "mouse";
        snprintf(detail, sizeof detail, "USB HID %04x:%04x, a %s: answers through the window (button boxes "
                 "that type keys belong here too)", u->vid, u->pid, u->hid_proto == 1 ? "keyboard" : "mouse");
        add(o, &e);
        return;
    }
    snprintf(detail, sizeof detail, "USB HID %04x:%04x bus %d device %d: a button box (%s[,map=...]) or a "
             "gamepad (gamepad:N)", u->vid, u->pid, u->bus, u->dev, spec);
    if (may_open(node, UDEV_HINT, why, sizeof why)) {
        e.status = "unusable";
        e.why = why;
    }
    add(o, &e);
}

static void list_usb(out_state *o)
{
    char base[PATH_MAX];
    snprintf(base, sizeof base, "%s/sys/bus/usb/devices", o->root);
    DIR *d = opendir(base);
    int photometers = 0;
    if (d) {
        struct dirent *de;
        while ((de = readdir(d))) {
            if (de->d_name[0] == '.' || strchr(de->d_name, ':')) continue;
            usb_dev u;
            memset(&u, 0, sizeof u);
            if (join(u.dir, sizeof u.dir, base, de->d_name, "")) continue;
            u.vid = read_hex(u.dir, "idVendor");
            u.pid = read_hex(u.dir, "idProduct");
            char b[32];
            if (u.vid < 0 || u.pid < 0) continue;
            u.bus = read_attr(u.dir, "busnum", b, sizeof b) ? 0 : atoi(b);
            u.dev = read_attr(u.dir, "devnum", b, sizeof b) ? 0 : atoi(b);
            read_attr(u.dir, "product", u.product, sizeof u.product);
            scan_interfaces(&u);
            int known = 0;
            for (size_t k = 0; k < sizeof known_photometers / sizeof known_photometers[0]; k++)
                if (u.vid == known_photometers[k].vid && u.pid == known_photometers[k].pid) {
                    list_usb_photometer(o, &u, k);
                    known = 1;
                    photometers++;
                }
            if (!known && u.hid_iface) list_usb_hid(o, &u);
        }
        closedir(d);
    }
    if (!photometers && !o->json) simple(o, "photometer", "(no USB photometer found)", "-", "-", "");
}

/* The USB device a tty hangs off: walk up from its device link to the first dir with idVendor. */
static int tty_usb(const char *sysdev, int *vid, int *pid, char *product, size_t plen)
{
    char p[PATH_MAX];
    if (!realpath(sysdev, p)) return -1;
    for (int up = 0; up < 6; up++) {
        int v = read_hex(p, "idVendor");
        if (v >= 0) {
            *vid = v;
            *pid = read_hex(p, "idProduct");
            if (read_attr(p, "product", product, plen)) product[0] = 0;
            return 0;
        }
        char *slash = strrchr(p, '/');
        if (!slash || slash == p) break;
        *slash = 0;
    }
    return -1;
}

static void list_serial(out_state *o)
{
    char base[PATH_MAX];
    snprintf(base, sizeof base, "%s/sys/class/tty", o->root);
    DIR *d = opendir(base);
    if (!d) return;
    struct dirent *de;
    while ((de = readdir(d))) {
        if (strncmp(de->d_name, "ttyUSB", 6) != 0 && strncmp(de->d_name, "ttyACM", 6) != 0) continue;
        char sysdev[PATH_MAX], node[PATH_MAX], product[128] = "", name[200], spec[96], detail[400], why[600];
        if (join(sysdev, sizeof sysdev, base, de->d_name, "/device")) continue;
        char devdir[PATH_MAX];
        if (join(devdir, sizeof devdir, o->root, "dev", "") || join(node, sizeof node, devdir, de->d_name, "")) continue;
        int vid = -1, pid = -1;
        tty_usb(sysdev, &vid, &pid, product, sizeof product);
        const char *dev = node + strlen(o->root);
        entry e = {"photometer", name, spec, "ok", detail, NULL, dev, vid, vid >= 0 ? pid : -1};
        if (vid == 0x0861 && pid == 0x1001) {
            /* the ColorCAL's own serial face (cdc_acm); it is listed as a USB photometer */
            snprintf(name, sizeof name, "serial port %s", dev);
            snprintf(spec, sizeof spec, "colorcal2");
            snprintf(detail, sizeof detail, "the ColorCAL MkII's serial face (cdc_acm): use --photometer colorcal2");
            e.status = "ok";
            add(o, &e);
            continue;
        }
        snprintf(name, sizeof name, "serial port %s%s%s%s", dev, product[0] ? " (" : "", product, product[0] ? ")" : "");
        snprintf(spec, sizeof spec, "ls100:%s | pr655:%s", dev, dev);
        if (vid >= 0)
            snprintf(detail, sizeof detail, "USB serial %04x:%04x: may be a Konica Minolta LS-100/LS-110/CS-100A "
                     "(ls100, ls110, cs100a) or a Photo Research PR-655/PR-670 (pr655, pr670); csfcal cannot tell "
                     "without talking to it", vid, pid);
        else
            snprintf(detail, sizeof detail, "serial port: may be a Konica Minolta or Photo Research meter");
        if (may_open(node, "add the user to the group dialout (sudo usermod -aG dialout $USER) and log in again",
                     why, sizeof why)) {
            e.status = "unusable";
            e.why = why;
        }
        add(o, &e);
    }
    closedir(d);
}

static void list_spotread(out_state *o)
{
    const char *path = getenv("PATH");
    char found[PATH_MAX] = "";
    while (path && *path && !found[0]) {
        size_t n = strcspn(path, ":");
        char cand[PATH_MAX];
        snprintf(cand, sizeof cand, "%.*s/spotread", (int)(n ? n : 1), n ? path : ".");
        if (access(cand, X_OK) == 0) snprintf(found, sizeof found, "%s", cand);
        path += n + (path[n] == ':');
    }
    entry e = {"photometer", "ArgyllCMS spotread", "spotread[:ARGS]", "ok", NULL, NULL, NULL, -1, -1};
    char detail[PATH_MAX + 160];
    if (found[0]) {
        snprintf(detail, sizeof detail, "%s: a bridge to every instrument ArgyllCMS drives (i1Display Pro, "
                 "Spyder, i1Pro, K-10, JETI ...)", found);
        e.detail = detail;
        e.path = found;
    } else {
        e.status = "unusable";
        e.detail = "a bridge to every instrument ArgyllCMS drives";
        e.why = "no spotread on PATH: install ArgyllCMS (apt-get install argyll) or put its bin folder on PATH";
    }
    add(o, &e);
}

/* Joysticks and gamepads the kernel has (udev's by-id links), whether or not a window system runs. */
static void list_input(out_state *o)
{
    char base[PATH_MAX];
    snprintf(base, sizeof base, "%s/dev/input/by-id", o->root);
    DIR *d = opendir(base);
    if (!d) return;
    struct dirent *de;
    while ((de = readdir(d))) {
        const char *suffix = "-event-joystick";
        size_t n = strlen(de->d_name), sl = strlen(suffix);
        if (n <= sl || strcmp(de->d_name + n - sl, suffix) != 0) continue;
        char node[PATH_MAX], name[200], why[600];
        if (join(node, sizeof node, base, de->d_name, "")) continue;
        snprintf(name, sizeof name, "%.*s", (int)(n - sl), de->d_name);
        entry e = {"responder", name, "gamepad[:N]", "ok",
                   "joystick or gamepad (GLFW numbers them: with a window system `csfcal devices` shows N)", NULL,
                   node + strlen(o->root), -1, -1};
        if (access(node, R_OK) != 0) {
            snprintf(why, sizeof why, "found but not accessible: %s on %s; the person at the seat gets access "
                     "through udev's uaccess (csfcal's rules add it), or add the user to the group input",
                     strerror(errno), node + strlen(o->root));
            e.status = "unusable";
            e.why = why;
        }
        add(o, &e);
    }
    closedir(d);
}

static void list_monitors(out_state *o, int asked_headless, int no_display)
{
    if (asked_headless || no_display || !glfwInit()) {
        entry e = {"display",
                   "(none)",
                   "-",
                   "unusable",
                   "--headless rendering only",
                   asked_headless
                       ? "--headless was asked for: monitors and GLFW joysticks are not looked for"
                       : "no window system reachable (no X or Wayland display): monitors and GLFW joysticks "
                         "cannot be listed",
                   NULL,
                   -1,
                   -1};
        add(o, &e);
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
                 m ? m->width : 0, m ? m->height : 0, m ? m->refreshRate : 0, wmm, hmm, ramp ? ramp->size : 0u);
        simple(o, "display", glfwGetMonitorName(mons[i]), spec, "ok", detail);
    }
    for (int j = 0; j <= GLFW_JOYSTICK_LAST; j++) {
        if (!glfwJoystickPresent(j)) continue;
        char spec[24], detail[200];
        snprintf(spec, sizeof spec, "gamepad:%d", j);
        snprintf(detail, sizeof detail, "GLFW joystick %d, %s", j,
                 glfwJoystickIsGamepad(j) ? "gamepad layout (A press, X/B intervals, bumpers/triggers places)"
                                          : "no gamepad mapping: raw button numbers (map=...)");
        simple(o, "responder", glfwGetJoystickName(j), spec, "ok", detail);
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
        entry e = {"renderer", "(EGL unavailable)", "--headless", "unusable", "offscreen rendering",
                   "no surfaceless EGL platform (Mesa's libegl-mesa0 provides one)", NULL, -1, -1};
        add(o, &e);
        return;
    }
    char detail[160];
    snprintf(detail, sizeof detail, "EGL %d.%d, %s", major, minor, eglQueryString(dpy, EGL_VENDOR));
    simple(o, "renderer", "offscreen (surfaceless EGL)", "--headless", "ok", detail);
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
                   "Lists photometers (simulated; USB meters by VID:PID; serial ports that may be Minolta or\n"
                   "Photo Research meters; ArgyllCMS spotread on PATH), response devices (keyboard, mouse, HID\n"
                   "button boxes, gamepads), monitors (with their EDID size, which is often wrong: put the\n"
                   "measured size in the station configuration) and the offscreen renderer. A device that is\n"
                   "present but not usable is marked unusable with the reason (permissions: install the udev\n"
                   "rules; another program holding it; no spotread on PATH). Nothing is opened.\n"
                   "--json: an array of {kind, name, spec, status, detail[, why, path, vid, pid]}.\n\n%s",
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
    const char *root = getenv("CSFCAL_DEVICES_ROOT");
    out_state o = {.json = cli.json, .list = cli.json ? json_array() : NULL, .root = root ? root : ""};
    if (o.json && !o.list) {
        fprintf(stderr, "csfcal devices: out of memory\n");
        return 1;
    }
    if (!o.json) printf("  %-10s %-30s %-22s %-9s %s\n", "KIND", "NAME", "SPEC", "STATUS", "DETAIL");
    simple(&o, "photometer", "simulated photometer", "sim", "simulated",
           "display=crt|lcd|oled|file=CSV, noise, drift, faults");
    simple(&o, "observer", "simulated observer", "sim", "simulated",
           "CSF surface or table=CSV, Weibull, lapses, reaction times");
    list_usb(&o);
    list_serial(&o);
    list_spotread(&o);
    simple(&o, "responder", "keyboard / mouse", "keyboard | mouse", "ok", "through the GLFW window");
    list_input(&o);
    list_monitors(&o, cli.headless, csf_cli_want_headless(&cli));
    list_egl(&o);
    if (o.json) {
        char *text = json_dumps(o.list, JSON_INDENT(2));
        json_decref(o.list);
        if (!text) {
            fprintf(stderr, "csfcal devices: could not write the JSON\n");
            return 1;
        }
        printf("%s\n", text);
        free(text);
    }
    return fflush(stdout) == 0 ? 0 : 1;
}
