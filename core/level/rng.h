/* Counter-based random numbers of the bake: SplitMix64 (Steele, Lea,
 * Flood 2014) keyed by (seed, stream), so that a sample's numbers depend
 * on the seed and the sample's index alone, never on the thread that
 * draws them. */
#ifndef OBSCURA_BAKE_RNG_H
#define OBSCURA_BAKE_RNG_H

#include <stdint.h>

typedef struct obs__bake_rng {
    uint64_t state;
} obs__bake_rng;

static inline uint64_t obs__bake_rng_next(obs__bake_rng *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline obs__bake_rng obs__bake_rng_stream(uint64_t seed, uint64_t stream, uint64_t salt)
{
    obs__bake_rng r = {seed ^ (salt * 0xd1b54a32d192ed03ULL)};
    r.state = obs__bake_rng_next(&r) ^ (stream * 0x8cb92ba72f3d8dd7ULL);
    obs__bake_rng_next(&r);
    return r;
}

/* [0, 1) with 53 bits. */
static inline double obs__bake_rng_unit(obs__bake_rng *r)
{
    return (double)(obs__bake_rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
