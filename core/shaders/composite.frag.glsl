// Composite (VAO++ section 5: the effect "is applied to resulting image
// simply by multiplication by occlusion values"): colour x AO, and x the
// colour-bleed term (section 4.7) when bleeding is on; grey AO where there
// is no colour.  C twin: composite_pixel in vao_cpu.c.

uniform sampler2D u_ao;
uniform sampler2D u_color;
uniform sampler2D u_bleed;
uniform int u_has_color;
uniform int u_has_bleed;

out vec4 o_color;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float ao = texelFetch(u_ao, px, 0).r;
    if (u_has_color == 0) {
        o_color = vec4(ao, ao, ao, 1.0);
        return;
    }
    vec4 c = texelFetch(u_color, px, 0);
    if (u_has_bleed != 0) {
        vec3 b = texelFetch(u_bleed, px, 0).rgb;
        o_color = vec4(c.r * ao * b.r, c.g * ao * b.g, c.b * ao * b.b, c.a);
        return;
    }
    o_color = vec4(c.rgb * ao, c.a);
}
