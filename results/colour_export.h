/* Colour-pipeline exports of a display profile, through OpenColorIO 2.1 (CLF/CTF via
 * GroupTransform::write, .cube via Baker, an OCIO config with a display and view) and Little CMS
 * (ICC: OCIO's library baker has no ICC writer). A thin C++ shim with a C interface.
 *
 * What is exported: the display's grey transfer function (EOTF) as a 1-D curve from drive value
 * (0..1, same on R, G, B) to relative luminance Y = (L - black) / (white - black). A renderer
 * applies the inverse (OCIO inverts a Lut1D exactly; ICC consumers invert the TRC) to get the
 * drive value that produces a wanted luminance on this monitor. See docs/display-profile.md. */
#ifndef CSF_COLOUR_EXPORT_H
#define CSF_COLOUR_EXPORT_H

#include <stddef.h>

#include "results/csf_status.h"
#include "results/display_profile.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    CSF_EXPORT_CLF = 0,  /* Academy/ASC Common LUT Format (.clf) */
    CSF_EXPORT_CTF,      /* OCIO's CTF (.ctf) */
    CSF_EXPORT_CUBE,     /* Resolve .cube (1-D), baked by OCIO's Baker */
    CSF_EXPORT_ICC,      /* ICC v4 RGB display profile with the curve as its TRCs (lcms2) */
    CSF_EXPORT_OCIO,     /* OCIO config (.ocio) plus its .clf beside it: display + view */
    CSF_EXPORT_COUNT
} csf_export_format;

/* "clf", "ctf", "cube", "icc", "ocio" -> format; -1 if unknown. */
int csf_export_format_from_name(const char *name);
const char *csf_export_format_name(csf_export_format f);
/* File extension including the dot (".clf" ...). */
const char *csf_export_extension(csf_export_format f);

/* Number of samples in the exported 1-D curves. */
#define CSF_EXPORT_LUT_SIZE 4096

csf_status csf_colour_export(const csf_display_profile *p, csf_export_format f, const char *out_path,
                             csf_error *err);

/* Reads an export back (OpenColorIO for clf/ctf/cube/ocio, lcms2 for icc) and evaluates its
 * drive -> relative luminance curve at n drive values (grey, R=G=B). */
csf_status csf_colour_export_eval(const char *path, csf_export_format f, const double *drive01,
                                  double *rel_lum, size_t n, csf_error *err);

/* The same through OpenColorIO's own ICC reader (cross-check for icc exports). */
csf_status csf_colour_export_eval_icc_ocio(const char *path, const double *drive01, double *rel_lum,
                                           size_t n, csf_error *err);

#ifdef __cplusplus
}
#endif

#endif
