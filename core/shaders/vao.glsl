// Volumetric ambient occlusion (VAO++ section 3, after Szirmay-Kalos et
// al.): the fraction of a tangent sphere of radius R/2, moved along the
// normal, that is not behind the depth buffer, estimated with line samples
// (pipes along view Z) through a disk.  Shared by the AO pass
// (vao.frag.glsl) and the culling pre-pass (cull.frag.glsl).  C twin:
// obs__vao_estimate.

uniform sampler2D u_pos;         // prep: view position, planar depth in w
uniform sampler2D u_vnormal;     // prep: view normal
uniform ivec2 u_size;
uniform float u_radius;          // R, in depth units
uniform vec2 u_samples[62];      // all sets of section 4.5 (core/sample_tables.c), the
                                 // set of n from n - 2: the single array of section 4.1
uniform vec2 u_rot[9];           // (cos, sin) of the 3x3 tile's rotations
uniform int u_range_check;       // 1: depth range check (section 4.4, eq 4)
uniform float u_range_u;         // u of eq 4

// The AO of the point p (xyz; w: planar depth) with normal n at pixel px
// from the ns samples of the set at u_samples[ns - 2].
float vao_estimate(ivec2 px, vec4 p, vec3 n, int ns)
{
    float R = u_radius, r = 0.5 * u_radius;
    vec3 c = p.xyz + n * r;     // tangent sphere centre
    vec2 rot = u_rot[3 * (px.x % 3) + (px.y % 3)];
    float open = 0.0, F = 0.0;
    int off = ns - 2;
    for (int i = 0; i < ns; i++) {
        float sx = u_samples[off + i].x, sy = u_samples[off + i].y;
        float l = sqrt(max(0.0, 1.0 - sx * sx - sy * sy));
        float h = r * l;        // half length of the pipe through the sphere
        F += R * l;             // eq 2: F = R * sum sqrt(1 - x^2 - y^2)

        vec3 s = vec3(c.x + r * (rot.x * sx - rot.y * sy), c.y + r * (rot.y * sx + rot.x * sy), c.z);
        float cw = PM(3, 0) * s.x + PM(3, 1) * s.y + PM(3, 2) * s.z + PM(3, 3);
        float zs = FAR_AWAY;    // scene depth at the sample's pixel
        if (cw > 0.0) {
            float cx = PM(0, 0) * s.x + PM(0, 1) * s.y + PM(0, 2) * s.z + PM(0, 3);
            float cy = PM(1, 0) * s.x + PM(1, 1) * s.y + PM(1, 2) * s.z + PM(1, 3);
            float u = (cx / cw * 0.5 + 0.5) * u_viewport.z - u_viewport.x;
            float v = (0.5 - cy / cw * 0.5) * u_viewport.w - u_viewport.y;
            float fu = floor(u), fv = floor(v);
            if (fu >= 0.0 && fv >= 0.0 && fu < float(u_size.x) && fv < float(u_size.y)) {
                float d = texelFetch(u_pos, ivec2(int(fu), int(fv)), 0).w;
                if (d > 0.0)
                    zs = d;
            }
        }
        // Unoccluded length of the pipe (cases A, B, C of section 3).
        float front = -c.z - h;
        float dz = min(max(zs - front, 0.0), 2.0 * h);
        if (u_range_check != 0 && zs < front) {
            // Case C with the depth range check, section 4.4, eq 4:
            // s(d) = u / max(u, d / radius), d behind the visible surface,
            // measured from the pipe's near end (s = 1 where case C meets
            // case A); the occluded weight 2h is multiplied by s(d).
            float d = front - zs;
            float sd = u_range_u / max(u_range_u, d / R);
            dz = 2.0 * h * (1.0 - sd);
        }
        open += dz;
    }
    return F > 0.0 ? open / F : 1.0;   // eq 1: V = (1/F) sum dz_i
}
