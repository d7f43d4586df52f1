/* Method angle (angle.c, angle.glsl): its own values in the frame and its
 * functions.  Not installed. */
#ifndef OBSCURA_METHOD_ANGLE_H
#define OBSCURA_METHOD_ANGLE_H

#include "chain/frame.h"

/* Pair i's offset on the unit disk (its partner is the negation); the
 * arc cosine used (OBS_ACOS_*). */
typedef struct obs__angle_state {
    int pairs;
    float xy[OBS_MAX_PAIRS][2];
    int acos;
} obs__angle_state;
_Static_assert(sizeof(obs__angle_state) <= OBS__METHOD_STATE_BYTES, "fits obs__frame.ms");

static inline const obs__angle_state *obs__angle_of(const obs__frame *f)
{
    return (const obs__angle_state *)(const void *)f->ms.bytes;
}

/* Fills the frame's method values from the resolved parameters. */
void obs__angle_setup(const obs_params *p, obs__frame *f);

/* The pair offsets on the unit disk, 2 floats per pair. */
void obs__angle_pattern(int pairs, float *out);

/* The arc cosine of the angle-based method: mode OBS_ACOS_QUADRATIC,
 * _LINEAR or _EXACT; x is clamped to [-1, 1] (GLSL: acos_mode() in
 * angle.glsl). */
float obs__acos_mode(int mode, float x);

/* Angle-based paired-sample SSAO of the point p (xyzw, w the planar
 * depth) with normal n at pixel (x, y) (GLSL: angle.glsl). */
float obs__angle_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                       const float n[3]);
/* obs__angle_pixel that also sums the bent normal of its pairs into
 * bent[3] (NULL: not wanted; obs__angle_bent_side, bent.c). */
float obs__angle_pixel_bent(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                            const float n[3], float bent[3]);

#endif
