/* csflut — reader and writer for csfcal threshold-contrast tables (.csflut).
 *
 * For renderers that decide whether a detail may be simplified away: a .csflut file holds the
 * threshold Michelson contrast an observer needs to see a pattern, on a grid of spatial frequency
 * (cpd) x eccentricity (deg), optionally x velocity (deg/s) x adapting luminance (cd/m2). The
 * format is specified in docs/csflut.md. This library depends on libc and libm only, so a renderer
 * can link it (pkg-config csflut) or vendor its four .c files and two headers from one folder.
 *
 * Argument order: every query takes the position of the pattern first, in the order frequency,
 * eccentricity (then velocity, luminance), and the contrast last.
 *
 * Interpolation: geometric (linear in log threshold), in log2 frequency, linear eccentricity,
 * velocity in the warp log(|v| + v0) (v0 = 0.5 deg/s in the files this library writes; files of
 * format 1.0 say log or linear) and log luminance, nested in that order. A geometric
 * blend is never above the linear one. Outside the grid every axis is clamped to its edge. With the
 * conservative view (default) both are the safe direction: the table may call something visible
 * that is not, never the other way round. A NaN argument gives a NaN threshold.
 *
 * Never visible: a node of +INFINITY means "not visible at any contrast". Inside a cell such a node
 * enters the blend as a finite cap (at least one octave above contrast 1 and above the table's
 * highest finite threshold; docs/csflut.md), so a query next to a visible node gets a threshold
 * close to that node's. The result is +INFINITY only where every corner with a non-zero weight is
 * never visible. Grid nodes return the stored value to within a few units in the last place.
 *
 * Conservative view (default ON): each node's threshold is replaced by the lowest threshold among
 * all nodes at the same or higher frequency and the same or higher eccentricity of the same
 * velocity and luminance slice (each slice on its own: velocity is not made monotone, since
 * motion raises sensitivity at low frequencies and lowers it at high ones; Kelly 1979). Below the most sensitive frequency the threshold is therefore the peak's
 * (the conservative clamp of D. Luebke and B. Hallen, "Perceptually Driven Simplification for
 * Interactive Rendering", Eurographics Workshop on Rendering 2001); above it thresholds never fall
 * as frequency or eccentricity rise, so measurement noise never makes one cell claim "invisible"
 * where a neighbour at a higher frequency or eccentricity says "visible". Optionally every node
 * is first lowered by k standard errors: threshold * 10^(-k * stderr_log10) (nodes with unknown
 * stderr are not shifted).
 *
 * Thread safety: a table is read-only after open, so queries may run concurrently from any number
 * of threads. csflut_set_conservative / csflut_set_stderr_shift change the table: do not call them
 * while another thread queries the same table.
 */
#ifndef CSFLUT_H
#define CSFLUT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Only the functions below are exported from the shared library (it is built with hidden
 * visibility). On Windows a DLL exports only what is marked dllexport, and a program calling into a
 * DLL needs dllimport: the library's own build defines CSFLUT_BUILD; a program that links the
 * static library, or compiles the sources into itself (vendoring), defines CSFLUT_STATIC, because
 * a dllimport declaration of a function that is not in a DLL does not link. Elsewhere neither
 * define matters. */
#if defined(_WIN32) || defined(__CYGWIN__)
#if defined(CSFLUT_STATIC)
#define CSFLUT_API
#elif defined(CSFLUT_BUILD)
#define CSFLUT_API __declspec(dllexport)
#else
#define CSFLUT_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define CSFLUT_API __attribute__((visibility("default")))
#else
#define CSFLUT_API
#endif

