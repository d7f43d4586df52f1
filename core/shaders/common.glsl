// Shared by the passes (prepended to each fragment shader).  Each function
// has a C twin of the same name in core/chain/vao_cpu.c.
//
// Pixel (x, y) is row y from the top, as the planes are uploaded: texel
// row y of every texture is image row y, so gl_FragCoord.xy (row 0 first)
// indexes the planes directly.
//
// The planes a pass reads at more than its own pixel (the prep pass's
// neighbours, the samples of the AO passes, the blur's taps) are bound as
// read-only images and read with imageLoad, not texelFetch: on llvmpipe an
// image load is a bounds check and a load, a texel fetch goes through the
// sampler's code (level, swizzle, format), and the blur took 0.55x, the AO
// pass 0.85x the time (bench/RESULTS.md).  An image load off the image
// returns 0 like a texel fetch; the passes test their bounds anyway.  The
// images were written by earlier draws through the framebuffer, which GL
// orders before later commands' loads (no barrier: barriers are for a
// shader's own image stores).

// The frame's values, one uniform block for every pass of the chain and
// the deep pass, filled once per frame from the C struct that mirrors it
// (obs__frame_block in core/chain/frame.h; std140, so the C side can
// place each member).
layout(std140, binding = 0) uniform Frame {
    layout(row_major) mat4 u_proj;          // view -> clip
    vec4 u_viewport;                        // display x, y, width, height of the planes
    layout(row_major) mat3 u_normal_matrix; // input normal -> view normal (prep)
    ivec2 u_size;                           // the planes' size
    ivec2 u_cull_size;                      // the pre-pass texture: ceil(size / OBS_CULL_BLOCK)
    float u_radius;                         // R, in depth units (the methods: D)
    float u_range_u;                        // u of eq 4
    int u_range_normal;                     // 1: eq 4's d along the occluder's normal
    int u_count;                            // samples (with adaptive sampling: the most)
    float u_adaptive_k;                     // vw / (vh * D0^2), see adaptive_count
    int u_culling;                          // section 4.2: 1 greedy, 2 careful (0 off)
    float u_cull_threshold;                 // a pre-pass estimate below this shows occlusion
    int u_bleed_step;                       // section 4.7: 0 off, else every u_bleed_step-th sample
    int u_luminance;                        // section 4.3: 1 Rec. 709 luminance, 2 HSV V
    float u_lum_threshold, u_lum_width, u_lum_sigma; // eq 3
    vec2 u_rot[9];                          // (cos, sin) of the 3x3 tile's rotations
    vec2 u_samples[OBS_SAMPLE_TABLE_LEN];   // all sets of section 4.5, the set of n from n - 2:
                                            // the single array of section 4.1
    float u_blur_w[OBS_MAX_BLUR + 1];       // Gaussian weight of offset 0..blur_radius (4.6)
};

const float SKY_DEPTH = OBS_BACKGROUND_DEPTH; // shared.h
const float FAR_AWAY = 1e30;

#define PM(r, c) u_proj[c][r]

// The pixel's place in the 3x3 rotation tile (VAO++ 4.5), counted from
// the display window's corner, so that a cropped frame (a data window
// inside the display window) gets the whole frame's rotations.  C twin:
// obs__tile_index (frame.h).
int tile_index(ivec2 p)
{
    ivec2 d = p + ivec2(floor(u_viewport.xy));
    ivec2 t = d - 3 * ivec2(floor(vec2(d) / 3.0));
    return 3 * t.x + t.y;
}

vec2 px_ndc(ivec2 p)
{
    return vec2((float(p.x) + 0.5 + u_viewport.x) / u_viewport.z * 2.0 - 1.0,
                1.0 - (float(p.y) + 0.5 + u_viewport.y) / u_viewport.w * 2.0);
}

// The point seen at ndc with planar depth d is origin + d * dir, dir.z = -1.
void view_ray(vec2 ndc, out vec3 origin, out vec3 dir)
{
    float nx = ndc.x, ny = ndc.y;
    float a = PM(0, 0) - nx * PM(3, 0), b = PM(0, 1) - nx * PM(3, 1);
    float c = PM(1, 0) - ny * PM(3, 0), d = PM(1, 1) - ny * PM(3, 1);
    float b0x = nx * PM(3, 3) - PM(0, 3), b0y = ny * PM(3, 3) - PM(1, 3);
    float b1x = nx * PM(3, 2) - PM(0, 2), b1y = ny * PM(3, 2) - PM(1, 2);
    float inv = 1.0 / (a * d - b * c);
    origin = vec3((d * b0x - b * b0y) * inv, (a * b0y - c * b0x) * inv, 0.0);
    dir = vec3(-(d * b1x - b * b1y) * inv, -(a * b1y - c * b1x) * inv, -1.0);
}

