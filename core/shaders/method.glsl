// Shared by the comparison methods' AO pass (parameter method:
// hemisphere.glsl, angle.glsl, hbao.glsl, each defining method_ao(), and
// method.frag.glsl's main).  C twins: frame.c, *_cpu.c.

uniform sampler2D u_pos;         // prep: view position, planar depth in w
uniform sampler2D u_vnormal;     // prep: view normal
uniform ivec2 u_size;
uniform float u_radius;          // R, the AO distance, in depth units
uniform vec2 u_rot[9];           // (cos, sin) of the 3x3 tile's rotations

// The pixel holding the view-space point s; false when s is behind the
// camera or off the image.  C twin: obs__view_to_px.
bool view_to_px(vec3 s, out ivec2 q)
{
    q = ivec2(0);
    float cw = PM(3, 0) * s.x + PM(3, 1) * s.y + PM(3, 2) * s.z + PM(3, 3);
    if (!(cw > 0.0))
        return false;
    float cx = PM(0, 0) * s.x + PM(0, 1) * s.y + PM(0, 2) * s.z + PM(0, 3);
    float cy = PM(1, 0) * s.x + PM(1, 1) * s.y + PM(1, 2) * s.z + PM(1, 3);
    float u = (cx / cw * 0.5 + 0.5) * u_viewport.z - u_viewport.x;
    float v = (0.5 - cy / cw * 0.5) * u_viewport.w - u_viewport.y;
    float fu = floor(u), fv = floor(v);
    if (!(fu >= 0.0 && fv >= 0.0 && fu < float(u_size.x) && fv < float(u_size.y)))
        return false;
    q = ivec2(int(fu), int(fv));
    return true;
}
