/* The sample sets the passes use and the per-pixel rotation of the set.
 *
 * The sets are the output of the VAO++ generator (section 4.5,
 * core/chain/samples_gen.c), checked in as core/chain/sample_tables.c; a unit test
 * regenerates them and compares.  Only the sizes 2, 4, 8, 16 and 32
 * exist: the samples parameter takes those (the first n of a larger set
 * would not do: z-order puts them all in one part of the disk). */
#include <math.h>

#include "internal.h"

const float *obs__samples(int n)
{
    if (n < 2 || n > OBS_MAX_SAMPLES || (n & (n - 1)) != 0)
        return NULL;
    return obs__sample_table[n - 2]; /* sets of 2, 4, 8, ... follow each other */
}

const float *obs_samples_table(int n) { return obs__samples(n); }

/* Index k = 3 * (x mod 3) + (y mod 3) of the 3x3 tile; angle 2 pi k / 9
 * (section 4.5: nine uniform-step angles, computed from the pixel, not
 * fetched from a texture).  The GL passes index the same table (uniform
 * u_rot) the same way; samples_gen.c generates for the same angles. */
void obs__pixel_rotation(int x, int y, float *cos_a, float *sin_a)
{
    int k = 3 * (x % 3) + (y % 3);
    double a = 2.0 * M_PI * k / 9.0;
    *cos_a = (float)cos(a);
    *sin_a = (float)sin(a);
}
