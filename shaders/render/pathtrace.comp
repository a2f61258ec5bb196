#version 460
#extension GL_GOOGLE_include_directive : require
// render.pathtrace: progressive unidirectional path tracing of the scene camera, the ground truth the raster
// pipeline is measured against. Same materials (evaluateLayers), BRDF (common/brdf.glsl) and lights as
// gbuffer.layered + lighting.deferred: the sun as a delta directional light of illuminance E (sky `sh`
// texel 9) by next-event estimation, the sky cube map as an environment light (importance sampled with
// sky.env_cdf and combined with BRDF sampling by the power heuristic), emissive surfaces hit by BRDF
// sampling. Russian roulette after the third surface; at most `max_bounces` surfaces reflect light.
// With `transparent` (PATHTRACE_SEE_THROUGH) the BVH also holds forward.transparent's surfaces and light passes them
// as it passes there: alpha coverage and KHR_materials_transmission's thin-walled glass (straight on, tinted by the
// base colour), for paths and shadow rays alike. KHR_materials_volume's glass (a thicknessFactor > 0) is a closed
// volume that paths refract into and out of, paying Beer's law on the way through (pathtrace/volume.glsl). The sky's
// shadow rays stop at it (paths find that light); the sun's pass it straight on (shadowTransmittance). Volumes nest:
// paths and shadow rays keep the media they are in (pathtrace/media.glsl).
#define VITRINE_BVH_SET 1
#define VITRINE_SCENE_SET 2
#define VITRINE_GEOMETRY_SET 3
#define VITRINE_SCENE_TEXEL_POOL // one buffer for all textures: no walk over the sampler array per sample
#include "render/pathtrace.h"
#define PATHTRACE_SEE_THROUGH_SURFACE // PathSurface's coverage, transmission and volume boundary
#include "pathtrace/sampling.glsl"
#include "pathtrace/surface.glsl"
#include "pathtrace/volume.glsl"
#include "pathtrace/media.glsl"
#include "common/thin_transmission.glsl"

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

// Light t that a thin-walled transmissive dielectric lets through towards v, under its layers: scaled by the sheen's
// albedo and seen through the coat, 1 - c Fc(nc.v).
vec3 dielectricLayers(PathSurface s, vec3 v, vec3 t) {
    float NoV = clamp(dot(s.normal, v), 0.0, 1.0);
    if (hasSheen(s.sheen)) t *= sheenScaling(s.sheen.rgb, NoV, s.sheen.a);
    return clearcoatLayer(t, s.coat.x, dot(s.coatNormal, v), vec3(0.0));
}

// KHR_materials_transmission's dielectric (forward.transparent's `through`): what it does not reflect, 1 - F(n.v),
// tinted by the base colour, under its layers. A thin wall lets it pass straight on; a volume's boundary refracts it.
vec3 dielectricThrough(PathSurface s, vec3 v) {
    float NoV = clamp(dot(s.normal, v), 0.0, 1.0);
    vec3 t = (vec3(1.0) - schlickFresnelF90(s.dielectric.rgb, s.dielectric.a, NoV)) * s.baseColor * s.attenuation;
    return dielectricLayers(s, v, t);
}

// What passes surface s seen along -v on a shadow ray: its uncovered share, plus where it is covered the transmissive
// dielectric's share (1 - metallic) transmission of dielectricThrough. Nothing more for an opaque surface, nor for a
// volume's boundary unless throughVolumes: see shadowTransmittance. From inside a volume, the way out of it: 1 - F(n.v)
// (Beer's law inside is the ray's, over each segment).
vec3 pathPassing(PathSurface s, vec3 v, bool throughVolumes) {
    if (s.boundary && !throughVolumes) return vec3(0.0);
    if (s.inside)
        return vec3(1.0) - schlickFresnelF90(s.dielectric.rgb, s.dielectric.a, clamp(dot(s.normal, v), 0.0, 1.0));
    vec3 through = s.transmission > 0.0 ? s.transmission * (1.0 - s.metallic) * dielectricThrough(s, v) : vec3(0.0);
    return vec3(1.0 - s.coverage) + s.coverage * through;
}