// The pixel holding the view-space point s on planes of the given size;
// false when s is behind the camera or off the image.  Shared by the VAO
// estimator, the comparison methods and the deep pass.  C twin:
// obs__view_to_px.
bool view_to_px(vec3 s, ivec2 size, out ivec2 q)
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
    if (!(fu >= 0.0 && fv >= 0.0 && fu < float(size.x) && fv < float(size.y)))
        return false;
    q = ivec2(int(fu), int(fv));
    return true;
}

// The samples' pixels.  The disk of the samples, c + r (dx, dy, 0) with
// (dx, dy) a sample rotated by the pixel's tile rotation, lies in the plane
// z = c.z, perpendicular to view Z, so its pixel coordinates are a
// projective map of the sample (sx, sy): (u, v) = (U.s, V.s) / W.s with
// s = (sx, sy, 1).  disk_map sets U, V, W up once per pixel; disk_px is
// then 9 multiply-adds and two divisions per sample instead of projecting
// the sample's view-space point (view_to_px, which gives the same pixel
// up to rounding at pixel borders).  Shared by the VAO estimator and the
// deep pass.  C twin: obs__disk_map, obs__disk_px.
void disk_map(vec3 c, float r, vec2 rot, out vec3 U, out vec3 V, out vec3 W)
{
    vec4 k0 = u_proj * vec4(c, 1.0);                 // clip coordinates of c
    vec4 ex = u_proj[0] * r, ey = u_proj[1] * r;     // of a step r along view x, y
    vec4 A = rot.x * ex + rot.y * ey, B = rot.x * ey - rot.y * ex; // of sx, sy
    // pixel u = (X / W * 0.5 + 0.5) vw - vx, v = (0.5 - Y / W * 0.5) vh - vy
    float hx = 0.5 * u_viewport.z, hy = 0.5 * u_viewport.w;
    float ox = hx - u_viewport.x, oy = hy - u_viewport.y;
    U = vec3(hx * A.x + ox * A.w, hx * B.x + ox * B.w, hx * k0.x + ox * k0.w);
    V = vec3(-hy * A.y + oy * A.w, -hy * B.y + oy * B.w, -hy * k0.y + oy * k0.w);
    W = vec3(A.w, B.w, k0.w);
}

// The pixel coordinates (floored, on the planes or not) of the sample
// (sx, sy) under disk_map's U, V, W; false when it is behind the camera.
// C twin: disk_uv in vao_cpu.c.
bool disk_uv(vec3 U, vec3 V, vec3 W, float sx, float sy, out vec2 q)
{
    q = vec2(0.0);
    float sw = W.x * sx + W.y * sy + W.z;
    if (!(sw > 0.0))
        return false;
    q = vec2(floor((U.x * sx + U.y * sy + U.z) / sw), floor((V.x * sx + V.y * sy + V.z) / sw));
    return true;
}

// The pixel q of the sample (sx, sy) under disk_map's U, V, W on planes of
// the given size; false when it is behind the camera or off the planes.
bool disk_px(vec3 U, vec3 V, vec3 W, float sx, float sy, ivec2 size, out ivec2 q)
{
    q = ivec2(0);
    vec2 f;
    if (!disk_uv(U, V, W, sx, sy, f))
        return false;
    if (!(f.x >= 0.0 && f.y >= 0.0 && f.x < float(size.x) && f.y < float(size.y)))
        return false;
    q = ivec2(int(f.x), int(f.y));
    return true;
}

// Samples off the planes (C twin and derivation: chain/border_cpu.c): a
// sample at pixel q off the planes reads the tangent plane of the last
// pixel b on the planes along the segment from the shaded pixel px to q,
// where q's pixel-centre ray meets it.  border_px gives b: false where q
// is too far out to be a pixel (near the camera's plane).  C twin:
// obs__border_px.
bool border_px(ivec2 px, vec2 q, out ivec2 b)
{
    b = ivec2(0);
    if (!(abs(q.x) < OBS_BORDER_MAX_PX && abs(q.y) < OBS_BORDER_MAX_PX))
        return false;
    vec2 size = vec2(u_size), s = vec2(px) + 0.5, d = q + 0.5 - s;
    float t = 1.0;
    if (d.x > 0.0)
        t = min(t, (size.x - s.x) / d.x);
    else if (d.x < 0.0)
        t = min(t, -s.x / d.x);
    if (d.y > 0.0)
        t = min(t, (size.y - s.y) / d.y);
    else if (d.y < 0.0)
        t = min(t, -s.y / d.y);
    b = ivec2(min(max(floor(s + t * d), vec2(0.0)), size - 1.0));
    return true;
}

// Where the view ray of pixel q meets the plane through b with normal nb:
// true and pt (view point, planar depth in w), false where the plane does
// not face the ray (edge-on or turned away) or meets it behind the camera.
// C twin: obs__plane_point.
bool plane_point(vec2 q, vec3 b, vec3 nb, out vec4 pt)
{
    pt = vec4(0.0);
    vec3 o, dir;
    view_ray(px_ndc(ivec2(q)), o, dir);
    float den = dot(nb, dir);
    if (!(den < 0.0))
        return false;
    float d = dot(nb, b - o) / den;
    if (!(d > 0.0 && d < OBS_BACKGROUND_DEPTH))
        return false;
    pt = vec4(o + d * dir, d);
    pt.z = -d;
    return true;
}

