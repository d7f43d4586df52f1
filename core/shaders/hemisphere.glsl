// Method hemisphere: normal-oriented hemisphere SSAO (Crytek's SSAO with
// the kernel in the hemisphere around the normal, as Unity's
// post-processing stack ships it).  C twin: obs__hemisphere_pixel
// (methods/hemisphere.c), which documents the kernel.

uniform int u_hs_count;          // samples
uniform float u_hs_bias;         // occluders must be this far in front (depth units)
uniform float u_hs_kernel[192];  // unit hemisphere around +z, (x, y, z) per sample
                                 // (obs__hemisphere_kernel)

float method_ao(ivec2 px, vec4 p, vec3 n, out int count)
{
    float R = u_radius;
    vec2 rot = u_rot[3 * (px.x % 3) + (px.y % 3)];
    vec3 t1, t2;                // the kernel's +z goes to n
    tangent_basis(n, t1, t2);
    float occ = 0.0;
    count = u_hs_count;
    for (int i = 0; i < u_hs_count; i++) {
        vec3 k = vec3(u_hs_kernel[3 * i], u_hs_kernel[3 * i + 1], u_hs_kernel[3 * i + 2]);
        // the 3x3 tile's rotation about the normal
        float kx = rot.x * k.x - rot.y * k.y, ky = rot.y * k.x + rot.x * k.y;
        vec3 s = vec3(p.x + R * (kx * t1.x + ky * t2.x + k.z * n.x),
                      p.y + R * (kx * t1.y + ky * t2.y + k.z * n.y),
                      p.z + R * (kx * t1.z + ky * t2.z + k.z * n.z));
        ivec2 q;
        if (!view_to_px(s, u_size, q))
            continue;
        float zq = imageLoad(u_dz, q).x;   // the depth plane: one RG texel
        if (!(zq > 0.0))
            continue;                     // background never occludes
        // occluded: a surface in front of the sample, past the bias
        if (zq <= -s.z - u_hs_bias) {
            // range check: smoothstep(0, 1, R / |z_p - z_q|)
            float dz = abs(-p.z - zq);
            float r = dz > R ? R / dz : 1.0;
            occ += r * r * (3.0 - 2.0 * r);
        }
    }
    return u_hs_count > 0 ? 1.0 - occ / float(u_hs_count) : 1.0;
}