// The light a shadow ray from origin along dir brings through what lies in its way: 0 behind anything opaque (either
// side, as shadow.directional draws both); with seeThrough the product of pathPassing over every surface it crosses.
// A volume's boundary stops the ray unless throughVolumes. The sun's rays pass volumes straight on: the sun through
// glass is a caustic, which neither a path (the sun is a delta light) nor next-event estimation can find, so its
// light is spread flat over the shadow with the transmittance of the straight chord, instead of being lost. The sky's
// rays stop there: paths refracted through the volume find that light. `media`: the volumes the ray starts in (the
// path's), whose boundaries it crosses as a path would and whose medium attenuates each segment by Beer's law.
vec3 shadowTransmittance(vec3 origin, vec3 dir, bool seeThrough, bool throughVolumes, PathMedia media) {
    if (!seeThrough) return bvhTraceAny(origin, dir, 0.0, kInfinity) ? vec3(0.0) : vec3(1.0);
    vec3 T = vec3(1.0);
    float tmin = 0.0;
    for (uint i = 0u; i < PATHTRACE_MAX_PASSES; ++i) {
        BvhHit hit;
        if (!bvhTraceClosest(origin, dir, tmin, kInfinity, hit)) return T;
        vec4 medium = currentMedium(media);
        if (medium.a > 0.0) T *= pow(medium.rgb, vec3((hit.t - tmin) / medium.a));
        PathSurface s = pathSurface(hit, origin, dir);
        if (s.boundary && throughVolumes) {
            meetBoundary(s, media);
            crossMedia(media, s, true);
        }
        T *= pathPassing(s, -dir, throughVolumes);
        if (max(max(T.r, T.g), T.b) <= 0.0) return vec3(0.0);
        tmin = hit.t;
    }
    return vec3(0.0);
}

// The sun behind a thin-walled transmissive dielectric, scattered towards v by its rough surface
// (common/thin_transmission.glsl, as forward.transparent draws it), tinted by the base colour under the sheen's
// scaling and the coat, and shadowed from the far side. The path itself passes such a surface straight on, so it
// never meets the sun (a delta light) through it: this is the only way that light arrives. 0 with the sun on v's
// side, and for a volume's boundary (the sun reaches what lies behind a volume through shadowTransmittance).
vec3 sunThroughTransmission(PathSurface s, vec3 v, vec3 sunDir, vec3 sunE, bool seeThrough, PathMedia media) {
    if (s.boundary || dot(s.geometricNormal, sunDir) >= 0.0) return vec3(0.0);
    vec3 f = thinTransmissionCosine(s.normal, v, sunDir, s.dielectric.rgb, s.dielectric.a, s.roughness);
    if (!any(greaterThan(f, vec3(0.0)))) return vec3(0.0);
    vec3 t = dielectricLayers(s, v, s.baseColor * s.attenuation * f);
    return t * sunE * shadowTransmittance(offsetRay(s.position, s.geometricNormal, sunDir), sunDir, seeThrough, true, media);
}

// KHR_materials_transmission as the glTF spec mixes it, one component drawn per surface: the metal (probability
// metallic), the opaque dielectric ((1 - metallic)(1 - transmission)) and the transmissive one ((1 - metallic)
// transmission), whose reflection is its specular alone and which lets dielectricThrough pass. Each is
// drawn with its own probability and weighted 1, so the estimate is the mixture's. Inside the transmissive one,
// passing is chosen in proportion to what passes against what is reflected (clamped to [0.05, 0.95]) and weighted by
// its inverse. True when the path passes (throughput scaled); else s is the drawn component's reflecting surface.
bool drawTransmission(inout PathSurface s, vec3 v, inout vec3 throughput, inout uint rng) {
    float u = rngNext(rng), metallic = s.metallic;
    s.metallic = u < metallic ? 1.0 : 0.0;
    if (u < metallic + (1.0 - metallic) * (1.0 - s.transmission)) return false;
    vec3 through = dielectricThrough(s, v);
    float reflected = luminance(schlickFresnelF90(s.dielectric.rgb, s.dielectric.a, clamp(dot(s.normal, v), 0.0, 1.0)));
    float pass = clamp(luminance(through) / max(luminance(through) + reflected, 1e-6), 0.05, 0.95);
    if (rngNext(rng) < pass) {
        throughput *= through / pass;
        return true;
    }
    throughput /= 1.0 - pass;
    s.baseColor = vec3(0.0); // no diffuse: the transmissive dielectric reflects by its specular only
    return false;
}

// Whether a path meets boundary s (met by meetBoundary) from its denser side: from inside its volume (towards air, or a
// rarer medium around it), or entering it from a denser medium (water from glass). There the crossing's Fresnel is
// drawn at the microfacet, total internal reflection included (throughBoundary); elsewhere drawTransmission draws it.
bool fromDenserSide(PathSurface s) { return s.inside || s.eta > 1.0; }

// A path along dir through a volume's boundary s (met by meetBoundary): across it or reflected back by Fresnel from
// its denser side (fromDenserSide), else into the volume, the Fresnel choice made by drawTransmission. dir, throughput
// and the media the path is in follow the microfacet crossBoundary draws; false where that sends the path nowhere.
bool throughBoundary(PathSurface s, inout vec3 dir, inout vec3 throughput, inout PathMedia media, inout uint rng) {
    vec3 l, w;
    bool across;
    if (!crossBoundary(s.normal, s.geometricNormal, -dir, s.roughness, s.dielectric, s.eta, fromDenserSide(s),
                       vec3(rngNext(rng), rngNext2(rng)), l, w, across))
        return false;
    throughput *= w;
    crossMedia(media, s, across);
    dir = l;
    return true;
}

