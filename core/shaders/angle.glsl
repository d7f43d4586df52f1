// Method angle: angle-based paired-sample SSAO
// (shared/papers/angle-based-ssao.txt).  C twin: obs__angle_pixel
// (methods/angle.c), which documents the method.

uniform int u_angle_pairs;       // sample pairs
uniform vec2 u_angle_xy[OBS_MAX_PAIRS];     // pair offsets on the unit disk (obs__angle_pattern)
uniform int u_angle_acos;        // 1 quadratic, 2 linear, 3 exact (obs_acos)

const float PI = 3.14159265358979;

// The article's arc cosine approximations: linear pi (1 - x) / 2,
// quadratic pi (1 - sign(x) x^2) / 2.  C twin: obs__acos_mode.
float acos_mode(int mode, float x)
{
    x = min(1.0, max(-1.0, x));
    if (mode == 3)
        return acos(x);
    if (mode == 2)
        return PI * (1.0 - x) * 0.5;
    return PI * (1.0 - (x >= 0.0 ? x * x : -x * x)) * 0.5;
}

// theta: the angle between n and v (pi/2 for v = 0)
float angle_to_normal(vec3 n, vec3 v)
{
    float l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    float c = l > 0.0 ? (n.x * v.x + n.y * v.y + n.z * v.z) / l : 0.0;
    return acos_mode(u_angle_acos, c);
}

// OBS_OUTPUT_BENT (method.glsl's g_bent): one side of a pair, the open
// arc from n to u's side, theta long, weighted alike in angle:
// sin theta n + (1 - cos theta) t, times the pair's weight.  C twin:
// obs__angle_bent_side (methods/bent.c), which derives it.
void angle_bent_side(vec3 n, vec3 u, float theta, float w)
{
    vec3 t = u - dot(u, n) * n;
    float l = length(t);
    g_bent += w * (sin(theta) * n + (l > 0.0 ? (1.0 - cos(theta)) / l : 0.0) * t);
}

float method_ao(ivec2 px, vec4 p, vec3 n, out int count)
{
    float R = u_radius;
    vec2 rot = u_rot[tile_index(px)];
    float sum = 0.0, wsum = 0.0;
    count = 2 * u_angle_pairs;
    for (int i = 0; i < u_angle_pairs; i++) {
        vec2 a = u_angle_xy[i];
        float ox = R * (rot.x * a.x - rot.y * a.y), oy = R * (rot.y * a.x + rot.x * a.y);
        vec3 v[2];
        float far[2];
        for (int k = 0; k < 2; k++) {
            float sg = k == 0 ? 1.0 : -1.0;
            vec3 s = vec3(p.x + sg * ox, p.y + sg * oy, p.z);
            ivec2 q;
            vec4 xq = vec4(0.0);
            if (view_to_px(s, u_size, q))
                xq = imageLoad(u_pos, q);
            if (!(xq.w > 0.0)) {          // off the image or background: far
                v[k] = vec3(0.0);
                far[k] = 1.0;
                continue;
            }
            v[k] = xq.xyz - p.xyz;
            // "too far away": a depth difference over R, fully from 2R
            far[k] = min(1.0, max(0.0, abs(xq.w - p.w) / R - 1.0));
            // object masks: a surface that may not occlude counts as far
            far[k] += (1.0 - far[k]) * (1.0 - occluder_weight(px, q));
        }
        // pair weight 1 / 0.5 / 0 for none / one / both far
        float w = 1.0 - 0.5 * (far[0] + far[1]);
        if (!(w > 0.0))
            continue;
        // a far sample moves towards the coplanar point 2p - x_other
        vec3 u0 = v[0] + far[0] * (-v[1] - v[0]);
        vec3 u1 = v[1] + far[1] * (-v[0] - v[1]);
        float th0 = angle_to_normal(n, u0), th1 = angle_to_normal(n, u1);
        float th = th0 + th1;
        angle_bent_side(n, u0, th0, w);
        angle_bent_side(n, u1, th1, w);
        sum += w * min(th / PI, 1.0);     // min((theta_l + theta_r) / pi, 1)
        wsum += w;
    }
    return wsum > 0.0 ? sum / wsum : 1.0;
}
