// Composite (VAO++ section 5: the effect "is applied to resulting image
// simply by multiplication by occlusion values"): colour x AO, and x the
// colour-bleed term (section 4.7) when bleeding is on; grey AO where there
// is no colour; with u_multibounce, colour x the multi-bounce AO of the
// colour's albedo.  C twin: composite_pixel in passes_cpu.c.

uniform sampler2D u_ao;
uniform sampler2D u_color;
uniform sampler2D u_bleed;
uniform int u_has_color;
uniform int u_has_bleed;
uniform int u_multibounce;

out vec4 o_color;

// Jimenez et al. 2016 eq 10: the multi-bounce fit of the AO, per channel
// of the albedo (clamped to [0, 1], the fit's domain).  C twin:
// obs__multibounce in core/chain/multibounce.c.
vec3 obs_multibounce(float ao, vec3 albedo)
{
    vec3 rho = clamp(albedo, 0.0, 1.0);
    vec3 a = 2.0404 * rho - 0.3324;
    vec3 b = -4.7951 * rho + 0.6417;
    vec3 c = 2.7552 * rho + 0.6903;
    return max(vec3(ao), ((a * ao + b) * ao + c) * ao);
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float ao = texelFetch(u_ao, px, 0).r;
    if (u_has_color == 0) {
        o_color = vec4(ao, ao, ao, 1.0);
        return;
    }
    vec4 c = texelFetch(u_color, px, 0);
    vec3 occ = u_multibounce != 0 ? obs_multibounce(ao, c.rgb) : vec3(ao);
    if (u_has_bleed != 0) {
        vec3 b = texelFetch(u_bleed, px, 0).rgb;
        o_color = vec4(c.r * occ.r * b.r, c.g * occ.g * b.g, c.b * occ.b * b.b, c.a);
        return;
    }
    o_color = vec4(c.rgb * occ, c.a);
}
