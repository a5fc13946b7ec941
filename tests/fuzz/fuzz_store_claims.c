/* STORE-claims beside an SQLite store is outside input: any process that can write the folder
 * can write it, and a station refused a session reads the holder's record from it for the
 * message. The record is the input here: a handle holds session 1's claim, the input replaces
 * its record, and a second handle's refused resume must read it without crashing or reading
 * past it. */
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "results/store/store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], path[96], claims[128];
static csf_store *holder;
static int64_t sid;

static void cleanup(void)
{
    csf_store_close(holder);
    const char *sides[] = {"", "-wal", "-shm", "-claims"};
    for (size_t i = 0; i < sizeof sides / sizeof sides[0]; i++) {
        char p[160];
        snprintf(p, sizeof p, "%s%s", path, sides[i]);
        unlink(p);
    }
    rmdir(dir);
}

/* One store for the whole run: its handle holds session 1's claim throughout. */
static int setup(void)
{
    if (holder) return 0;
    snprintf(dir, sizeof dir, "/tmp/csfcal-fuzz-claims-XXXXXX");
    if (!mkdtemp(dir)) return -1;
    snprintf(path, sizeof path, "%s/store.sqlite", dir);
    snprintf(claims, sizeof claims, "%s-claims", path);
    csf_error err;
    if (csf_store_open(path, &holder, &err) != CSF_OK ||
        csf_store_begin_session(holder, CSF_SESSION_OBSERVER, "o", "d", NULL, 1, &sid, &err) != CSF_OK) {
        fprintf(stderr, "fuzz_store_claims: %s\n", err.msg);
        return -1;
    }
    atexit(cleanup);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (setup() < 0) abort();
    if (size > 512) size = 512; /* a record is 128 bytes; a longer input also covers the next */
    int fd = open(claims, O_WRONLY);
    if (fd < 0) return 0;
    if (pwrite(fd, data, size, (off_t)(sid * 128)) != (ssize_t)size) {
        close(fd);
        return 0;
    }
    close(fd);
    csf_store *other = NULL;
    csf_error err;
    if (csf_store_open(path, &other, &err) != CSF_OK) return 0;
    csf_status cs = csf_store_set_session_state(other, sid, CSF_SESSION_RUNNING, &err);
    if (cs == CSF_OK) abort(); /* the claim is held: a resume must be refused */
    if (!memchr(err.msg, '\0', sizeof err.msg)) abort();
    csf_store_close(other);
    return 0;
}
