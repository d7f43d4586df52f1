/* The AO pass of the comparison methods (parameter method: hemisphere,
 * angle, hbao), which take the place of the VAO estimator in the chain;
 * the CPU twin of method.frag.glsl. */
#include "chain/frame.h"

/* GLSL: main() of method.frag.glsl */
float obs__method_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        int *count)
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    const float *p = pos + 4 * i, *n = nrm + 3 * i;
    *count = 0;
    if (!(p[3] > 0.0f))
        return 1.0f;
    switch (f->method) {
    case OBS_METHOD_HEMISPHERE:
        *count = f->hs_count;
        return obs__hemisphere_pixel(f, pos, x, y, p, n);
    case OBS_METHOD_ANGLE:
        *count = 2 * f->angle_pairs;
        return obs__angle_pixel(f, pos, x, y, p, n);
    case OBS_METHOD_HBAO:
        return obs__hbao_pixel(f, pos, x, y, p, n, count);
    default:
        return 1.0f;
    }
}
