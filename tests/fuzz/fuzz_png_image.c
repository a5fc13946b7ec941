/* Fuzz target: the PNG stimulus loader (stimuli/image.h) on arbitrary bytes. */
#include <stddef.h>
#include <stdint.h>

#include "stimuli/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    csf_image *img = NULL;
    csf_error err;
    if (csf_image_load_png_memory(data, size, &img, &err) == CSF_OK) {
        /* touch every decoded value so out-of-bounds or uninitialised output shows up */
        volatile float acc = 0;
        for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++)
            acc += img->lum[i] + img->alpha[i];
        (void)acc;
        csf_image_free(img);
    }
    return 0;
}
