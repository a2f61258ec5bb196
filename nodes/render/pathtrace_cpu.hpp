#pragma once
// render.pathtrace on the CPU, for CPU devices (lavapipe): the same estimator as shaders/render/pathtrace.comp
// (next-event estimation of the sun and of the sky through sky.env_cdf, MIS with BRDF sampling, Russian roulette,
// the same back-face rule), the same packed materials (GpuScene's packMaterials / packTexelPool, evaluated by a
// line-for-line port of scene.glsl's evaluateLayers and texel-pool sampling), the same BRDF (core/shading, the
// tested CPU mirror of common/brdf.glsl), traced through Embree. The GPU tracer and this one are held to each
// other by tests (a furnace and a box room within noise).
#include "core/image/image.hpp"
#include "core/scene/scene.hpp"

#include <glm/glm.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace vitrine {

// What the tracer reads from the sky nodes, read back from the GPU once a frame.
struct CpuSky {
    int size = 0;                  // cube face size
    std::vector<Image> faces;      // 6 faces, +X -X +Y -Y +Z -Z (radiance)
    Image envCdf;                  // sky.env_cdf's table (r), or empty
    glm::vec3 sunIlluminance{0.0f}; // lux (sky `sh` texel 9)
    glm::vec3 sunDirection{0.0f, 1.0f, 0.0f};
};

struct CpuTraceSettings {
    glm::mat4 invViewProj{1.0f};
    glm::vec3 cameraPos{0.0f};
    // An orthographic camera: primary rays start on the near plane, parallel (a perspective one's start at cameraPos).
    bool orthographic = false;
    int width = 0, height = 0;
    uint32_t spp = 1;
    uint32_t maxBounces = 8;
    uint32_t seed = 0; // of this batch of samples
    float sunScale = 1.0f, skyScale = 1.0f, emissiveScale = 1.0f;
    bool antialias = true;
    bool envSampling = true;
    // Metres over which the sun's reflection by a glossy lobe is spread (regularizedRoughness; the lightmap bake's
    // caustic_footprint). 0, the path tracer's: exact.
    float causticFootprint = 0.0f;
    // render.pathtrace's `transparent` on a tracer built with its transparent primitives: paths and shadow rays pass
    // alpha coverage and KHR_materials_transmission (pathtrace.comp's PATHTRACE_SEE_THROUGH).
    bool seeThrough = false;
    // render.pathtrace's `multiscatter`: the GGX lobe with its multiple-scattering compensation (core/shading's).
    bool multiscatter = false;
};

// Per-pixel accumulation, the layout of the node's outputs: color (mean rgb, 1) and stats (count, mean luminance,
// sum of squared deviations, standard error).
struct CpuAccumulation {
    int width = 0, height = 0;
    std::vector<glm::vec4> color, stats;
    void reset(int w, int h);
    // For the bake cache: a small header (magic, size), then color and stats. deserialize() is false (and leaves
    // this unchanged) for bytes of another size or format.
    std::vector<uint8_t> serialize() const;
    bool deserialize(const std::vector<uint8_t>& bytes, int w, int h);
    // The median (and 90th percentile) over pixels with light of the standard error of the mean luminance relative
    // to that mean (stats.w / stats.y): the noise figure target_noise is compared with.
    double relativeNoise(double* p90 = nullptr) const;
};