/* Two versions that change independently:
 * - the FILE FORMAT version: the .csflut layout. This library reads files of format major 1 (any
 *   minor) and writes 1.0, or 1.1 for a table with a velocity axis or extra metadata (the header
 *   extension of docs/csflut.md); csflut_version_major(t) / csflut_version_minor(t) give an open
 *   file's.
 * - the LIBRARY version: this API and ABI. The shared library's soname carries the major,
 *   pkg-config's Version the whole string. csflut_version() / csflut_version_number() give the
 *   version of the library actually linked, which a program built against a newer header may
 *   compare with these macros.
 *   2.0.0: every query takes (freq, ecc, ..., contrast); geometric interpolation.
 *   2.1.0: csflut_version(), csflut_version_number(); Windows DLL exports; the reserved status
 *          code CSFLUT_E_UNREACHABLE (never returned) removed, every other code unchanged.
 *   2.2.0: velocity in the warp log(|v| + v0) (format 1.1), csflut_threshold3 and its batch and
 *          perceptible forms, key/value metadata (csflut_write_*_meta, csflut_meta_*), the C
 *          and GLSL exports with a velocity axis. Nothing removed or changed in layout. */
#define CSFLUT_FORMAT_VERSION_MAJOR 1
#define CSFLUT_FORMAT_VERSION_MINOR 1 /* the highest minor this library writes */
#define CSFLUT_LIB_VERSION_MAJOR 2
#define CSFLUT_LIB_VERSION_MINOR 2
#define CSFLUT_LIB_VERSION_PATCH 0
#define CSFLUT_LIB_VERSION "2.2.0"
/* The velocity warp v0 (deg/s) this library writes: log(|v| + v0) is finite at v = 0 (a static
 * grating) and logarithmic where sensitivity changes by octaves of velocity. */
#define CSFLUT_VEL_WARP_V0_DPS 0.5
/* major * 10000 + minor * 100 + patch: 20200 for 2.2.0; compare with >= */
#define CSFLUT_LIB_VERSION_NUMBER \
    (CSFLUT_LIB_VERSION_MAJOR * 10000 + CSFLUT_LIB_VERSION_MINOR * 100 + CSFLUT_LIB_VERSION_PATCH)
/* Deprecated names of the file format version (they never meant the library's version). */
#define CSFLUT_VERSION_MAJOR CSFLUT_FORMAT_VERSION_MAJOR
#define CSFLUT_VERSION_MINOR CSFLUT_FORMAT_VERSION_MINOR

typedef enum {
    CSFLUT_OK = 0,
    CSFLUT_E_ARG = 1,         /* bad argument to a library call (NULL pointer, bad option) */
    CSFLUT_E_NOMEM = 2,       /* out of memory */
    CSFLUT_E_IO = 3,          /* cannot open, read or write the file */
    CSFLUT_E_TRUNCATED = 4,   /* file shorter than its header says, or shorter than a header */
    CSFLUT_E_BAD_MAGIC = 5,   /* not a .csflut file */
    CSFLUT_E_BAD_VERSION = 6, /* a format major version this library does not read */
    CSFLUT_E_BAD_CHECKSUM = 7,/* CRC-32 over the file does not match: corrupted */
    CSFLUT_E_BAD_HEADER = 8,  /* inconsistent header or section layout (sizes, flags, trailing bytes) */
    CSFLUT_E_BAD_AXIS = 9,    /* absurd axis: count, id, order, scale, or number of points */
    CSFLUT_E_NONMONOTONE = 10,/* grid points not strictly increasing */
    CSFLUT_E_BAD_VALUE = 11,  /* non-finite, zero or negative grid point, threshold or stderr */
    CSFLUT_E_BAD_METADATA = 12,/* metadata string too long or containing NUL; bad numeric field */
    CSFLUT_E_CSV = 13         /* CSV input refused (the diagnostic names the line) */
} csflut_status;

/* The library's version as linked at run time: "MAJOR.MINOR.PATCH" (CSFLUT_LIB_VERSION of the
 * library's own build; never NULL), and the same as major * 10000 + minor * 100 + patch
 * (CSFLUT_LIB_VERSION_NUMBER). Not the file format's version (csflut_version_major(t)). */
