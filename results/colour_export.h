/* Colour-pipeline exports of a display profile, through OpenColorIO 2.1 (CLF/CTF via
 * GroupTransform::write, .cube via Baker, an OCIO config with a display and view) and Little CMS
 * (ICC: OCIO's library baker has no ICC writer). A thin C++ shim with a C interface.
 *
 * What is exported: the display's grey transfer function (EOTF) as a 1-D curve from drive value
 * (0..1, same on R, G, B) to luminance relative to white, black included: Y = L / L(1), so
 * Y(0) = black / white and cd/m2 = Y * white. A renderer applies the inverse (OCIO inverts a Lut1D
 * exactly; ICC consumers invert the TRC) to get the drive value that produces a wanted luminance
 * on this monitor. Every file is written atomically (core/file_write.h). See
 * docs/display-profile.md. */
#ifndef CSF_COLOUR_EXPORT_H
#define CSF_COLOUR_EXPORT_H

#include <stddef.h>

#include "core/csf_status.h"
#include "results/display_profile.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    CSF_EXPORT_CLF = 0,  /* Academy/ASC Common LUT Format (.clf) */
    CSF_EXPORT_CTF,      /* OCIO's CTF (.ctf) */
    CSF_EXPORT_CUBE,     /* Resolve .cube (1-D), baked by OCIO's Baker */
    CSF_EXPORT_ICC,      /* ICC v2.4 or v4.3 RGB display profile, the curve as its TRCs (lcms2);
                          * v4.3 also as float D2B0/B2D0 tags */
    CSF_EXPORT_OCIO,     /* OCIO config (.ocio) plus its .clf beside it: display + view */
    CSF_EXPORT_COUNT
} csf_export_format;

/* "clf", "ctf", "cube", "icc", "ocio" -> format; -1 if unknown. */
int csf_export_format_from_name(const char *name);
const char *csf_export_format_name(csf_export_format f);
/* File extension including the dot (".clf" ...). */
const char *csf_export_extension(csf_export_format f);

/* Number of samples in the exported 1-D curves (clf, ctf, cube, ocio) and in the ICC TRCs. */
#define CSF_EXPORT_LUT_SIZE 4096
#define CSF_ICC_TRC_SIZE 4096

/* v2.4 by default: what every ICC reader takes, ArgyllCMS included (docs/display-profile.md). */
#define CSF_ICC_VERSION_DEFAULT 2

typedef struct {
    int icc_version; /* 2 (v2.4) or 4 (v4.3); 0 = CSF_ICC_VERSION_DEFAULT */
} csf_export_options;

/* Writes the export atomically; opt may be NULL (defaults). */
csf_status csf_colour_export(const csf_display_profile *p, csf_export_format f, const csf_export_options *opt,
                             const char *out_path, csf_error *err);

/* cd/m2 from an ICC export alone, through a Little CMS transform (device grey -> PCS XYZ,
 * relative colorimetric) times the luminance tag; white_cdm2 (may be NULL) gets the tag. */
csf_status csf_colour_export_icc_cdm2(const char *path, const double *drive01, double *lum_cdm2, size_t n,
                                      double *white_cdm2, csf_error *err);

/* Reads an export back (OpenColorIO for clf/ctf/cube/ocio, a Little CMS transform for icc) and
 * evaluates its drive -> relative luminance curve at n drive values (grey, R=G=B). */
csf_status csf_colour_export_eval(const char *path, csf_export_format f, const double *drive01,
                                  double *rel_lum, size_t n, csf_error *err);

/* The same through OpenColorIO's own ICC reader (cross-check for icc exports). */
csf_status csf_colour_export_eval_icc_ocio(const char *path, const double *drive01, double *rel_lum,
                                           size_t n, csf_error *err);

#ifdef __cplusplus
}
#endif

#endif
