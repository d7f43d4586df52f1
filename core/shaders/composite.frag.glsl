// Composite: colour x AO (grey AO where there is no colour).

uniform sampler2D u_ao;
uniform sampler2D u_color;
uniform int u_has_color;

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
    o_color = vec4(c.rgb * ao, c.a);
}
