/* Responder registry: the queue backend delivers pushed events in order with their timestamps;
 * unknown names and window backends without a window are refused with a message. */
#include "devices/responder.h"
#include "tests/check.h"

int main(void)
{
    csf_responder *r = NULL;
    csf_error err;
    CHECK(csf_responder_open("queue", NULL, &r, &err) == CSF_OK);
    if (r) {
        CHECK(strcmp(csf_responder_name(r), "queue") == 0);
        csf_response ev;
        CHECK(csf_responder_poll(r, &ev) == 0);
        double t0 = csf_responder_now();
        csf_response a = {CSF_RESP_PRESS, 0, 0, 0, 0, t0, 0};
        csf_response b = {CSF_RESP_CLICK, 0, 0, 12.5, 40.0, t0 + 0.25, 0};
        csf_response c = {CSF_RESP_ESCAPE, 0, 0, 0, 0, t0 + 0.5, 0};
        CHECK(csf_responder_push(r, &a) == 0);
        CHECK(csf_responder_push(r, &b) == 0);
        CHECK(csf_responder_push(r, &c) == 0);
        CHECK(csf_responder_poll(r, &ev) == 1 && ev.kind == CSF_RESP_PRESS && ev.t_s == t0);
        CHECK(csf_responder_poll(r, &ev) == 1 && ev.kind == CSF_RESP_CLICK && ev.x_px == 12.5 && ev.y_px == 40.0);
        CHECK(csf_responder_poll(r, &ev) == 1 && ev.kind == CSF_RESP_ESCAPE);
        CHECK(csf_responder_poll(r, &ev) == 0);
        int pushed = 0;
        for (int i = 0; i < 1000; i++) pushed += csf_responder_push(r, &a) == 0;
        CHECK_INT_EQ(pushed, 256); /* bounded queue: the rest is refused, not overwritten */
        csf_responder_close(r);
    }
    CHECK(csf_responder_open("joystick", NULL, &r, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "keyboard, mouse, gamepad");
    CHECK(csf_responder_open("keyboard", NULL, &r, &err) == CSF_E_UNSUPPORTED);
    CHECK_STR_CONTAINS(err.msg, "need a window");
    /* The monotonic clock moves forward. */
    double t1 = csf_responder_now(), t2 = csf_responder_now();
    CHECK(t2 >= t1 && t1 > 0);
    return CHECK_RESULT();
}
