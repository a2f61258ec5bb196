#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/tonemap.h"
#include "common/color.glsl"
#include "camera/exposure.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = texelFetch(in_color, p, 0);
    vec3 rgb = max(c.rgb, vec3(0.0));
    float exposureScale = pc.exposureScale;
#ifdef CAMERA_EXPOSURE
    exposureScale *= cameraExposure.exposure; // the camera's, on the GPU (pc.exposureScale is 1 then)
#endif
    if (pc.inverse == 0u) {
        rgb *= exposureScale;
        if (pc.op == TONEMAP_REINHARD) rgb = tonemapReinhard(rgb);
        else if (pc.op == TONEMAP_REINHARD_MAX) rgb = tonemapReinhardMax(rgb);
        else if (pc.op == TONEMAP_ACES_FIT) rgb = tonemapAcesFit(rgb);
        else if (pc.op == TONEMAP_PBR_NEUTRAL) rgb = tonemapPbrNeutral(rgb);
    } else {
        if (pc.op == TONEMAP_REINHARD) rgb = tonemapReinhardInverse(rgb);
        else if (pc.op == TONEMAP_REINHARD_MAX) rgb = tonemapReinhardMaxInverse(rgb);
        rgb /= exposureScale;
    }
    imageStore(out_color, p, vec4(rgb, c.a));
}
