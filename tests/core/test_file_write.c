/* Atomic output files: the destination holds the old bytes or the new ones, never a part; a write
 * that fails (here: past RLIMIT_FSIZE, which fails like a full disk) leaves no temporary behind and
 * says the OS error. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "results/file_read.h"
#include "results/file_write.h"
#include "tests/check.h"

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    if (d) closedir(d);
    return n;
}

static int contents_are(const char *path, const char *want)
{
    char *buf;
    size_t len;
    csf_error err;
    if (csf_read_file(path, "test file", 1 << 20, &buf, &len, &err)) return 0;
    int same = len == strlen(want) && memcmp(buf, want, len) == 0;
    free(buf);
    return same;
}

int main(void)
{
    char dir[] = "/tmp/csf_fw_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256], sub[300];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    csf_error err;

    CHECK(csf_write_file_atomic(path, "test file", "first", 5, &err) == CSF_OK);
    CHECK(contents_are(path, "first"));
    CHECK(csf_write_file_atomic(path, "test file", "second!", 7, &err) == CSF_OK);
    CHECK(contents_are(path, "second!"));
    CHECK(count_entries(dir) == 1);

    struct stat sb;
    CHECK(stat(path, &sb) == 0 && (sb.st_mode & 0644) == 0644);

    /* Streaming, then abort: the destination keeps its old bytes. */
    csf_atomic_file af;
    CHECK(csf_atomic_open(&af, path, "test file", &err) == CSF_OK);
    fputs("never seen", af.fp);
    csf_atomic_abort(&af);
    CHECK(contents_are(path, "second!"));
    CHECK(count_entries(dir) == 1);

    /* A write that the OS refuses part way: old contents stay, no temporary, the OS error named. */
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit old_lim, lim;
    getrlimit(RLIMIT_FSIZE, &old_lim);
    lim = old_lim;
    lim.rlim_cur = 4096;
    CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
    size_t big_len = 1 << 20;
    char *big = malloc(big_len);
    memset(big, 'x', big_len);
    csf_status st = csf_write_file_atomic(path, "test file", big, big_len, &err);
    setrlimit(RLIMIT_FSIZE, &old_lim);
    CHECK(st == CSF_E_IO);
    CHECK_MSG(strstr(err.msg, strerror(EFBIG)) != NULL, "message: %s", err.msg);
    CHECK_MSG(strstr(err.msg, path) != NULL, "message: %s", err.msg);
    CHECK(contents_are(path, "second!"));
    CHECK(count_entries(dir) == 1);
    free(big);

    /* A folder that does not exist: named, with the OS error; the up-front check says the same. */
    snprintf(sub, sizeof sub, "%s/missing/out.txt", dir);
    CHECK(csf_write_file_atomic(sub, "test file", "x", 1, &err) == CSF_E_IO);
    CHECK_MSG(strstr(err.msg, strerror(ENOENT)) != NULL, "message: %s", err.msg);
    CHECK(csf_check_output_path(sub, "test file", &err) == CSF_E_IO);
    CHECK_MSG(strstr(err.msg, "missing") != NULL, "message: %s", err.msg);
    CHECK(csf_check_output_path(path, "test file", &err) == CSF_OK);
    CHECK(csf_check_output_path(dir, "test file", &err) == CSF_E_INVALID_ARG);
    CHECK(csf_check_output_path("", "test file", &err) == CSF_E_INVALID_ARG);

    unlink(path);
    rmdir(dir);
    return CHECK_RESULT();
}
