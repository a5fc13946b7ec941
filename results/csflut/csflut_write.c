/* csflut writer: validates a csflut_build with the reader's rules and serialises it in the
 * little-endian v1 layout of docs/csflut.md, CRC-32 last. Files are written to a temporary in the
 * same folder, fsynced and renamed (POSIX), so a reader never sees half a table; a device or FIFO
 * at the destination is written in place, never replaced. */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* mkstemp, fsync, fileno: this file builds on its own when vendored */
#endif
#if !defined(_XOPEN_SOURCE) || _XOPEN_SOURCE < 700
#undef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* realpath: glibc declares it only for X/Open */
#endif
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "csflut.h"
#include "csflut_internal.h"

static const char *const axis_name16[4] = {"freq", "ecc", "velocity", "luminance"};
static const char *const axis_unit16[4] = {"cpd", "deg", "deg/s", "cd/m2"};

static int vel_scale(const csflut_build *b)
{
    /* log velocity unless the grid includes 0 deg/s (a static stimulus), which log cannot hold */
    for (int i = 0; i < b->n_vel; i++)
        if (!(b->vel_dps[i] > 0)) return CSFLUT_SCALE_LINEAR;
    return CSFLUT_SCALE_LOG;
}

static size_t build_nodes(const csflut_build *b)
{
    return (size_t)b->n_freq * (size_t)b->n_ecc * (size_t)(b->n_vel > 0 ? b->n_vel : 1) *
           (size_t)(b->n_lum > 0 ? b->n_lum : 1);
}

static const char *build_str(const csflut_build *b, int k)
{
    const char *s[CSFLUT_N_STRINGS] = {b->observer, b->display_profile_id, b->method, b->date_utc,
                                       b->tool_version};
    return s[k] ? s[k] : "";
}

static const char *const string_names[CSFLUT_N_STRINGS] = {
    "observer", "display_profile_id", "method", "date_utc", "tool_version"};

csflut_status csflut_validate_build(const csflut_build *b, csflut_diag *diag)
{
    if (diag) memset(diag, 0, sizeof *diag);
    if (!b) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL build description");
        return CSFLUT_E_ARG;
    }
    const int n[4] = {b->n_freq, b->n_ecc, b->n_vel, b->n_lum};
    const double *p[4] = {b->freq_cpd, b->ecc_deg, b->vel_dps, b->lum_cdm2};
    for (int a = 0; a < 4; a++) {
        if (n[a] > 0 && !p[a]) {
            csflut_diag_set(diag, CSFLUT_E_ARG, 0, "%s axis has %d points but no array",
                            axis_name16[a], n[a]);
            return CSFLUT_E_ARG;
        }
        int scale = a == 1 ? CSFLUT_SCALE_LINEAR : (a == 2 ? vel_scale(b) : CSFLUT_SCALE_LOG);
        csflut_status st = csflut_check_axis(a, n[a], p[a], scale, CSFLUT_VEL_WARP_V0_DPS, diag, 0);
        if (st) return st;
    }
    size_t nodes = 1;
    for (int a = 0; a < 4; a++) {
        if (n[a] > 0) nodes *= (size_t)n[a];
        if (nodes > CSFLUT_MAX_NODES) {
            csflut_diag_set(diag, CSFLUT_E_BAD_AXIS, 0, "the grid has more than %u nodes",
                            (unsigned)CSFLUT_MAX_NODES);
            return CSFLUT_E_BAD_AXIS;
        }
    }
    if (!b->threshold) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "no threshold array");
        return CSFLUT_E_ARG;
    }
    csflut_status st = csflut_check_values(b->threshold, b->stderr_log10, nodes, diag, 0, 0);
    if (st) return st;
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) {
        size_t sl = strlen(build_str(b, k));
        if (sl > CSFLUT_MAX_STRING) {
            csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, 0, "%s is %zu bytes (at most %d)",
                            string_names[k], sl, CSFLUT_MAX_STRING);
            return CSFLUT_E_BAD_METADATA;
        }
    }
    double dist = b->viewing_distance_mm, lum = b->mean_lum_cdm2;
    if (!(dist != dist || dist == 0 || (isfinite(dist) && dist > 0))) {
        csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, 0,
                        "viewing distance %g mm (must be > 0, or 0/NaN for unknown)", dist);
        return CSFLUT_E_BAD_METADATA;
    }
    if (!(lum != lum || lum == 0 || (isfinite(lum) && lum > 0))) {
        csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, 0,
                        "mean luminance %g cd/m2 (must be > 0, or 0/NaN for unknown)", lum);
        return CSFLUT_E_BAD_METADATA;
    }
    if (b->trials < 0) {
        csflut_diag_set(diag, CSFLUT_E_BAD_METADATA, 0, "trials %d (must be >= 0)", b->trials);
        return CSFLUT_E_BAD_METADATA;
    }
    return CSFLUT_OK;
}

