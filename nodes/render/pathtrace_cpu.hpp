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
    int width = 0, height = 0;
    uint32_t spp = 1;
    uint32_t maxBounces = 8;
    uint32_t seed = 0; // of this batch of samples
    float sunScale = 1.0f, skyScale = 1.0f, emissiveScale = 1.0f;
    bool antialias = true;
    bool envSampling = true;
};

// Per-pixel accumulation, the layout of the node's outputs: color (mean rgb, 1) and stats (count, mean luminance,
// sum of squared deviations, standard error).
struct CpuAccumulation {
    int width = 0, height = 0;
    std::vector<glm::vec4> color, stats;
    void reset(int w, int h);
};

struct CpuTraceCounters {
    uint64_t paths = 0, rays = 0;
    double seconds = 0.0;    // wall clock
    double cpuSeconds = 0.0; // CPU time of the process meanwhile (all cores): throughput on a loaded machine
};

class CpuPathTracer {
public:
    // Builds the Embree scene of every instance at `instanceWorld` (the pose of the frame).
    CpuPathTracer(const scene::Scene& scene, const std::vector<glm::mat4>& instanceWorld);
    ~CpuPathTracer();
    CpuPathTracer(const CpuPathTracer&) = delete;
    CpuPathTracer& operator=(const CpuPathTracer&) = delete;

    // Adds s.spp samples per pixel to `acc` on all cores. `progress` (may be empty) is called from the calling
    // thread with the fraction done; `cancel` stops early (the samples of finished rows are kept: rows are traced
    // in full, so a cancelled batch leaves some rows with fewer samples).
    CpuTraceCounters trace(const CpuTraceSettings& s, const CpuSky& sky, CpuAccumulation& acc,
                           const std::function<void(double)>& progress = {});

    struct Impl;

private:
    std::unique_ptr<Impl> mImpl;
};

// CPU time of this process so far (all threads), in seconds: throughput figures that hold on a loaded machine.
double processCpuSeconds();

// Whether this build has the CPU tracer (Embree found at configure time).
bool cpuPathTracerAvailable();

} // namespace vitrine
