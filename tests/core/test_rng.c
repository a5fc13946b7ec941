#include <math.h>

#include "core/rng.h"
#include "tests/check.h"

int main(void)
{
    /* Pure function of (seed, stream, index). */
    CHECK(csf_rng_u64(7, 1, 100) == csf_rng_u64(7, 1, 100));
    CHECK(csf_rng_u64(7, 1, 100) != csf_rng_u64(7, 1, 101));
    CHECK(csf_rng_u64(7, 1, 100) != csf_rng_u64(7, 2, 100));
    CHECK(csf_rng_u64(7, 1, 100) != csf_rng_u64(8, 1, 100));

    /* Moments of the uniform and normal draws over 200k samples. */
    const int n = 200000;
    double su = 0, su2 = 0, sn = 0, sn2 = 0, umin = 1, umax = 0;
    int tail = 0;
    for (int i = 0; i < n; i++) {
        double u = csf_rng_uniform(42, 3, (uint64_t)i);
        double z = csf_rng_normal(42, 4, (uint64_t)i);
        su += u; su2 += u * u; sn += z; sn2 += z * z;
        if (u < umin) umin = u;
        if (u > umax) umax = u;
        if (fabs(z) > 1.959964) tail++;
    }
    CHECK(umin > 0 && umax < 1);
    CHECK_NEAR(su / n, 0.5, 0.005);
    CHECK_NEAR(su2 / n - (su / n) * (su / n), 1.0 / 12, 0.002);
    CHECK_NEAR(sn / n, 0.0, 0.01);
    CHECK_NEAR(sn2 / n, 1.0, 0.015);
    CHECK_NEAR((double)tail / n, 0.05, 0.003);

    csf_rng r;
    csf_rng_init(&r, 42, 3);
    CHECK(csf_rng_next_uniform(&r) == csf_rng_uniform(42, 3, 0));
    CHECK(csf_rng_next_uniform(&r) == csf_rng_uniform(42, 3, 1));
    return CHECK_RESULT();
}
