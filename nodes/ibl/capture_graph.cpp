#include "nodes/ibl/capture_graph.hpp"

#include "core/graph/loader.hpp"
#include "core/shading/cubemap.hpp"
#include "nodes/bake/baked_lighting.hpp"

#include <glm/gtc/quaternion.hpp>

namespace vitrine {
namespace {

constexpr const char* kViewType = "ibl.capture_view";

NodeSchema viewSchema() {
    NodeSchema s;
    s.type = kViewType;
    s.doc = "ibl.capture's inner graph source: the parent's scene, sky and baked lighting, and a cube-face camera "
            "per frame (frame f: probe f / 6, face f % 6)";
    auto tex = [](const char* name, VkFormat format) {
        OutputPort o;
        o.name = name;
        o.format = format;
        o.usage = Usage::TransferDst;
        o.persistent = true;
        return o;
    };
    OutputPort scene, camera, baked;
    scene.name = "scene";
    scene.kind = PortKind::Scene;
    camera.name = "camera";
    camera.kind = PortKind::Camera;
    baked.name = "baked";
    baked.kind = PortKind::Buffer;
    s.outputs = {scene,
                 camera,
                 baked,
                 tex("sky", VK_FORMAT_R32G32B32A32_SFLOAT),
                 tex("sky_sh", VK_FORMAT_R32G32B32A32_SFLOAT),
                 tex("lightmap", VK_FORMAT_E5B9G9R9_UFLOAT_PACK32),
                 tex("volume", VK_FORMAT_R32G32B32A32_SFLOAT)};
    return s;
}

class CaptureView final : public Node {
public:
    explicit CaptureView(std::shared_ptr<const CaptureInputs> inputs) : mIn(std::move(inputs)) {}

    void setup(SetupContext& ctx) override {
        mZnear = static_cast<float>(ctx.params().getFloat("znear"));
        mScene = std::make_shared<SceneObject>(mIn->scene);
        mScene->anisotropy = mIn->anisotropy;
        mCamera = std::make_shared<CameraObject>();
        mCamera->current.width = ctx.frame().width;
        mCamera->current.height = ctx.frame().height;
        ctx.setObject("scene", mScene);
        ctx.setObject("camera", mCamera);
        ctx.setObject("baked", mIn->baked ? mIn->baked : std::make_shared<BakedLightingObject>());
        auto size = [&](const char* port, const Image* image, uint32_t layers = 1) {
            ImageDesc& d = ctx.output(port);
            d.width = image ? static_cast<uint32_t>(image->width) : 1;
            d.height = image ? static_cast<uint32_t>(image->height) : 1;
            d.layers = layers;
            d.cube = layers == 6;
        };
        size("sky", &mIn->sky.at(0), 6);
        size("sky_sh", &mIn->skySh);
        size("lightmap", mIn->lightmap ? &*mIn->lightmap : nullptr);
        size("volume", mIn->volume ? &*mIn->volume : nullptr);
    }

    void execute(ExecuteContext& ctx) override {
        if (!mUploaded) {
            for (uint32_t f = 0; f < 6; ++f) ctx.upload("sky", mIn->sky[f], f);
            ctx.upload("sky_sh", mIn->skySh);
            if (mIn->lightmap) ctx.upload("lightmap", *mIn->lightmap);
            if (mIn->volume) ctx.upload("volume", *mIn->volume);
            mPose = mIn->scene->evaluate(mIn->time);
            mUploaded = true;
        }
        const uint32_t frame = ctx.frameIndex();
        const scene::Scene& s = *mIn->scene;
        const scene::ReflectionProbe& probe = s.probes.at(frame / 6);
        CameraFrame& c = mCamera->current;
        c.state = cubeFaceCamera(probe.position, static_cast<int>(frame % 6), mZnear);
        c.projNoJitter = c.proj = c.state.projection(1.0f, true);
        c.jitter = c.prevJitter = glm::vec2(0.0f);
        c.vertexJitterThreshold = 0.0f;
        c.viewProj = c.viewProjNoJitter = c.prevViewProjNoJitter = c.proj * c.state.view;
        c.invViewProj = glm::inverse(c.viewProj);
        c.time = mIn->time;
        c.frame = frame;
        mScene->time = mIn->time;
        mScene->pose = mPose;
        mScene->previousPose = mPose;
        mScene->gpu(ctx.gpu(), ctx.shaders()).update(mPose, mPose, c);
    }

