#pragma once
// The ray-traced twins (issue #26): nodes that compute, on the CPU tracer's scene (Embree, the same materials and
// BRDF as render.pathtrace), the exact term a real-time approximation estimates, at each pixel's primary surface.
// A twin is render.pathtrace with another per-pixel estimator: the same inputs (scene, camera, sky, sky_sh,
// env_cdf), outputs (color, stats), `spp` a frame or "converge, then cache" (nodes/render/converge.hpp).
//
// Primary surfaces: the camera ray through each pixel's centre (unjittered), intersected with the tracer's scene:
// the same geometry and materials the G-buffer rasterises (PathTrace.TexturedSurfacesMatchTheRasterisersSamplers),
// but without TAA's sub-pixel jitter, so edges may differ from the G-buffer by a pixel. With `antialias` each sample's
// ray passes through a random point of the pixel instead (render.pathtrace's box filter): textures minified at grazing
// views are then averaged over the pixel, as the G-buffer's mip maps and the reference's pixels average them, where
// rays through the centre alias them.
#include "nodes/render/converge.hpp"
#include "nodes/render/pathtrace_cpu.hpp"

#include <memory>
#include <optional>
#include <string>

namespace vitrine {

struct TwinSchema {
    std::string type;       // "reference.reflections"
    std::string doc;        // what the twin estimates
    std::string colorDoc;   // its `color` output
    std::string what;       // the progress bar's verb phrase ("tracing reflections")
    uint32_t version = 1;   // bump when the estimator changes (part of the cache key)
};

// The shared schema: inputs scene, camera, sky, sky_sh, env_cdf; outputs color (rgba32f) and stats; params spp,
// max_bounces, sun_scale, sky_scale, emissive_scale, report, seed, target_noise, min_spp, max_seconds.
NodeSchema twinSchema(const TwinSchema& t);

// A twin: subclasses give the per-pixel estimator. The sample function must only read `this` (it runs on every
// core at once).
class TwinNode : public Node {
public:
    explicit TwinNode(TwinSchema t) : mTwin(std::move(t)) {}
    void setup(SetupContext& ctx) override;
    void execute(ExecuteContext& ctx) override;

protected:
    // One sample of the term at pixel (x, y).
    virtual glm::vec3 sample(const CpuRays& rays, int x, int y, uint32_t& rng) const = 0;
    // Params of the subclass that change the estimate, into the cache key.
    virtual void hashParams(scene::Hasher& h, const Params& p) const { (void)h, (void)p; }
    // Called at the start of each frame with the node's params (the sample function reads what it stores).
    virtual void readParams(const Params& p) { (void)p; }
    // Where in the pixel a sample's camera ray passes: its centre, or a random point with `antialias`.
    glm::vec2 primaryJitter(uint32_t& rng) const { return mAntialias ? CpuRays::next2(rng) : glm::vec2(0.5f); }
    // `multiscatter`: the GGX lobe with its multiple-scattering compensation (the primary surface's and the paths').
    bool multiscatter() const { return mMultiscatter; }

private:
    CpuTraceSettings settings(ExecuteContext& ctx, uint32_t spp, uint32_t seed) const;
    void traceBatch(ExecuteContext& ctx, const CpuSky& sky, uint32_t spp, uint32_t seed,
                    const std::function<void(double)>& progress = {});
    void executeConverge(ExecuteContext& ctx);

    TwinSchema mTwin;
    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mStorePipeline = 0;
    std::unique_ptr<CpuPathTracer> mCpu;
    CpuAccumulation mAccumulation;
    CpuResultUpload mUpload;
    std::optional<uint64_t> mConvergedKey;
    bool mAntialias = false;
    bool mMultiscatter = false;
};

// GGX visible-normal sampling (Heitz 2018) and its pdf of the reflected direction: the path tracer's
// (nodes/render/pathtrace_cpu.cpp, sampleGgxVndf and ggxVndfPdf), which keeps them private.
} // namespace vitrine
