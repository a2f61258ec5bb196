#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/dof.h"

// post.dof pass 0: clears the scatter counter (texel 0) and the frame's largest |CoC| (texel 1).
layout(local_size_x = 1, local_size_y = 1) in;
layout(binding = 0, r32ui) writeonly uniform uimage2D out_sprite_count;

// The zero comes from the push block's pad (0) so the shader declares the node's one push block.
void main() {
    imageStore(out_sprite_count, ivec2(0, 0), uvec4(pc.pad));
    imageStore(out_sprite_count, ivec2(1, 0), uvec4(pc.pad));
}
