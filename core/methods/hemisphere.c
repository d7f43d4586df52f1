/* Method hemisphere: the conventional normal-oriented hemisphere SSAO
 * (Mittring's Crytek SSAO with its sphere kernel turned into a hemisphere
 * around the normal; the kind Unity's post-processing stack ships, whose
 * quality levels take 3, 6, 10 and 16 samples, VAO++ Table 2).  Each
 * sample is a point of the hemisphere of radius R (the AO distance) on
 * the surface; it is occluded when the depth buffer holds a surface more
 * than the bias in front of it, weighted by a range check so that a
 * surface far in front does not count.  The CPU twin of hemisphere.glsl. */
#include <math.h>

#include "methods/bent.h"
#include "methods/hemisphere.h"
#include "chain/mask_weight.h"

/* Radical inverse of i in base b: the van der Corput sequence. */
static double radical_inverse(unsigned i, unsigned b)
{
    double inv = 1.0 / b, f = inv, r = 0.0;
    for (; i; i /= b, f *= inv)
        r += f * (double)(i % b);
    return r;
}

/* Sample i of n: a direction of the unit hemisphere around +z, uniform in
 * solid angle (cos of the polar angle from the base-2, azimuth from the
 * base-3 radical inverse: a Halton set instead of the random kernel, so
 * GL and C use the same one), at the distance sqrt((i + 1) / n) of the
 * radius, the distribution of Unity's post-processing stack ("distributed
 * between [0, radius]": more samples near the point). */
void obs__hemisphere_kernel(int n, float *out)
{
    for (int i = 0; i < n && i < OBS_MAX_HEMISPHERE; i++) {
        double c = fmin(1.0, radical_inverse((unsigned)i, 2) + 0.5 / n);
        double s = sqrt(fmax(0.0, 1.0 - c * c));
        double phi = 2.0 * M_PI * radical_inverse((unsigned)i, 3);
        double l = sqrt((i + 1.0) / n);
        out[3 * i] = (float)(l * s * cos(phi));
        out[3 * i + 1] = (float)(l * s * sin(phi));
        out[3 * i + 2] = (float)(l * c);
    }
}

void obs__hemisphere_basis(const float n[3], float t1[3], float t2[3])
{
    /* The tangent frame of n (Duff et al., "Building an orthonormal
     * basis, revisited", 2017): the kernel's +z goes to n. */
    float sg = n[2] >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (sg + n[2]), b = n[0] * n[1] * a;
    t1[0] = 1.0f + sg * n[0] * n[0] * a;
    t1[1] = sg * b;
    t1[2] = -sg * n[0];
    t2[0] = b;
    t2[1] = sg + n[1] * n[1] * a;
    t2[2] = -n[1];
}

void obs__hemisphere_sample(const obs__frame *f, int x, int y, const float p[3], const float n[3],
                            const float t1[3], const float t2[3], int i, float s[3])
{
    const obs__hemisphere_state *hs = obs__hemisphere_of(f);
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    const float *k = hs->kernel[i];
    /* the 3x3 tile's rotation about the normal (interleaved sampling,
     * removed by the shared blur as for VAO++) */
    float kx = rot[0] * k[0] - rot[1] * k[1], ky = rot[1] * k[0] + rot[0] * k[1];
    for (int j = 0; j < 3; j++)
        s[j] = p[j] + f->radius * (kx * t1[j] + ky * t2[j] + k[2] * n[j]);
}

/* The one hemisphere estimator of the flat and the deep chain (GLSL:
 * hemisphere_estimate() in hemisphere.glsl, also one function for both
 * chains: the deep pass defines the nodes it reads, HS_NODE).  Sample s
 * of the kernel is occluded by a node at its pixel whose surface lies in front of it (planar depths, -s.z for the
 * sample) past the bias; with several nodes (deep input, OITAO Algorithm
 * 1) the largest occlusion counts, each weighted by the node's alpha.
 * Range check: smoothstep(0, 1, R / |z_p - z_q|), a surface much nearer
 * than R counts fully, one far in front fades. */
float obs__hemisphere_estimate(const obs__frame *f, const obs__hemisphere_nodes *nodes, int x,
                               int y, const float p[3], const float n[3])
{
    return obs__hemisphere_estimate_bent(f, nodes, x, y, p, n, NULL);
}

float obs__hemisphere_estimate_bent(const obs__frame *f, const obs__hemisphere_nodes *nodes, int x,
                                    int y, const float p[3], const float n[3], float bent[3])
{
    const obs__hemisphere_state *hs = obs__hemisphere_of(f);
    const float R = f->radius;
    float t1[3], t2[3];
    obs__hemisphere_basis(n, t1, t2);
    float occ = 0.0f;
    for (int i = 0; i < hs->count; i++) {
        float s[3];
        obs__hemisphere_sample(f, x, y, p, n, t1, t2, i, s);
        int qx, qy;
        if (!obs__view_to_px(f, s, &qx, &qy)) {
            if (bent) /* left out of the AO's sum: open */
                obs__hemisphere_bent_sample(p, s, 1.0f, bent);
            continue;
        }
        size_t q = (size_t)qy * (size_t)f->width + (size_t)qx;
        float best = 0.0f;
        for (int k = 0; k < nodes->layers; k++) {
            const float *pk = nodes->pos + ((size_t)k * nodes->layer_px + q) * 4;
            float zn = pk[3];
            if (!(zn > 0.0f))
                continue; /* empty node: background never occludes */
            if (nodes->end && nodes->end[(size_t)k * nodes->layer_px + q] < 0.0f)
                continue; /* inside a nearer node's interval */
            if (!(zn <= -s[2] - hs->bias))
                continue; /* s is not behind the node */
            if (nodes->interior &&
                (pk[0] - p[0]) * n[0] + (pk[1] - p[1]) * n[1] + (pk[2] - p[2]) * n[2] <= hs->bias)
                continue; /* on the hull's exterior side */
            float dz = fabsf(-p[2] - zn);
            float r = dz > R ? R / dz : 1.0f;
            float an = nodes->nrm ? nodes->nrm[((size_t)k * nodes->layer_px + q) * 4 + 3] : 1.0f;
            /* object masks: the weight of the node's surface */
            best = fmaxf(best, an * r * r * (3.0f - 2.0f * r) *
                                   obs__occluder_weight_node(f, x, y, nodes->self, qx, qy, k));
        }
        occ += best;
        if (bent) /* OBS_OUTPUT_BENT: the sample's direction times its open part */
            obs__hemisphere_bent_sample(p, s, 1.0f - best, bent);
    }
    return hs->count > 0 ? 1.0f - occ / (float)hs->count : 1.0f;
}

/* GLSL: method_ao() in hemisphere.glsl (one opaque node per pixel) */
float obs__hemisphere_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                            const float n[3])
{
    return obs__hemisphere_pixel_bent(f, pos, x, y, p, n, NULL);
}

float obs__hemisphere_pixel_bent(const obs__frame *f, const float *pos, int x, int y,
                                 const float p[3], const float n[3], float bent[3])
{
    const obs__hemisphere_nodes flat = {pos, NULL, NULL, 1, 0, 0, 0};
    return obs__hemisphere_estimate_bent(f, &flat, x, y, p, n, bent);
}

void obs__hemisphere_setup(const obs_params *p, obs__frame *f)
{
    obs__hemisphere_state *s = (obs__hemisphere_state *)(void *)f->ms.bytes;
    s->count = p->hemisphere_samples;
    s->bias = p->hemisphere_bias * f->radius;
    obs__hemisphere_kernel(s->count, &s->kernel[0][0]);
}
