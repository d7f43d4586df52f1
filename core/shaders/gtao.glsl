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
// Deep input with intervals (deep.frag.glsl): GT_INTERVALS 1 and
// GT_END(q, k) node k's interval end (obs__deep_intervals): each slice's
// visibility over its free arcs (C twin: methods/gtao_deep.c).
#ifndef GT_INTERVALS
#define GT_INTERVALS 0
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

float gtao_arc(float h, float gamma, float cos_gamma)
{
    return (cos_gamma + 2.0 * h * sin(gamma) - cos(2.0 * h - gamma)) / 4.0;
}

#if GT_INTERVALS
// The sides of the slice (side 0: dir +1): their occupied arcs, angles
// from v sorted by their near end, and the free depth ranges of the last
// column read with the cosines of their ends' angles (gt_t).
// C twin: obs__gtao_side (methods/gtao_deep.h); GT_MAX_GAPS and
// GT_MAX_ARCS are OBS__GTAO_MAX_GAPS and OBS__GTAO_MAX_ARCS for 8 nodes
// and 32 steps.
//
// The cost.  Most columns add no arc (gtao_deep.c's cost comment), and the
// arcs, as the C twin's, wait for a column that adds one: its angles are
// kept as cosines until then (gtao_cos_v).  A GL implementation without
// branches (llvmpipe runs the pixels of a block together, each branch
// for all of them under a mask) pays for every line a pixel could run,
// so what the C twin takes where first needed (a column's ray, u_z,
// window) stays taken once a column here, and the work of an added arc
// (three acos, the sorted insertion) is done once, at the column's end
// (gtao_add_reached), rather than at each of its call sites; a step past
// the border reads the same gtao_column call as one inside
// (gtao_side_horizon).  Measured on llvmpipe: bench/RESULTS.md, "gtao on
// deep intervals on llvmpipe".
const int GT_MAX_GAPS = 5;
const int GT_MAX_ARCS = 32 * 13;
float gt_lo[2 * GT_MAX_ARCS], gt_hi[2 * GT_MAX_ARCS];
int gt_n[2], gt_gaps[2];
vec2 gt_win[2]; // the cosines of the angles where the last column's ray lies within the radius
vec2 gt_z[2 * GT_MAX_GAPS], gt_t[2 * GT_MAX_GAPS];

// C twin: obs__gtao_side_start
void gtao_side_start(int side, vec3 c, float z0)
{
    gt_n[side] = 0;
    gt_gaps[side] = 1;
    gt_win[side] = vec2(1.0, -1.0); // the angles 0 and pi
    gt_z[side * GT_MAX_GAPS] = vec2(min(z0, -c.z), -c.z);
    gt_t[side * GT_MAX_GAPS] = vec2(1.0, -1.0);
}

// The cosine of the angle of d from v, clamped; low where d is 0.  C
// twin: cos_v (methods/gtao_deep.c) and its clamp.  A column's angles
// are kept as these cosines until an arc is added, as the C twin keeps
// them: acos is decreasing, so the larger of two angles is the arc
// cosine of the smaller cosine, and a clip that leaves an arc empty is
// seen on the cosines.
float gtao_cos_v(vec3 d, vec3 v, float low)
{
    float dist = length(d);
    return clamp(dist > 0.0 ? dot(d, v) / dist : low, -1.0, 1.0);
}

// The depths of the ray o + s dir where the falloff weight is not 0
// (within R = -u_gtao_falloff.y / u_gtao_falloff.x of c, z scaled by
// 1 + gtao_thin); false where it passes outside.  C twin: chord
// (methods/gtao_deep.c)
bool gtao_chord(vec3 o, vec3 dir, vec3 c, out vec2 s)
{
    float k = 1.0 + u_gtao_thin_power.x, r = -u_gtao_falloff.y / u_gtao_falloff.x;
    vec3 a3 = vec3((o - c).xy, (o.z - c.z) * k), d3 = vec3(dir.xy, dir.z * k);
    float a = dot(d3, d3), b = dot(a3, d3), disc = b * b - a * (dot(a3, a3) - r * r);
    s = vec2(0.0);
    if (!(disc > 0.0) || !(a > 0.0))
        return false;
    s = (vec2(-b) + vec2(-1.0, 1.0) * sqrt(disc)) / a;
    return true;
}

