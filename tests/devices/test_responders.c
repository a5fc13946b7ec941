/* Gamepad and HID button-box responders through their seams: the button map text, the HID spec,
 * report decoding (report ids, offsets, multi-byte and active-low bits), edges (a held button
 * answers once), the reader thread's timestamps (taken when the report arrives, not when the
 * session polls), a device that goes away (one pause event), and the gamepad's choice of joystick. */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "devices/responder.h"
#include "devices/responder_gamepad.h"
#include "devices/responder_hid.h"
#include "devices/responder_map.h"
#include "emu_hid.h"
#include "tests/check.h"

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (time_t)s) * 1e9)};
    nanosleep(&ts, NULL);
}

static void map_text(void)
{
    csf_button_map m;
    memset(&m, 0, sizeof m);
    csf_error err;
    const char *t = "press:0/first:4/second:5/ur:10/ul:11/ll:12/lr:13/pause:63";
    CHECK_INT_EQ(csf_button_map_parse(t, strlen(t), &m, &err), CSF_OK);
    char back[256];
    csf_button_map_format(&m, back, sizeof back);
    CHECK(strcmp(back, t) == 0);
    /* a bad entry leaves the map as it was and names the entry */
    const char *bad[] = {"press", "press:", "press:64", "jump:1", "press:1/", "/press:1", "press:1x", "press:-1",
                         "press:100", ""};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        csf_button_map before = m;
        CHECK_MSG(csf_button_map_parse(bad[i], strlen(bad[i]), &m, &err) == CSF_E_INVALID_ARG, "'%s' accepted", bad[i]);
        CHECK(memcmp(&before, &m, sizeof m) == 0);
    }
    CHECK_STR_CONTAINS(err.msg, "button map");
    /* edges: only buttons that went down, lowest first */
    csf_response ev[8];
    CHECK_INT_EQ(csf_button_events(&m, 0, 1u << 4 | 1u << 0, 2.5, ev, 8), 2);
    CHECK(ev[0].kind == CSF_RESP_PRESS && ev[0].t_s == 2.5);
    CHECK(ev[1].kind == CSF_RESP_CHOICE && ev[1].choice == 0 && ev[1].places == 2);
    CHECK_INT_EQ(csf_button_events(&m, 1u << 4, 1u << 4, 3, ev, 8), 0);       /* held */
    CHECK_INT_EQ(csf_button_events(&m, 1u << 4, 0, 3, ev, 8), 0);             /* released */
    CHECK_INT_EQ(csf_button_events(&m, 0, 1u << 12, 3, ev, 8), 1);
    CHECK(ev[0].kind == CSF_RESP_CHOICE && ev[0].choice == 2 && ev[0].places == 4); /* lower left */
    CHECK_INT_EQ(csf_button_events(&m, 0, 1ull << 63, 3, ev, 8), 1);
    CHECK(ev[0].kind == CSF_RESP_ESCAPE);
    CHECK_INT_EQ(csf_button_events(&m, 0, 1u << 7, 3, ev, 8), 1);
    CHECK(ev[0].kind == CSF_RESP_KEY && ev[0].key == CSF_BUTTON_KEY_BASE + 7); /* unmapped */
}

static void hid_spec(void)
{
    csf_hid_spec s;
    csf_error err;
    CHECK_INT_EQ(csf_hid_spec_parse("1b4f:9206", &s, &err), CSF_OK);
    CHECK(s.vid == 0x1b4f && s.pid == 0x9206 && s.report_id == -1 && s.offset == 0 && s.bytes == 1);
    CHECK(s.map.action[0] == CSF_ACT_PRESS && s.map.action[7] == CSF_ACT_PAUSE);
    CHECK_INT_EQ(csf_hid_spec_parse("0x16C0:0x05df,serial=BOX2,report=3,offset=2,bytes=2,active=low,map=first:9/none:0",
                                    &s, &err), CSF_OK);
    CHECK(s.vid == 0x16c0 && s.pid == 0x05df && strcmp(s.serial, "BOX2") == 0 && s.report_id == 3 && s.offset == 2 &&
          s.bytes == 2 && s.active_low);
    CHECK(s.map.action[9] == CSF_ACT_FIRST && s.map.action[0] == CSF_ACT_NONE && s.map.action[1] == CSF_ACT_FIRST);
    const char *bad[] = {"", "1b4f", "1b4f:", "12345:1", "xyz:1", "1b4f:9206,", "1b4f:9206,report=0",
                         "1b4f:9206,report=256", "1b4f:9206,offset=64", "1b4f:9206,bytes=9", "1b4f:9206,bytes=0",
                         "1b4f:9206,active=maybe", "1b4f:9206,colour=red", "1b4f:9206,map=press:99",
                         "1b4f:9206,serial=", "1b4f:9206,report"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err.msg[0] = 0;
        CHECK_MSG(csf_hid_spec_parse(bad[i], &s, &err) == CSF_E_INVALID_ARG, "'%s' accepted", bad[i]);
        CHECK_MSG(err.msg[0] != 0, "'%s': no message", bad[i]);
    }
    /* reports */
    CHECK_INT_EQ(csf_hid_spec_parse("1:2,report=3,offset=1,bytes=2,active=low", &s, &err), CSF_OK);
    uint64_t bits = 0;
    uint8_t r1[] = {3, 0xaa, 0xfe, 0x7f};
    CHECK_INT_EQ(csf_hid_report_buttons(&s, r1, sizeof r1, &bits), 0);
    CHECK(bits == (0x01u | 0x80u << 8)); /* active low: bit 0 of the first and bit 7 of the second */
    uint8_t r2[] = {4, 0xaa, 0xfe, 0x7f}; /* another report id */
    CHECK_INT_EQ(csf_hid_report_buttons(&s, r2, sizeof r2, &bits), -1);
    CHECK_INT_EQ(csf_hid_report_buttons(&s, r1, 3, &bits), -1); /* too short */
    CHECK_INT_EQ(csf_hid_report_buttons(&s, r1, 0, &bits), -1);
}

