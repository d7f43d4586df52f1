// ao_resolution half, the upsample: the full-resolution AO from the half
// one by a joint bilateral filter guided by the full planes.  The four
// half pixels around the pixel's centre, each weighted by its bilinear
// weight times max(0, n . n_q); one without a surface, or whose planar
// depth is more than R from the pixel's (the blur's threshold, section
// 4.6), is left out; when all are, the one nearest in depth gives its AO.
// Drawn over the full frame with its block bound; the pixel's own depth
// and normal come from the raw planes through prep.glsl (the prep pass
// ran at half size only).  OBS_RAYS (0 or 1, defined by the program): the
// result converted for ao_definition rays, as the blur's vertical pass
// does at full resolution; OBS_RECONSTRUCT and OBS_DEPTH_MODE: as for the
// prep pass.  C twin: obs__half_upsample in half_cpu.c (the conversion:
// run_cpu.c).

layout(rgba32f) readonly uniform image2D u_hnormal; // half planes (prep.frag.glsl, OBS_HALF)
layout(rg32f) readonly uniform image2D u_hao;       // half AO after the blur, planar depth
uniform ivec2 u_half_size;

out vec2 o_ao;                                      // AO, the pixel's planar depth

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 c;
    vec3 n;
    prep_pixel(px, c, n);
    float zp = c.w;
    if (zp <= 0.0) {            // background: what the AO pass writes there
        o_ao = vec2(1.0, zp);
        return;
    }
    // the 2x2 half pixels around the centre; at the border the two inside
    // (half_cpu.c says why)
    float u = (float(px.x) + 0.5) * 0.5 - 0.5, v = (float(px.y) + 0.5) * 0.5 - 0.5;
    int x0 = clamp(int(floor(u)), 0, max(u_half_size.x - 2, 0));
    int y0 = clamp(int(floor(v)), 0, max(u_half_size.y - 2, 0));
    ivec2 d = ivec2(u_half_size.x > 1 ? 1 : 0, u_half_size.y > 1 ? 1 : 0);
    float fx = clamp(u - float(x0), 0.0, 1.0), fy = clamp(v - float(y0), 0.0, 1.0);
    float sum = 0.0, wsum = 0.0, near_ao = 1.0, near_dz = 0.0;
    bool found = false;
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++) {
            ivec2 q = ivec2(x0 + k * d.x, y0 + j * d.y);
            vec2 aq = imageLoad(u_hao, q).rg;
            float a = aq.x, zq = aq.y;
            if (zq <= 0.0)
                continue;
            float dz = abs(zq - zp);
            if (!found || dz < near_dz) {
                found = true;
                near_dz = dz;
                near_ao = a;
            }
            if (dz > u_radius) // section 4.6's threshold
                continue;
            vec3 nq = imageLoad(u_hnormal, q).xyz;
            float c = n.x * nq.x + n.y * nq.y + n.z * nq.z;
            float w = (k == 1 ? fx : 1.0 - fx) * (j == 1 ? fy : 1.0 - fy) * (c > 0.0 ? c : 0.0);
            sum += w * a;
            wsum += w;
        }
    float ao = wsum > 0.0 ? sum / wsum : near_ao;
#if OBS_RAYS
    ao = rays_from_volume(ao); // common.glsl
#endif
    o_ao = vec2(ao, zp);
}
