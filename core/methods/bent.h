/* The bent normal of method gtao's slices (methods/bent.c).  Not
 * installed. */
#ifndef OBSCURA_METHODS_BENT_H
#define OBSCURA_METHODS_BENT_H

/* The bent normal of one slice, added to acc (GLSL: gtao_bent_slice in
 * method.glsl): XeGTAO's t0 (along the slice's screen direction od,
 * orthogonal to v, normalised here) and t1 (along v) of the horizon
 * angles h0, h1 and the projected normal's angle gamma, times |n_p|. */
void obs__gtao_bent_slice(float h0, float h1, float gamma, float np_len, const float od[3],
                          const float v[3], float acc[3]);

#endif
