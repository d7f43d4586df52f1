// Multi-layer, opacity-based AO of deep input (OITAO, Bauer et al.): each
// pixel's compressed list (section III-B) is a column of the 2D array
// textures, node k in layer k.  For every node: VAO++'s volumetric AO
// (section 3) whose line samples are occluded by every node at their
// pixel, the largest occlusion counting (OITAO Algorithm 1), weighted by
// opacity (eq 1, or eqs 2-4 for thin hulls); the nodes' AO blended front
// to back by alpha (section III, the separated scheme).  With
// OBS_DEEP_HEMISPHERE the per-node occlusion is method hemisphere's point samples
// (the normal-oriented hemisphere kernel), each against every node, the
// largest counting (Algorithm 1); with OBS_DEEP_HORIZON method gtao's or
// hbao's horizon search, each step reading every node at its pixel (as
// OITAO's multi-layer HBAO, Fig. 9).  C twin: core/deep/deep_cpu.c (same
// function names).

layout(rgba32f) readonly uniform image2DArray u_lpos; // node view position xyz, planar depth w (0: empty)
layout(rgba32f) readonly uniform image2DArray u_lnrm; // node view normal xyz, alpha w
#if OBS_DEEP_INTERVALS
// the node's interval end (obs__deep_intervals): 0 solid behind it, e > 0
// solid from its depth to e, -1 inside a nearer node's interval
layout(r32f) readonly uniform image2DArray u_lend;
#endif
// Object masks (occluders, self_only; obs_deep_read_masks): each node's
// occluders weight (x) and object ID (y, compared as bits), bound when
// u_deep_mask is not 0 (1: the weights, 2: self_only, 3: both).
layout(rg32f) readonly uniform image2DArray u_lmask;
#if OBS_DEEP_NODES
// every node's AO, node k in layer k (the deep AO out, obs_deep_run_nodes;
// C twin: obs_deep_ao_nodes); layers past the pixel's last node untouched
layout(r32f) writeonly uniform image2DArray u_lao;
#endif
uniform int u_deep_mask;
int g_self = 0;                 // the receiver's node, set by node_ao()
uniform int u_m;                // nodes per pixel
uniform int u_multi;            // 1: every node occludes (Algorithm 1); 0: node 0 only
// u_size, u_radius (R), u_count (the line samples, the set of section 4.5
// at u_samples[u_count - 2]), u_rot, u_range_u, u_range_normal: the Frame
// block (common.glsl)
// Defined by the program (deep_gl.c), 0 or 1, so that a SIMD rasteriser
// does not run the unused side of a uniform branch for every node:
// OBS_DEEP_HEMISPHERE, method hemisphere's point samples (else VAO's line
// samples); OBS_DEEP_THIN, thin hulls (eqs 2-4; else solid volumes, eq 1);
// OBS_RANGE_CHECK, the depth range check (VAO++ 4.4, eq 4);
// OBS_DEEP_INTERVALS, the nodes' intervals from their facing flags;
// OBS_DEEP_HORIZON, method gtao's or hbao's horizon search over the nodes;
// OBS_DEEP_NODES, every node's AO stored (u_lao).
// Method hemisphere's estimator (hemisphere.glsl, appended after this file
// in the OBS_DEEP_HEMISPHERE programs) reads the nodes through these.
// The object masks' weight of node k at pixel s as an occluder of node
// g_self at pixel c: its occluders weight, times 0 where self_only's
// object there is not the receiver's; a pixel off the image reads the
// nearest one on it.  1 without masks.  C twin: obs__occluder_weight_node
// (chain/mask_weight.h), with the deep frame's per-node planes.
float node_weight(ivec2 c, ivec2 s, int k)
{
    if (u_deep_mask == 0)
        return 1.0;
    s = clamp(s, ivec2(0), u_size - 1);
    vec2 ms = imageLoad(u_lmask, ivec3(s, k)).xy;
    float w = (u_deep_mask & 1) != 0 ? ms.x : 1.0;
    if ((u_deep_mask & 2) != 0 &&
        floatBitsToUint(ms.y) != floatBitsToUint(imageLoad(u_lmask, ivec3(c, g_self)).y))
        w = 0.0;
    return w;
}
// Whether node k at q can occlude: not where the facing flags put it
// inside a nearer node's interval (end < 0, deep_internal.h), as a back
// face closing it; method hemisphere's samples take such a node's weight
// as 0, which adds nothing (C: the ends passed to obs__hemisphere_estimate).
bool node_occludes(ivec2 q, int k)
{
#if OBS_DEEP_INTERVALS
    return imageLoad(u_lend, ivec3(q, k)).x >= 0.0;
#else
    return true;
#endif
}
#define HS_NODE(q, k) imageLoad(u_lpos, ivec3(q, k))
#define HS_WEIGHT(c, q, k) (node_occludes(q, k) ? node_weight(c, q, k) : 0.0)
#define HS_ALPHA(q, k) imageLoad(u_lnrm, ivec3(q, k)).w
float hemisphere_estimate(ivec2 px, vec3 p, vec3 n, int layers, bool interior);
// Methods gtao's and hbao's horizon searches (gtao.glsl, hbao.glsl,
// after this file in the OBS_DEEP_HORIZON programs, with method.glsl's
// radius_px) read every node at a step's pixel through these (gtao: the
// front nodes past the border); method_ao(px, vec4 p, n, count) is theirs.
#define GT_LAYERS (u_multi != 0 ? u_m : 1)
#define GT_NODE(q, k) imageLoad(u_lpos, ivec3(q, k))
#define GT_FRONT(b) imageLoad(u_lpos, ivec3(b, 0))
#define GT_FRONT_NORMAL(b) imageLoad(u_lnrm, ivec3(b, 0))
#define GT_WEIGHT(c, q, k) node_weight(c, q, k)
#if OBS_DEEP_INTERVALS
#define GT_INTERVALS 1      // gtao: each slice's free arcs (gtao.glsl)
#define GT_END(q, k) imageLoad(u_lend, ivec3(q, k)).x
#endif
#define HB_LAYERS (u_multi != 0 ? u_m : 1)
#define HB_NODE(q, k) imageLoad(u_lpos, ivec3(q, k))
#define HB_WEIGHT(c, q, k) node_weight(c, q, k)
float method_ao(ivec2 px, vec4 p, vec3 n, out int count);

