/* Reference values for the third-party read-back checks (test_colour_thirdparty.sh): the
 * profile's own luminance at each drive value given, so the script compares other people's
 * readings of the exports with the profile, not with another export.
 * Prints "white_cdm2 black_cdm2", then one "drive01 lum_cdm2" line per drive value. */
#include <stdio.h>
#include <stdlib.h>

#include "results/display_profile.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: profile_eval PROFILE [DRIVE01 ...]\n");
        return 2;
    }
    csf_display_profile *p;
    csf_error err;
    if (csf_profile_load(argv[1], &p, &err) != CSF_OK) {
        fprintf(stderr, "profile_eval: %s\n", err.msg);
        return 1;
    }
    printf("%.17g %.17g\n", csf_profile_lum_max(p), csf_profile_lum_black(p));
    for (int i = 2; i < argc; i++) {
        double v = strtod(argv[i], NULL);
        printf("%.17g %.17g\n", v, csf_profile_grey_lum(p, v));
    }
    csf_profile_free(p);
    return 0;
}