// A surface found by a ray, as the path tracer shades it (shading normal facing the ray, the material evaluated
// through the texel pool).
struct CpuSurface {
    glm::vec3 position{0.0f}, geometricNormal{0.0f}, normal{0.0f}, baseColor{0.0f};
    float metallic = 0.0f, roughness = 1.0f, cavity = 1.0f;
    glm::vec3 emissive{0.0f};
    float t = 0.0f; // distance along the ray
    // The dielectric's Fresnel F0 (rgb) and F90 (a), KHR_materials_specular over F0 0.04 (core/shading
    // dielectricSpecular).
    glm::vec4 dielectric{0.04f, 0.04f, 0.04f, 1.0f};
    // KHR_materials_clearcoat: strength and perceptual roughness (0, 0 without it), and the coat's shading normal
    // (its own normal map, else the vertex normal; `normal` without a coat).
    glm::vec2 coat{0.0f};
    glm::vec3 coatNormal{0.0f};
    // KHR_materials_sheen: colour (rgb) and perceptual roughness (a); 0 without it.
    glm::vec4 sheen{0.0f};
    // What lets light pass (read only with CpuTraceSettings::seeThrough): 0 where an alpha mask cuts the surface away,
    // a blended surface's alpha, else 1; KHR_materials_transmission's factor.
    float coverage = 1.0f, transmission = 0.0f;
    // KHR_materials_volume's boundary (shaders/pathtrace/volume.glsl): transmission and a thicknessFactor > 0; seen
    // from inside (its back face); KHR_materials_ior.
    bool boundary = false, inside = false;
    float ior = 1.5f;
    // The volume's material (which of the media a path is in it bounds, and their attenuation:
    // shaders/pathtrace/media.glsl); the IOR on the
    // ray's side over the IOR across (against air; PathMedia::meet's in a medium); KHR_materials_specular's colour
    // (rgb) and strength (a), for an interface's Fresnel.
    uint32_t material = 0;
    float eta = 1.0f / 1.5f;
    glm::vec4 specular{1.0f};
    // What thin-walled glass lets through is tinted by: 1, but for a KHR_materials_volume on faces that bound nothing
    // (scene::openVolumePrimitives) Beer's law over the refracted path through its thickness, as forward.transparent.
    glm::vec3 attenuation{1.0f};
};

class CpuPathTracer;

// Ray queries on the tracer's scene for the ray-traced twins (nodes/reference/): the same Embree scene, back-face
// rule and materials as the path tracer, and the path tracer's own estimator for the radiance along a ray. One per
// thread (it counts the rays it traces); made by CpuPathTracer::estimate.
class CpuRays {
public:
    // The first visible surface along o + t d, t in (0, tmax) (single-sided materials' backs are skipped, as the
    // rasteriser culls them).
    bool intersect(glm::vec3 o, glm::vec3 d, float tmax, CpuSurface& hit) const;
    // The first triangle along o + t d, either side: true with `hit` where it is a visible surface; false with
    // `inside` set where it is the back of a single-sided surface (what intersect() passes through: the ray started
    // inside geometry, as bake.lightmap counts it), false with `inside` clear where nothing is hit (the sky).
    bool firstHit(glm::vec3 o, glm::vec3 d, CpuSurface& hit, bool& inside) const;
    // Whether anything (either side of any opaque triangle) lies along o + t d, t in (0, tmax).
    bool occluded(glm::vec3 o, glm::vec3 d, float tmax) const;
    // render.pathtrace's estimate of the radiance arriving at o from direction -d (emission of the first surface,
    // sun and sky NEE at every bounce, up to maxBounces surfaces), in cd/m^2 with the settings' scales.
    glm::vec3 radiance(glm::vec3 o, glm::vec3 d, uint32_t& rng) const;
    // Like radiance(), but the path starts at a known surface `s` seen along `d` from `o` (the first hit is not
    // traced again). With emission false the surface's own emission is left out.
    glm::vec3 radianceFrom(const CpuSurface& s, glm::vec3 d, uint32_t& rng, bool emission = true) const;
    // The sky cube map's radiance along d (times sky_scale); the sun's illuminance (times sun_scale) and direction.
    glm::vec3 sky(glm::vec3 d) const;
    glm::vec3 sunIlluminance() const;
    glm::vec3 sunDirection() const;
    // The camera ray through pixel (x, y) at sub-pixel position `jitter` (0.5: the centre): origin and direction.
    void cameraRay(int x, int y, glm::vec2 jitter, glm::vec3& origin, glm::vec3& direction) const;
    // A point just off the surface on the side of `dir` (the tracer's self-intersection offset).
    static glm::vec3 offset(glm::vec3 p, glm::vec3 geometricNormal, glm::vec3 dir);
    // Uniform random numbers in [0, 1) from the tracer's PCG sequence.
    static float next(uint32_t& rng);
    static glm::vec2 next2(uint32_t& rng);

