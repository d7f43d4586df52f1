// Method hemisphere: normal-oriented hemisphere SSAO (Crytek's SSAO with
// the kernel in the hemisphere around the normal, as Unity's
// post-processing stack ships it).  C twin: obs__hemisphere_estimate and
// obs__hemisphere_pixel (methods/hemisphere.c), which document the kernel.
//
// One estimator for the flat and the deep chain: a sample is tested
// against the nodes at its pixel, read through HS_NODE(q, k) (view xyz,
// planar depth w; w 0: empty), HS_ALPHA(q, k) and HS_WEIGHT(px, q, k)
// (the object masks' weight of node k at q for the receiver at px).  The deep pass
// (deep.frag.glsl) defines them for its node arrays; without them this
// file is the flat method's AO pass, one opaque node per pixel from the
// depth plane, and defines method_ao().

#ifndef HS_NODE
#define HS_NODE(q, k) vec4(0.0, 0.0, 0.0, imageLoad(u_dz, q).x) // the depth plane: one RG texel
#define HS_ALPHA(q, k) 1.0
#define HS_WEIGHT(c, q, k) occluder_weight(c, q) // object masks (common.glsl)
#define HS_FLAT 1
// OBS_OUTPUT_BENT (method.glsl's g_bent): each sample's unit direction
// times its open part.  The deep pass leaves it out.  C twin:
// obs__hemisphere_bent_sample (methods/bent.c), which derives it.
#define HS_BENT(s, open) g_bent += (open) * normalize((s) - p)
#endif
#ifndef HS_BENT
#define HS_BENT(s, open)
#endif

uniform int u_hs_count;          // samples
uniform float u_hs_bias;         // occluders must be this far in front (depth units)
uniform float u_hs_kernel[3 * OBS_MAX_HEMISPHERE]; // unit hemisphere around +z, (x, y, z) per sample
                                 // (obs__hemisphere_kernel)

// The AO of p with normal n at px against `layers` nodes per pixel: a
// sample is occluded by a node whose surface lies in front of it past the
// bias, by the range check's smoothstep(0, 1, R / |z_p - z_q|), times the
// node's alpha; the largest over the nodes counts (OITAO Algorithm 1).
// interior: a node on the exterior side of p's tangent plane hides
// nothing (OITAO eqs 2-4).
float hemisphere_estimate(ivec2 px, vec3 p, vec3 n, int layers, bool interior)
{
    float R = u_radius;
    vec2 rot = u_rot[tile_index(px)];
    vec3 t1, t2;                // the kernel's +z goes to n
    tangent_basis(n, t1, t2);
    float occ = 0.0;
    for (int i = 0; i < u_hs_count; i++) {
        vec3 k = vec3(u_hs_kernel[3 * i], u_hs_kernel[3 * i + 1], u_hs_kernel[3 * i + 2]);
        // the 3x3 tile's rotation about the normal
        float kx = rot.x * k.x - rot.y * k.y, ky = rot.y * k.x + rot.x * k.y;
        vec3 s = vec3(p.x + R * (kx * t1.x + ky * t2.x + k.z * n.x),
                      p.y + R * (kx * t1.y + ky * t2.y + k.z * n.y),
                      p.z + R * (kx * t1.z + ky * t2.z + k.z * n.z));
        ivec2 q;
        if (!view_to_px(s, u_size, q)) {
            HS_BENT(s, 1.0);        // left out of the AO's sum: open
            continue;               // off the planes: left out
        }
        float best = 0.0;
        for (int j = 0; j < layers; j++) {
            vec4 pk = HS_NODE(q, j);
            if (!(pk.w > 0.0))
                continue;           // empty node: background never occludes
            if (!(pk.w <= -s.z - u_hs_bias))
                continue;           // s is not behind the node
            if (interior && dot(pk.xyz - p, n) <= u_hs_bias)
                continue;           // on the hull's exterior side
            float dz = abs(-p.z - pk.w);
            float r = dz > R ? R / dz : 1.0;
            // times the object masks' weight of the node's surface
            best = max(best, HS_ALPHA(q, j) * r * r * (3.0 - 2.0 * r) * HS_WEIGHT(px, q, j));
        }
        occ += best;
        HS_BENT(s, 1.0 - best);
    }
    return u_hs_count > 0 ? 1.0 - occ / float(u_hs_count) : 1.0;
}

#ifdef HS_FLAT
float method_ao(ivec2 px, vec4 p, vec3 n, out int count)
{
    count = u_hs_count;
    return hemisphere_estimate(px, p.xyz, n, 1, false);
}
#endif
