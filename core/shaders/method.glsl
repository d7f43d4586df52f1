// Shared by the comparison methods' AO pass (parameter method:
// hemisphere.glsl, angle.glsl, hbao.glsl, gtao.glsl, each defining method_ao(), and
// method.frag.glsl's main).  C twins: frame.c, *_cpu.c.

layout(rgba32f) readonly uniform image2D u_pos;     // prep: view position, planar depth in w
layout(rgba32f) readonly uniform image2D u_vnormal; // prep: view normal
layout(rg32f) readonly uniform image2D u_dz;        // prep: planar depth (x), view normal z (y)

// The bent normal's view-space sum of the method's samples, written by
// method.frag.glsl (OBS_OUTPUT_BENT; the view normal where it is 0).
vec3 g_bent;

// One gtao slice's bent normal, added to g_bent: Jimenez et al. 2016,
// Algorithm 2, as XeGTAO computes it (t0 along the slice's direction od
// orthogonal to v, t1 along v).  C twin: obs__gtao_bent_slice
// (methods/bent.c).
void gtao_bent_slice(float h0, float h1, float g, float np_len, vec3 od, vec3 v)
{
    float t0 = (6.0 * sin(h0 - g) - sin(3.0 * h0 - g) + 6.0 * sin(h1 - g) - sin(3.0 * h1 - g) +
                16.0 * sin(g) - 3.0 * (sin(h0 + g) + sin(h1 + g))) / 12.0;
    float t1 = (-cos(3.0 * h0 - g) - cos(3.0 * h1 - g) + 8.0 * cos(g) -
                3.0 * (cos(h0 + g) + cos(h1 + g))) / 12.0;
    float l = length(od);
    g_bent += np_len * (t0 * (l > 0.0 ? od / l : vec3(0.0)) + t1 * v);
}
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
