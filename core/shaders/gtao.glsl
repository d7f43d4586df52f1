// Method gtao: ground-truth-based AO (Jimenez et al. 2016, Algorithm 1)
// as XeGTAO implements it (XeGTAO.hlsli, XeGTAO_MainPass): per slice
//   A_slice = |n_p| (a(h0) + a(h1)),
//   a(h) = (cos gamma + 2 h sin gamma - cos(2 h - gamma)) / 4,
// horizons from the depth samples weighted by the falloff.  C twin:
// obs__gtao_pixel (methods/gtao.c), which documents the method.

// The planes the horizon search reads: the flat chain's (method.glsl);
// the deep pass (deep.frag.glsl) defines them for its nodes: GT_LAYERS
// nodes at a pixel, GT_NODE(q, k) the view position and planar depth of
// node k at q, GT_FRONT and GT_FRONT_NORMAL the front surface that a step
// past the border continues.
#ifndef GT_LAYERS
#define GT_LAYERS 1
#define GT_NODE(q, k) imageLoad(u_pos, q)
#define GT_FRONT(b) imageLoad(u_pos, b)
#define GT_FRONT_NORMAL(b) imageLoad(u_vnormal, b)
#endif
// The object masks' weight of node k at q for the receiver at px (the
// flat chain: occluder_weight, common.glsl; the deep pass defines it).
#ifndef GT_WEIGHT
#define GT_WEIGHT(c, q, k) occluder_weight(c, q)
#endif

uniform int u_gtao_slices;
uniform int u_gtao_steps;
uniform int u_gtao_heuristics;     // 1: XeGTAO's three empirical corrections
uniform float u_gtao_radius;       // the search radius, depth units
uniform vec2 u_gtao_falloff;       // weight = saturate(r * x + y)
uniform vec2 u_gtao_thin_power;    // thin-occluder compensation, final power

const float GTAO_TOO_CLOSE = 1.3;
const float GTAO_CENTRE_SCALE = 0.99999;
const float GTAO_SLOPE_FUDGE = 0.05;
const float GTAO_MIN_VISIBILITY = 0.03;
const float GTAO_R1 = 0.6180339887498948482;
const float GTAO_HALF_PI = 1.5707963267948966;

// C twin: obs__gtao_noise
vec2 gtao_noise(ivec2 px)
{
    float k = float(tile_index(px));
    return fract(vec2(0.5) + k * vec2(0.75487766624669276, 0.56984029099805327));
}

// A step at pixel q off the planes: true and xq, the surface continued
// past the border (chain/border_cpu.c), or xq.w = 0 where that is
// background (the horizon stays, the step counted); false where there is
// no estimate (the horizon stays).  C twin: border_step (methods/gtao.c).
bool gtao_border_step(ivec2 px, ivec2 q, out vec4 xq)
{
    xq = vec4(0.0);
    ivec2 b;
    if (!border_px(px, vec2(q), b))
        return false;
    vec4 pb = GT_FRONT(b);
    if (!(pb.w > 0.0))
        return true;
    return plane_point(vec2(q), pb.xyz, GT_FRONT_NORMAL(b).xyz, xq);
}

// The horizon cosine of one sample point xq for the centre c, its falloff
// weight times om (the object masks' weight of its pixel): low where it
// adds nothing.  C twin: sample_cos (methods/gtao.c)
float gtao_sample_cos(vec4 xq, vec3 c, vec3 v, float low, float om)
{
    if (!(xq.w > 0.0))
        return low;
    vec3 d = xq.xyz - c;
    float dist = length(d);
    if (!(dist > 0.0))
        return low;
    float shc = dot(d, v) / dist;
    float fb = length(vec3(d.xy, d.z * (1.0 + u_gtao_thin_power.x)));
    float w = clamp(fb * u_gtao_falloff.x + u_gtao_falloff.y, 0.0, 1.0) * om;
    return low + (shc - low) * w;
}