/* ---- little-endian output ------------------------------------------------------------------ */
static unsigned char *put_u32(unsigned char *o, uint32_t v)
{
    o[0] = (unsigned char)v;
    o[1] = (unsigned char)(v >> 8);
    o[2] = (unsigned char)(v >> 16);
    o[3] = (unsigned char)(v >> 24);
    return o + 4;
}
static unsigned char *put_u64(unsigned char *o, uint64_t v)
{
    put_u32(o, (uint32_t)v);
    return put_u32(o + 4, (uint32_t)(v >> 32)) ;
}
static unsigned char *put_f64(unsigned char *o, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return put_u64(o, u);
}

/* The metadata pairs checked as the reader checks them. */
static csflut_status check_meta_pairs(const csflut_meta *meta, size_t n_meta, csflut_diag *diag)
{
    if (n_meta && !meta) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "%zu metadata pairs but no array", n_meta);
        return CSFLUT_E_ARG;
    }
    if (n_meta > CSFLUT_MAX_META) return csflut_check_meta(NULL, NULL, n_meta, diag, 0);
    const char *keys[CSFLUT_MAX_META], *vals[CSFLUT_MAX_META];
    for (size_t i = 0; i < n_meta; i++) {
        keys[i] = meta[i].key;
        vals[i] = meta[i].value;
    }
    return csflut_check_meta(keys, vals, n_meta, diag, 0);
}

/* The format 1.1 header extension: the velocity warp (NaN without a velocity axis), the pairs. */
static size_t extension_size(const csflut_meta *meta, size_t n_meta)
{
    size_t size = CSFLUT_EXT_FIXED;
    for (size_t i = 0; i < n_meta; i++) size += 8 + strlen(meta[i].key) + strlen(meta[i].value);
    return size;
}

static unsigned char *put_u32(unsigned char *o, uint32_t v);
static unsigned char *put_f64(unsigned char *o, double d);

static unsigned char *put_extension(unsigned char *o, const csflut_build *b, const csflut_meta *meta,
                                    size_t n_meta)
{
    o = put_f64(o, b->n_vel > 0 ? CSFLUT_VEL_WARP_V0_DPS : NAN);
    o = put_u32(o, (uint32_t)n_meta);
    o = put_u32(o, 0);
    for (size_t i = 0; i < n_meta; i++) {
        const char *s[2] = {meta[i].key, meta[i].value};
        for (int k = 0; k < 2; k++) {
            size_t sl = strlen(s[k]);
            o = put_u32(o, (uint32_t)sl);
            memcpy(o, s[k], sl);
            o += sl;
        }
    }
    return o;
}

csflut_status csflut_write_memory_diag(const csflut_build *b, unsigned char **out, size_t *len,
                                       csflut_diag *diag)
{
    return csflut_write_memory_meta(b, NULL, 0, out, len, diag);
}