CSFLUT_API const char *csflut_version(void);
CSFLUT_API int csflut_version_number(void);

/* A short English sentence for a status code; never NULL. */
CSFLUT_API const char *csflut_strerror(csflut_status s);

/* Detailed diagnostic filled by the *_diag variants: the code, the byte offset (or CSV line) of the
 * problem, and a message that names the problem and the limit. */
typedef struct {
    csflut_status code;
    size_t where;        /* byte offset in the file, or 1-based line for CSV; 0 if not applicable */
    char message[256];
} csflut_diag;

typedef struct csflut_table csflut_table;

/* ---- opening ---------------------------------------------------------------------------- */
CSFLUT_API csflut_status csflut_open_file(const char *path, csflut_table **out);
CSFLUT_API csflut_status csflut_open_memory(const void *buf, size_t len, csflut_table **out);
/* Same, with a detailed diagnostic (diag may be NULL). */
CSFLUT_API csflut_status csflut_open_file_diag(const char *path, csflut_table **out, csflut_diag *diag);
CSFLUT_API csflut_status csflut_open_memory_diag(const void *buf, size_t len, csflut_table **out,
                                      csflut_diag *diag);
CSFLUT_API void csflut_close(csflut_table *t);

/* ---- views -------------------------------------------------------------------------------- */
/* Conservative view on (1, the default) or raw measured values (0). */
CSFLUT_API void csflut_set_conservative(csflut_table *t, int on);
CSFLUT_API int csflut_get_conservative(const csflut_table *t);
/* Shift of the conservative view by k standard errors (k >= 0, finite; default 0). */
CSFLUT_API csflut_status csflut_set_stderr_shift(csflut_table *t, double k_stderr);
CSFLUT_API double csflut_get_stderr_shift(const csflut_table *t);

/* ---- queries (cycles per degree, degrees) ------------------------------------------------- */
/* Threshold Michelson contrast at (freq, ecc), at the table's default velocity and luminance
 * (the lowest velocity grid point; the metadata mean luminance, or the lowest luminance grid point
 * when the metadata has none). May exceed 1 or be +INFINITY (never visible). */
CSFLUT_API double csflut_threshold(const csflut_table *t, double freq_cpd, double ecc_deg);
/* Full query. For a table without a velocity or luminance axis that argument is ignored. The
 * sign of the velocity (drift direction) does not matter. For a table without a luminance axis it
 * is csflut_threshold3 bit for bit. */
CSFLUT_API double csflut_threshold4(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps,
                         double lum_cdm2);
/* Threshold at (freq, ecc, velocity) at the table's default luminance: the fast path for a table
 * with a velocity axis, and what the C and GLSL exports' PREFIX_threshold3 reproduce. At the
 * lowest velocity grid point it equals csflut_threshold bit for bit. */
CSFLUT_API double csflut_threshold3(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps);
/* contrast >= csflut_threshold3(t, freq, ecc, vel); NaN gives 0. */
CSFLUT_API int csflut_perceptible3(const csflut_table *t, double freq_cpd, double ecc_deg, double vel_dps,
                                   double contrast);
/* 1 if a pattern of this contrast is visible at (freq, ecc): contrast >= threshold(freq, ecc)
 * (the perceptibility test of Luebke & Hallen 2001); NaN gives 0. */
CSFLUT_API int csflut_perceptible(const csflut_table *t, double freq_cpd, double ecc_deg, double contrast);
/* The inverse, as a level-of-detail renderer uses it: the highest frequency at which `contrast` is still
 * visible at ecc, exact with respect to the interpolated table, so threshold(max_frequency(e, c),
 * e) == c (to rounding) wherever the crossing lies inside the grid. Returns +INFINITY when the
 * contrast is visible at the highest grid frequency (clamping makes it visible at every higher
 * frequency) and 0 when it is not visible at any frequency. */
CSFLUT_API double csflut_max_frequency(const csflut_table *t, double ecc_deg, double contrast);
CSFLUT_API double csflut_max_frequency4(const csflut_table *t, double ecc_deg, double vel_dps,
                             double lum_cdm2, double contrast);