static int poll_wait(csf_responder *r, csf_response *ev, double timeout_s)
{
    double t0 = csf_responder_now();
    while (csf_responder_now() - t0 < timeout_s) {
        if (csf_responder_poll(r, ev)) return 1;
        sleep_s(0.001);
    }
    return 0;
}

static void hid_box(void)
{
    emu_hid e;
    csf_hid_io io = emu_hid_init(&e);
    csf_responder *r = NULL;
    csf_error err;
    CHECK_INT_EQ(csf_responder_open_hid_io("1b4f:9206,report=1,map=ur:2", &io, &r, &err), CSF_OK);
    if (!r) return;
    CHECK(strcmp(csf_responder_name(r), "hid") == 0);
    csf_response ev;
    CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
    uint8_t down1[] = {1, 0x02}, held[] = {1, 0x02}, both[] = {1, 0x06}, none[] = {1, 0x00}, other[] = {2, 0xff};
    emu_hid_send(&e, down1, 2);
    double t_sent = e.delivered_s;
    /* the session polls late (a frame or more): the time is still the report's */
    sleep_s(0.05);
    CHECK_INT_EQ(poll_wait(r, &ev, 1), 1);
    CHECK(ev.kind == CSF_RESP_CHOICE && ev.choice == 0 && ev.places == 2); /* bit 1: first */
    CHECK_MSG(ev.t_s >= t_sent - 1e-6 && ev.t_s - t_sent < 0.02, "event at %.6f, report read at %.6f", ev.t_s, t_sent);
    CHECK_MSG(csf_responder_now() - ev.t_s >= 0.045, "stamped at the poll, not at the report");
    emu_hid_send(&e, held, 2);       /* still held: no new answer */
    emu_hid_send(&e, other, 2);      /* another report id: ignored */
    emu_hid_send(&e, both, 2);       /* bit 2 goes down: ur (mapped) */
    CHECK_INT_EQ(poll_wait(r, &ev, 1), 1);
    CHECK(ev.kind == CSF_RESP_CHOICE && ev.choice == 0 && ev.places == 4);
    CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
    emu_hid_send(&e, none, 2);
    emu_hid_send(&e, down1, 2);      /* released and pressed again: a new answer */
    CHECK_INT_EQ(poll_wait(r, &ev, 1), 1);
    CHECK(ev.kind == CSF_RESP_CHOICE && ev.places == 2);
    /* unplugged: one pause event that says so, then nothing */
    pthread_mutex_lock(&e.mu);
    e.len = -1;
    pthread_cond_broadcast(&e.cv);
    pthread_mutex_unlock(&e.mu);
    CHECK_INT_EQ(poll_wait(r, &ev, 1), 1);
    CHECK(ev.kind == CSF_RESP_ESCAPE && ev.key == CSF_RESP_KEY_GONE);
    CHECK_INT_EQ(poll_wait(r, &ev, 0.1), 0);
    csf_responder_close(r);
    CHECK(e.closed);
    /* a bad spec is refused and the io closed */
    e.closed = 0;
    CHECK_INT_EQ(csf_responder_open_hid_io("nothex:1", &io, &r, &err), CSF_E_INVALID_ARG);
    CHECK(r == NULL && e.closed);
    pthread_cond_destroy(&e.cv);
    pthread_mutex_destroy(&e.mu);
}

/* An emulated set of joysticks: 0 absent, 1 a plain joystick, 2 a gamepad. */
typedef struct {
    uint64_t bits[16];
    int present[16], pad[16];
} emu_pads;

static int emu_buttons(csf_pad_io *io, int jid, uint64_t *bits)
{
    emu_pads *p = io->user;
    if (jid < 0 || jid > 15 || !p->present[jid]) return 0;
    *bits = p->bits[jid];
    return 1;
}