    const CpuTraceSettings& settings() const { return *mSettings; }
    uint64_t rays() const { return mRays; }

private:
    friend class CpuPathTracer;
    const void* mImpl = nullptr; // CpuPathTracer::Impl
    const CpuTraceSettings* mSettings = nullptr;
    const void* mEnv = nullptr;
    mutable uint64_t mRays = 0;
};

// One sample of a per-pixel estimate: rng is seeded per pixel, batch and sample as the path tracer's are.
using CpuSampleFn = std::function<glm::vec3(const CpuRays& rays, int x, int y, uint32_t& rng)>;

struct CpuTraceCounters {
    uint64_t paths = 0, rays = 0;
    double seconds = 0.0;    // wall clock
    double cpuSeconds = 0.0; // CPU time of the process meanwhile (all cores): throughput on a loaded machine
};

class CpuPathTracer {
public:
    // Builds the Embree scene of every instance at `pose` (the frame's: instance transforms, and the vertices of
    // deforming meshes, scene::Deformation, which shading reads too; a pose without instances is the rest pose); with
    // `transparent` it holds the transparent primitives too (alpha blend, transmission), for
    // CpuTraceSettings::seeThrough.
    CpuPathTracer(const scene::Scene& scene, const scene::ScenePose& pose, bool transparent = false);
    // Whether the tracer of `pose` would differ from this one (instances moved, meshes deformed differently).
    bool outdated(const scene::ScenePose& pose) const;
    ~CpuPathTracer();
    CpuPathTracer(const CpuPathTracer&) = delete;
    CpuPathTracer& operator=(const CpuPathTracer&) = delete;

    // Adds s.spp samples per pixel to `acc` on all cores. `progress` (may be empty) is called from the calling
    // thread with the fraction done; `cancel` stops early (the samples of finished rows are kept: rows are traced
    // in full, so a cancelled batch leaves some rows with fewer samples).
    CpuTraceCounters trace(const CpuTraceSettings& s, const CpuSky& sky, CpuAccumulation& acc,
                           const std::function<void(double)>& progress = {});

    // Like trace(), but each sample is `sample` (a ray-traced twin's estimator) instead of a camera path; the
    // accumulation and its stats are the same (the luminance of the returned value drives the noise estimate).
    CpuTraceCounters estimate(const CpuTraceSettings& s, const CpuSky& sky, CpuAccumulation& acc,
                              const CpuSampleFn& sample, const std::function<void(double)>& progress = {});

    struct Impl;

private:
    std::unique_ptr<Impl> mImpl;
};

// The path tracer's own sampling routines, for the ray-traced twins (nodes/reference/) to draw directions exactly as
// the tracer does.
namespace cpu_sampling {
glm::mat3 basisAround(glm::vec3 n);                               // columns t, b, n (Duff et al. 2017)
glm::vec3 sampleCosine(glm::vec2 u);                              // z-up, pdf cos / pi
glm::vec3 sampleGgxVndf(glm::vec3 v, float alpha, glm::vec2 u);   // v and the result in the frame of the normal (z)
float ggxVndfPdf(float NoV, float NoH, float alpha);              // of l = reflect(-v, h), per steradian
} // namespace cpu_sampling

// CPU time of this process so far (all threads), in seconds: throughput figures that hold on a loaded machine.
double processCpuSeconds();

// Whether this build has the CPU tracer (Embree found at configure time).
bool cpuPathTracerAvailable();

} // namespace vitrine