/* Frequency of the lowest threshold at ecc (the peak of the CSF), a grid frequency. */
CSFLUT_API double csflut_peak_frequency(const csflut_table *t, double ecc_deg);

/* ---- the forms the LOD runtime uses: cycles per radian, wavelength in radians per cycle,
 *      eccentricity in radians ------------------------------------------------------------ */
CSFLUT_API double csflut_threshold_cpr(const csflut_table *t, double freq_cpr, double ecc_rad);
CSFLUT_API double csflut_threshold_wavelength(const csflut_table *t, double wavelength_rad, double ecc_rad);
CSFLUT_API int csflut_perceptible_cpr(const csflut_table *t, double freq_cpr, double ecc_rad, double contrast);
CSFLUT_API int csflut_perceptible_wavelength(const csflut_table *t, double wavelength_rad, double ecc_rad,
                                  double contrast);
CSFLUT_API double csflut_max_frequency_cpr(const csflut_table *t, double ecc_rad, double contrast);
/* Smallest wavelength (radians per cycle) still visible: 1 / max_frequency_cpr; 0 when every
 * wavelength is visible, +INFINITY when none is. */
CSFLUT_API double csflut_min_wavelength(const csflut_table *t, double ecc_rad, double contrast);

/* ---- batch ------------------------------------------------------------------------------ */
/* out[i] = csflut_threshold(t, freq_cpd[i], ecc_deg[i]) for i < n (bit-identical results). */
CSFLUT_API void csflut_threshold_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                            double *out, size_t n);
/* out[i] = csflut_threshold3(t, freq_cpd[i], ecc_deg[i], vel_dps[i]) (bit-identical). */
CSFLUT_API void csflut_threshold3_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                                        const double *vel_dps, double *out, size_t n);
CSFLUT_API void csflut_threshold4_batch(const csflut_table *t, const double *freq_cpd, const double *ecc_deg,
                             const double *vel_dps, const double *lum_cdm2, double *out, size_t n);
/* out[i] = csflut_perceptible(t, freq_cpd[i], ecc_deg[i], contrast[i]). */
CSFLUT_API void csflut_perceptible_batch(const csflut_table *t, const double *freq_cpd,
                              const double *ecc_deg, const double *contrast, unsigned char *out,
                              size_t n);

/* ---- axes, values and metadata ----------------------------------------------------------- */
typedef enum { CSFLUT_AXIS_FREQ = 0, CSFLUT_AXIS_ECC = 1, CSFLUT_AXIS_VEL = 2, CSFLUT_AXIS_LUM = 3 }
    csflut_axis;
typedef enum { CSFLUT_SCALE_LINEAR = 0, CSFLUT_SCALE_LOG = 1 } csflut_scale;

/* Number of grid points on an axis; 0 when the axis is absent. */
CSFLUT_API int csflut_axis_size(const csflut_table *t, csflut_axis a);
CSFLUT_API const double *csflut_axis_points(const csflut_table *t, csflut_axis a); /* NULL if absent */
CSFLUT_API csflut_scale csflut_axis_scale(const csflut_table *t, csflut_axis a);
CSFLUT_API const char *csflut_axis_name(csflut_axis a); /* "freq", "ecc", "velocity", "luminance" */
CSFLUT_API const char *csflut_axis_unit(csflut_axis a); /* "cpd", "deg", "deg/s", "cd/m2" */
/* Stored node values, index ((lum*n_vel' + vel)*n_ecc + ecc)*n_freq + freq (n' = max(n, 1)). */
CSFLUT_API size_t csflut_node_count(const csflut_table *t);
CSFLUT_API const double *csflut_raw_thresholds(const csflut_table *t);
CSFLUT_API const double *csflut_conservative_thresholds(const csflut_table *t); /* under the current shift */
CSFLUT_API const double *csflut_stderr_log10(const csflut_table *t); /* NULL when the file has none */

