// Culling pre-pass (VAO++ section 4.2): "We first calculate AO in a lower
// resolution texture (we use 1/8 resolution of the final image) to
// estimate areas where AO occurs ... We also always use 8 samples for this
// pass."  Texel (i, j) is the 8-sample AO (vao.glsl, range check included,
// no adaptive sampling) of the 8 x 8 block's centre pixel (8i + 4, 8j + 4),
// clamped into a partial last block; 1 for background.  The AO pass reads
// it with GL_LINEAR at the pixel corners (cull_candidate in vao.frag.glsl).
// C twin: obs__cull_prepass (cull_cpu.c).

out float o_est;

void main()
{
    ivec2 px = min(ivec2(gl_FragCoord.xy) * OBS_CULL_BLOCK + OBS_CULL_BLOCK / 2, u_size - 1);
    vec4 p = imageLoad(u_pos, px);
    vec3 unused;                // no colour bleeding in the pre-pass
    o_est = p.w > 0.0 ? vao_estimate(px, p, imageLoad(u_vnormal, px).xyz, OBS_CULL_SAMPLES, 0, unused) : 1.0;
}
