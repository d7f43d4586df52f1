// Volumetric ambient occlusion (VAO++ section 3, after Szirmay-Kalos et
// al.): the fraction of a tangent sphere of radius R/2, moved along the
// normal, that is not behind the depth buffer, estimated with line samples
// (pipes along view Z) through a disk.  C twin: obs__vao_pixel.

uniform sampler2D u_pos;         // prep: view position, planar depth in w
uniform sampler2D u_vnormal;     // prep: view normal
uniform ivec2 u_size;
uniform float u_radius;          // R, in depth units
uniform int u_count;             // samples (with adaptive sampling: the most)
uniform vec2 u_samples[62];      // all sets of section 4.5 (core/sample_tables.c), the
                                 // set of n from n - 2: the single array of section 4.1
uniform int u_adaptive;          // 1: adaptive sampling (section 4.1)
uniform float u_adaptive_k;      // vw / (vh * D0^2), see adaptive_count
uniform vec2 u_rot[9];           // (cos, sin) of the 3x3 tile's rotations
uniform int u_range_check;       // 1: depth range check (section 4.4, eq 4)
uniform float u_range_u;         // u of eq 4

layout(location = 0) out float o_ao;
layout(location = 1) out float o_count; // samples taken (debug output)

// Adaptive sampling, section 4.1: "double the number of samples every time
// surface area of the sampling disc doubles", 2 samples for a disk of
// diameter D0 (a fraction of the image height).  The disk c + (dx, dy, 0),
// |(dx, dy)| <= r, has in NDC the Jacobian at c
//   J = [[P00 w - X P30, P01 w - X P31], [P10 w - Y P30, P11 w - Y P31]] / w^2,
// (X, Y, w) the clip coordinates of c, and the area pi r^2 |det J| (exact
// for perspective and orthographic cameras: affine at fixed view z).  The
// diameter D of the disk of that area in pixels, as a fraction of vh, has
// D^2 = r^2 |det J| vw / vh; the area ratio q = D^2 / D0^2.  Count: 2 for
// q < 2, 4 for 2 <= q < 4, ..., at most u_count.  C twin:
// obs__adaptive_count.
int adaptive_count(vec3 c)
{
    float w = PM(3, 0) * c.x + PM(3, 1) * c.y + PM(3, 2) * c.z + PM(3, 3);
    if (!(w > 0.0))
        return u_count;
    float X = PM(0, 0) * c.x + PM(0, 1) * c.y + PM(0, 2) * c.z + PM(0, 3);
    float Y = PM(1, 0) * c.x + PM(1, 1) * c.y + PM(1, 2) * c.z + PM(1, 3);
    float w2 = w * w;
    float j00 = (PM(0, 0) * w - X * PM(3, 0)) / w2, j01 = (PM(0, 1) * w - X * PM(3, 1)) / w2;
    float j10 = (PM(1, 0) * w - Y * PM(3, 0)) / w2, j11 = (PM(1, 1) * w - Y * PM(3, 1)) / w2;
    float r = 0.5 * u_radius;
    float q = r * r * abs(j00 * j11 - j01 * j10) * u_adaptive_k;
    int n = 2;
    while (n < u_count && q >= float(n))
        n *= 2;
    return n;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_pos, px, 0);
    if (p.w <= 0.0) {
        o_ao = 1.0;
        o_count = 0.0;
        return;
    }
    vec3 n = texelFetch(u_vnormal, px, 0).xyz;
    float R = u_radius, r = 0.5 * u_radius;
    vec3 c = p.xyz + n * r;     // tangent sphere centre
    vec2 rot = u_rot[3 * (px.x % 3) + (px.y % 3)];
    float open = 0.0, F = 0.0;
    // Section 4.1: the pixel's set, by its offset in the one array of sets.
    int ns = u_adaptive != 0 ? adaptive_count(c) : u_count;
    int off = ns - 2;
    o_count = float(ns);

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
    o_ao = F > 0.0 ? open / F : 1.0;   // eq 1: V = (1/F) sum dz_i
}
