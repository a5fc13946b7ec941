/* Writes the sample store (tests/store/store_sample.h) to argv[1] for the command-line tests;
 * prints the observer and display session IDs. */
#include <stdio.h>
#include <stdlib.h>

#include "store_sample.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_sample_store PATH\n");
        return 2;
    }
    int64_t obs = 0, disp = 0;
    if (make_sample_store(argv[1], 77, &obs, &disp) != 0) return 1;
    printf("%lld %lld\n", (long long)obs, (long long)disp);
    return 0;
}
