// AO pass: the volumetric AO of every pixel (the estimator is in
// vao.glsl), with the sample count of adaptive sampling (section 4.1) and
// the culling test of the pre-pass (section 4.2).  C twin: obs_run_cpu's
// AO loop (obs__vao_count, obs__cull_candidate, obs__vao_estimate).

// OBS_ADAPTIVE and OBS_CULLING (0 or 1) are defined by the program (see
// run_gl.c): with 0 the stage is compiled out.
// u_count, u_adaptive_k, u_culling, u_cull_size, u_cull_threshold,
// u_bleed_step: the Frame block (common.glsl)
layout(r32f) readonly uniform image2D u_cull; // the pre-pass's 1/8-resolution AO

layout(location = 0) out vec2 o_ao;    // AO, planar depth (for the blur)
layout(location = 1) out float o_count; // samples taken (debug output)
layout(location = 2) out float o_cull;  // 1: culling candidate (debug output)
layout(location = 3) out vec4 o_bleed;  // section 4.7: the colour-bleed term
layout(location = 4) out vec4 o_bent;   // the bent normal's sum (vao.glsl's g_bent)

// Adaptive sampling, section 4.1: "double the number of samples every time
// surface area of the sampling disc doubles", 2 samples for a disk of
// diameter D0 (a fraction of the image height).  The disk c + (dx, dy, 0),
// |(dx, dy)| <= r, has in NDC the Jacobian at c
//   J = [[P00 w - X P30, P01 w - X P31], [P10 w - Y P30, P11 w - Y P31]] / w^2,
// (X, Y, w) the clip coordinates of c, and the area pi r^2 |det J| (exact
// for perspective and orthographic cameras: affine at fixed view z).  The
// diameter D of the disk of that area in pixels, as a fraction of vh, has
// D^2 = r^2 |det J| vw / vh; the area ratio q = D^2 / D0^2.  Count: 2 for
// q < 2, 4 for 2 <= q < 4, ..., at most u_count.  C twin:
// obs__adaptive_count.
int adaptive_count(vec3 c)
{
    float w = PM(3, 0) * c.x + PM(3, 1) * c.y + PM(3, 2) * c.z + PM(3, 3);
    if (!(w > 0.0))
        return u_count;
    float X = PM(0, 0) * c.x + PM(0, 1) * c.y + PM(0, 2) * c.z + PM(0, 3);
    float Y = PM(1, 0) * c.x + PM(1, 1) * c.y + PM(1, 2) * c.z + PM(1, 3);
    float w2 = w * w;
    float j00 = (PM(0, 0) * w - X * PM(3, 0)) / w2, j01 = (PM(0, 1) * w - X * PM(3, 1)) / w2;
    float j10 = (PM(1, 0) * w - Y * PM(3, 0)) / w2, j11 = (PM(1, 1) * w - Y * PM(3, 1)) / w2;
    float r = 0.5 * u_radius;
    float q = r * r * abs(j00 * j11 - j01 * j10) * u_adaptive_k;
    int n = 2;
    while (n < u_count && q >= float(n))
        n *= 2;
    return n;
}


// Culling pre-pass, section 4.2: "Checking for estimated occlusion in the
// second pass is done via four texel fetches from downsized AO texture in
// given pixel corners.  Texture interpolation mode is set to linear ...
// When at least one of these pixels exhibits occlusion, we calculate full
// AO - otherwise the pixel is a candidate for culling."  The four linear
// fetches are done here from four image loads: a corner c (integers, in
// pixels) lies at texel coordinate c / 8 - 0.5, so the corners px and
// px + 1 share the 2 x 2 texels around the first one.  Only where px + 1
// sits on a texel's centre (weight 1 on the next texel: t0 + 1 exactly)
// does it reach past them, and there GL_LINEAR gives that texel itself.
// Same filtering (lerp as fma, clamped to the edge) as llvmpipe's
// sampler; on llvmpipe the sampler's four fetches took ~18 ms of the AO
// pass at 1080p (bench/RESULTS.md).  C twin: obs__cull_candidate,
// obs__cull_fetch (cull_cpu.c).
float cull_texel(ivec2 t)
{
    return imageLoad(u_cull, clamp(t, ivec2(0), u_cull_size - ivec2(1))).r;
}

bool cull_candidate(ivec2 px)
{
    ivec2 t0 = ivec2(floor(vec2(px) * (1.0 / float(OBS_CULL_BLOCK)) - 0.5));
    float t00 = cull_texel(t0), t10 = cull_texel(t0 + ivec2(1, 0));
    float t01 = cull_texel(t0 + ivec2(0, 1)), t11 = cull_texel(t0 + ivec2(1, 1));
    for (int k = 0; k < 4; k++) {
        vec2 w = vec2(px + ivec2(k & 1, k >> 1)) * (1.0 / float(OBS_CULL_BLOCK)) - 0.5 - vec2(t0); // in [0, 1]
        float top = w.x < 1.0 ? fma(w.x, t10 - t00, t00) : t10;
        float bottom = w.x < 1.0 ? fma(w.x, t11 - t01, t01) : t11;
        float est = w.y < 1.0 ? fma(w.y, bottom - top, top) : bottom;
        if (est < u_cull_threshold)
            return false;
    }
    return true;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = imageLoad(u_pos, px);
    o_cull = 0.0;
    o_bleed = vec4(1.0);
    o_bent = vec4(0.0);
    g_bent = vec3(0.0);
    if (p.w <= 0.0) {
        o_ao = vec2(1.0, 0.0);
        o_count = 0.0;
        return;
    }
    vec3 n = imageLoad(u_vnormal, px).xyz;
    // Section 4.1: the pixel's set, by its offset in the one array of sets.
#if OBS_ADAPTIVE
    int ns = adaptive_count(p.xyz + n * (0.5 * u_radius));
#else
    int ns = u_count;
#endif
#if OBS_CULLING
    // Section 4.2: a culling candidate gets AO 1 (greedy) or at most the
    // 4-sample set (careful: "calculates occlusion with 4 samples in areas
    // where no AO is estimated"; never more than the pixel would take).
    if (cull_candidate(px)) {
        o_cull = 1.0;
        ns = u_culling == 1 ? 0 : min(ns, OBS_CULL_CAREFUL);
    }
#endif
    o_count = float(ns);
    vec3 bleed = vec3(1.0);
    o_ao = vec2(ns > 0 ? vao_estimate(px, p, n, ns, u_bleed_step, bleed) : 1.0, p.w);
    o_bleed = vec4(bleed, 1.0);
    // nothing open or nothing sampled: the normal (C twin: vao_bent in passes_cpu.c)
    o_bent = vec4(g_bent == vec3(0.0) ? n : g_bent, 0.0);
}
