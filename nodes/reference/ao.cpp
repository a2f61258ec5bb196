// reference.ao: ray-traced ambient occlusion, the twin of ao.alchemy (issue #26).
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/reference/twin_tracer.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {


NodeSchema schema() {
    NodeSchema s;
    s.type = "reference.ao";
    s.doc = "Ray-traced twin of ao.alchemy: at each pixel's primary surface (the camera ray through the pixel centre, "
            "traced through the scene's BVH with the G-buffer's geometry and back-face rule), the cosine-weighted "
            "obscurance O = (1/pi) integral over the hemisphere of the shading normal of [a surface lies within "
            "`radius` along w] (n.w) dw, estimated with cosine-distributed rays of length `radius` (directions below "
            "the geometric surface count as occluded). ao.alchemy estimates the same integral from the depth buffer: "
            "its spiral's sum, r (v.n) / (v.v) per sample with samples beyond r ignored, has the expectation "
            "(1/2 pi) x the solid-angle-weighted obscurance within r, so its A = max(0, 1 - sigma O)^k; this node "
            "outputs the same A with the same radius (the same step falloff at r), intensity sigma and contrast k, "
            "without the screen-space limits (off-screen and hidden geometry, the 96-pixel cap, thickness). "
            "With intensity 1 and contrast 1 it is the plain visibility 1 - O. Runs on the CPU (Embree) whatever the "
            "Vulkan device; converges and caches like render.pathtrace with target_noise > 0.";
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to trace (the G-buffer's scene)"},
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera (its unjittered view)"},
    };
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    color.size = SizeRule::frame();
    color.usage = Usage::StorageReadWrite;
    color.doc = "Ambient visibility A = max(0, 1 - intensity O)^contrast in r (g = b = 0, a = 1: ao.alchemy's `ao` "
                "as its consumers read it): 1 unoccluded, 0 fully occluded, 1 where no surface was hit";
    OutputPort stats = color;
    stats.name = "stats";
    stats.doc = "Of the samples of 1 - intensity x occluded (before the clamp and the contrast): x samples per pixel, "
                "y mean, z sum of squared deviations, w standard error of the mean";
    s.outputs = {color, stats};
    s.params = {
        {"radius", ParamType::Float, 0.5, 0.01, 100.0, {}, "Length of the occlusion rays (m): ao.alchemy's radius r"},
        {"intensity", ParamType::Float, 0.15, 0.0, 100.0, {}, "sigma: ao.alchemy's intensity (1: plain visibility)"},
        {"contrast", ParamType::Float, 1.0, 0.1, 8.0, {}, "k: the visibility is raised to this power (ao.alchemy's contrast)"},
    };
    appendTwinParams(s.params, 16);
    return s;
}

class ReferenceAo final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        mStorePipeline = ctx.computePipeline("render/pathtrace_store.comp", {}, 1);
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const ImageDesc& out = ctx.output("color").desc();
        const int w = static_cast<int>(out.width), h = static_cast<int>(out.height);
        const float radius = p.getFloat("radius"), intensity = p.getFloat("intensity");
        const float contrast = p.getFloat("contrast");

        const CpuSky sky; // AO needs no light
        scene::Hasher key;
        key.string("reference.ao v1");
        hashTraceInputs(key, *mScene, cam, sky, w, h);
        key.value(radius);
        key.value(intensity);

        const CpuSampleFn sample = [radius, intensity](const CpuRays& rays, int x, int y, uint32_t& rng) {
            glm::vec3 o, d;
            rays.cameraRay(x, y, glm::vec2(0.5f), o, d);
            CpuSurface s;
            if (!rays.intersect(o, d, 3.4e38f, s)) return glm::vec3(1.0f); // nothing drawn: unoccluded
            glm::vec3 ng = glm::dot(s.geometricNormal, d) > 0.0f ? -s.geometricNormal : s.geometricNormal;
            const glm::vec3 dir = glm::normalize(cpu_sampling::basisAround(s.normal) *
                                                 cpu_sampling::sampleCosine(CpuRays::next2(rng)));
            const bool occluded =
                glm::dot(dir, ng) <= 0.0f || rays.occluded(CpuRays::offset(s.position, ng, dir), dir, radius);
            return glm::vec3(1.0f - intensity * (occluded ? 1.0f : 0.0f));
        };
        const CpuAccumulation& acc = mTwin.run(ctx, "reference.ao", *mScene, TwinTracer::settings(cam, w, h), sky,
                                               key, sample);
        mResult = acc;
        for (glm::vec4& c : mResult.color) {
            const float a = std::pow(std::max(0.0f, c.r), contrast);
            c = glm::vec4(a, 0.0f, 0.0f, 1.0f);
        }
        mUpload.upload(ctx, mStorePipeline, mResult);
    }

private:
    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mStorePipeline = 0;
    TwinTracer mTwin;
    CpuAccumulation mResult;
    CpuResultUpload mUpload;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<ReferenceAo>(); });

} // namespace
} // namespace vitrine