csflut_status csflut_write_memory_meta(const csflut_build *b, const csflut_meta *meta, size_t n_meta,
                                       unsigned char **out, size_t *len, csflut_diag *diag)
{
    if (!out || !len) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL output pointer");
        return CSFLUT_E_ARG;
    }
    *out = NULL;
    *len = 0;
    csflut_status st = csflut_validate_build(b, diag);
    if (st) return st;
    st = check_meta_pairs(meta, n_meta, diag);
    if (st) return st;
    const int n[4] = {b->n_freq, b->n_ecc, b->n_vel, b->n_lum};
    const double *p[4] = {b->freq_cpd, b->ecc_deg, b->vel_dps, b->lum_cdm2};
    size_t nodes = build_nodes(b);
    int n_axes = 0;
    /* Format 1.0, byte for byte as before, unless the table needs the 1.1 extension: a velocity
     * axis (its warp) or metadata pairs. */
    int ext = b->n_vel > 0 || n_meta > 0;
    size_t header_size = CSFLUT_HEADER_SIZE + (ext ? extension_size(meta, n_meta) : 0);
    size_t size = header_size;
    for (int a = 0; a < 4; a++)
        if (n[a] > 0) {
            n_axes++;
            size += CSFLUT_AXIS_RECORD_SIZE + 8 * (size_t)n[a];
        }
    size += 8 * nodes * (b->stderr_log10 ? 2 : 1);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) size += 4 + strlen(build_str(b, k));
    size += 4;
    unsigned char *buf = calloc(1, size);
    if (!buf) {
        csflut_diag_set(diag, CSFLUT_E_NOMEM, 0, "out of memory");
        return CSFLUT_E_NOMEM;
    }
    unsigned char *o = buf;
    memcpy(o, CSFLUT_MAGIC, CSFLUT_MAGIC_LEN);
    o[8] = CSFLUT_FORMAT_VERSION_MAJOR;
    o[10] = ext ? 1 : 0;
    put_u32(o + 12, (uint32_t)header_size);
    put_u64(o + 16, size);
    put_u32(o + 24, (uint32_t)n_axes);
    put_u32(o + 28, b->stderr_log10 ? CSFLUT_FLAG_STDERR : 0);
    double dist = b->viewing_distance_mm > 0 ? b->viewing_distance_mm : NAN;
    double lum = b->mean_lum_cdm2 > 0 ? b->mean_lum_cdm2 : NAN;
    put_f64(o + 32, dist);
    put_f64(o + 40, lum);
    put_u32(o + 48, (uint32_t)b->trials);
    o += CSFLUT_HEADER_SIZE;
    if (ext) o = put_extension(o, b, meta, n_meta);
    for (int a = 0; a < 4; a++) {
        if (n[a] == 0) continue;
        int scale = a == 1 ? CSFLUT_SCALE_LINEAR : (a == 2 ? vel_scale(b) : CSFLUT_SCALE_LOG);
        put_u32(o, (uint32_t)a);
        put_u32(o + 4, (uint32_t)scale);
        put_u32(o + 8, (uint32_t)n[a]);
        memcpy(o + 16, axis_name16[a], strlen(axis_name16[a]));
        memcpy(o + 32, axis_unit16[a], strlen(axis_unit16[a]));
        o += CSFLUT_AXIS_RECORD_SIZE;
        for (int i = 0; i < n[a]; i++) o = put_f64(o, p[a][i]);
    }
    for (size_t i = 0; i < nodes; i++) o = put_f64(o, b->threshold[i]);
    if (b->stderr_log10)
        for (size_t i = 0; i < nodes; i++) o = put_f64(o, b->stderr_log10[i]);
    for (int k = 0; k < CSFLUT_N_STRINGS; k++) {
        const char *s = build_str(b, k);
        size_t sl = strlen(s);
        o = put_u32(o, (uint32_t)sl);
        memcpy(o, s, sl);
        o += sl;
    }
    put_u32(o, csflut_crc32(buf, size - 4));
    *out = buf;
    *len = size;
    return CSFLUT_OK;
}

csflut_status csflut_write_memory(const csflut_build *b, unsigned char **out, size_t *len)
{
    return csflut_write_memory_diag(b, out, len, NULL);
}

/* Writes all of buf to fd; 0 or an errno value. */
static int write_all(int fd, const unsigned char *buf, size_t len)
{
    while (len > 0) {
        ssize_t w = write(fd, buf, len);
        if (w < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (w == 0) return EIO;
        buf += w;
        len -= (size_t)w;
    }
    return 0;
}

/* The folder of path ("." when it has none), for the temporary and the directory fsync. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) : 1;
    if (slash && n == 0) n = 1; /* "/x": the root */
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, slash ? path : ".", n);
    d[n] = 0;
    return d;
}

/* An existing destination that is not a regular file (/dev/null, a terminal, a FIFO, a pipe
 * behind /dev/stdout) is written in place, never replaced by a file: opened without O_CREAT or
 * O_TRUNC. Folders, block devices and sockets are refused. */
static csflut_status write_through(const char *path, const struct stat *sb,
                                   const unsigned char *buf, size_t len, csflut_diag *diag)
{
    if (!S_ISCHR(sb->st_mode) && !S_ISFIFO(sb->st_mode)) {
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot write %s: it is %s, not a file", path,
                        S_ISDIR(sb->st_mode) ? "a folder" : S_ISBLK(sb->st_mode) ? "a block device"
                                                                                 : "a socket");
        return CSFLUT_E_IO;
    }
    int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC), err = 0;
    if (fd < 0) err = errno;
    else {
        err = write_all(fd, buf, len);
        if (close(fd) != 0 && !err) err = errno;
    }
    if (err) csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot write %s: %s", path, strerror(err));
    return err ? CSFLUT_E_IO : CSFLUT_OK;
}

/* The mode a new file gets (what the umask allows) or the one the replaced file had. */
static mode_t mode_for(const struct stat *old)
{
    if (old) return old->st_mode & 0777;
    mode_t mask = umask(0);
    umask(mask);
    return 0666 & ~mask;
}

