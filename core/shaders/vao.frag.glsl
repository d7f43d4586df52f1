// Volumetric ambient occlusion (VAO++ section 3, after Szirmay-Kalos et
// al.): the fraction of a tangent sphere of radius R/2, moved along the
// normal, that is not behind the depth buffer, estimated with line samples
// (pipes along view Z) through a disk.  C twin: obs__vao_pixel.

uniform sampler2D u_pos;         // prep: view position, planar depth in w
uniform sampler2D u_vnormal;     // prep: view normal
uniform ivec2 u_size;
uniform float u_radius;          // R, in depth units
uniform int u_count;             // samples
uniform vec2 u_samples[32];      // unit disk: a set of section 4.5 (core/sample_tables.c)
uniform vec2 u_rot[9];           // (cos, sin) of the 3x3 tile's rotations
uniform int u_range_check;       // 1: depth range check (section 4.4, eq 4)
uniform float u_range_u;         // u of eq 4

out float o_ao;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_pos, px, 0);
    if (p.w <= 0.0) {
        o_ao = 1.0;
        return;
    }
    vec3 n = texelFetch(u_vnormal, px, 0).xyz;
    float R = u_radius, r = 0.5 * u_radius;
    vec3 c = p.xyz + n * r;     // tangent sphere centre
    vec2 rot = u_rot[3 * (px.x % 3) + (px.y % 3)];
    float open = 0.0, F = 0.0;

    for (int i = 0; i < u_count; i++) {
        float sx = u_samples[i].x, sy = u_samples[i].y;
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
    o_ao = F > 0.0 ? open / F : 1.0;   // eq 1: V = (1/F) sum dz_i
}