static int emu_is_gamepad(csf_pad_io *io, int jid)
{
    emu_pads *p = io->user;
    return jid >= 0 && jid <= 15 && p->present[jid] && p->pad[jid];
}

static void gamepad(void)
{
    emu_pads p;
    memset(&p, 0, sizeof p);
    csf_pad_io io = {emu_buttons, emu_is_gamepad, &p};
    csf_responder *r = NULL;
    csf_error err;
    CHECK_INT_EQ(csf_responder_open_gamepad_io("", &io, &r, &err), CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(err.msg, "no joystick");
    p.present[1] = 1;
    p.present[2] = p.pad[2] = 1;
    p.bits[2] = 1u << 0; /* A already held when the session starts: not an answer */
    CHECK_INT_EQ(csf_responder_open_gamepad_io("", &io, &r, &err), CSF_OK); /* picks the gamepad, 2 */
    if (r) {
        csf_response ev;
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
        p.bits[1] = 1u << 0;                 /* the other joystick: not listened to */
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
        p.bits[2] = 0;
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
        double t0 = csf_responder_now();
        p.bits[2] = 1u << 0 | 1u << 16;      /* A and the right trigger together */
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_PRESS && ev.t_s >= t0);
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_CHOICE && ev.choice == 3 && ev.places == 4); /* lower right */
        p.bits[2] = 1u << 14;                /* d-pad left */
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_CHOICE && ev.choice == 0 && ev.places == 2);
        p.bits[2] |= 1u << 7;                /* start */
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_ESCAPE && ev.key != CSF_RESP_KEY_GONE);
        p.present[2] = 0;                    /* unplugged */
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_ESCAPE && ev.key == CSF_RESP_KEY_GONE);
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 0);
        csf_responder_close(r);
    }
    p.present[2] = 1;
    /* joystick 1 by number (no gamepad mapping: raw buttons), with a map */
    CHECK_INT_EQ(csf_responder_open_gamepad_io("1,map=second:3", &io, &r, &err), CSF_OK);
    if (r) {
        csf_response ev;
        p.bits[1] = 1u << 3;
        CHECK_INT_EQ(csf_responder_poll(r, &ev), 1);
        CHECK(ev.kind == CSF_RESP_CHOICE && ev.choice == 1 && ev.places == 2);
        csf_responder_close(r);
    }
    CHECK_INT_EQ(csf_responder_open_gamepad_io("3", &io, &r, &err), CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(err.msg, "joystick 3 is not connected");
    const char *bad[] = {"16", "x", "1,map=", "1,map=fire:1", "1,turbo=1", "-1", "123"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_MSG(csf_responder_open_gamepad_io(bad[i], &io, &r, &err) == CSF_E_INVALID_ARG, "'%s' accepted", bad[i]);
    /* through the registry: needs the presenter's window (GLFW), refused plainly without one */
    CHECK_INT_EQ(csf_responder_open("gamepad", NULL, &r, &err), CSF_E_UNSUPPORTED);
    CHECK_STR_CONTAINS(err.msg, "need a window");
    CHECK_INT_EQ(csf_responder_open("keyboard:x", NULL, &r, &err), CSF_E_INVALID_ARG);
    CHECK_INT_EQ(csf_responder_open("hid:zz:1", NULL, &r, &err), CSF_E_INVALID_ARG);
}

static void check_spec(void)
{
    csf_error err;
    const char *good[] = {"keyboard", "mouse", "queue", "gamepad", "gamepad:3", "gamepad:0,map=press:1",
                          "hid:1b4f:9206", "hid:1b4f:9206,report=2,map=first:0"};
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
        CHECK_MSG(csf_responder_check_spec(good[i], &err) == CSF_OK, "'%s': %s", good[i], err.msg);
    const char *bad[] = {"", "joystick", "keyboard:x", "gamepad:16", "gamepad:1,map=fire:0", "hid", "hid:",
                         "hid:1b4f", "hid:1b4f:9206,bytes=0", "mouse:x", "queue:1"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err.msg[0] = 0;
        CHECK_MSG(csf_responder_check_spec(bad[i], &err) == CSF_E_INVALID_ARG && err.msg[0], "'%s' accepted", bad[i]);
    }
}

int main(void)
{
    check_spec();
    map_text();
    hid_spec();
    hid_box();
    gamepad();
    /* a HID box that is not connected: refused with NOT_FOUND naming the ids (no box of this id
     * exists on a test machine: 0xffff is reserved) */
    csf_responder *r = NULL;
    csf_error err;
    csf_status st = csf_responder_open("hid:ffff:fffe", NULL, &r, &err);
    CHECK_MSG(st == CSF_E_NOT_FOUND || st == CSF_E_DEVICE, "status %d: %s", (int)st, err.msg);
    CHECK_STR_CONTAINS(err.msg, "ffff:fffe");
    return CHECK_RESULT();
}
