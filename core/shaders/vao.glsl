// Volumetric ambient occlusion (VAO++ section 3, after Szirmay-Kalos et
// al.): the fraction of a tangent sphere of radius R/2, moved along the
// normal, that is not behind the depth buffer, estimated with line samples
// (pipes along view Z) through a disk.  Shared by the AO pass
// (vao.frag.glsl) and the culling pre-pass (cull.frag.glsl).  C twin:
// obs__vao_estimate.

layout(rgba32f) readonly uniform image2D u_pos;     // prep: view position, planar depth in w
layout(rgba32f) readonly uniform image2D u_vnormal; // prep: view normal
layout(rg32f) readonly uniform image2D u_dz; // prep: planar depth and view normal z, one load per sample
// u_size, u_radius, u_samples, u_rot, u_range_u, u_range_normal: the
// Frame block (common.glsl)
layout(rgba32f) readonly uniform image2D u_color;   // G-buffer colour (section 4.7)
// Defined by the program (run_gl.c), 0 or 1: OBS_BLEED, colour bleeding
// compiled in; OBS_RANGE_CHECK, the depth range check (section 4.4).

// Colour bleeding, section 4.7, eq 5:
//   c(x) = max(0, (x - p).n / |x - p|) (1 - |x - p| / radius)^2,
// x the view-space point the depth buffer holds at the sample's pixel (the
// paper uses the samples "regardless of whether they lie on the surface").
// As printed the falloff grows again past 2 radius; it is clamped at 0
// from |x - p| = radius on.  x = p gives 0.  C twin: obs__bleed_weight.
float bleed_weight(vec3 x, vec3 p, vec3 n, float R)
{
    float dx = x.x - p.x, dy = x.y - p.y, dz = x.z - p.z;
    float len = sqrt(dx * dx + dy * dy + dz * dz);
    if (!(len > 0.0))
        return 0.0;
    float cosv = (dx * n.x + dy * n.y + dz * n.z) / len;
    float fall = max(0.0, 1.0 - len / R);
    return max(0.0, cosv) * fall * fall;
}

// A sample off the planes (chain/border_cpu.c derives it): true and zs,
// nz of the surface continued past the border (zs left as it is, open,
// where that is background); false where the sample is left out of eq 1
// (behind the camera, or no estimate).  C twin: border_sample in
// vao_cpu.c.
bool border_sample(ivec2 px, vec3 U, vec3 V, vec3 W, float sx, float sy, inout float zs,
                   inout float nz)
{
    vec2 q;
    ivec2 b;
    if (!disk_uv(U, V, W, sx, sy, q) || !border_px(px, q, b))
        return false;
    vec4 pb = imageLoad(u_pos, b);
    if (!(pb.w > 0.0))
        return true;
    vec3 nb = imageLoad(u_vnormal, b).xyz;
    vec4 pt;
    if (!plane_point(q, pb.xyz, nb, pt))
        return false;
    zs = pt.w;
    nz = nb.z;
    return true;
}

// OBS_OUTPUT_BENT: the sum of the open pipes' centroids seen from p,
// written by vao.frag.glsl.  C twin: obs__vao_bent_sample
// (chain/vao_bent_cpu.c, where the definition is).
vec3 g_bent;
void vao_bent_sample(vec3 c, float r, vec2 rot, float sx, float sy, float h, float dz, vec3 p)
{
    g_bent += dz * (vec3(disk_point(c, r, rot, sx, sy), c.z + h - 0.5 * dz) - p);
}

