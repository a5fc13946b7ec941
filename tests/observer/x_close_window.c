/* Closes a window the way a window manager does when the user clicks its close button: a
 * WM_PROTOCOLS client message carrying WM_DELETE_WINDOW (ICCCM 4.2.8.1), sent to the window
 * itself. Under a bare Xvfb there is no window manager to do it, and xdotool's windowclose
 * destroys the window instead, which a real close never does.
 *   x_close_window NAME: the first top-level window whose WM_NAME is NAME, on $DISPLAY.
 * Exit 0 when sent; 1 when no such window (or it does not take WM_DELETE_WINDOW, so a window
 * manager would not send it either); 2 on bad use or no display. */
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <stdio.h>
#include <string.h>

static Window find_named(Display *dpy, Window w, const char *name, int depth)
{
    char *wn = NULL;
    if (XFetchName(dpy, w, &wn) && wn) {
        int same = strcmp(wn, name) == 0;
        XFree(wn);
        if (same) return w;
    }
    if (depth > 2) return None; /* top levels, and their frames had there been a manager */
    Window root, parent, *kids = NULL, found = None;
    unsigned int n = 0;
    if (!XQueryTree(dpy, w, &root, &parent, &kids, &n)) return None;
    for (unsigned int i = 0; i < n && found == None; i++) found = find_named(dpy, kids[i], name, depth + 1);
    if (kids) XFree(kids);
    return found;
}

static int takes_delete(Display *dpy, Window w, Atom wm_delete)
{
    Atom *protos = NULL;
    int n = 0, yes = 0;
    if (XGetWMProtocols(dpy, w, &protos, &n)) {
        for (int i = 0; i < n; i++) yes |= protos[i] == wm_delete;
        XFree(protos);
    }
    return yes;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: x_close_window WINDOW-NAME\n");
        return 2;
    }
    Display *dpy = XOpenDisplay(NULL);
    if (!dpy) {
        fprintf(stderr, "x_close_window: cannot open display '%s'\n", XDisplayName(NULL));
        return 2;
    }
    Window w = find_named(dpy, DefaultRootWindow(dpy), argv[1], 0);
    Atom wm_protocols = XInternAtom(dpy, "WM_PROTOCOLS", False);
    Atom wm_delete = XInternAtom(dpy, "WM_DELETE_WINDOW", False);
    int rc = 0;
    if (w == None) {
        fprintf(stderr, "x_close_window: no window named '%s'\n", argv[1]);
        rc = 1;
    } else if (!takes_delete(dpy, w, wm_delete)) {
        fprintf(stderr, "x_close_window: window 0x%lx does not list WM_DELETE_WINDOW in WM_PROTOCOLS\n",
                (unsigned long)w);
        rc = 1;
    } else {
        XEvent ev;
        memset(&ev, 0, sizeof ev);
        ev.xclient.type = ClientMessage;
        ev.xclient.window = w;
        ev.xclient.message_type = wm_protocols;
        ev.xclient.format = 32;
        ev.xclient.data.l[0] = (long)wm_delete;
        ev.xclient.data.l[1] = CurrentTime;
        XSendEvent(dpy, w, False, NoEventMask, &ev);
        XSync(dpy, False);
    }
    XCloseDisplay(dpy);
    return rc;
}
