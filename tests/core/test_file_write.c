/* Atomic output files: the destination holds the old bytes or the new ones, never a part; a write
 * that fails (here: past RLIMIT_FSIZE, which fails like a full disk) leaves no temporary behind and
 * says the OS error. What is at the destination decides how it is written: a FIFO, /dev/null or a
 * character device made with mknod (root only) is written in place and stays what it was; a link
 * to a file has its target replaced and stays a link; a link to nothing, a folder and a socket are
 * refused; a new file honours the umask and a replaced one keeps its mode. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/file_read.h"
#include "core/file_write.h"
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


static mode_t mode_of(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? sb.st_mode & 07777 : (mode_t)-1;
}

/* A FIFO at the destination: its reader (opened first, so neither side waits) gets the bytes,
 * and the FIFO is still a FIFO. */
static void test_fifo(const char *dir)
{
    char fifo[300];
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    CHECK(mkfifo(fifo, 0600) == 0);
    int rfd = open(fifo, O_RDONLY | O_NONBLOCK);
    CHECK(rfd >= 0);
    csf_error err;
    CHECK(csf_check_output_path(fifo, "test file", &err) == CSF_OK);
    CHECK_MSG(csf_write_file_atomic(fifo, "test file", "fifo!", 5, &err) == CSF_OK, "%s", err.msg);
    char got[16] = "";
    ssize_t n = read(rfd, got, sizeof got - 1);
    close(rfd);
    CHECK(n == 5 && !memcmp(got, "fifo!", 5));
    struct stat sb;
    CHECK(lstat(fifo, &sb) == 0 && S_ISFIFO(sb.st_mode));
    unlink(fifo);
}

/* A character device (as root: a /dev/null node made where a file was expected, as
 * `mknod n c 1 3; csfcal ... -o n` does): written through, never replaced by a regular file. */
static void test_devices(const char *dir)
{
    /* The machine's own /dev/null is only checked, never written: a regression would replace it
     * for every program on the machine. The written one is a node of the same device. */
    csf_error err;
    CHECK(csf_check_output_path("/dev/null", "test file", &err) == CSF_OK);
    struct stat sb;
    if (geteuid() != 0) {
        fprintf(stderr, "SKIP part: mknod of a character device needs root (running as uid %d)\n",
                (int)geteuid());
        return;
    }
    char node[300];
    snprintf(node, sizeof node, "%s/n", dir);
    CHECK(mknod(node, S_IFCHR | 0666, makedev(1, 3)) == 0);
    CHECK_MSG(csf_write_file_atomic(node, "test file", "abc", 3, &err) == CSF_OK, "%s", err.msg);
    CHECK(lstat(node, &sb) == 0 && S_ISCHR(sb.st_mode) && sb.st_rdev == makedev(1, 3));
    csf_atomic_file af;
    CHECK(csf_atomic_open(&af, node, "test file", &err) == CSF_OK);
    fputs("streamed", af.fp);
    CHECK(csf_atomic_commit(&af, &err) == CSF_OK);
    CHECK(lstat(node, &sb) == 0 && S_ISCHR(sb.st_mode));
    unlink(node);
}

/* "-" and /dev/stdout write through this process's standard output: a shell's ">>" stays an
 * append (the old bytes survive), and the file stays the same file. */
static void test_stdout(const char *dir)
{
    char log[300];
    snprintf(log, sizeof log, "%s/log", dir);
    CHECK(csf_write_file_atomic(log, "test file", "old\n", 4, NULL) == CSF_OK);
    struct stat before, after;
    CHECK(stat(log, &before) == 0);
    fflush(stdout);
    int saved = dup(STDOUT_FILENO);
    int fd = open(log, O_WRONLY | O_APPEND);
    CHECK(fd >= 0 && dup2(fd, STDOUT_FILENO) == STDOUT_FILENO);
    close(fd);
    csf_error err;
    csf_status a = csf_write_file_atomic("/dev/stdout", "test file", "one\n", 4, &err);
    csf_status b = csf_write_file_atomic("-", "test file", "two\n", 4, &err);
    fflush(stdout);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    CHECK(a == CSF_OK && b == CSF_OK);
    CHECK(contents_are(log, "old\none\ntwo\n"));
    CHECK(stat(log, &after) == 0 && after.st_ino == before.st_ino);
    unlink(log);
}

