// The prep pass's functions: the view-space position (xyz, planar depth
// in w) and unit normal of a pixel from the raw planes.  Included by the
// prep pass (prep.frag.glsl) and by ao_resolution half's upsample
// (up.frag.glsl), which derives its own pixel's depth and normal from the
// raw planes instead of from full prep planes.  C twin:
// obs__prep_position/_normal in prep_cpu.c.

layout(r32f) readonly uniform image2D u_depth;     // raw depth
layout(rgba32f) readonly uniform image2D u_normal;  // input normals (when given)
// OBS_RECONSTRUCT (0 or 1, defined by the program): 1 derives the normals
// from depth, 0 reads them from u_normal.  A define, not a uniform: a
// SIMD rasteriser runs both sides of a uniform branch.
// u_normal_matrix (input normal -> view normal), u_size: the Frame block
// (common.glsl)

// The clip range (near, far) of the projection's z row: the planar depths
// whose OpenGL depth is -1 and 1.  C twin: clip_range in prep_cpu.c.
vec2 clip_range()
{
    float a = PM(2, 2), b = PM(2, 3), c = PM(3, 2), d = PM(3, 3);
    return vec2((d + b) / (a + c), (b - d) / (a - c));
}

// Planar depth from the raw value; 0 for background.  OBS_DEPTH_MODE (1
// planar, 2 radial, 3 ndc, 4 inverse, 5 normalized: obs_depth_mode) is
// defined by the program, one
// per mode: as uniform branches, the radial and ndc code ran for every
// pixel (bench/RESULTS.md).  C twin: linear_depth in vao_cpu.c.
float linear_depth(float raw, vec3 dir)
{
    if (OBS_DEPTH_MODE == 4) // 1/Z: 0 (or below) is background
        return raw > 0.0 && 1.0 / raw < SKY_DEPTH ? 1.0 / raw : 0.0;
    if (OBS_DEPTH_MODE == 5) { // 0..1 between the clip planes; 1 is background
        if (!(raw >= 0.0) || raw >= 1.0)
            return 0.0;
        vec2 nf = clip_range();
        return nf.x + raw * (nf.y - nf.x);
    }
    if (!(raw > 0.0) || raw >= SKY_DEPTH)
        return 0.0;
    if (OBS_DEPTH_MODE == 2)
        return raw / sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
    if (OBS_DEPTH_MODE == 3) {
        if (raw >= 1.0)
            return 0.0;
        float zn = 2.0 * raw - 1.0;
        float z = (PM(2, 3) - zn * PM(3, 3)) / (zn * PM(3, 2) - PM(2, 2));
        return -z > 0.0 ? -z : 0.0;
    }
    return raw;
}

// View-space position and planar depth; vec4(0) for background.
vec4 prep_position(float raw, ivec2 p)
{
    vec3 o, dir;
    view_ray(px_ndc(p), o, dir);
    float d = linear_depth(raw, dir);
    if (d <= 0.0 || isinf(d) || isnan(d))
        return vec4(0.0);
    return vec4(o.x + d * dir.x, o.y + d * dir.y, -d, d);
}

vec4 position_at(ivec2 p)
{
    return prep_position(imageLoad(u_depth, p).r, p);
}

// Difference towards the neighbour along step whose depth is closer to the
// centre's, so that edges do not bend the normal.
bool neighbour_delta(ivec2 p, vec4 c, ivec2 step, out vec3 delta)
{
    bool found = false;
    float best_dz = 0.0;
    delta = vec3(0.0);
    for (int s = -1; s <= 1; s += 2) {
        ivec2 q = p + s * step;
        if (q.x < 0 || q.y < 0 || q.x >= u_size.x || q.y >= u_size.y)
            continue;
        vec4 n = position_at(q);
        if (n.w <= 0.0)
            continue;
        float dz = abs(n.w - c.w);
        if (!found || dz < best_dz) {
            found = true;
            best_dz = dz;
            delta = float(s) * (n.xyz - c.xyz);
        }
    }
    return found;
}

vec3 normalize_safe(vec3 v)
{
    float l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return l > 0.0 ? v / l : v;
}

// The position and normal of pixel p (the prep pass's output there).
void prep_pixel(ivec2 p, out vec4 c, out vec3 n)
{
    c = position_at(p);
#if OBS_RECONSTRUCT == 0
    n = normalize_safe(u_normal_matrix * imageLoad(u_normal, p).xyz);
#else
    vec3 dx, dy;
    n = vec3(0.0);
    if (neighbour_delta(p, c, ivec2(1, 0), dx) && neighbour_delta(p, c, ivec2(0, 1), dy))
        n = cross(dx, dy);
    if (n == vec3(0.0))
        n = -c.xyz;             // isolated pixel: face the camera
    else if (dot(n, c.xyz) > 0.0)
        n = -n;                 // a visible surface faces the camera
    n = normalize_safe(n);
#endif
}