vec3 tracePath(vec3 origin, vec3 dir, inout uint rng) {
    bool envSampling = (push.counts.w & PATHTRACE_ENV_CDF) != 0u && push.scales.y > 0.0;
    int envSize = textureSize(in_sky, 0).x;
    if (envSampling) envSampling = envTotal(in_env_cdf, envSize) > 0.0;
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * push.scales.x;
    vec3 sunDir = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);
    bool sun = any(greaterThan(sunE, vec3(0.0)));
    bool seeThrough = (push.counts.w & PATHTRACE_SEE_THROUGH) != 0u;

    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    // Density of the last BRDF-sampled direction; 0 for a camera ray and after a volume's boundary, where the sky's
    // own sampling cannot reach (shadow rays stop there), so what the path finds counts in full.
    float brdfPdfPrev = 0.0;
    uint maxBounces = push.counts.y;
    uint passes = 0u; // surfaces passed through (not bounces)
    PathMedia media = noMedia(); // the volumes the path is in (pathtrace/media.glsl)
    for (uint bounce = 0u;;) {
        BvhHit hit;
        bool found = pathTraceVisible(origin, dir, hit);
        // Beer's law over the way inside a volume. A path that leaves the scene from inside one (an open mesh) keeps
        // nothing of an absorbing medium.
        vec4 medium = currentMedium(media);
        if (medium.a > 0.0) {
            if (!found) break;
            throughput *= pow(medium.rgb, vec3(hit.t / medium.a));
        }
        if (!found) {
            float w = brdfPdfPrev <= 0.0 || !envSampling ? 1.0 : powerHeuristic(brdfPdfPrev, envPdf(in_env_cdf, envSize, dir));
            radiance += throughput * skyRadiance(dir) * w;
            break;
        }
        PathSurface s = pathSurface(hit, origin, dir);
        if (seeThrough && s.boundary) meetBoundary(s, media); // the IORs on its two sides
        if (seeThrough && s.boundary && fromDenserSide(s)) { // across by Fresnel, or back
            if (++passes > PATHTRACE_MAX_PASSES || !throughBoundary(s, dir, throughput, media, rng)) break;
            brdfPdfPrev = 0.0;
            origin = offsetRay(s.position, s.geometricNormal, dir);
            continue;
        }
        // Alpha coverage: the uncovered share lets the path on, untouched (an alpha mask's cut-away part always).
        bool pass = seeThrough && s.coverage < 1.0 && rngNext(rng) >= s.coverage;
        bool refracts = false; // passes into a volume
        if (!pass) {
            // Emitters are not sampled as lights: what BRDF sampling finds counts in full.
            radiance += throughput * s.emissive * push.scales.z;
            if (seeThrough && s.transmission > 0.0) {
                // The transmissive component's share of the mixture, (1 - metallic) transmission, whichever
                // component drawTransmission then draws.
                if (sun)
                    radiance += throughput * (s.transmission * (1.0 - s.metallic)) *
                                sunThroughTransmission(s, -dir, sunDir, sunE, seeThrough, media);
                pass = drawTransmission(s, -dir, throughput, rng);
                refracts = pass && s.boundary;
            }
        }
        if (pass) {
            if (++passes > PATHTRACE_MAX_PASSES) break;
            if (refracts) { // into the volume, through one of the boundary's microfacets
                if (!throughBoundary(s, dir, throughput, media, rng)) break;
                brdfPdfPrev = 0.0;
            } // else straight on from the far side: the direction's density (for MIS at the sky) is unchanged
            origin = offsetRay(s.position, s.geometricNormal, dir);
            continue;
        }
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
            if (any(greaterThan(f, vec3(0.0))))
                radiance += weight * f * sunE * shadowTransmittance(offsetRay(s.position, ng, sunDir), sunDir, seeThrough, true, media);
        }
        // Sky: a direction from its luminance table, weighted against BRDF sampling (power heuristic).
        if (envSampling) {
            vec3 l = sampleEnv(in_env_cdf, envSize, vec3(rngNext(rng), rngNext2(rng)));
            float pdf = envPdf(in_env_cdf, envSize, l);
            if (dot(ng, l) > 0.0 && pdf > 0.0) {
                vec3 f = brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric,
                                         s.coat, s.sheen);
                if (any(greaterThan(f, vec3(0.0))))
                    radiance += weight * f * skyRadiance(l) * shadowTransmittance(offsetRay(s.position, ng, l), l, seeThrough, false, media) *
                                powerHeuristic(pdf, brdfPdf(lobes, n, v, l)) / pdf;
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
        ++bounce;
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
        vec3 origin = (push.counts.w & PATHTRACE_ORTHOGRAPHIC) != 0u ? nearH.xyz / nearH.w : push.cameraPos.xyz;
        vec3 L = tracePath(origin, dir, rng);
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
