// Shared by the comparison methods' AO pass (parameter method:
// hemisphere.glsl, angle.glsl, hbao.glsl, each defining method_ao(), and
// method.frag.glsl's main).  C twins: frame.c, *_cpu.c.

layout(rgba32f) readonly uniform image2D u_pos;     // prep: view position, planar depth in w
layout(rgba32f) readonly uniform image2D u_vnormal; // prep: view normal
layout(rg32f) readonly uniform image2D u_dz;        // prep: planar depth (x), view normal z (y)
// u_size, u_radius (the AO distance D, in depth units), u_rot: the Frame
// block (common.glsl)
