// G-buffer rasterisers (core/ground/raster_gl.c, core/ground/raster_deep_gl.c), fragment
// stage, shared part: the vertex stage's outputs and the shading normal.
in vec3 v_world;
in vec3 v_normal;
in vec3 v_albedo;
in float v_depth;

uniform mat3 u_normal_to_camera; // inverse transpose of world_to_camera's 3x3
uniform vec4 u_eye;              // camera position (w = 1) or, orthographic,
                                 // the direction towards the camera (w = 0)
uniform int u_has_normals;
uniform int u_has_albedo;

// The world-space shading normal, facing the camera.
vec3 raster_normal()
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
    return n;
}
