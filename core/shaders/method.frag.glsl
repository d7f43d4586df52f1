// AO pass of the comparison methods: method_ao() of the method's file in
// place of the VAO estimator; writes the attachments of the VAO pass (no
// culling, no bleeding).  C twin: obs__method_pixel (methods/methods.c).

layout(location = 0) out vec2 o_ao;    // AO, planar depth (for the blur)
layout(location = 1) out float o_count; // samples taken (debug output)
layout(location = 2) out float o_cull;  // always 0: no culling pre-pass
layout(location = 3) out vec4 o_bleed;  // always white: no bleeding
layout(location = 4) out vec4 o_bent;   // the bent normal's view-space sum (g_bent)

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = imageLoad(u_pos, px);
    o_cull = 0.0;
    o_bleed = vec4(1.0);
    o_count = 0.0;
    g_bent = vec3(0.0);
    o_bent = vec4(0.0);
    if (p.w <= 0.0) {
        o_ao = vec2(1.0, 0.0);
        return;
    }
    vec3 n = imageLoad(u_vnormal, px).xyz;
    int count = 0;
    o_ao = vec2(method_ao(px, p, n, count), p.w);
    o_count = float(count);
    o_bent = vec4(g_bent == vec3(0.0) ? n : g_bent, 0.0); // nothing open: the normal
}