// The AO of the point p (xyz; w: planar depth) with normal n at pixel px
// from the ns samples of the set at u_samples[ns - 2].  With bleed_step >
// 0, bleed gets the colour-bleed term of section 4.7: the mean over every
// bleed_step-th sample of white mixed towards the colour at the sample's
// pixel by eq 5's c(x); else vec3(1).  C twin: obs__vao_estimate_bleed.
float vao_estimate(ivec2 px, vec4 p, vec3 n, int ns, int bleed_step, out vec3 bleed)
{
    float R = u_radius, r = 0.5 * u_radius;
    vec3 c = p.xyz + n * r;     // tangent sphere centre
    vec2 rot = u_rot[tile_index(px)];
    vec3 U, V, W;
    disk_map(c, r, rot, U, V, W);
    float open = 0.0, F = 0.0;
    int off = ns - 2;
    vec3 acc = vec3(0.0);
    float taken = 0.0;
    for (int i = 0; i < ns; i++) {
        // Section 4.7: "every second or fourth sample"; the sets are
        // z-ordered, so those still cover the disk evenly.
        // With OBS_BLEED 0 the bleed code below is compiled out.
        bool bleeds = OBS_BLEED != 0 && bleed_step > 0 && i % bleed_step == 0;
        float c5 = 0.0;         // eq 5's c(x); 0 (white) without a surface there
        bool hit = false;
        ivec2 q = ivec2(0);
        float sx = u_samples[off + i].x, sy = u_samples[off + i].y;
        float l = sqrt(max(0.0, 1.0 - sx * sx - sy * sy));
        float h = r * l;        // half length of the pipe through the sphere
        bool seen = false;      // the sample's pixel is on the planes

        float zs = FAR_AWAY;    // scene depth at the sample's pixel
        float nz = 1.0;         // view normal z there
        seen = disk_px(U, V, W, sx, sy, u_size, q);
        ivec2 qm = seen ? q : px; // object masks: off the planes, the shaded pixel's
        if (seen) {
            vec2 dq = imageLoad(u_dz, q).xy;
            if (dq.x > 0.0) {
                zs = dq.x;
                nz = dq.y;
                // a sample on the shaded pixel itself: p's tangent plane
                if (q == px)
                    zs = own_plane_depth(p.xyz, n, disk_point(c, r, rot, sx, sy), zs);
                if (bleeds) {       // eq 5, x the surface point at the sample's pixel
                    c5 = bleed_weight(imageLoad(u_pos, q).xyz, p.xyz, n, R);
                    hit = true;
                }
            }
        } else {
            seen = border_sample(px, U, V, W, sx, sy, zs, nz);
        }
        if (bleeds) {
            // "We use c(x) to linearly interpolate between the white color
            // and the sampled color."
            vec3 col = hit ? imageLoad(u_color, q).rgb : vec3(1.0);
            acc += hit ? vec3(1.0 + c5 * (col.r - 1.0), 1.0 + c5 * (col.g - 1.0),
                              1.0 + c5 * (col.b - 1.0))
                       : vec3(1.0);
            taken += 1.0;
        }
        // Unoccluded length of the pipe (cases A, B, C of section 3).
        float front = -c.z - h;
        float dz = min(max(zs - front, 0.0), 2.0 * h);
        float om = occluder_weight(px, qm); // object masks
        if (OBS_RANGE_CHECK != 0 && zs < front) {
            // Case C with the depth range check, section 4.4, eq 4:
            // s(d) = u / max(u, d / radius), d behind the visible surface,
            // measured from the pipe's near end (s = 1 where case C meets
            // case A); the occluded weight 2h is multiplied by s(d).
            float sd = range_falloff(front - zs, nz, R, u_range_u, u_range_normal);
            dz = 2.0 * h * (1.0 - sd);
        }
        dz += (2.0 * h - dz) * (1.0 - om); // the occluded length times the mask (om 1: dz)
        // A sample off the planes reads the surface continued past the
        // border; one behind the camera, or without that estimate, is left
        // out of eq 1's sum and of F alike (C twin: the same comment).
        if (seen) {
            open += dz;
            F += R * l;         // eq 2: F = R * sum sqrt(1 - x^2 - y^2)
            vao_bent_sample(c, r, rot, sx, sy, h, dz, p.xyz); // OBS_OUTPUT_BENT
        }
    }
    bleed = taken > 0.0 ? acc / taken : vec3(1.0);
    return F > 0.0 ? open / F : 1.0;   // eq 1: V = (1/F) sum dz_i
}
