#version 460
#extension GL_GOOGLE_include_directive : require
// render.pathtrace: progressive unidirectional path tracing of the scene camera, the ground truth the raster
// pipeline is measured against. Same materials (evaluateLayers), BRDF (common/brdf.glsl) and lights as
// gbuffer.layered + lighting.deferred: the sun as a delta directional light of illuminance E (sky `sh`
// texel 9) by next-event estimation, the sky cube map as an environment light (importance sampled with
// sky.env_cdf and combined with BRDF sampling by the power heuristic), emissive surfaces hit by BRDF
// sampling. Russian roulette after the third surface; at most `max_bounces` surfaces reflect light.
#define VITRINE_BVH_SET 1
#define VITRINE_SCENE_SET 2
#define VITRINE_GEOMETRY_SET 3
#define VITRINE_SCENE_TEXEL_POOL // one buffer for all textures: no walk over the sampler array per sample
#include "pathtrace/sampling.glsl"
#include "pathtrace/surface.glsl"
#include "render/pathtrace.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform samplerCube in_sky;
layout(set = 0, binding = 1) uniform sampler2D in_sky_sh;
layout(set = 0, binding = 2) uniform sampler2D in_env_cdf;
layout(set = 0, binding = 3) uniform sampler2D in_history;
layout(set = 0, binding = 4) uniform sampler2D in_history_stats;
layout(set = 0, binding = 5, rgba32f) uniform image2D out_color;
layout(set = 0, binding = 6, rgba32f) uniform image2D out_stats;

const float kInfinity = 3.4e38; // rays end nowhere (traversal compares t against this)

vec3 skyRadiance(vec3 d) { return textureLod(in_sky, d, 0.0).rgb * push.scales.y; }

// A point just off the surface on the side of `dir`, so the next ray does not hit the same triangle.
vec3 offsetRay(vec3 p, vec3 ng, vec3 dir) {
    float scale = 1e-4 * (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z)));
    return p + ng * (dot(ng, dir) >= 0.0 ? scale : -scale);
}

