/* Measures the Gabor in a picture of the whole screen (a screenshot of `csfcal stimulus show`'s
 * window, converted to PNG): the Michelson contrast and the spatial frequency in cycles per degree,
 * through the simulated display the frame was drawn for and the station geometry (tests/stimuli/
 * gabor_fit.h). Prints one line: "contrast C freq_cpd F mean_cdm2 M"; exit 1 when the picture
 * cannot be read. Usage:
 *   show_shot_fit SHOT.png WIDTH_MM HEIGHT_MM DISTANCE_MM FREQ_CPD ECC_DEG POLAR_DEG SIGMA_DEG DISPLAY
 * FREQ_CPD is the frequency asked of show: the measured one is searched within +-20 % of it. */
#include <stdio.h>
#include <stdlib.h>

#include "gabor_fit.h"
#include "stim_test.h"

int main(int argc, char **argv)
{
    if (argc != 10) {
        fprintf(stderr, "usage: show_shot_fit SHOT.png WIDTH_MM HEIGHT_MM DISTANCE_MM FREQ_CPD ECC_DEG "
                        "POLAR_DEG SIGMA_DEG DISPLAY\n");
        return 2;
    }
    gfit_image im = {0};
    if (gfit_load_png(argv[1], &im)) {
        fprintf(stderr, "show_shot_fit: cannot read %s as PNG\n", argv[1]);
        return 1;
    }
    csf_geometry g;
    csf_error e;
    if (csf_geometry_init(&g, atof(argv[2]), atof(argv[3]), (int)im.w, (int)im.h, atof(argv[4]), 0, 0, &e)) {
        fprintf(stderr, "show_shot_fit: geometry: %s\n", e.msg);
        free(im.rgb);
        return 1;
    }
    gfit_patch pt = {atof(argv[6]), atof(argv[7]), atof(argv[8])};
    csf_display_model *dm = stim_test_model(argv[9]);
    gfit_pixels px;
    int rc = gfit_prepare(&im, &g, dm, &pt, &px);
    if (!rc) {
        double f = gfit_best_freq(&px, atof(argv[5]), 0.0025);
        gfit_result r = gfit_at(&px, f);
        printf("contrast %.6f freq_cpd %.6f mean_cdm2 %.4f\n", r.contrast, f, r.mean);
    } else fprintf(stderr, "show_shot_fit: out of memory\n");
    gfit_pixels_free(&px);
    csf_display_model_free(dm);
    free(im.rgb);
    return rc ? 1 : 0;
}
