// G-buffer rasteriser, fragment stage (after a #version line and
// raster_common.glsl).  One sample at the pixel centre; the clear values
// are the background's.
layout(location = 0) out float o_depth;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_normal_cam;
layout(location = 3) out vec4 o_position;
layout(location = 4) out vec4 o_color;

void main()
{
    vec3 n = raster_normal();
    o_depth = v_depth;
    o_normal = vec4(n, 0.0);
    o_normal_cam = vec4(normalize(u_normal_to_camera * n), 0.0);
    o_position = vec4(v_world, 1.0);
    o_color = vec4(u_has_albedo != 0 ? v_albedo : vec3(0.0), 1.0);
}