/* The open file's FORMAT version (header bytes 8 and 10), not the library's (csflut_version). */
CSFLUT_API int csflut_version_major(const csflut_table *t);
CSFLUT_API int csflut_version_minor(const csflut_table *t);
CSFLUT_API const char *csflut_observer(const csflut_table *t);           /* "" when absent, never NULL */
CSFLUT_API const char *csflut_display_profile_id(const csflut_table *t);
CSFLUT_API const char *csflut_method(const csflut_table *t);
CSFLUT_API const char *csflut_date_utc(const csflut_table *t);
CSFLUT_API const char *csflut_tool_version(const csflut_table *t);
CSFLUT_API double csflut_viewing_distance_mm(const csflut_table *t);     /* NaN when unknown */
CSFLUT_API double csflut_mean_lum_cdm2(const csflut_table *t);           /* NaN when unknown */
CSFLUT_API int csflut_trials(const csflut_table *t);
CSFLUT_API double csflut_default_velocity(const csflut_table *t);        /* used by the 2-D queries */
CSFLUT_API double csflut_default_luminance(const csflut_table *t);
/* v0 (deg/s) of the velocity warp log(|v| + v0) the table interpolates in; NaN when it has no
 * velocity axis or is a format 1.0 file (velocity then in log, or linear, as its axis says). */
CSFLUT_API double csflut_velocity_warp_v0(const csflut_table *t);
/* Key/value metadata (format 1.1; none in 1.0 files): count, the i-th key and value (NULL when
 * i is out of range), and the value of a key (NULL when absent). Keys are 1-64 of
 * [A-Za-z0-9_.-]; values UTF-8 text of at most 4096 bytes without NUL, CR or LF. */
CSFLUT_API int csflut_meta_count(const csflut_table *t);
CSFLUT_API const char *csflut_meta_key(const csflut_table *t, int i);
CSFLUT_API const char *csflut_meta_value(const csflut_table *t, int i);
CSFLUT_API const char *csflut_meta_find(const csflut_table *t, const char *key);

/* ---- writer (csflut_write.c) ------------------------------------------------------------- */
typedef struct {
    int n_freq, n_ecc, n_vel, n_lum;           /* n_vel, n_lum = 0 when the axis is absent */
    const double *freq_cpd, *ecc_deg, *vel_dps, *lum_cdm2;
    const double *threshold;      /* Michelson; INFINITY = never visible; index
                                     ((lum*n_vel' + vel)*n_ecc + ecc)*n_freq + freq, n' = max(n,1) */
    const double *stderr_log10;   /* may be NULL; NaN = unknown */
    const char *observer, *display_profile_id, *method, *date_utc, *tool_version; /* may be NULL */
    double viewing_distance_mm, mean_lum_cdm2; /* NaN (or 0) = unknown */
    int trials;
} csflut_build;

CSFLUT_API csflut_status csflut_write_file(const csflut_build *b, const char *path);
CSFLUT_API csflut_status csflut_write_memory(const csflut_build *b, unsigned char **out, size_t *len);
/* Same, with a diagnostic naming the offending field (diag may be NULL). */
CSFLUT_API csflut_status csflut_write_memory_diag(const csflut_build *b, unsigned char **out, size_t *len,
                                       csflut_diag *diag);
CSFLUT_API csflut_status csflut_write_file_diag(const csflut_build *b, const char *path, csflut_diag *diag);
/* Checks a build description without writing (same rules as the reader). */
CSFLUT_API csflut_status csflut_validate_build(const csflut_build *b, csflut_diag *diag);
/* Key/value metadata written beside a build (format 1.1): n_meta pairs (at most 256), keys
 * unique, 1-64 of [A-Za-z0-9_.-], values at most 4096 bytes without NUL, CR or LF. The same as
 * the plain writers when n_meta is 0 (meta may then be NULL). A table with a velocity axis is
 * written as format 1.1 with the warp v0 = CSFLUT_VEL_WARP_V0_DPS either way; a 2-D table
 * without metadata pairs stays format 1.0, byte for byte as before. */