// C twin: add_arc (methods/gtao_deep.c)
void gtao_add_arc(int side, float lo, float hi)
{
    if (!(hi > lo))
        return;
    int base = side * GT_MAX_ARCS, i = gt_n[side];
    if (i == GT_MAX_ARCS) {
        gt_lo[base + i - 1] = min(gt_lo[base + i - 1], lo);
        gt_hi[base + i - 1] = max(gt_hi[base + i - 1], hi);
        return;
    }
    for (; i > 0 && gt_lo[base + i - 1] > lo; i--) {
        gt_lo[base + i] = gt_lo[base + i - 1];
        gt_hi[base + i] = gt_hi[base + i - 1];
    }
    gt_lo[base + i] = lo;
    gt_hi[base + i] = hi;
    gt_n[side]++;
}

// A column's arcs, found by gtao_reach and added at its end in the order
// found (gtao_add_reached): the arc cosines [x, y] clipped to the window,
// z the cosine of the half width of the band's reach (-1: c at the
// band's depths, no reach clip), w its middle.  At most a call per node
// and per pair of free ranges.
const int GT_MAX_REACHED = 8 + GT_MAX_GAPS * GT_MAX_GAPS;
vec4 gt_reached[GT_MAX_REACHED];
int gt_nreached;

// The arc of a solid met between the previous column and this one, the
// angles whose cosines are [clo, chi] (clo >= chi), where it can lie
// within the radius r: the window's clip, then the depths [zlo, zhi]
// reached from the centre's depth cz (uz: u_z(t) = uz.x cos(t - uz.y)).
// C twin: add_reach (methods/gtao_deep.c), which adds it at once; here
// it waits in gt_reached for gtao_add_reached (the cost, above).
void gtao_reach(int side, float clo, float chi, float zlo, float zhi, float cz, float r, vec2 uz)
{
    clo = min(clo, gt_win[side].x);
    chi = max(chi, gt_win[side].y);
    if (!(chi < clo))
        return;
    float dz = cz < zlo ? zlo - cz : cz > zhi ? cz - zhi : 0.0;
    vec4 a = vec4(clo, chi, -1.0, 0.0);
    if (dz > 0.0) {
        if (!(uz.x * r > dz))
            return;
        a.zw = vec2(dz / (r * uz.x), cz > zhi ? uz.y : uz.y + 3.14159265358979);
    }
    gt_reached[gt_nreached++] = a;
}

// Adds the column's arcs (gtao_reach) in the order found, as the C twin
// adds them: the same sorted arcs
void gtao_add_reached(int side)
{
    for (int j = 0; j < gt_nreached; j++) {
        vec4 a = gt_reached[j];
        float lo = acos(a.x), hi = acos(a.y);
        bool reach = a.z >= 0.0;
        float half_w = reach ? acos(a.z) : 0.0;
        for (int i = -1; i <= 1; i++) {
            float m = a.w + 6.28318530717959 * float(i);
            if (reach)
                gtao_add_arc(side, max(lo, m - half_w), min(hi, m + half_w));
            else if (i == 0)
                gtao_add_arc(side, lo, hi);
        }
    }
}

// C twin: obs__gtao_centre_start (methods/gtao_deep.c), for the receiver
// node g_self (deep.frag.glsl)
float gtao_centre_start(ivec2 px)
{
    float z0 = 0.0;
    for (int k = 0; k < g_self; k++) {
        float w = GT_NODE(px, k).w, e = GT_END(px, k);
        if (w > 0.0 && e >= 0.0)
            z0 = max(z0, e > 0.0 ? e : w);
    }
    return z0;
}