// The planar depth under a pipe of the view-space sample point s (x, y)
// when its pixel is the shaded pixel itself, for eq 1's dz: the tangent
// plane at p (normal n) there, not the depth at the pixel's centre zs,
// which is p's (with it, a sphere smaller than a pixel would see its own
// surface as an occluder).  zs where |n.z| <= OWN_PLANE_NZ (the plane
// nearly edge-on).  Shared by the VAO estimator and the deep pass.  C
// twin: obs__own_plane_depth.
const float OWN_PLANE_NZ = OBS_OWN_PLANE_NZ; // shared.h
float own_plane_depth(vec3 p, vec3 n, vec2 s, float zs)
{
    if (!(abs(n.z) > OWN_PLANE_NZ))
        return zs;
    return -p.z + (n.x * (s.x - p.x) + n.y * (s.y - p.y)) / n.z;
}

// The view-space x, y of the sample (sx, sy) on the disk of radius r
// around c, turned by the tile rotation rot (the point disk_map maps).
vec2 disk_point(vec3 c, float r, vec2 rot, float sx, float sy)
{
    return c.xy + r * vec2(rot.x * sx - rot.y * sy, rot.y * sx + rot.x * sy);
}

// The depth range check's falloff, VAO++ section 4.4, eq 4:
// s(d) = u / max(u, d / R), the weight of a pipe's occlusion when it lies
// d behind the surface that hides it ("we assume they are flat and their
// thickness gradually decreases").  d comes in along view Z, the
// direction of the pipes (eq 1's dz); along_normal != 0 turns it into the
// pipe's depth below that flat surface, d |n.z| with nz the surface's view
// normal z, so a floor seen at a grazing angle is as thick as one seen
// from above.  C twin: obs__range_falloff.
float range_falloff(float d, float nz, float R, float u, int along_normal)
{
    if (along_normal != 0)
        d *= abs(nz);
    return u / max(u, d / R);
}

// ao_definition rays: the AO of cosine-weighted rays of length D for the
// AO ao of the tangent sphere of radius D (R = 2 D), through a floor-wall
// crease, where both are known in closed form: a wall at x = b D fills
// (1 - b)^2 (2 + b) / 4 of the sphere and blocks (acos b - b sqrt(1 -
// b^2)) / pi of the rays.  The first is inverted for b (the root in
// [0, 1] of the cubic, trigonometric form), the second is returned as
// AO; an occlusion over 1/2, deeper than the crease's corner, is kept.
// Run after the blur (luminance.frag.glsl) and on the deep pass's nodes.
// C twin: obs__rays_from_volume.
float rays_from_volume(float ao)
{
    const float PI = 3.14159265358979;
    float o = 1.0 - clamp(ao, 0.0, 1.0);
    if (o >= 0.5)
        return ao;
    float b = clamp(2.0 * cos((acos(1.0 - 2.0 * o) + PI) / 3.0), 0.0, 1.0);
    return 1.0 - (acos(b) - b * sqrt(max(0.0, 1.0 - b * b))) / PI;
}

// Tangent frame of n (Duff et al., "Building an orthonormal basis,
// revisited", 2017): t1, t2, n orthonormal.  C twin: obs__hemisphere_basis.
void tangent_basis(vec3 n, out vec3 t1, out vec3 t2)
{
    float sg = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (sg + n.z), b = n.x * n.y * a;
    t1 = vec3(1.0 + sg * n.x * n.x * a, sg * b, -sg * n.x);
    t2 = vec3(b, sg + n.y * n.y * a, -n.y);
}

// Object masks (parameters occluders and self_only, core/mask.c): the
// weight of the surface seen at pixel s as an occluder of pixel c, its
// occluders coverage times 0 where self_only's object there is not c's;
// a pixel off the image reads the nearest one on it.  Bound by the AO pass
// only (u_mask_on: 1 occluders, 2 self_only; 0 elsewhere, the default).
// C twin: obs__occluder_weight (chain/mask_weight.h).
layout(r32f) readonly uniform image2D u_mask_w;  // occluders weight
layout(r32f) readonly uniform image2D u_mask_id; // object ID (compared as bits)
uniform int u_mask_on;
float occluder_weight(ivec2 c, ivec2 s)
{
    if (u_mask_on == 0)
        return 1.0;
    s = clamp(s, ivec2(0), u_size - 1);
    float w = (u_mask_on & 1) != 0 ? imageLoad(u_mask_w, s).x : 1.0;
    if ((u_mask_on & 2) != 0 &&
        floatBitsToUint(imageLoad(u_mask_id, s).x) != floatBitsToUint(imageLoad(u_mask_id, c).x))
        w = 0.0;
    return w;
}