typedef struct {
    const char *key, *value;
} csflut_meta;
CSFLUT_API csflut_status csflut_write_memory_meta(const csflut_build *b, const csflut_meta *meta,
                                                  size_t n_meta, unsigned char **out, size_t *len,
                                                  csflut_diag *diag);
CSFLUT_API csflut_status csflut_write_file_meta(const csflut_build *b, const csflut_meta *meta, size_t n_meta,
                                                const char *path, csflut_diag *diag);
/* The metadata pairs of a table, valid while t is open, for csflut_write_*_meta: fills up to
 * cap entries of out and returns the count. */
CSFLUT_API size_t csflut_table_meta(const csflut_table *t, csflut_meta *out, size_t cap);
/* Fills b with pointers into t (raw values), valid while t is open. */
CSFLUT_API void csflut_table_to_build(const csflut_table *t, csflut_build *b);

/* ---- CSV import (csflut_csv.c) ----------------------------------------------------------
 * Columns by header name: freq_cpd, ecc_deg, [velocity_dps], [lum_cdm2], threshold,
 * [stderr_log10], in any order; '#' starts a comment line; "inf" = never visible, empty or "nan"
 * stderr = unknown. Every grid combination must appear exactly once. The metadata comments that
 * csflut_export writes ("# observer: ...", "# viewing_distance_mm: 600", "# trials: 240", every
 * field of csflut_build) fill the build's metadata, and "# meta.KEY: value" comments the
 * key/value metadata (csflut_grid_meta), so export -> import keeps all of it. */
typedef struct csflut_grid csflut_grid;
CSFLUT_API csflut_status csflut_import_csv(const char *text, size_t len, csflut_grid **out,
                                csflut_diag *diag);
/* The grid's build description, metadata from the CSV comments included (owned by the grid); the
 * caller may point metadata elsewhere (such pointers are not freed). */
CSFLUT_API csflut_build *csflut_grid_build(csflut_grid *g);
CSFLUT_API void csflut_grid_free(csflut_grid *g);
/* The grid's key/value metadata (owned by the grid): *n gets the count. */
CSFLUT_API const csflut_meta *csflut_grid_meta(const csflut_grid *g, size_t *n);

/* ---- exports (csflut_export.c) ----------------------------------------------------------
 * CSV and JSON hold every axis and the raw values (+ stderr); the C header and GLSL hold the 2-D
 * (frequency, eccentricity) view at the default velocity and luminance, in the table's current
 * view (conservative or raw), as a self-contained function named PREFIX_threshold(freq_cpd,
 * ecc_deg) that reproduces csflut_threshold (C: bit for bit, built without fused multiply-add;
 * GLSL: in float32, but a NaN argument gives a finite result there), and PREFIX_perceptible.
 * A table with a velocity axis adds every velocity slice (at the default luminance) and
 * PREFIX_threshold3(freq_cpd, ecc_deg, vel_dps) / PREFIX_perceptible3(..., contrast), which
 * reproduce csflut_threshold3 the same way.
 * `prefix` (NULL = "csflut_gen") starts every generated name, so it must be a C identifier of at
 * most 64 characters that GLSL and C++ also accept: not starting with "gl_", not containing "__",
 * not ending in '_'; otherwise CSFLUT_E_ARG. *out is malloc'd and NUL-terminated. */
typedef enum { CSFLUT_FORMAT_CSV = 0, CSFLUT_FORMAT_JSON, CSFLUT_FORMAT_C, CSFLUT_FORMAT_GLSL }
    csflut_format;
CSFLUT_API csflut_status csflut_export(const csflut_table *t, csflut_format fmt, const char *prefix,
                            char **out, size_t *len);

#ifdef __cplusplus
}
#endif
#endif