    void releaseGpu() override { mUploaded = false; }

private:
    std::shared_ptr<const CaptureInputs> mIn;
    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    scene::ScenePose mPose;
    float mZnear = 0.05f;
    bool mUploaded = false;
};

} // namespace

scene::CameraState cubeFaceCamera(glm::vec3 position, int face, float znear) {
    // Axes of the face: dir(u, v) = centre + u * du + v * dv, v pointing down the face's rows.
    const glm::vec3 centre = glm::vec3(shading::cubeDirection(face, 0.0, 0.0));
    const glm::vec3 du = glm::vec3(shading::cubeDirection(face, 1.0, 0.0)) - centre;
    const glm::vec3 dv = glm::vec3(shading::cubeDirection(face, 0.0, 1.0)) - centre;
    // Right = -du (the mirror), up = -dv, back = -centre: a rotation, since the face basis is left-handed.
    const glm::mat3 axes(-du, -dv, -centre);
    scene::CameraState state;
    state.position = position;
    state.orientation = glm::quat_cast(axes);
    state.lens.yfov = glm::radians(90.0f);
    state.lens.aspectRatio = 1.0f;
    state.lens.znear = znear;
    state.lens.zfar = 0.0f;
    state.world = glm::mat4(axes);
    state.world[3] = glm::vec4(position, 1.0f);
    state.view = glm::inverse(state.world);
    return state;
}

std::unique_ptr<CaptureGraph> buildCaptureGraph(std::shared_ptr<const CaptureInputs> inputs, const CaptureLighting& l) {
    using nlohmann::json;
    auto out = std::make_unique<CaptureGraph>();
    out->registry = NodeRegistry::global();
    NodeSchema view = viewSchema();
    view.params = {{"znear", ParamType::Float, 0.05, 1e-4, 100.0, {}, "Near plane of the face cameras (m)"}};
    const bool baked = inputs->lightmap && inputs->volume && inputs->baked;
    out->registry.add(view, [inputs] { return std::make_unique<CaptureView>(inputs); });

    json gbufferIn = {{"scene", "view.scene"}};
    json lightingIn = {{"normal", "gbuffer.normal"},     {"base_color", "gbuffer.base_color"},
                       {"material", "gbuffer.material"}, {"emissive", "gbuffer.emissive"},
                       {"sheen", "gbuffer.sheen"},       {"depth", "gbuffer.depth"},
                       {"sky_sh", "view.sky_sh"},        {"sky", "view.sky"},
                       {"camera", "view.camera"},        {"scene", "view.scene"}};
    if (baked) {
        gbufferIn["lightmap"] = "view.lightmap";
        gbufferIn["baked"] = "view.baked";
        lightingIn["volume"] = "view.volume";
        lightingIn["baked"] = "view.baked";
    }
    if (l.shadows) {
        lightingIn["shadow_map"] = "shadow.shadow_map";
        lightingIn["cascades"] = "shadow.cascades";
    }
    json nodes = {
        {"view", {{"type", kViewType}, {"params", {{"znear", l.znear}}}}},
        {"gbuffer", {{"type", "gbuffer.layered"}, {"in", gbufferIn}}},
        {"lighting",
         {{"type", "lighting.deferred"},
          {"in", lightingIn},
          {"params",
           {{"sky_ambient", l.skyAmbient}, {"sun_scale", l.sunScale}, {"emissive_scale", l.emissiveScale}, {"shadows", l.shadows}}}}},
    };
    if (l.shadows)
        nodes["shadow"] = {{"type", "shadow.directional"},
                           {"in", {{"scene", "view.scene"}, {"camera", "view.camera"}}},
                           {"params",
                            {{"resolution", l.shadowResolution}, {"cascades", l.shadowCascades}, {"distance", l.shadowDistance}}}};
    const uint32_t frames = static_cast<uint32_t>(6 * inputs->scene->probes.size());
    json write = json::array();
    for (uint32_t f = 0; f < frames; ++f) write.push_back(f);
    json doc = {{"format", "vitrine-graph/1"},
                {"frame", {{"width", l.size}, {"height", l.size}, {"frames", frames}, {"write", write}}},
                {"nodes", nodes},
                {"outputs", {{"color", "lighting.color"}}}};
    out->graph = compileGraph(validateGraph(doc, "ibl.capture (inner graph)", out->registry), out->registry);
    return out;
}

} // namespace vitrine
