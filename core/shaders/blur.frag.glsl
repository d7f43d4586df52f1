// Low-pass filter (VAO++ section 4.6): a depth-aware cross-bilateral
// Gaussian blur of the AO, run twice, along x and then along y, as if it
// were separable.  Neighbours whose linear view depth differs from the
// centre's by more than the AO radius are left out, so occlusion does not
// bleed across depth edges.  C twin: obs__blur_pixel in blur_cpu.c.
//
// BLUR_RADIUS, the half-width in pixels, is defined by the program (one
// program per radius, built on first use): a loop of constant length is
// unrolled, which halves the pass's time on llvmpipe (bench/RESULTS.md).
// The AO planes carry the pixel's planar depth beside the AO (rg, written
// by the AO pass and by each blur pass): one image load per tap.
// OBS_RAYS (defined by the program, 0 or 1): the vertical pass converts
// its result for ao_definition rays, so that the conversion costs no pass
// of its own (the finishing pass does it when the blur is off).

layout(rg32f) readonly uniform image2D u_ao; // AO to filter (r), planar depth (g; 0: background)
uniform ivec2 u_dir;             // (1, 0) horizontal pass, (0, 1) vertical
// u_size, u_blur_w (the Gaussian weights), u_radius (the depth threshold,
// the AO radius R): the Frame block (common.glsl)

out vec2 o_ao;                   // blurred AO, the centre's depth

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec2 c = imageLoad(u_ao, px).rg;
    float zc = c.y;
    if (zc <= 0.0) {            // background: nothing to filter
        o_ao = c;
        return;
    }
    float sum = 0.0, wsum = 0.0;
    for (int k = -BLUR_RADIUS; k <= BLUR_RADIUS; k++) {
        ivec2 q = px + k * u_dir;
        if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y)
            continue;
        vec2 aq = imageLoad(u_ao, q).rg;
        // section 4.6: leave out neighbours over the depth threshold
        if (aq.y <= 0.0 || abs(aq.y - zc) > u_radius)
            continue;
        float w = u_blur_w[abs(k)];
        sum += w * aq.x;
        wsum += w;
    }
    float ao = sum / wsum;      // the centre always counts: wsum > 0
#if OBS_RAYS
    ao = rays_from_volume(ao);  // the vertical pass under ao_definition rays (common.glsl)
#endif
    o_ao = vec2(ao, zc);
}