// C twin: side_horizon (methods/gtao.c); a step inside the image reads
// every node at its pixel (GT_LAYERS), the largest counting
float gtao_side_horizon(ivec2 px, vec3 c, vec3 v, vec2 omega, int slice, float noise_step,
                        float min_s, int dir, float low, inout int taken)
{
    float hc = low;
    for (int st = 0; st < u_gtao_steps; st++) {
        float base = float(slice + st * u_gtao_steps) * GTAO_R1;
        float sn = fract(noise_step + base);
        float s = (float(st) + sn) / float(u_gtao_steps);
        s = s * s + min_s;
        ivec2 q = px + dir * ivec2(int(floor(s * omega.x + 0.5)), int(floor(s * omega.y + 0.5)));
        // object masks: the weight of each node's surface at q (past the
        // border, the front one's)
        if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y) {
            vec4 xq;
            if (!gtao_border_step(px, q, xq))
                continue;
            taken++;
            hc = max(hc, gtao_sample_cos(xq, c, v, low, GT_WEIGHT(px, q, 0)));
            continue;
        }
        taken++;
        for (int k = 0; k < GT_LAYERS; k++)
            hc = max(hc, gtao_sample_cos(GT_NODE(q, k), c, v, low, GT_WEIGHT(px, q, k)));
    }
    return hc;
}

float gtao_arc(float h, float gamma, float cos_gamma)
{
    return (cos_gamma + 2.0 * h * sin(gamma) - cos(2.0 * h - gamma)) / 4.0;
}

float method_ao(ivec2 px, vec4 p, vec3 n, out int count)
{
    int taken = 0;
    count = 0;
    float rpx = radius_px(p.xyz, u_gtao_radius);
    if (!(rpx > 0.0))
        return 1.0;                       // behind the camera
    vec3 c = p.xyz * GTAO_CENTRE_SCALE;
    vec3 v = vec3(0.0, 0.0, 1.0);         // orthographic: +z
    if (PM(3, 2) != 0.0) {
        float l = length(c);
        if (!(l > 0.0))
            return 1.0;
        v = -c / l;
    }
    vec2 noise = gtao_noise(px);
    float min_s = GTAO_TOO_CLOSE / rpx;
    float vis = u_gtao_heuristics != 0 ? clamp((10.0 - rpx) / 100.0, 0.0, 1.0) * 0.5 : 0.0;
    for (int sl = 0; sl < u_gtao_slices; sl++) {
        float phi = (float(sl) + noise.x) / float(u_gtao_slices) * 3.14159265358979;
        float cp = cos(phi), sp = sin(phi);
        vec2 omega = vec2(cp, -sp) * rpx;  // screen pixels: y runs down, view y up
        vec3 d = vec3(cp, sp, 0.0);
        vec3 od = d - dot(d, v) * v;
        vec3 ax = normalize(cross(od, v));
        vec3 np = n - ax * dot(n, ax);
        float np_len = length(np);
        float cos_g = np_len > 0.0 ? clamp(dot(np, v) / np_len, 0.0, 1.0) : 1.0;
        float gamma = sign(dot(od, np)) * acos(cos_g);
        float low0 = cos(gamma + GTAO_HALF_PI), low1 = cos(gamma - GTAO_HALF_PI);
        float hc0 = gtao_side_horizon(px, c, v, omega, sl, noise.y, min_s, 1, low0, taken);
        float hc1 = gtao_side_horizon(px, c, v, omega, sl, noise.y, min_s, -1, low1, taken);
        if (u_gtao_heuristics != 0)
            np_len += (1.0 - np_len) * GTAO_SLOPE_FUDGE;
        float h0 = -acos(clamp(hc1, -1.0, 1.0));
        float h1 = acos(clamp(hc0, -1.0, 1.0));
        h0 = gamma + max(h0 - gamma, -GTAO_HALF_PI);   // Algorithm 1: clamped to n's hemisphere
        h1 = gamma + min(h1 - gamma, GTAO_HALF_PI);
        vis += np_len * (gtao_arc(h0, gamma, cos_g) + gtao_arc(h1, gamma, cos_g));
        gtao_bent_slice(h0, h1, gamma, np_len, od, v); // OBS_OUTPUT_BENT (method.glsl)
    }
    vis /= float(u_gtao_slices);
    vis = pow(max(vis, 0.0), u_gtao_thin_power.y);
    if (u_gtao_heuristics != 0)
        vis = max(vis, GTAO_MIN_VISIBILITY);
    count = taken;
    return clamp(vis, 0.0, 1.0);
}
