/* For fuzz targets whose input is a file (stores, configuration): the input written to a fresh
 * temporary file, and that file removed again with the -wal / -shm files SQLite may leave beside
 * it. */
#ifndef CSF_TESTS_FUZZ_FILE_H
#define CSF_TESTS_FUZZ_FILE_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static inline void fuzz_file_remove(const char *path)
{
    char side[80];
    unlink(path);
    snprintf(side, sizeof side, "%s-wal", path);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", path);
    unlink(side);
}

/* Writes data to /tmp/csfcal-fuzz-NAME-XXXXXX; its path in path[64]. 0 on success, -1 when the
 * file could not be made or written (nothing is left behind then). */
static inline int fuzz_file_write(const char *name, const uint8_t *data, size_t size, char path[64])
{
    snprintf(path, 64, "/tmp/csfcal-fuzz-%s-XXXXXX", name);
    int fd = mkstemp(path);
    if (fd < 0) return -1;
    int ok = write(fd, data, size) == (ssize_t)size;
    close(fd);
    if (!ok) fuzz_file_remove(path);
    return ok ? 0 : -1;
}

#endif
