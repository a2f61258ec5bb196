#version 460
#extension GL_GOOGLE_include_directive : require
#include "ibl/capture.h"
#include "ibl/ggx_sampling.glsl"
#include "common/cubemap.glsl"

// GGX prefilter of one mip of a cube-map array (ibl.capture's probes, ibl.environment's sky) [Karis13]: with
// n = v = r, the texel holds
//   sum_k L(l_k) (n.l_k) / sum_k (n.l_k),  h_k ~ D(h) (n.h),  l_k = reflect(-v, h_k),
// the radiance convolved with the lobe of this mip's roughness. Filtered importance sampling (GPU Gems 3
// ch. 20, Karis13): each sample reads the mip-filtered source at the level whose texel covers the sample's
// share of the sphere, 1 / (samples pdf), so a small bright texel is spread over its neighbours instead of
// appearing as a firefly in a few texels. No +1 lod bias: against the brute-force integral it only blurred
// (gpu.IblCapture.PrefilteredMips: worst 3.4 % with it at 64 samples, 1.2 % without at 512).
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 1, binding = 0) uniform samplerCubeArray source;
layout(set = 1, binding = 1, rgba16f) uniform writeonly image2DArray target;

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    int size = int(pc.size);
    if (g.x >= size || g.y >= size * int(pc.layers)) return;
    int layer = g.y / size;
    ivec2 texel = ivec2(g.x, g.y - layer * size);
    uint face = uint(layer % 6);
    float cube = float(layer / 6);
    vec3 n = cubeTexelDirection(face, texel, size);

    vec3 color;
    if (pc.roughness <= 0.0) {
        // The mirror: the source itself.
        color = textureLod(source, vec4(n, cube), 0.0).rgb;
    } else {
        float alpha = ggxAlpha(pc.roughness);
        float texelSolidAngle = 4.0 * kPi / (6.0 * float(pc.sourceSize) * float(pc.sourceSize));
        vec3 sum = vec3(0.0);
        float weight = 0.0;
        for (uint i = 0u; i < pc.samples; ++i) {
            vec3 h = importanceSampleGgx(hammersley(i, pc.samples), alpha, n);
            float NoH = clamp(dot(n, h), 0.0, 1.0);
            vec3 l = 2.0 * NoH * h - n;
            float NoL = dot(n, l);
            if (NoL <= 0.0) continue;
            // pdf of l: D(h) (n.h) / (4 v.h), and v.h = n.h here.
            float pdf = ggxD(NoH, alpha) * 0.25;
            float sampleSolidAngle = 1.0 / (float(pc.samples) * pdf + 1e-6);
            float lod = clamp(0.5 * log2(sampleSolidAngle / texelSolidAngle), 0.0, pc.sourceMips - 1.0);
            sum += textureLod(source, vec4(l, cube), lod).rgb * NoL;
            weight += NoL;
        }
        color = sum / max(weight, 1e-6);
    }
#ifdef PREFILTER_CLAMP_TO_HALF
    // ibl.environment: a sky's sun disk passes half float's range; its readers clamp radiance at 60000 anyway
    // (shaders/lighting/ambient.glsl's kHalfMax), so the largest half keeps what they see and stays finite.
    color = min(color, vec3(65504.0));
#endif
    imageStore(target, ivec3(texel, layer), vec4(color, 1.0));
}
