// Prep pass: view-space position (xyz, planar depth in w) and view-space
// unit normal of every pixel (prep.glsl).  C twin: obs__prep_position/_normal.
//
// OBS_HALF 1 (ao_resolution half): drawn over the half frame, with the
// full frame's block bound; half pixel (x, y) takes the prep of one whole
// pixel of its 2x2 block, never an average: the nearest with a surface
// where x + y is even, the farthest where it is odd (half_cpu.c says why).
// That is the full prep planes' downsample, without computing the full
// planes.  C twin: obs__half_source in half_cpu.c.

#if OBS_HALF
// Object masks at half resolution (u_mask_on, u_mask_w, u_mask_id of
// common.glsl: the full frame's): each half pixel gets those of the pixel
// whose prep it takes, for the AO pass at half size.  C twin:
// obs__half_masks in half_cpu.c.
layout(r32f) writeonly uniform image2D u_hmask_w;
layout(r32f) writeonly uniform image2D u_hmask_id;
#endif

layout(location = 0) out vec4 o_pos;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec2 o_dz;     // planar depth and n.z: what the samples read

void main()
{
#if OBS_HALF == 0
    ivec2 p = ivec2(gl_FragCoord.xy);
#else
    ivec2 hp = ivec2(gl_FragCoord.xy);
    bool nearest = ((hp.x + hp.y) & 1) == 0;
    ivec2 p = 2 * hp; // all background: the block's first pixel
    float best_z = 0.0;
    bool found = false;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            ivec2 q = 2 * hp + ivec2(i, j);
            if (q.x >= u_size.x || q.y >= u_size.y)
                continue;
            float z = position_at(q).w;
            if (z <= 0.0)
                continue;
            if (!found || (nearest ? z < best_z : z > best_z)) {
                found = true;
                p = q;
                best_z = z;
            }
        }
    // the weight and the self_only test read the surface whose depth this
    // half pixel keeps (p), never a neighbour's across an edge
    if ((u_mask_on & 1) != 0)
        imageStore(u_hmask_w, hp, imageLoad(u_mask_w, p));
    if ((u_mask_on & 2) != 0)
        imageStore(u_hmask_id, hp, imageLoad(u_mask_id, p));
#endif
    vec4 c;
    vec3 n;
    prep_pixel(p, c, n);
    o_pos = c;
    o_normal = vec4(n, 0.0);
    o_dz = vec2(c.w, n.z);
}
