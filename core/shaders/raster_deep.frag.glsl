// A-buffer rasteriser (core/ground/raster_deep_gl.c), fragment stage (after a
// #version line and raster_common.glsl): every fragment is appended to its
// pixel's linked list, the PPLL of OITAO section IV-A (Yang et al.): one
// geometry pass, depth test off, a node pool in a shader storage buffer
// allocated by an atomic counter, the list heads in another.
layout(binding = 0, offset = 0) uniform atomic_uint u_node_count;
layout(std430, binding = 0) coherent buffer Heads { uint head[]; };  // ~0u: empty
layout(std430, binding = 1) writeonly buffer Nodes { uint node[]; };
layout(std430, binding = 2) readonly buffer Opacity { float opacity[]; }; // per triangle

uniform int u_width;
uniform int u_capacity;    // nodes the pool holds
uniform int u_has_opacity;

// Words of one node (raster_deep_gl.c reads them back): depth, alpha,
// colour rgb (premultiplied), world normal xyz, next, triangle, facing.
const uint NODE_WORDS = 11u;

void main()
{
    float a = u_has_opacity != 0 ? clamp(opacity[gl_PrimitiveID], 0.0, 1.0) : 1.0;
    if (a <= 0.0)
        return; // fully transparent: no sample
    vec3 n = raster_normal();
    // Counted even when the pool is full: the host grows it to the count
    // and draws again.
    uint idx = atomicCounterIncrement(u_node_count);
    if (idx >= uint(u_capacity))
        return;
    ivec2 px = ivec2(gl_FragCoord.xy);
    uint next = atomicExchange(head[px.y * u_width + px.x], idx);
    vec3 rgb = u_has_albedo != 0 ? v_albedo * a : vec3(0.0);
    uint b = idx * NODE_WORDS;
    node[b + 0u] = floatBitsToUint(v_depth);
    node[b + 1u] = floatBitsToUint(a);
    node[b + 2u] = floatBitsToUint(rgb.r);
    node[b + 3u] = floatBitsToUint(rgb.g);
    node[b + 4u] = floatBitsToUint(rgb.b);
    node[b + 5u] = floatBitsToUint(n.x);
    node[b + 6u] = floatBitsToUint(n.y);
    node[b + 7u] = floatBitsToUint(n.z);
    node[b + 8u] = next;
    node[b + 9u] = uint(gl_PrimitiveID);
    // Facing (OBS_DEEP_FACING): +1 where the triangle is seen from its
    // front, i.e. its outward side by the mesh's counter-clockwise winding
    // (OBJ's and glTF's convention), entering the solid; -1 from its back.
    node[b + 10u] = floatBitsToUint(gl_FrontFacing ? 1.0 : -1.0);
}