/* buf -> temporary beside path -> fsync -> rename over path -> fsync of the folder. On failure
 * the temporary is removed, path is untouched, and the OS error is named. A symbolic link is
 * followed: its target is replaced and the link stays; a link to nothing is refused. */
static csflut_status write_atomic(const char *path, const unsigned char *buf, size_t len,
                                  csflut_diag *diag)
{
    struct stat lsb, sb;
    int exists = lstat(path, &lsb) == 0;
    if (exists && S_ISLNK(lsb.st_mode) && stat(path, &sb) != 0) {
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot write %s: a symbolic link to a file that "
                        "does not exist", path);
        return CSFLUT_E_IO;
    }
    if (exists && !S_ISLNK(lsb.st_mode)) sb = lsb;
    if (exists && !S_ISREG(sb.st_mode)) return write_through(path, &sb, buf, len, diag);
    char *real = exists && S_ISLNK(lsb.st_mode) ? realpath(path, NULL) : strdup(path);
    if (!real) {
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "cannot write %s: %s", path, strerror(errno));
        return CSFLUT_E_IO;
    }
    size_t pl = strlen(real);
    char *tmp = malloc(pl + 16), *dir = dir_of(real);
    if (!tmp || !dir) {
        free(tmp);
        free(dir);
        free(real);
        csflut_diag_set(diag, CSFLUT_E_NOMEM, 0, "out of memory");
        return CSFLUT_E_NOMEM;
    }
    snprintf(tmp, pl + 16, "%s.tmp.XXXXXX", real);
    int fd = mkstemp(tmp), err = 0;
    const char *step = "cannot create a temporary file in";
    if (fd < 0) {
        err = errno;
    } else {
        step = "cannot write";
        err = write_all(fd, buf, len);
        if (!err && fchmod(fd, mode_for(exists ? &sb : NULL)) != 0) err = errno; /* mkstemp: 0600 */
        if (!err && fsync(fd) != 0) err = errno;
        if (close(fd) != 0 && !err) err = errno;
        if (!err && rename(tmp, real) != 0) {
            err = errno;
            step = "cannot rename the temporary file over";
        }
        if (err) remove(tmp);
    }
    if (err) {
        csflut_diag_set(diag, CSFLUT_E_IO, 0, "%s %s: %s", step, fd < 0 ? dir : path,
                        strerror(err));
    } else {
        int dfd = open(dir, O_RDONLY);
        if (dfd >= 0) { /* the rename itself reaches the disk; failure here is not fatal */
            (void)fsync(dfd);
            close(dfd);
        }
    }
    free(tmp);
    free(dir);
    free(real);
    return err ? CSFLUT_E_IO : CSFLUT_OK;
}

csflut_status csflut_write_file_diag(const csflut_build *b, const char *path, csflut_diag *diag)
{
    return csflut_write_file_meta(b, NULL, 0, path, diag);
}

csflut_status csflut_write_file_meta(const csflut_build *b, const csflut_meta *meta, size_t n_meta,
                                     const char *path, csflut_diag *diag)
{
    if (!path) {
        csflut_diag_set(diag, CSFLUT_E_ARG, 0, "NULL path");
        return CSFLUT_E_ARG;
    }
    unsigned char *buf;
    size_t len;
    csflut_status st = csflut_write_memory_meta(b, meta, n_meta, &buf, &len, diag);
    if (st) return st;
    st = write_atomic(path, buf, len, diag);
    free(buf);
    return st;
}

csflut_status csflut_write_file(const csflut_build *b, const char *path)
{
    return csflut_write_file_diag(b, path, NULL);
}

void csflut_table_to_build(const csflut_table *t, csflut_build *b)
{
    if (!b) return;
    memset(b, 0, sizeof *b);
    if (!t) return;
    b->n_freq = t->n[0];
    b->n_ecc = t->n[1];
    b->n_vel = t->n[2];
    b->n_lum = t->n[3];
    b->freq_cpd = t->pts[0];
    b->ecc_deg = t->pts[1];
    b->vel_dps = t->pts[2];
    b->lum_cdm2 = t->pts[3];
    b->threshold = t->raw;
    b->stderr_log10 = t->se;
    b->observer = csflut_observer(t);
    b->display_profile_id = csflut_display_profile_id(t);
    b->method = csflut_method(t);
    b->date_utc = csflut_date_utc(t);
    b->tool_version = csflut_tool_version(t);
    b->viewing_distance_mm = t->dist_mm;
    b->mean_lum_cdm2 = t->mean_lum;
    b->trials = t->trials;
}
