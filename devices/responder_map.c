/* Button maps for gamepad and HID responders (see devices/responder_map.h). */
#include "devices/responder_map.h"

#include <stdio.h>
#include <string.h>

static const char *const names[CSF_ACT_COUNT] = {"none", "press", "first", "second", "ur", "ul", "ll", "lr", "pause"};

const char *csf_button_action_name(csf_button_action a)
{
    return (unsigned)a < CSF_ACT_COUNT ? names[a] : "?";
}

static int parse_pair(const char *p, size_t n, int *act, int *button)
{
    const char *colon = memchr(p, ':', n);
    if (!colon) return -1;
    size_t an = (size_t)(colon - p);
    *act = -1;
    for (int a = 0; a < CSF_ACT_COUNT; a++)
        if (strlen(names[a]) == an && memcmp(p, names[a], an) == 0) *act = a;
    if (*act < 0) return -1;
    const char *d = colon + 1, *end = p + n;
    if (d == end || end - d > 2) return -1;
    int b = 0;
    for (; d < end; d++) {
        if (*d < '0' || *d > '9') return -1;
        b = b * 10 + (*d - '0');
    }
    if (b >= CSF_MAP_BUTTONS) return -1;
    *button = b;
    return 0;
}

csf_status csf_button_map_parse(const char *text, size_t len, csf_button_map *m, csf_error *err)
{
    csf_button_map out = *m;
    size_t i = 0;
    if (len == 0) return csf_error_set(err, CSF_E_INVALID_ARG, "button map is empty (ACTION:BUTTON/...)");
    while (i <= len) {
        size_t j = i;
        while (j < len && text[j] != '/') j++;
        int act, b;
        if (parse_pair(text + i, j - i, &act, &b))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "button map entry '%.*s' not understood (ACTION:BUTTON, ACTION one of press, "
                                 "first, second, ur, ul, ll, lr, pause, none; BUTTON 0 to %d)",
                                 (int)(j - i > 40 ? 40 : j - i), text + i, CSF_MAP_BUTTONS - 1);
        out.action[b] = (unsigned char)act;
        i = j + 1;
    }
    *m = out;
    return CSF_OK;
}

void csf_button_map_format(const csf_button_map *m, char *buf, size_t len)
{
    size_t k = 0;
    if (len) buf[0] = 0;
    for (int b = 0; b < CSF_MAP_BUTTONS && k < len; b++) {
        if (m->action[b] == CSF_ACT_NONE) continue;
        int w = snprintf(buf + k, len - k, "%s%s:%d", k ? "/" : "", csf_button_action_name(m->action[b]), b);
        if (w < 0) break;
        k += (size_t)w;
    }
}

static csf_response event_for(int action, int button, double t_s)
{
    csf_response ev;
    memset(&ev, 0, sizeof ev);
    ev.t_s = t_s;
    ev.key = CSF_BUTTON_KEY_BASE + button;
    switch (action) {
    case CSF_ACT_PRESS: ev.kind = CSF_RESP_PRESS; break;
    case CSF_ACT_FIRST:
    case CSF_ACT_SECOND:
        ev.kind = CSF_RESP_CHOICE;
        ev.choice = action - CSF_ACT_FIRST;
        ev.places = 2;
        break;
    case CSF_ACT_UR:
    case CSF_ACT_UL:
    case CSF_ACT_LL:
    case CSF_ACT_LR:
        ev.kind = CSF_RESP_CHOICE;
        ev.choice = action - CSF_ACT_UR;
        ev.places = 4;
        break;
    case CSF_ACT_PAUSE: ev.kind = CSF_RESP_ESCAPE; break;
    default: ev.kind = CSF_RESP_KEY; break;
    }
    return ev;
}

int csf_button_events(const csf_button_map *m, uint64_t prev, uint64_t now, double t_s, csf_response *out,
                      int cap)
{
    uint64_t down = now & ~prev;
    int n = 0;
    for (int b = 0; b < CSF_MAP_BUTTONS && n < cap; b++)
        if (down >> b & 1) out[n++] = event_for(m->action[b], b, t_s);
    return n;
}
