/* An emulated HID response box behind the responder's csf_hid_io seam (devices/responder_hid.h),
 * shared by test_responders and bench/bench_hid_latency: reports are handed to the reader thread
 * through a one-slot mailbox, and the reader blocks on it as on hid_read_timeout. */
#ifndef CSF_TESTS_EMU_HID_H
#define CSF_TESTS_EMU_HID_H

#include <pthread.h>
#include <string.h>
#include <time.h>

#include "devices/responder_hid.h"

typedef struct {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    uint8_t rep[16];
    int len;     /* > 0: a report waits; -1: unplugged */
    int closed;
    double delivered_s; /* when the reader took the last report (csf_responder_now) */
} emu_hid;

static inline int emu_hid_read(csf_hid_io *io, uint8_t *buf, size_t cap, int timeout_ms)
{
    emu_hid *e = io->user;
    pthread_mutex_lock(&e->mu);
    if (e->len == 0) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += (long)timeout_ms * 1000000L;
        ts.tv_sec += ts.tv_nsec / 1000000000L;
        ts.tv_nsec %= 1000000000L;
        pthread_cond_timedwait(&e->cv, &e->mu, &ts);
    }
    int n = e->len;
    if (n > 0) {
        if ((size_t)n > cap) n = (int)cap;
        memcpy(buf, e->rep, (size_t)n);
        e->len = 0;
        e->delivered_s = csf_responder_now();
        pthread_cond_broadcast(&e->cv);
    }
    pthread_mutex_unlock(&e->mu);
    return n;
}

static inline void emu_hid_close(csf_hid_io *io)
{
    emu_hid *e = io->user;
    e->closed = 1;
}

/* An empty box and the io that reads from it. */
static inline csf_hid_io emu_hid_init(emu_hid *e)
{
    memset(e, 0, sizeof *e);
    pthread_mutex_init(&e->mu, NULL);
    pthread_cond_init(&e->cv, NULL);
    return (csf_hid_io){emu_hid_read, emu_hid_close, e};
}

/* Hands one report (len <= 16 bytes) to the reader and waits until it took it. */
static inline void emu_hid_send(emu_hid *e, const uint8_t *rep, int len)
{
    pthread_mutex_lock(&e->mu);
    memcpy(e->rep, rep, (size_t)len);
    e->len = len;
    pthread_cond_broadcast(&e->cv);
    while (e->len > 0) pthread_cond_wait(&e->cv, &e->mu);
    pthread_mutex_unlock(&e->mu);
}

#endif