// the front node's AO and the blended AO, each beside the front node's
// planar depth (0: empty), as the blur reads them (blur.frag.glsl)
layout(location = 0) out vec2 o_front;
layout(location = 1) out vec2 o_blend;

// The length of the pipe [front, front + 2h] hidden by a node at planar
// depth zs with view normal z nz: VAO++ section 3's cases with the node as
// the depth buffer, eq 4's falloff when it lies in front.  interior: a
// node in front of the pipe is on a thin hull's exterior side (eqs 2-4)
// and hides nothing.
float node_occlusion(float zs, float nz, float front, float h, bool interior)
{
    if (!(zs > 0.0))
        return 0.0;
    float dz = min(max(zs - front, 0.0), 2.0 * h);
    if (zs < front) {
        if (interior)
            return 0.0;
        if (OBS_RANGE_CHECK != 0) {
            float sd = range_falloff(front - zs, nz, u_radius, u_range_u, u_range_normal);
            dz = 2.0 * h * (1.0 - sd);
        }
    }
    return 2.0 * h - dz;
}

// The length of the pipe [front, front + 2h] inside a node's closed
// interval [zs, e]: their overlap, no range check.
float interval_occlusion(float zs, float e, float front, float h)
{
    return max(0.0, min(e, front + 2.0 * h) - max(zs, front));
}

// A line sample off the planes: true and the surface continued past the
// border (chain/border_cpu.c) from the front node of the last pixel b on
// the planes, zs (0, an empty node, open, where b is background), nz, and a, b's
// front node's alpha times the masks' weight; false where there is no
// estimate (the sample is left out).  As vao.glsl's border_sample reads
// the flat planes.  C twin: obs__disk_border in sphere_ao (deep_cpu.c).
bool deep_border(ivec2 px, vec3 U, vec3 V, vec3 W, float sx, float sy, out float zs,
                 out float nz, out float a)
{
    zs = 0.0;
    nz = 1.0;
    a = 0.0;
    vec2 q;
    ivec2 b;
    if (!disk_uv(U, V, W, sx, sy, q) || !border_px(px, q, b))
        return false;
    vec4 pb = imageLoad(u_lpos, ivec3(b, 0));
    vec4 nb = imageLoad(u_lnrm, ivec3(b, 0));
    a = nb.w * node_weight(px, b, 0);
    if (!(pb.w > 0.0))
        return true;
    vec4 pt;
    if (!plane_point(q, pb.xyz, nb.xyz, pt))
        return false;
    zs = pt.w;
    nz = nb.z;
    return true;
}

