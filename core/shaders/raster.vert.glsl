#version 430 core
// G-buffer rasteriser (core/ground/raster_gl.c): world-space triangles through the
// camera; the fragment stage writes the G-buffer's planes.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;

uniform mat4 u_world_to_clip;   // projection * world_to_camera
uniform mat4 u_world_to_camera;

out vec3 v_world;
out vec3 v_normal;
out vec3 v_albedo;
out float v_depth;

void main()
{
    vec4 pw = vec4(a_position, 1.0);
    v_world = a_position;
    v_normal = a_normal;
    v_albedo = a_albedo;
    // Planar view depth: the camera looks down -Z.  Interpolated with
    // perspective correction, so it is exact on the plane of the triangle.
    v_depth = -(u_world_to_camera * pw).z;
    gl_Position = u_world_to_clip * pw;
}
