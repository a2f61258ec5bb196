#version 460
#extension GL_GOOGLE_include_directive : require
#include "ibl/localized.h"
#include "ibl/ibl_common.glsl"
#include "common/octahedral.glsl"
#include "common/brdf.glsl"
// ibl.localized's volume passes: one fragment per pixel covered by a probe's proxy whose surface (the G-buffer's
// depth) lies in front of the proxy's back face. The exact volume test rejects the rest; what remains adds the
// probe's weight w (fade ramp x 16^priority) and its radiance C along the reflection (and the roughest mip along
// the normal for diffuse). IBL_PASS (a define):
//   0 blend "a": (C w, w) and (D w, w) added into RGBA16F targets, divided by the resolve;
//   1 blend "b", first pass: w alone added into the R16_UNORM weight target;
//   2 blend "b", second pass: (C w / W, w / W) with W the first pass's sum read back here.
// Passes 0 and 1 also count the probes shading each pixel.
layout(set = 0, binding = 0) uniform Uniforms { LocalizedUniforms u; };
layout(set = 0, binding = 1) uniform sampler2D in_depth;
layout(set = 0, binding = 2) uniform sampler2D in_normal;
layout(set = 0, binding = 4) uniform samplerCubeArray in_cubes;
#if IBL_PASS == 2
layout(set = 0, binding = 5) uniform sampler2D in_weights;
#endif
layout(location = 0) flat in int vProbe;
#include "ibl/localized.glsl"

#if IBL_PASS == 1
layout(location = 0) out vec4 outWeight;
layout(location = 1) out vec4 outCount;
#else
layout(location = 0) out vec4 outRadiance;
layout(location = 1) out vec4 outIrradiance;
#if IBL_PASS == 0
layout(location = 2) out vec4 outCount;
#endif
#endif

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float z = texelFetch(in_depth, p, 0).r;
    vec3 world = localizedWorld(gl_FragCoord.xy, vec2(textureSize(in_depth, 0)), z);
    LocalizedProbe pr = u.probes[vProbe];
    float d = probeBorderDistance(pr, world);
    if (z <= 0.0 || d <= 0.0) discard;
    float w = probeWeight(pr, d);
#if IBL_PASS == 1
    outWeight = vec4(w);
    outCount = vec4(1.0);
#else
    vec4 g0 = texelFetch(in_normal, p, 0);
    vec3 n = octDecode(g0.xy);
    float roughness = roughnessFromShininess(g0.w);
    vec3 v = normalize(u.cameraPos.xyz - world);
    vec3 r = u.params.w > 0.5 ? specularDominantDirection(n, reflect(-v, n), roughness) : reflect(-v, n);
    vec3 dir = u.params.y > 0.5 ? parallaxDirection(pr, world, r) : r;
    float mips = float(textureQueryLevels(in_cubes));
    vec3 c = textureLod(in_cubes, vec4(dir, float(vProbe)), iblMipForRoughness(roughness, mips)).rgb;
    vec3 irr = textureLod(in_cubes, vec4(n, float(vProbe)), mips - 1.0).rgb;
#if IBL_PASS == 2
    // W quantised to 16 bits: the alpha sums w / W as well, and the resolve divides by it, so the quantisation
    // cancels (the alpha is 1 up to it).
    w /= max(texelFetch(in_weights, p, 0).r, 1.0 / 65535.0);
#endif
    outRadiance = vec4(c * w, w);
    outIrradiance = vec4(irr * w, w);
#if IBL_PASS == 0
    outCount = vec4(1.0);
#endif
#endif
}
