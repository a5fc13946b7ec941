/* Open refuses, before any stimulus could be shown, with a message naming the file and the cause:
 *   - corrupt stores (not a database at all; damaged pages; truncated file),
 *   - read-only stores (file mode, folder mode, read-only file system when we can mount one),
 *   - a full disk: a real tiny tmpfs when the test may mount one (root), and always a file-size
 *     limit (RLIMIT_FSIZE) in a child process, which makes writes fail like a full disk.
 * A disk that fills up mid-session makes add_trial fail loudly, and every trial reported stored
 * before that is still there afterwards. */
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "results/store/store.h"
#include "results/store/internal.h"
#include "store_test_util.h"
#include "tests/check.h"

static int fill_store(const char *path, int n_trials)
{
    csf_error err;
    csf_store *s = NULL;
    if (csf_store_open(path, &s, &err) != CSF_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    int64_t id = 0;
    int ok = csf_store_begin_session(s, CSF_SESSION_OBSERVER, "eve", "lcd", NULL, 1, &id, &err) == CSF_OK;
    sqlite3_exec(csf_store_db(s), "BEGIN", NULL, NULL, NULL); /* bulk: one commit */
    for (int i = 0; i < n_trials && ok; i++) {
        csf_trial t = make_trial(id, i, 3);
        ok = csf_store_add_trial(s, &t, &err) == CSF_OK;
    }
    sqlite3_exec(csf_store_db(s), "COMMIT", NULL, NULL, NULL);
    csf_store_close(s); /* last connection: checkpoints the WAL into the main file */
    return ok ? 0 : -1;
}

static void overwrite(const char *path, long offset, long len, unsigned char byte)
{
    FILE *f = fopen(path, "r+b");
    if (!f) return;
    fseek(f, offset, SEEK_SET);
    for (long i = 0; i < len; i++) fputc(byte + (int)(i * 37 % 11), f);
    fclose(f);
}

static void expect_refused(const char *path, const char *needle)
{
    csf_error err;
    csf_store *s = NULL;
    csf_status st = csf_store_open(path, &s, &err);
    CHECK_MSG(st == CSF_E_STORE, "open %s gave %d (%s)", path, (int)st, err.msg);
    CHECK(s == NULL);
    if (s) csf_store_close(s);
    CHECK_STR_CONTAINS(err.msg, path);
    CHECK_STR_CONTAINS(err.msg, needle);
    fprintf(stderr, "  refused as expected: %s\n", err.msg);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static void test_corrupt(const char *dir)
{
    char path[600];
    /* Not a database at all: a CSV someone passed by mistake. Left untouched. */
    snprintf(path, sizeof path, "%s/results.csv", dir);
    FILE *f = fopen(path, "w");
    fputs("freq_cpd,threshold\n1,0.01\n2,0.005\n4,0.004\n", f);
    fclose(f);
    long before = file_size(path);
    expect_refused(path, "not a database");
    CHECK_INT_EQ(file_size(path), before);

    /* A store whose b-tree pages were overwritten (bad sector, a stray write). */
    snprintf(path, sizeof path, "%s/damaged.sqlite", dir);
    CHECK_INT_EQ(fill_store(path, 600), 0);
    long sz = file_size(path);
    CHECK(sz > 20 * 4096);
    overwrite(path, 4096 * 6, 4096 * 3, 0xA5);
    expect_refused(path, "corrupt");

    /* A store cut short (copy interrupted, disk full during a copy). */
    snprintf(path, sizeof path, "%s/truncated.sqlite", dir);
    CHECK_INT_EQ(fill_store(path, 600), 0);
    CHECK_INT_EQ(truncate(path, file_size(path) / 2), 0);
    expect_refused(path, "corrupt");

    /* A damaged header (first page) is refused too, as not a database. */
    snprintf(path, sizeof path, "%s/header.sqlite", dir);
    CHECK_INT_EQ(fill_store(path, 10), 0);
    overwrite(path, 0, 16, 0x00);
    expect_refused(path, "not a database");
}

static void test_read_only(const char *dir)
{
    char path[700], sub[600];
    snprintf(path, sizeof path, "%s/ro.sqlite", dir);
    CHECK_INT_EQ(fill_store(path, 5), 0);
    chmod(path, 0444);
    expect_refused(path, "read-only file");
    chmod(path, 0644);

    snprintf(sub, sizeof sub, "%s/locked", dir);
    mkdir(sub, 0755);
    snprintf(path, sizeof path, "%s/store.sqlite", sub);
    CHECK_INT_EQ(fill_store(path, 5), 0);
    chmod(sub, 0555);
    expect_refused(path, "read-only");
    chmod(sub, 0755);

    /* A read-only file system, when this test is allowed to mount one (root). */
    snprintf(sub, sizeof sub, "%s/rofs", dir);
    mkdir(sub, 0755);
    if (mount("tmpfs", sub, "tmpfs", 0, "size=8m") == 0) {
        snprintf(path, sizeof path, "%s/store.sqlite", sub);
        CHECK_INT_EQ(fill_store(path, 7), 0);
        CHECK_INT_EQ(mount("tmpfs", sub, "tmpfs", MS_REMOUNT | MS_RDONLY, "size=8m"), 0);
        expect_refused(path, "read-only file system");
        /* An archived store on read-only media can still be read, listed and exported. */
        csf_error err;
        csf_store *s = NULL;
        CHECK_INT_EQ(csf_store_open_readonly(path, &s, &err), CSF_OK);
        if (s) {
            csf_session_info *list = NULL;
            size_t n = 0;
            CHECK_INT_EQ(csf_store_list_sessions(s, &list, &n, &err), CSF_OK);
            CHECK_INT_EQ(n, 1);
            if (n == 1) CHECK_INT_EQ(list[0].n_trials, 7);
            csf_trial *t = NULL;
            size_t nt = 0;
            if (n == 1) CHECK_INT_EQ(csf_store_get_trials(s, list[0].id, &t, &nt, &err), CSF_OK);
            CHECK_INT_EQ(nt, 7);
            free(t);
            csf_trial more = make_trial(n == 1 ? list[0].id : 1, 7, 3);
            CHECK_INT_EQ(csf_store_add_trial(s, &more, &err), CSF_E_STORE);
            CHECK_STR_CONTAINS(err.msg, "read-only");
            csf_session_list_free(list, n);
            csf_store_close(s);
        }
        umount(sub);
    } else {
        fprintf(stderr, "  (read-only mount not permitted here: %s; file/folder modes tested)\n",
                strerror(errno));
    }
}

/* Full disk simulated with a file-size limit: the open-time write probe must fail. */
static void test_full_rlimit(const char *dir)
{
    char path[600];
    snprintf(path, sizeof path, "%s/limited.sqlite", dir);
    CHECK_INT_EQ(fill_store(path, 5), 0);
    int pfd[2];
    if (pipe(pfd) != 0) return;
    pid_t pid = fork();
    if (pid == 0) {
        close(pfd[0]);
        signal(SIGXFSZ, SIG_IGN); /* get EFBIG from write() instead of being killed */
        struct rlimit rl = {32 * 1024, 32 * 1024};
        setrlimit(RLIMIT_FSIZE, &rl);
        csf_error err;
        csf_store *s = NULL;
        csf_status st = csf_store_open(path, &s, &err);
        if (s) csf_store_close(s);
        char msg[600];
        snprintf(msg, sizeof msg, "%d %s", (int)st, err.msg);
        ssize_t w = write(pfd[1], msg, strlen(msg) + 1);
        (void)w;
        _exit(0);
    }
    close(pfd[1]);
    char buf[600] = "";
    ssize_t got = read(pfd[0], buf, sizeof buf - 1);
    close(pfd[0]);
    waitpid(pid, NULL, 0);
    buf[got > 0 ? got : 0] = '\0';
    fprintf(stderr, "  file-size-limited child: %s\n", buf);
    CHECK(atoi(buf) == CSF_E_STORE);
    CHECK_STR_CONTAINS(buf, "disk full");
    CHECK_STR_CONTAINS(buf, path);
}

/* A real full disk: a small tmpfs. Mid-session failure, then refusal at the next open. */
static void test_full_tmpfs(const char *dir)
{
    char mnt[600], path[700], filler[700];
    snprintf(mnt, sizeof mnt, "%s/small", dir);
    mkdir(mnt, 0755);
    if (mount("tmpfs", mnt, "tmpfs", 0, "size=6m") != 0) {
        fprintf(stderr, "  (tmpfs mount not permitted here: %s; full disk tested with RLIMIT_FSIZE only)\n",
                strerror(errno));
        return;
    }
    snprintf(path, sizeof path, "%s/store.sqlite", mnt);
    snprintf(filler, sizeof filler, "%s/filler", mnt);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    int64_t id = 0;
    if (s)
        CHECK_INT_EQ(csf_store_begin_session(s, CSF_SESSION_OBSERVER, "eve", "lcd", NULL, 1, &id, &err),
                     CSF_OK);
    int stored = 0;
    for (int i = 0; s && i < 20; i++) {
        csf_trial t = make_trial(id, i, 9);
        if (csf_store_add_trial(s, &t, &err) == CSF_OK) stored = i + 1;
    }
    CHECK_INT_EQ(stored, 20);
    /* Something else fills the disk. */
    FILE *f = fopen(filler, "wb");
    char block[4096];
    memset(block, 0x5a, sizeof block);
    while (f && fwrite(block, 1, sizeof block, f) == sizeof block) {
    }
    if (f) fclose(f);
    csf_status st = CSF_OK;
    int i = stored;
    for (; s && i < stored + 2000 && st == CSF_OK; i++) {
        csf_trial t = make_trial(id, i, 9);
        st = csf_store_add_trial(s, &t, &err);
        if (st == CSF_OK) stored = i + 1;
    }
    CHECK_INT_EQ(st, CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "disk full");
    CHECK_STR_CONTAINS(err.msg, path);
    fprintf(stderr, "  mid-session: %s (after %d trials)\n", err.msg, stored);
    csf_store_close(s);
    /* The next session is refused before it starts. */
    expect_refused(path, "disk full");
    /* Space freed: every trial reported stored is there, none beyond. */
    unlink(filler);
    s = NULL;
    CHECK_INT_EQ(csf_store_open(path, &s, &err), CSF_OK);
    if (s) {
        csf_trial *t = NULL;
        size_t n = 0;
        CHECK_INT_EQ(csf_store_get_trials(s, id, &t, &n, &err), CSF_OK);
        CHECK_INT_EQ(n, stored);
        int ok = 1;
        for (size_t k = 0; k < n; k++) {
            csf_trial want = make_trial(id, (int)k, 9);
            ok &= trials_equal(&t[k], &want);
        }
        CHECK(ok);
        free(t);
        csf_store_close(s);
    }
    umount(mnt);
}

int main(void)
{
    char dir[512];
    if (tmp_dir(dir, sizeof dir, "errors") < 0) return 1;
    test_corrupt(dir);
    test_read_only(dir);
    test_full_rlimit(dir);
    test_full_tmpfs(dir);
    rm_rf(dir);
    return CHECK_RESULT();
}