vec3 tracePath(vec3 origin, vec3 dir, inout uint rng) {
    bool envSampling = (push.counts.w & PATHTRACE_ENV_CDF) != 0u && push.scales.y > 0.0;
    int envSize = textureSize(in_sky, 0).x;
    if (envSampling) envSampling = envTotal(in_env_cdf, envSize) > 0.0;
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * push.scales.x;
    vec3 sunDir = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);
    bool sun = any(greaterThan(sunE, vec3(0.0)));

    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    float brdfPdfPrev = 0.0; // density of the last BRDF-sampled direction (0: a camera ray)
    uint maxBounces = push.counts.y;
    for (uint bounce = 0u;; ++bounce) {
        BvhHit hit;
        if (!pathTraceVisible(origin, dir, hit)) {
            float w = bounce == 0u || !envSampling ? 1.0 : powerHeuristic(brdfPdfPrev, envPdf(in_env_cdf, envSize, dir));
            radiance += throughput * skyRadiance(dir) * w;
            break;
        }
        PathSurface s = pathSurface(hit, origin, dir);
        // Emitters are not sampled as lights: what BRDF sampling finds counts in full.
        radiance += throughput * s.emissive * push.scales.z;
        if (bounce >= maxBounces) break;

        vec3 v = -dir, n = s.normal, ng = s.geometricNormal;
        BrdfLobes lobes = brdfLobes(s.baseColor, s.metallic, s.roughness, s.dielectric, clamp(dot(n, v), 0.0, 1.0));
        addClearcoatLobe(lobes, s.coat, s.coatNormal, v);
        addSheenLobe(lobes, s.sheen, clamp(dot(n, v), 0.0, 1.0));
        // Cavity darkens all light the surface reflects, as lighting.deferred does for the sun and the sky.
        vec3 weight = throughput * s.cavity;

        // Sun: a delta light, reached only by next-event estimation; lit exactly as lighting.deferred lights
        // it, brdfCosine x E (shadeDirectional with intensity E / pi).
        if (sun && dot(ng, sunDir) > 0.0) {
            vec3 f = brdfCosineSheen(n, s.coatNormal, v, sunDir, s.baseColor, s.metallic, s.roughness, s.dielectric,
                                         s.coat, s.sheen);
            if (any(greaterThan(f, vec3(0.0))) && !bvhTraceAny(offsetRay(s.position, ng, sunDir), sunDir, 0.0, kInfinity))
                radiance += weight * f * sunE;
        }
        // Sky: a direction from its luminance table, weighted against BRDF sampling (power heuristic).
        if (envSampling) {
            vec3 l = sampleEnv(in_env_cdf, envSize, vec3(rngNext(rng), rngNext2(rng)));
            float pdf = envPdf(in_env_cdf, envSize, l);
            if (dot(ng, l) > 0.0 && pdf > 0.0) {
                vec3 f = brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric,
                                         s.coat, s.sheen);
                if (any(greaterThan(f, vec3(0.0))) && !bvhTraceAny(offsetRay(s.position, ng, l), l, 0.0, kInfinity))
                    radiance += weight * f * skyRadiance(l) * powerHeuristic(pdf, brdfPdf(lobes, n, v, l)) / pdf;
            }
        }

        vec3 l;
        if (!sampleBrdf(lobes, n, v, vec3(rngNext(rng), rngNext2(rng)), l) || dot(ng, l) <= 0.0) break;
        float pdf = brdfPdf(lobes, n, v, l);
        if (pdf <= 0.0) break;
        throughput = weight *
                     brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric, s.coat,
                                     s.sheen) /
                     pdf;
        brdfPdfPrev = pdf;
        // Russian roulette from the third surface on, unbiased: survivors carry 1 / q.
        if (bounce >= 2u) {
            float q = min(max(max(throughput.r, throughput.g), throughput.b), 0.95);
            if (rngNext(rng) >= q) break;
            throughput /= q;
        }
        origin = offsetRay(s.position, ng, l);
        dir = l;
    }
    return radiance;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    uint spp = push.counts.x;
    bool antialias = (push.counts.w & PATHTRACE_ANTIALIAS) != 0u;

    vec3 sum = vec3(0.0);
    float mean = 0.0, m2 = 0.0; // Welford over this frame's samples of luminance
    for (uint i = 0u; i < spp; ++i) {
        uint rng = rngSeed(uvec2(p), push.counts.z, i);
        vec2 jitter = antialias ? rngNext2(rng) : vec2(0.5);
        vec2 ndc = (vec2(p) + jitter) / vec2(size) * 2.0 - 1.0;
        vec4 nearH = push.invViewProj * vec4(ndc, 1.0, 1.0);
        vec4 farH = push.invViewProj * vec4(ndc, 0.5, 1.0);
        vec3 dir = normalize(farH.xyz / farH.w - nearH.xyz / nearH.w);
        vec3 L = tracePath(push.cameraPos.xyz, dir, rng);
        if (any(isnan(L)) || any(isinf(L))) L = vec3(0.0); // counted as a black sample, never propagated
        sum += L;
        float y = luminance(L), delta = y - mean;
        mean += delta / float(i + 1u);
        m2 += delta * (y - mean);
    }

    // Merge with the history (Chan et al.'s pairwise update of count, mean and squared deviations).
    float nB = float(spp);
    vec3 colorB = sum / max(nB, 1.0);
    vec3 color = colorB;
    float n = nB, meanY = mean, M2 = m2;
    bool more = (push.counts.w & PATHTRACE_CONTINUE) != 0u;
    if (more || (push.counts.w & PATHTRACE_RESET) == 0u) {
        vec3 colorA = more ? imageLoad(out_color, p).rgb : texelFetch(in_history, p, 0).rgb;
        vec4 statsA = more ? imageLoad(out_stats, p) : texelFetch(in_history_stats, p, 0);
        float nA = statsA.x;
        n = nA + nB;
        color = (colorA * nA + colorB * nB) / max(n, 1.0);
        float delta = mean - statsA.y;
        meanY = statsA.y + delta * nB / max(n, 1.0);
        M2 = statsA.z + m2 + delta * delta * nA * nB / max(n, 1.0);
    }
    float standardError = n > 1.0 ? sqrt(max(M2, 0.0) / ((n - 1.0) * n)) : 0.0;
    imageStore(out_color, p, vec4(color, 1.0));
    imageStore(out_stats, p, vec4(n, meanY, M2, standardError));
}
