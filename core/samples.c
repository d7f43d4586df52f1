/* Sample sets on the unit disk and the per-pixel rotation of the set.
 *
 * The sets are Poisson-disk-like (Mitchell's best-candidate algorithm,
 * area-uniform candidates, a fixed seed), so every run and every machine
 * uses the same samples.  VAO's estimator (eq 1) assumes samples spread
 * uniformly over the disk; the rotation-aware generator of VAO++ section
 * 4.5 refines this. */
#include <math.h>
#include <pthread.h>

#include "internal.h"

#define CANDIDATES 64

/* sets[n] holds n samples, for n in [2, OBS__MAX_SAMPLES]. */
static float sets[OBS__MAX_SAMPLES + 1][OBS__MAX_SAMPLES * 2];
static pthread_once_t sets_once = PTHREAD_ONCE_INIT;

static uint32_t xorshift32(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return *s = x;
}

static float unit(uint32_t *s) { return (float)(xorshift32(s) >> 8) / 16777216.0f; }

static void generate(int n, float *out)
{
    uint32_t seed = 0x9e3779b9u ^ (uint32_t)n;
    for (int i = 0; i < n; i++) {
        float best_x = 0, best_y = 0, best_d = -1.0f;
        for (int c = 0; c < CANDIDATES; c++) {
            float r = sqrtf(unit(&seed)), a = 6.28318530718f * unit(&seed);
            float x = r * cosf(a), y = r * sinf(a);
            float dmin = 1e9f;
            for (int j = 0; j < i; j++) {
                float dx = x - out[2 * j], dy = y - out[2 * j + 1];
                dmin = fminf(dmin, dx * dx + dy * dy);
            }
            if (dmin > best_d) {
                best_d = dmin;
                best_x = x;
                best_y = y;
            }
        }
        out[2 * i] = best_x;
        out[2 * i + 1] = best_y;
    }
}

static void generate_all(void)
{
    for (int n = 2; n <= OBS__MAX_SAMPLES; n++)
        generate(n, sets[n]);
}

const float *obs__samples(int n)
{
    if (n < 2 || n > OBS__MAX_SAMPLES)
        return NULL;
    pthread_once(&sets_once, generate_all);
    return sets[n];
}

/* Index k = 3 * (x mod 3) + (y mod 3) of the 3x3 tile; angle 2 pi k / 9.
 * The GL passes index the same table (uniform u_rot) the same way. */
void obs__pixel_rotation(int x, int y, float *cos_a, float *sin_a)
{
    int k = 3 * (x % 3) + (y % 3);
    double a = 2.0 * M_PI * k / 9.0;
    *cos_a = (float)cos(a);
    *sin_a = (float)sin(a);
}
