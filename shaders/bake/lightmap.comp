#version 460
#extension GL_GOOGLE_include_directive : require
// bake.lightmap's integrator (MUSEUM_SPEC §3; CPU side in core/bake/lightmap_bake.hpp). Every job is a
// lightmap texel or one ray of an irradiance-volume probe; each dispatch adds `counts.y` paths per job to the
// job's running sum:
//   texel:      irradiance E = pi x radiance arriving along a cosine-distributed direction around the normal;
//   probe ray:  the radiance arriving along the ray's fixed direction.
// What arrives is the sky, emitters, and light reflected by the scene, where every surface reflects with its
// full material (common/brdf.glsl, as render.pathtrace's) and is lit by the sun (next-event estimation with a
// shadow ray), the sky and other surfaces; a glossy lobe the sun is reflected by is widened to the caustic
// footprint (push.scales.w). The sun's direct light on the
// texel or probe itself is left out: the frame draws it with its shadow maps. A ray that first meets the
// back of a single-sided surface started inside geometry (a texel under a wall, a probe in a pillar): it
// brings no light and is counted (w), so probes inside walls can be told apart. Past the first surface such
// backs are passed through (pathtrace/surface.glsl's pathTraceVisible), the rule of render.pathtrace and of the
// CPU integrator.
#define VITRINE_BVH_SET 1
#define VITRINE_SCENE_SET 2
#define VITRINE_GEOMETRY_SET 3
#include "pathtrace/sampling.glsl"
#include "pathtrace/surface.glsl"
#include "bake/lightmap.h"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) uniform samplerCube in_sky;
layout(set = 0, binding = 1) uniform sampler2D in_sky_sh;
// Two vec4 per job (core/bake/lightmap_bake.hpp, bakeJobs): (origin, kind), (normal or direction, id).
layout(set = 4, binding = 0, std430) readonly buffer Jobs { vec4 jobs[]; };
// Two vec4 per job: (sum of its paths' estimates (rgb), number of paths that started inside geometry),
// (sum of the squared luminance of the estimates, 0, 0, 0): the filter's noise estimate.
layout(set = 4, binding = 1, std430) buffer Sums { vec4 sums[]; };

const float kInfinity = 3.4e38;

vec3 offsetRay(vec3 p, vec3 n, vec3 dir) {
    float scale = 1e-4 * (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z)));
    return p + n * (dot(n, dir) >= 0.0 ? scale : -scale);
}

// Radiance arriving at `origin` from direction `dir` (without the sun's direct light at the origin).
vec3 incoming(vec3 origin, vec3 dir, inout uint rng, out bool inside) {
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * push.scales.x;
    vec3 sunDir = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);
    bool sun = any(greaterThan(sunE, vec3(0.0)));
    inside = false;
    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    for (uint bounce = 0u;; ++bounce) {
        // The first ray asks whether the texel or probe is inside geometry (it sees the back of a single-sided
        // surface: no light, counted); later rays pass through such backs, as render.pathtrace's do.
        BvhHit hit;
        bool found = bounce == 0u ? bvhTraceClosest(origin, dir, 0.0, kInfinity, hit) : pathTraceVisible(origin, dir, hit);
        if (!found) {
            radiance += throughput * textureLod(in_sky, dir, 0.0).rgb * push.scales.y;
            break;
        }
        if (bounce == 0u && pathCulled(hit, dir)) {
            inside = true;
            break;
        }
        PathSurface s = pathSurface(hit, origin, dir);
        radiance += throughput * s.emissive * push.scales.z;
        if (bounce >= push.counts.w) break;
        // The surface reflects with its full material (base, clear coat, sheen), as render.pathtrace's does
        // (common/brdf.glsl).
        vec3 v = -dir, n = s.normal, ng = s.geometricNormal;
        BrdfLobes lobes = brdfLobes(s.baseColor, s.metallic, s.roughness, s.dielectric, clamp(dot(n, v), 0.0, 1.0));
        addClearcoatLobe(lobes, s.coat, s.coatNormal, v);
        addSheenLobe(lobes, s.sheen, clamp(dot(n, v), 0.0, 1.0));
        vec3 weight = throughput * s.cavity;
        // The sun's reflection by a glossy lobe is spread over push.scales.w metres where the path came from (its
        // caustic, common/brdf.glsl's regularizedRoughness): hit.t is the distance from there.
        if (sun && dot(ng, sunDir) > 0.0 && !bvhTraceAny(offsetRay(s.position, ng, sunDir), sunDir, 0.0, kInfinity))
            radiance += weight * sunE *
                        brdfCosineSheen(n, s.coatNormal, v, sunDir, s.baseColor, s.metallic,
                                        regularizedRoughness(s.roughness, push.scales.w, hit.t), s.dielectric,
                                        vec2(s.coat.x, regularizedRoughness(s.coat.y, push.scales.w, hit.t)), s.sheen);
        vec3 l;
        if (!sampleBrdf(lobes, n, v, vec3(rngNext(rng), rngNext(rng), rngNext(rng)), l) || dot(ng, l) <= 0.0) break;
        float pdf = brdfPdf(lobes, n, v, l);
        if (pdf <= 0.0) break;
        throughput = weight *
                     brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric, s.coat,
                                     s.sheen) /
                     pdf;
        if (bounce >= 1u) { // Russian roulette, unbiased
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
    uint job = gl_GlobalInvocationID.y * push.grid.x + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= push.grid.x || job >= push.counts.x) return;
    vec4 a = jobs[2u * job], b = jobs[2u * job + 1u];
    bool texel = a.w == 0.0;
    vec3 n = normalize(b.xyz);
    mat3 frame = basisAround(n);
    vec3 sum = vec3(0.0);
    float insideCount = 0.0, squares = 0.0;
    for (uint i = 0u; i < push.counts.y; ++i) {
        uint rng = rngSeed(uvec2(job, 0u), push.counts.z, i);
        vec3 dir = texel ? frame * sampleCosine(vec2(rngNext(rng), rngNext(rng))) : n;
        bool inside;
        vec3 L = incoming(offsetRay(a.xyz, n, dir), dir, rng, inside);
        if (any(isnan(L)) || any(isinf(L))) L = vec3(0.0);
        vec3 estimate = texel ? kPi * L : L;
        sum += estimate;
        squares += luminance(estimate) * luminance(estimate);
        insideCount += inside ? 1.0 : 0.0;
    }
    vec4 value = vec4(sum, insideCount), value2 = vec4(squares, 0.0, 0.0, 0.0);
    if ((push.grid.y & LIGHTMAP_BAKE_FIRST) == 0u) {
        value += sums[2u * job];
        value2 += sums[2u * job + 1u];
    }
    sums[2u * job] = value;
    sums[2u * job + 1u] = value2;
}
