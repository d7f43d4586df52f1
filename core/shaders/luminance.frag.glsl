// Luminance sensitivity (VAO++ section 4.3, eq 3), run after the blur:
// the blur is depth-aware only and would carry a bright pixel's
// suppression onto its dark neighbours (and their occlusion onto it).
// C twin: obs__luminance_ao (luminance_cpu.c).

uniform sampler2D u_ao;          // AO after the blur
uniform sampler2D u_color;       // G-buffer colour
uniform int u_luminance;         // 1 Rec. 709 luminance, 2 HSV V
uniform float u_lum_threshold, u_lum_width, u_lum_sigma;

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
    float k = luminance_factor(texelFetch(u_color, px, 0).rgb);
    o_ao = 1.0 - (1.0 - texelFetch(u_ao, px, 0).r) * k;
    o_factor = k;
}
