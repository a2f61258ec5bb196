#version 460
// render.pathtrace with the CPU tracer (nodes/render/pathtrace_cpu.cpp): copies what the CPU accumulated (per
// pixel: mean colour, then stats) from a host-visible buffer into the node's outputs.
layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant) uniform Push {
    uvec4 size; // x, y: the outputs' size
} push;
layout(set = 1, binding = 0, std430) readonly buffer Traced { vec4 traced[]; };
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D out_color;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D out_stats;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, push.size.xy))) return;
    uint i = 2u * (p.y * push.size.x + p.x);
    imageStore(out_color, ivec2(p), traced[i]);
    imageStore(out_stats, ivec2(p), traced[i + 1u]);
}
