// G-buffer rasteriser, fragment stage (after a #version line).  One sample
// at the pixel centre; the clear values are the background's.
in vec3 v_world;
in vec3 v_normal;
in vec3 v_albedo;
in float v_depth;

uniform mat3 u_normal_to_camera; // inverse transpose of world_to_camera's 3x3
uniform vec4 u_eye;              // camera position (w = 1) or, orthographic,
                                 // the direction towards the camera (w = 0)
uniform int u_has_normals;
uniform int u_has_albedo;

layout(location = 0) out float o_depth;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_normal_cam;
layout(location = 3) out vec4 o_position;
layout(location = 4) out vec4 o_color;

void main()
{
    // The triangle's own normal, oriented towards the camera.
    vec3 ng = cross(dFdx(v_world), dFdy(v_world));
    vec3 to_eye = u_eye.w != 0.0 ? u_eye.xyz - v_world : u_eye.xyz;
    ng = length(ng) > 0.0 ? normalize(ng) : normalize(to_eye);
    if (dot(ng, to_eye) < 0.0)
        ng = -ng;

    // The interpolated vertex normal, flipped where the triangle is seen
    // from its back (winding), as a path tracer flips its shading normal.
    vec3 n = ng;
    float len = length(v_normal);
    if (u_has_normals != 0 && len > 1e-6) {
        n = v_normal / len;
        if (!gl_FrontFacing)
            n = -n;
    }

    o_depth = v_depth;
    o_normal = vec4(n, 0.0);
    o_normal_cam = vec4(normalize(u_normal_to_camera * n), 0.0);
    o_position = vec4(v_world, 1.0);
    o_color = vec4(u_has_albedo != 0 ? v_albedo : vec3(0.0), 1.0);
}