/* A link to a file: the target gets the new bytes and keeps its mode; the link stays a link. A
 * link to nothing is refused and creates nothing. A socket is refused. */
static void test_links_and_sockets(const char *dir)
{
    char target[300], link_path[300], dangling[300], missing[300], sock[300];
    snprintf(target, sizeof target, "%s/target", dir);
    snprintf(link_path, sizeof link_path, "%s/link", dir);
    snprintf(dangling, sizeof dangling, "%s/dangling", dir);
    snprintf(missing, sizeof missing, "%s/missing-target", dir);
    snprintf(sock, sizeof sock, "%s/sock", dir);
    csf_error err;
    CHECK(csf_write_file_atomic(target, "test file", "before", 6, &err) == CSF_OK);
    CHECK(chmod(target, 0640) == 0);
    CHECK(symlink("target", link_path) == 0);
    CHECK(csf_check_output_path(link_path, "test file", &err) == CSF_OK);
    CHECK_MSG(csf_write_file_atomic(link_path, "test file", "after", 5, &err) == CSF_OK, "%s", err.msg);
    struct stat sb;
    CHECK(lstat(link_path, &sb) == 0 && S_ISLNK(sb.st_mode));
    CHECK(contents_are(target, "after"));
    CHECK_INT_EQ(mode_of(target), 0640);

    CHECK(symlink(missing, dangling) == 0);
    CHECK(csf_check_output_path(dangling, "test file", &err) == CSF_E_IO);
    CHECK_STR_CONTAINS(err.msg, "symbolic link to a file that does not exist");
    CHECK(csf_write_file_atomic(dangling, "test file", "x", 1, &err) == CSF_E_IO);
    CHECK(access(missing, F_OK) != 0);

    int sfd = socket(AF_UNIX, SOCK_STREAM, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    CHECK(strlen(sock) < sizeof sa.sun_path);
    memcpy(sa.sun_path, sock, strlen(sock) + 1 < sizeof sa.sun_path ? strlen(sock) + 1 : 0);
    CHECK(sfd >= 0 && bind(sfd, (struct sockaddr *)&sa, sizeof sa) == 0);
    CHECK(csf_write_file_atomic(sock, "test file", "x", 1, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "socket");
    CHECK(lstat(sock, &sb) == 0 && S_ISSOCK(sb.st_mode));
    close(sfd);
    unlink(sock);
    unlink(dangling);
    unlink(link_path);
    unlink(target);
}

/* Under umask 077 a new file is 0600, and a file replaced keeps 0600 (or 0644) as it was. */
static void test_modes(const char *dir)
{
    char path[300];
    snprintf(path, sizeof path, "%s/mode", dir);
    mode_t old_mask = umask(077);
    CHECK(csf_write_file_atomic(path, "test file", "a", 1, NULL) == CSF_OK);
    CHECK_INT_EQ(mode_of(path), 0600);
    CHECK(csf_write_file_atomic(path, "test file", "b", 1, NULL) == CSF_OK);
    CHECK_INT_EQ(mode_of(path), 0600);
    umask(022);
    CHECK(csf_write_file_atomic(path, "test file", "c", 1, NULL) == CSF_OK);
    CHECK_INT_EQ(mode_of(path), 0600); /* replaced: keeps its mode, whatever the umask */
    CHECK(chmod(path, 0644) == 0);
    umask(077);
    CHECK(csf_write_file_atomic(path, "test file", "d", 1, NULL) == CSF_OK);
    CHECK_INT_EQ(mode_of(path), 0644);
    umask(old_mask);
    unlink(path);
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

    test_fifo(dir);
    test_devices(dir);
    test_stdout(dir);
    test_links_and_sockets(dir);
    test_modes(dir);

    unlink(path);
    CHECK_INT_EQ(count_entries(dir), 0);
    rmdir(dir);
    return CHECK_RESULT();
}
