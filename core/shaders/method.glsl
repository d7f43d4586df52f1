// Shared by the comparison methods' AO pass (parameter method:
// hemisphere.glsl, angle.glsl, hbao.glsl, gtao.glsl, each defining method_ao(), and
// method.frag.glsl's main).  C twins: frame.c, *_cpu.c.

layout(rgba32f) readonly uniform image2D u_pos;     // prep: view position, planar depth in w
layout(rgba32f) readonly uniform image2D u_vnormal; // prep: view normal
layout(rg32f) readonly uniform image2D u_dz;        // prep: planar depth (x), view normal z (y)
// u_size, u_radius (the AO distance D, in depth units), u_rot: the Frame
// block (common.glsl)

// The radius r projected at p in pixels (the square root of the projected
// area of a disk of radius r perpendicular to the view axis); 0 behind the
// camera.  C twin: obs__radius_px (chain/prep_cpu.c).
float radius_px(vec3 p, float r)
{
    float w = PM(3, 0) * p.x + PM(3, 1) * p.y + PM(3, 2) * p.z + PM(3, 3);
    if (!(w > 0.0))
        return 0.0;
    float X = PM(0, 0) * p.x + PM(0, 1) * p.y + PM(0, 2) * p.z + PM(0, 3);
    float Y = PM(1, 0) * p.x + PM(1, 1) * p.y + PM(1, 2) * p.z + PM(1, 3);
    float w2 = w * w;
    float j00 = (PM(0, 0) * w - X * PM(3, 0)) / w2, j01 = (PM(0, 1) * w - X * PM(3, 1)) / w2;
    float j10 = (PM(1, 0) * w - Y * PM(3, 0)) / w2, j11 = (PM(1, 1) * w - Y * PM(3, 1)) / w2;
    return r * sqrt(abs(j00 * j11 - j01 * j10) * u_viewport.z * u_viewport.w * 0.25);
}
