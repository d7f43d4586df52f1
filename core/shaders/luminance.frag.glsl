// The finishing pass, run after the blur: ao_definition rays' conversion
// of the volume fraction, then luminance sensitivity (VAO++ section 4.3,
// eq 3).  Both act on the filtered AO: the conversion is not linear, so
// it is applied to the blur's noise-free estimate; the blur is
// depth-aware only and would carry a bright pixel's suppression onto its
// dark neighbours (and their occlusion onto it).  OBS_RAYS and
// OBS_LUMINANCE (0 or 1) are defined by the program: a SIMD rasteriser
// would run both sides of a uniform branch.  With the blur on, the
// conversion is done by the blur's vertical pass instead (blur.frag.glsl).
// rays_from_volume is in common.glsl.  C twins: obs__rays_from_volume
// (vao_cpu.c), obs__luminance_ao (luminance_cpu.c).

uniform sampler2D u_ao;          // AO after the blur
uniform sampler2D u_color;       // G-buffer colour
// u_luminance (1 Rec. 709 luminance, 2 HSV V), u_lum_threshold,
// u_lum_width, u_lum_sigma: the Frame block (common.glsl)

layout(location = 0) out float o_ao;
layout(location = 1) out float o_factor; // debug output: the factor of eq 3

// Eq 3: AO_L = AO (1 - min(1, max(0, lum - threshold + width)) / (2 width))^sigma.
// As printed, min(1, .) clamps the numerator before the division, so for
// width < 0.5 the base turns negative above lum = threshold + width, where
// pow is undefined; the base is clamped at 0 there (no occlusion left).
// Eq 3's AO is the occlusion (it vanishes on bright pixels): ours, 1 =
// unoccluded, becomes 1 - (1 - AO) * factor.
float luminance_factor(vec3 rgb)
{
    float lum = u_luminance == 2 ? max(rgb.r, max(rgb.g, rgb.b))
                                 : 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
    float t = min(1.0, max(0.0, lum - u_lum_threshold + u_lum_width));
    float base = 1.0 - t / (2.0 * u_lum_width);
    return base > 0.0 ? pow(base, u_lum_sigma) : 0.0;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float ao = texelFetch(u_ao, px, 0).r;
#if OBS_RAYS
    ao = rays_from_volume(ao);
#endif
#if OBS_LUMINANCE
    float k = luminance_factor(texelFetch(u_color, px, 0).rgb);
#else
    float k = 1.0;
#endif
    o_ao = 1.0 - (1.0 - ao) * k;
    o_factor = k;
}