// The column of the step at q (border: the one point xq past the image
// instead, solid behind it).  C twin: obs__gtao_column (methods/gtao_deep.c)
float gtao_column(int side, ivec2 px, ivec2 q, bool border, vec4 xq, vec3 c, vec3 v, float low)
{
    vec2 gz[GT_MAX_GAPS], gt[GT_MAX_GAPS]; // gt: cosines
    float hc = low, cz = 0.0, ct = 1.0; // the free range open from depth cz (angle 0)
    int ng = 0, last = -1, layers = border ? 1 : GT_LAYERS;
    bool open = true;
    vec3 o, dir;
    vec2 cs;
    view_ray(px_ndc(q), o, dir);
    bool near = gtao_chord(o, dir, c, cs);
    float r = -u_gtao_falloff.y / u_gtao_falloff.x, cz0 = -c.z;
    vec2 uz = vec2(0.0);
    vec3 pc = o + cz0 * dir - c;
    vec3 od = pc - dot(pc, v) * v;
    float ol = length(od);
    if (ol > 0.0)
        uz = vec2(sqrt(v.z * v.z + od.z * od.z / (ol * ol)), atan(od.z / ol, v.z));
    gt_nreached = 0;
    int tail = -1;
    for (int k = 0; k < layers; k++) {
        vec4 qk = border ? xq : GT_NODE(q, k);
        if (qk.w > 0.0) {
            tail = k;
            if (!(!border && GT_END(q, k) < 0.0))
                last = k;
        }
    }
    if (!border && tail >= 0 && GT_END(q, tail) < -1.5) // the list was cut behind it
        last = -1;
    for (int k = 0; k < layers; k++) {
        vec4 qk = border ? xq : GT_NODE(q, k);
        float e = border || k == last ? 0.0 : GT_END(q, k);
        if (!(qk.w > 0.0) || e < 0.0)
            continue;
        vec3 d = qk.xyz - c;
        if (e == 0.0)
            hc = max(hc, gtao_sample_cos(qk, c, v, low, GT_WEIGHT(px, q, border ? 0 : k)));
        if (!open)
            continue;
        float tf = gtao_cos_v(d, v, low);
        if (qk.w > cz && ng < GT_MAX_GAPS) {
            gz[ng] = vec2(cz, qk.w);
            gt[ng] = vec2(ct, tf);
            ng++;
        }
        if (e == 0.0) {
            open = false;
            continue;
        }
        cz = e;
        ct = gtao_cos_v(o + e * dir - c, v, low);
        if (GT_WEIGHT(px, q, k) > 0.0)
            gtao_reach(side, tf, ct, qk.w, e, cz0, r, uz);
    }
    if (open && ng < GT_MAX_GAPS) {
        gz[ng] = vec2(cz, uintBitsToFloat(0x7f800000u)); // no surface from cz on
        gt[ng] = vec2(ct, -1.0); // the angle pi
        ng++;
    }
    int base = side * GT_MAX_GAPS;
    for (int a = 0; a < gt_gaps[side]; a++) {
        vec2 za = gt_z[base + a], ta = gt_t[base + a];
        for (int b = 0; b < ng; b++) {
            if (za.x < gz[b].y && gz[b].x < za.y)
                continue;
            bool before = za.y <= gz[b].x;
            // the angles both ranges' arcs hold: on the cosines, the
            // smaller start and the larger end
            gtao_reach(side, min(ta.x, gt[b].x), max(ta.y, gt[b].y), before ? za.y : gz[b].y,
                       before ? gz[b].x : za.x, cz0, r, uz);
        }
    }
    gtao_add_reached(side);
    gt_win[side] = vec2(1.0);
    if (near && cs.y > 0.0)
        gt_win[side] = vec2(gtao_cos_v(o + max(cs.x, 0.0) * dir - c, v, low),
                            gtao_cos_v(o + cs.y * dir - c, v, low));
    gt_gaps[side] = ng;
    for (int b = 0; b < ng; b++) {
        gt_z[base + b] = gz[b];
        gt_t[base + b] = gt[b];
    }
    return hc;
}

