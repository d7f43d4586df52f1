// Low-pass filter (VAO++ section 4.6): a depth-aware cross-bilateral
// Gaussian blur of the AO, run twice, along x and then along y, as if it
// were separable.  Neighbours whose linear view depth differs from the
// centre's by more than the AO radius are left out, so occlusion does not
// bleed across depth edges.  C twin: obs__blur_pixel in blur_cpu.c.

uniform sampler2D u_ao;          // AO to filter
uniform sampler2D u_dz;          // prep: planar depth in x
uniform ivec2 u_size;
uniform ivec2 u_dir;             // (1, 0) horizontal pass, (0, 1) vertical
uniform int u_blur_radius;       // half-width in pixels
uniform float u_blur_w[17];      // Gaussian weight of offset 0..radius
uniform float u_radius;          // depth threshold: the AO radius R

out float o_ao;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float a = texelFetch(u_ao, px, 0).r;
    float zc = texelFetch(u_dz, px, 0).x;
    if (zc <= 0.0) {            // background: nothing to filter
        o_ao = a;
        return;
    }
    float sum = 0.0, wsum = 0.0;
    for (int k = -u_blur_radius; k <= u_blur_radius; k++) {
        ivec2 q = px + k * u_dir;
        if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y)
            continue;
        float zq = texelFetch(u_dz, q, 0).x;
        // section 4.6: leave out neighbours over the depth threshold
        if (zq <= 0.0 || abs(zq - zc) > u_radius)
            continue;
        float w = u_blur_w[abs(k)];
        sum += w * texelFetch(u_ao, q, 0).r;
        wsum += w;
    }
    o_ao = sum / wsum;          // the centre always counts: wsum > 0
}
