/* How late the HID responder's timestamp is, in software: an emulated box hands N reports (a
 * button down, then up) to the responder's reader thread through the csf_hid_io seam; for each
 * press the time the emulator's read returned is compared with the event's t_s. The session polls
 * once per "frame" (16.7 ms) meanwhile, so the figure shows the stamp does not wait for the poll.
 * What this leaves out is the USB side (the box's polling interval, hidapi's transfer thread).
 * usage: bench_hid_latency [N]   (default 500 presses) */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "devices/responder_hid.h"
#include "tests/devices/emu_hid.h"

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 500;
    if (n < 10 || n > 100000) {
        fprintf(stderr, "bench_hid_latency: N from 10 to 100000\n");
        return 2;
    }
    emu_hid e;
    csf_hid_io io = emu_hid_init(&e);
    csf_responder *r = NULL;
    csf_error err;
    if (csf_responder_open_hid_io("1b4f:9206", &io, &r, &err)) {
        fprintf(stderr, "bench_hid_latency: %s\n", err.msg);
        return 1;
    }
    double *stamp = calloc((size_t)n, sizeof *stamp), *poll_late = calloc((size_t)n, sizeof *poll_late);
    if (!stamp || !poll_late) return 1;
    for (int i = 0; i < n; i++) {
        emu_hid_send(&e, (const uint8_t[]){0x01}, 1);
        double read_s = e.delivered_s;
        /* the session draws a frame before it polls */
        struct timespec frame = {0, 16700000L};
        nanosleep(&frame, NULL);
        csf_response ev;
        while (!csf_responder_poll(r, &ev)) nanosleep(&(struct timespec){0, 100000L}, NULL);
        stamp[i] = (ev.t_s - read_s) * 1e6;
        poll_late[i] = (csf_responder_now() - read_s) * 1e6;
        emu_hid_send(&e, (const uint8_t[]){0x00}, 1);
    }
    csf_responder_close(r);
    qsort(stamp, (size_t)n, sizeof *stamp, cmp);
    qsort(poll_late, (size_t)n, sizeof *poll_late, cmp);
    printf("presses  stamp after read (us): median  p99  max   poll after read (us): median\n");
    printf("%7d  %28.1f %5.1f %5.1f  %28.0f\n", n, stamp[n / 2], stamp[n * 99 / 100], stamp[n - 1], poll_late[n / 2]);
    free(stamp);
    free(poll_late);
    return 0;
}
