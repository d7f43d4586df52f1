/* The bent normals of the comparison methods' samples (methods/bent.c).
 * Not installed. */
#ifndef OBSCURA_METHODS_BENT_H
#define OBSCURA_METHODS_BENT_H

/* The bent normal of one slice, added to acc (GLSL: gtao_bent_slice in
 * method.glsl): XeGTAO's t0 (along the slice's screen direction od,
 * orthogonal to v, normalised here) and t1 (along v) of the horizon
 * angles h0, h1 and the projected normal's angle gamma, times |n_p|. */
void obs__gtao_bent_slice(float h0, float h1, float gamma, float np_len, const float od[3],
                          const float v[3], float acc[3]);

/* The bent normals of methods hemisphere, angle and hbao from their own
 * samples (methods/bent.c, which derives each; GLSL twins in
 * hemisphere.glsl, angle.glsl, hbao.glsl), added to acc: a hemisphere
 * sample s of p with its open part; one side of an angle pair (the
 * vector u, its angle theta to n, the pair's weight w); the hbao span of
 * elevations sin0..sin1 along the view direction (dx, dy) times w. */
void obs__hemisphere_bent_sample(const float p[3], const float s[3], float open, float acc[3]);
void obs__angle_bent_side(const float n[3], const float u[3], float theta, float w, float acc[3]);
void obs__hbao_bent_span(float dx, float dy, float sin0, float sin1, float w, float acc[3]);

#endif
