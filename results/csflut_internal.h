/* Private to the csflut library: file layout constants, the table structure, and helpers shared by
 * the reader, the writer, the CSV importer and the exporters. Not installed. */
#ifndef CSFLUT_INTERNAL_H
#define CSFLUT_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "results/csflut.h"

/* File layout (docs/csflut.md): 64-byte header, axis records, thresholds, optional stderr,
 * metadata strings, CRC-32 trailer. All little-endian. */
#define CSFLUT_MAGIC "\x89" "CSFLUT\n"
#define CSFLUT_MAGIC_LEN 8
#define CSFLUT_HEADER_SIZE 64
#define CSFLUT_AXIS_RECORD_SIZE 48 /* id, scale, n, reserved (4 x u32) + name[16] + unit[16] */
#define CSFLUT_MAX_POINTS 4096     /* per axis: far beyond any measured grid */
#define CSFLUT_MAX_NODES (1u << 22) /* product of axis sizes (32 MiB of doubles) */
#define CSFLUT_MAX_STRING 4096     /* per metadata string */
#define CSFLUT_N_STRINGS 5
#define CSFLUT_FLAG_STDERR 1u

/* Precomputed 2-D (frequency, eccentricity) slice for the fast path. Axes with one point are
 * padded to two identical-valued nodes so every query has a cell. */
typedef struct {
    int n;              /* >= 2 */
    double lo, hi;      /* first/last node in the interpolation coordinate (log2 f, or deg) */
    double *node;       /* n nodes in the interpolation coordinate */
    double *inv_step;   /* n-1: 1/(node[i+1]-node[i]) */
    int last_exact;     /* (hi - node[n-2]) * inv_step[n-2] == 1 exactly */
    /* Branch-free cell search: bucket b = (int)((x - lo) * bucket_scale) holds at most one
     * interior node; first[b] is the cell of the bucket's lowest x, next[s] the interior node that
     * ends cell s (+inf after the last), so cell = first[b] + (x >= next[first[b]]). */
    int n_buckets;      /* 0: nodes too close together for buckets, search linearly */
    double bucket_scale;
    unsigned short *first; /* n_buckets + 1 */
    double *next;          /* n */
} csflut_axis_fast;

struct csflut_table {
    int vmaj, vmin;
    int n[4];            /* points per axis; 0 when absent */
    int scale[4];
    double *pts[4];
    size_t n_nodes;
    double *raw, *cons, *se; /* se NULL when absent */
    int conservative;
    double k_shift;
    char *str[CSFLUT_N_STRINGS]; /* observer, display, method, date, tool version */
    double dist_mm, mean_lum;
    int trials;
    double def_vel, def_lum;
    csflut_axis_fast fx, ex;  /* frequency (log2) and eccentricity (linear) */
    double *slice_raw, *slice_cons; /* ex.n * fx.n values, freq fastest */
};

void csflut_diag_set(csflut_diag *d, csflut_status code, size_t where, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
uint32_t csflut_crc32(const unsigned char *p, size_t n);
/* log2(x) for the interpolation coordinate: accurate to about 1 ulp; x <= 0 gives -HUGE_VAL,
 * +inf gives +inf. Used by every query so all paths agree bit for bit. */
double csflut_log2(double x);
/* Creates the derived data (conservative view, 2-D slices) of a table whose axes and values are
 * filled. */
csflut_status csflut_table_finish(csflut_table *t);
/* Checks axes and values as the reader does (shared with the writer). */
csflut_status csflut_check_axis(int which, int n, const double *pts, int scale, csflut_diag *diag,
                                size_t where);
csflut_status csflut_check_values(const double *thr, const double *se, size_t n_nodes,
                                  csflut_diag *diag, size_t where_thr, size_t where_se);

#endif
