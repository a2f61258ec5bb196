#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/dof.h"
#include "camera/exposure.glsl"

// post.dof pass 1: the signed circle of confusion of every pixel from the thin-lens model, in pixels of diameter
// (negative in front of the focus plane, positive behind it), clamped to +-maxCoc. With a CoC history (this node's
// coc@prev) the CoC is resolved over frames: the history, reprojected by the velocity and clamped to the 3x3
// range of this frame's CoC, is blended with it, so the sub-pixel jitter of TAA (which moves depth edges by up
// to a pixel every frame) does not make the near/far layers flicker. Also finds the frame's largest |CoC| (the
// layers' span) and clears the layer masks of the tiles for the next passes.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_depth;
layout(binding = 1) uniform sampler2D in_coc_history;
layout(binding = 2) uniform sampler2D in_velocity;
layout(binding = 3, r32f) writeonly uniform image2D out_coc;
layout(binding = 4, r32ui) writeonly uniform uimage2D out_tiles;
layout(binding = 5, r32ui) uniform uimage2D out_sprite_count;

float viewDepth(float d) {
    return d > 0.0 ? pc.depthB / (d + pc.depthA) : 1e9; // depth 0: nothing drawn (sky), at infinity
}

float cocAt(ivec2 q, float focus) {
    ivec2 size = textureSize(in_depth, 0);
    float z = viewDepth(texelFetch(in_depth, clamp(q, ivec2(0), size - 1), 0).r);
#ifdef CAMERA_EXPOSURE
    float cocScale = pc.cocScale / cameraExposure.fNumber; // the camera's f-number, on the GPU
#else
    float cocScale = pc.cocScale;
#endif
    float c = cocScale / (focus - pc.focalLength) * (z - focus) / z;
    return clamp(c, -pc.maxCoc, pc.maxCoc);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_coc);
    if (any(greaterThanEqual(p, size))) return;
    if (p.x % DOF_TILE == 0 && p.y % DOF_TILE == 0) imageStore(out_tiles, p / DOF_TILE, uvec4(0u));

    float focus = pc.focusDistance;
    if (pc.autofocus.x >= 0.0) focus = viewDepth(texelFetch(in_depth, ivec2(pc.autofocus), 0).r);
    focus = max(focus, pc.focalLength * 1.001);
    float coc = cocAt(p, focus);

    if (pc.historyWeight > 0.0) {
        float lo = coc, hi = coc;
        for (int i = 0; i < 9; ++i) {
            float c = cocAt(p + ivec2(i % 3 - 1, i / 3 - 1), focus);
            lo = min(lo, c);
            hi = max(hi, c);
        }
        vec2 v = pc.hasVelocity != 0u ? texelFetch(in_velocity, p, 0).xy : vec2(0.0);
        vec2 prev = vec2(p) + 0.5 - v;
        if (all(greaterThanEqual(prev, vec2(0.0))) && all(lessThanEqual(prev, vec2(size)))) {
            // Bilinear by hand (the history is R32F, which need not be filterable).
            vec2 t = prev - 0.5;
            ivec2 b = ivec2(floor(t));
            vec2 f = t - vec2(b);
            float h00 = texelFetch(in_coc_history, clamp(b, ivec2(0), size - 1), 0).r;
            float h10 = texelFetch(in_coc_history, clamp(b + ivec2(1, 0), ivec2(0), size - 1), 0).r;
            float h01 = texelFetch(in_coc_history, clamp(b + ivec2(0, 1), ivec2(0), size - 1), 0).r;
            float h11 = texelFetch(in_coc_history, clamp(b + ivec2(1, 1), ivec2(0), size - 1), 0).r;
            float h = mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
            coc = mix(coc, clamp(h, lo, hi), pc.historyWeight);
        }
    }
    imageStore(out_coc, p, vec4(coc));
    imageAtomicMax(out_sprite_count, ivec2(1, 0), floatBitsToUint(abs(coc)));
}