// C twin: side_free (methods/gtao_deep.c)
float gtao_side_free(int side, float h, float s, float gamma, float cos_g)
{
    int n = gt_n[side], base = side * GT_MAX_ARCS;
    if (n == 0)
        return gtao_arc(h, gamma, cos_g);
    float end = s * h, cur = 0.0, sum = 0.0;
    for (int i = 0; i <= n; i++) {
        float lo = end, hi = end;
        if (i < n) {
            float a = gt_lo[base + i], b = gt_hi[base + i];
            lo = s > 0.0 ? gamma + min(a - gamma, GTAO_HALF_PI) : gamma + max(-a - gamma, -GTAO_HALF_PI);
            hi = s > 0.0 ? gamma + min(b - gamma, GTAO_HALF_PI) : gamma + max(-b - gamma, -GTAO_HALF_PI);
            lo = min(s * lo, end);
            hi = s * hi;
        }
        if (lo > cur)
            sum += gtao_arc(s * lo, gamma, cos_g) - (cur > 0.0 ? gtao_arc(s * cur, gamma, cos_g) : 0.0);
        cur = max(cur, hi);
        if (cur >= end)
            break;
    }
    return sum;
}
#endif

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
        bool off = q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y;
#if GT_INTERVALS
        // intervals: the step's column (C twin: obs__gtao_column); past
        // the border the surface continued, solid behind it (xq.w 0: a
        // column with no surface).  One call for both (the cost, at
        // GT_INTERVALS' sides above).
        vec4 xq = vec4(0.0);
        bool got = off && gtao_border_step(px, q, xq);
        float hq = gtao_column(dir > 0 ? 0 : 1, px, q, off, got ? xq : vec4(0.0), c, v, low);
        if (off) {
            if (!got)
                continue;
            taken++;
            hc = max(hc, gtao_sample_cos(xq, c, v, low, GT_WEIGHT(px, q, 0)));
            continue;
        }
        taken++;
        hc = max(hc, hq);
#else
        if (off) {
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
#endif
    }
    return hc;
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
#if GT_INTERVALS
        float z0 = gtao_centre_start(px);
        gtao_side_start(0, c, z0);
        gtao_side_start(1, c, z0);
#endif
        float hc0 = gtao_side_horizon(px, c, v, omega, sl, noise.y, min_s, 1, low0, taken);
        float hc1 = gtao_side_horizon(px, c, v, omega, sl, noise.y, min_s, -1, low1, taken);
        if (u_gtao_heuristics != 0)
            np_len += (1.0 - np_len) * GTAO_SLOPE_FUDGE;
        float h0 = -acos(clamp(hc1, -1.0, 1.0));
        float h1 = acos(clamp(hc0, -1.0, 1.0));
        h0 = gamma + max(h0 - gamma, -GTAO_HALF_PI);   // Algorithm 1: clamped to n's hemisphere
        h1 = gamma + min(h1 - gamma, GTAO_HALF_PI);
#if GT_INTERVALS
        vis += np_len * (gtao_side_free(1, h0, -1.0, gamma, cos_g) + gtao_side_free(0, h1, 1.0, gamma, cos_g));
#else
        vis += np_len * (gtao_arc(h0, gamma, cos_g) + gtao_arc(h1, gamma, cos_g));
#endif
        gtao_bent_slice(h0, h1, gamma, np_len, od, v); // OBS_OUTPUT_BENT (method.glsl)
    }
    vis /= float(u_gtao_slices);
    vis = pow(max(vis, 0.0), u_gtao_thin_power.y);
    if (u_gtao_heuristics != 0)
        vis = max(vis, GTAO_MIN_VISIBILITY);
    count = taken;
    return clamp(vis, 0.0, 1.0);
}