// VAO++ eqs 1-2 for the tangent sphere at p along n; each sample's
// occlusion is the largest over the nodes at its pixel (Algorithm 1, line
// 9), each node's weighted by its alpha (eq 1's alpha_omega).  self: the
// receiver's node at px, which a sample on px reads as its tangent plane
// (own_plane_depth, common.glsl).
float sphere_ao(ivec2 px, vec3 p, vec3 n, bool interior, int self)
{
    float R = u_radius, r = 0.5 * u_radius;
    vec3 c = p + n * r;
    vec2 rot = u_rot[tile_index(px)];
    vec3 U, V, W;
    disk_map(c, r, rot, U, V, W);   // the samples' pixels (common.glsl)
    int layers = u_multi != 0 ? u_m : 1;
    float open = 0.0, F = 0.0;
    for (int i = 0; i < u_count; i++) {
        vec2 xy = u_samples[u_count - 2 + i];
        float sx = xy.x, sy = xy.y;
        float l = sqrt(max(0.0, 1.0 - sx * sx - sy * sy));
        float h = r * l;
        ivec2 q;
        float front = -c.z - h, occ = 0.0, solid = 0.0;
        if (!disk_px(U, V, W, sx, sy, u_size, q)) {
            // off the planes: the front nodes' surface continued past the
            // border (deep_border), or left out where there is no estimate
            float zs, nz, a;
            if (!deep_border(px, U, V, W, sx, sy, zs, nz, a))
                continue;
            open += 2.0 * h - a * node_occlusion(zs, nz, front, h, interior);
            F += R * l;
            continue;
        }
        for (int k = 0; k < layers; k++) {
#if OBS_DEEP_INTERVALS
            float e = imageLoad(u_lend, ivec3(q, k)).x;
            if (e < 0.0)
                continue;               // inside a nearer node's interval
#endif
            float zs = imageLoad(u_lpos, ivec3(q, k)).w;
            vec4 nk = imageLoad(u_lnrm, ivec3(q, k));   // normal, alpha
            if (k == self && q == px)
                zs = own_plane_depth(p, n, disk_point(c, r, rot, sx, sy), zs);
            // alpha times the object masks' weight of the node's surface
            float a = nk.w * node_weight(px, q, k);
#if OBS_DEEP_INTERVALS
            if (e > 0.0 && zs > 0.0 && !interior)       // a closed interval
                solid += a * interval_occlusion(zs, e, front, h);
            else
#endif
                occ = max(occ, a * node_occlusion(zs, nk.z, front, h, interior));
        }
        // disjoint intervals add; the nodes solid behind them, the largest
        occ = min(2.0 * h, occ + solid);
        open += 2.0 * h - occ;
        F += R * l;
    }
    return F > 0.0 ? open / F : 1.0;
}

// The per-sample estimator of the method: VAO++'s or method hemisphere's;
// VAO++'s converted to the ray-traced AO under ao_definition rays
// (OBS_RAYS, defined by the program; C twin: method_ao in deep_cpu.c).
float method_ao(ivec2 px, vec3 p, vec3 n, bool interior, int self)
{
#if OBS_DEEP_HEMISPHERE
    return hemisphere_estimate(px, p, n, u_multi != 0 ? u_m : 1, interior);
#elif OBS_DEEP_HORIZON
    int count;
    return method_ao(px, vec4(p, 0.0), n, count);   // gtao.glsl or hbao.glsl, over the nodes
#else
#if OBS_RAYS
    return rays_from_volume(sphere_ao(px, p, n, interior, self)); // common.glsl
#else
    return sphere_ao(px, p, n, interior, self);
#endif
#endif
}

// OITAO eq 1 (solid) or eqs 2-4 (thin hull) for node k at px.
float node_ao(ivec2 px, int k)
{
    vec4 p = imageLoad(u_lpos, ivec3(px, k));
    vec4 n = imageLoad(u_lnrm, ivec3(px, k));
    if (!(p.w > 0.0))
        return 1.0;
    g_self = k;                                     // node_weight()'s receiver
    float ve = method_ao(px, p.xyz, n.xyz, false, k);
#if OBS_DEEP_THIN == 0
    return 1.0 - n.w * (1.0 - ve);                  // eq 1: alpha_p
#else
    float vi = method_ao(px, p.xyz, -n.xyz, true, k);
    float facing = -(p.x * n.x + p.y * n.y + p.z * n.z);
    float W = facing >= 0.0 ? n.w : 1.0 - n.w;      // eq 3
    return W * ve + (1.0 - W) * vi;                 // eq 4
#endif
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float T = 1.0, acc = 0.0, front = 1.0;
    for (int k = 0; k < u_m; k++) {
        vec4 p = imageLoad(u_lpos, ivec3(px, k));
        if (!(p.w > 0.0))
            break;
        float a = imageLoad(u_lnrm, ivec3(px, k)).w;
        float ao = node_ao(px, k);
        if (k == 0)
            front = ao;
#if OBS_DEEP_NODES
        imageStore(u_lao, ivec3(px, k), vec4(ao));
#endif
        acc += T * a * ao;   // "over", front to back
        T *= 1.0 - a;
#if !OBS_DEEP_NODES
        if (T == 0.0)
            break;           // an opaque node: every node behind it adds T a ao = 0
#endif
    }
    float z0 = max(imageLoad(u_lpos, ivec3(px, 0)).w, 0.0);
    o_front = vec2(front, z0);
    o_blend = vec2(acc + T, z0);
}
