/* A point's visibility over the whole sphere in spherical harmonics
 * (section 2.3; level.h): `rays` equal-area directions (a Fibonacci
 * spiral turned by a random rotation per point, sh.c), the spherical
 * obscurance f(w) = rho(d(p, w)) T(w) at both distances, projected and
 * convolved with the clamped cosine.  The dynamic-object bake's probes and
 * the instanced decorators' volume (bake/volume.c) take it from here. */
#include <math.h>
#include <stdlib.h>

#include "internal.h"
#include "level/kernel.h"
#include "level/level.h"

#define PI_D 3.14159265358979323846

int obs__point_sh(const obs__bake_bvh *bvh, const float o[3], const obs_dyn_params *p,
                      uint64_t stream, double sh[OBS_DYN_CHANNELS], int *dropped)
{
    int n = p->rays, ok = 0;
    float *dirs = malloc((size_t)n * 3 * sizeof *dirs), *t = malloc((size_t)n * sizeof *t);
    float *tr = malloc((size_t)n * sizeof *tr);
    uint8_t *back = malloc((size_t)n);
    double *w = malloc((size_t)n * sizeof *w), *f = malloc(2 * (size_t)n * sizeof *f);
    if (!dirs || !t || !tr || !back || !w || !f)
        goto done;
    obs__sphere_dirs(n, (uint64_t)p->seed, stream, dirs);
    float dist[2] = {p->distance_short, p->distance_long};
    obs__bake_bvh_cast(bvh, o, dirs, n, OBS__BAKE_RAY_LENGTH_FACTOR * fmaxf(dist[0], dist[1]), t, back,
                       tr);
    int nb = 0;
    for (int k = 0; k < n; k++) {
        w[k] = 4.0 * PI_D / n; /* equal-area directions */
        nb += back[k];
        for (int c = 0; c < 2; c++) {
            double a = log(0.5) / dist[c]; /* a = ln(0.5) / d, section 2 (in double) */
            /* rho(x), times the decorators' transmittance (section 2.1;
             * 1 without them): a ray's visibility as the surface samples' */
            f[(size_t)c * n + k] = (isinf(t[k]) ? 1.0 : 1.0 - exp(a * t[k])) * tr[k];
        }
    }
    *dropped = (double)nb > (double)p->backface_limit * n;
    for (int c = 0; c < 2; c++) {
        obs__sh_project(dirs, w, f + (size_t)c * n, (size_t)n, sh + OBS_DYN_SH * c);
        obs__sh_convolve(sh + OBS_DYN_SH * c);
    }
    ok = 1;
done:
    free(dirs);
    free(t);
    free(tr);
    free(back);
    free(w);
    free(f);
    return ok;
}
