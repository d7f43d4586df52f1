// Method hbao: horizon-based ambient occlusion (Bavoil, Sainz, Dimitrov,
// SIGGRAPH 2008):
//   AO = 1 - 1/(2 pi) Int (sin h(theta) - sin t(theta)) W(theta) dtheta,
// per-sample attenuation W(r) = 1 - r^2 / R^2.  C twin: obs__hbao_pixel
// (methods/hbao.c), which documents the method.

uniform int u_hbao_dirs;         // Nd
uniform int u_hbao_steps;        // Ns
uniform vec2 u_hbao_dir[OBS_MAX_DIRECTIONS];     // unit directions over 2 pi (view xy)
uniform vec2 u_hbao_bias_cs;     // cos, sin of the angle bias

// The planes the horizon search reads: the flat chain's (method.glsl);
// the deep pass (deep.frag.glsl) defines them for its nodes: HB_LAYERS
// nodes at a pixel, HB_NODE(q, k) node k's view position, planar depth.
#ifndef HB_LAYERS
#define HB_LAYERS 1
#define HB_NODE(q, k) imageLoad(u_pos, q)
#define HB_BENT 1 // the flat chain's bent normal (method.glsl's g_bent); not the deep pass's
#endif
// The object masks' weight of node k at q for the receiver at px (the
// flat chain: occluder_weight, common.glsl; the deep pass defines it).
#ifndef HB_WEIGHT
#define HB_WEIGHT(c, q, k) occluder_weight(c, q)
#endif

// OBS_OUTPUT_BENT (method.glsl's g_bent): the solid-angle sum of the
// directions cos a e + sin a z over the elevations asin(sin0)..asin(sin1)
// along e = (dx, dy), times w.  C twin: obs__hbao_bent_span
// (methods/bent.c), which derives it.
void hbao_bent_span(float dx, float dy, float sin0, float sin1, float w)
{
#ifdef HB_BENT
    float a0 = asin(clamp(sin0, -1.0, 1.0)), a1 = asin(clamp(sin1, -1.0, 1.0));
    float along = (a1 - a0) * 0.5 + (sin(2.0 * a1) - sin(2.0 * a0)) * 0.25;
    g_bent += w * vec3(along * dx, along * dy, (sin1 * sin1 - sin0 * sin0) * 0.5);
#endif
}

// One sample point xq of a direction e = (dx, dy) from p: where it rises
// above the horizon sin_h, W(r) times the rise into ao, and the occluded
// span taken from the bent normal; all times om, the object masks' weight
// of its pixel (0: no horizon raised).  C twin: hbao_sample.
void hbao_sample(vec4 xq, vec3 p, float R2, float om, inout float sin_h, inout float ao, float dx,
                 float dy)
{
    if (!(xq.w > 0.0))
        return;
    vec3 v = xq.xyz - p;
    float r2 = v.x * v.x + v.y * v.y + v.z * v.z;
    if (!(r2 < R2) || !(r2 > 0.0))
        return;
    float sin_s = v.z / sqrt(r2);
    if (sin_s > sin_h && om > 0.0) {
        ao += om * (1.0 - r2 / R2) * (sin_s - sin_h);   // W(r_i) (sin h_i - sin h_(i-1))
        hbao_bent_span(dx, dy, sin_h, sin_s, -om * (1.0 - r2 / R2)); // less the occluded step
        sin_h = sin_s;
    }
}

float method_ao(ivec2 px, vec4 p, vec3 n, out int count)
{
    float R = u_radius, R2 = R * R;
    vec2 rot = u_rot[tile_index(px)];
    float rpx = radius_px(p.xyz, R);
    count = 0;
    if (!(rpx >= 1.0))
        return 1.0;                       // the kernel reaches no other pixel
    int ns = min(u_hbao_steps, int(rpx));
    float stp = rpx / float(ns + 1);
    float ao = 0.0;
    for (int d = 0; d < u_hbao_dirs; d++) {
        vec2 e = u_hbao_dir[d];
        float dx = rot.x * e.x - rot.y * e.y, dy = rot.y * e.x + rot.x * e.y;
        // t(theta) + angle bias, by its sine and cosine
        float nd = n.x * dx + n.y * dy, nz = max(n.z, 0.0);
        float l = sqrt(nd * nd + nz * nz);
        float st = l > 0.0 ? -nd / l : 0.0, ct = l > 0.0 ? nz / l : 1.0;
        float sin_h = st * u_hbao_bias_cs.x + ct * u_hbao_bias_cs.y;
        if (ct * u_hbao_bias_cs.x - st * u_hbao_bias_cs.y < 0.0)
            sin_h = 1.0;
        hbao_bent_span(dx, dy, sin_h, 1.0, 1.0);   // open from the tangent up to the view axis
        for (int j = 1; j <= ns; j++) {
            ivec2 q = px + ivec2(int(floor(dx * stp * float(j) + 0.5)),
                                 int(floor(-dy * stp * float(j) + 0.5)));
            if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y)
                break;
            count++;
            for (int k = 0; k < HB_LAYERS; k++)   // deep input: every node
                hbao_sample(HB_NODE(q, k), p.xyz, R2, HB_WEIGHT(px, q, k), sin_h, ao, dx, dy);
        }
    }
    return max(0.0, 1.0 - ao / float(u_hbao_dirs));
}
