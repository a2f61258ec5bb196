#version 460
#extension GL_GOOGLE_include_directive : require
#include "ibl/capture.h"

// One mip of a cube-map array loaded from the bake cache, copied into the node's output.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 1, binding = 0) uniform sampler2DArray source;
layout(set = 1, binding = 1, rgba16f) uniform writeonly image2DArray target;

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    int size = int(pc.size);
    if (g.x >= size || g.y >= size * int(pc.layers)) return;
    int layer = g.y / size;
    ivec2 texel = ivec2(g.x, g.y - layer * size);
    imageStore(target, ivec3(texel, layer), texelFetch(source, ivec3(texel, layer), 0));
}
