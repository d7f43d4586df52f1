// ao_resolution half, the downsample: half pixel (x, y) takes the prep
// planes (position, normal, depth and n.z) of one whole pixel of its 2x2
// block of the full planes, never an average: the nearest with a surface
// where x + y is even, the farthest where it is odd (half_cpu.c says why).
// Drawn over the half frame, with the full frame's block bound (u_size:
// the full planes).  C twin: obs__half_source in half_cpu.c.

layout(rgba32f) readonly uniform image2D u_pos;     // full prep planes
layout(rgba32f) readonly uniform image2D u_vnormal;
layout(rg32f) readonly uniform image2D u_dz;

layout(location = 0) out vec4 o_pos;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec2 o_dz;

void main()
{
    ivec2 h = ivec2(gl_FragCoord.xy);
    bool nearest = ((h.x + h.y) & 1) == 0;
    ivec2 best = 2 * h; // all background: the block's first pixel
    float best_z = 0.0;
    bool found = false;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            ivec2 p = 2 * h + ivec2(i, j);
            if (p.x >= u_size.x || p.y >= u_size.y)
                continue;
            float z = imageLoad(u_pos, p).w;
            if (z <= 0.0)
                continue;
            if (!found || (nearest ? z < best_z : z > best_z)) {
                found = true;
                best = p;
                best_z = z;
            }
        }
    o_pos = imageLoad(u_pos, best);
    o_normal = imageLoad(u_vnormal, best);
    o_dz = imageLoad(u_dz, best).rg;
}
