/* Response device specs (`responder =` in the station configuration, the --set value, the
 * study's settings) are outside input: "hid:VID:PID[,serial=,report=,offset=,bytes=,active=,map=]"
 * and "gamepad[:N][,map=...]". Any bytes must be refused with a message (nothing changed) or give a
 * spec inside its ranges, whose map formats to text that parses back to the same map; a HID spec
 * must then decode any report without reading past it. The same bytes are also tried as a bare
 * button map. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "devices/responder_gamepad.h"
#include "devices/responder_hid.h"
#include "devices/responder_map.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void map_roundtrip(const csf_button_map *m)
{
    char text[1024];
    csf_button_map_format(m, text, sizeof text);
    csf_button_map back;
    memset(&back, 0, sizeof back);
    csf_error err;
    if (text[0] && csf_button_map_parse(text, strlen(text), &back, &err) != CSF_OK) abort();
    for (int b = 0; b < CSF_MAP_BUTTONS; b++) {
        if (m->action[b] >= CSF_ACT_COUNT) abort();
        if (back.action[b] != m->action[b]) abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char text[512];
    if (size >= sizeof text) return 0;
    memcpy(text, data, size);
    text[size] = 0;
    csf_error err;
    err.msg[0] = 0;
    csf_hid_spec h;
    memset(&h, 0x5a, sizeof h);
    csf_hid_spec before = h;
    if (csf_hid_spec_parse(text, &h, &err) == CSF_OK) {
        if (h.bytes < 1 || h.bytes > 8 || h.offset < 0 || h.offset > 63 || h.report_id < -1 || h.report_id > 255 ||
            h.report_id == 0 || !memchr(h.serial, 0, sizeof h.serial))
            abort();
        map_roundtrip(&h.map);
        /* the input itself as a report, and every shorter prefix of it */
        for (size_t n = 0; n <= size; n++) {
            uint64_t bits;
            uint8_t *rep = malloc(n ? n : 1);
            if (!rep) abort();
            memcpy(rep, data, n);
            (void)csf_hid_report_buttons(&h, rep, n, &bits);
            free(rep);
        }
    } else if (!err.msg[0] || memcmp(&h, &before, sizeof h) != 0) {
        abort();
    }
    err.msg[0] = 0;
    csf_gamepad_spec g;
    if (csf_gamepad_spec_parse(text, &g, &err) == CSF_OK) {
        if (g.joystick < -1 || g.joystick > 15) abort();
        map_roundtrip(&g.map);
    } else if (!err.msg[0]) {
        abort();
    }
    csf_button_map m;
    memset(&m, 0, sizeof m);
    csf_button_map m0 = m;
    err.msg[0] = 0;
    if (csf_button_map_parse(text, size, &m, &err) == CSF_OK) map_roundtrip(&m);
    else if (!err.msg[0] || memcmp(&m, &m0, sizeof m) != 0) abort();
    return 0;
}
