// lighting.deferred: sun (GGX + Lambert, cascaded shadows) and sky ambient over the G-buffer.
#include "shaders/lighting/deferred.h"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/bake/baked_lighting.hpp"
#include "nodes/lighting/multiscatter.hpp"
#include "nodes/lighting/punctual_lights.hpp"
#include "nodes/shadow/cascades.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "lighting.deferred";
    s.doc = "Deferred lighting (MUSEUM_SPEC §1, §3): Cook-Torrance (GGX, Smith, Schlick) + Lambert for the sun "
            "with PCF-filtered cascaded shadows and cavity, the scene's point and spot lights unshadowed; indirect "
            "diffuse from the G-buffer's baked lightmap or bake.lightmap's irradiance volume (the sky's SH irradiance "
            "scaled by sky_ambient where there is neither, or ibl.localized's diffuse); indirect specular from "
            "ibl.localized when connected, else the volume's SH radiance (else the sky); emissive added. Outputs HDR radiance (cd/m²).";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("normal", "G-buffer: octahedral normal, view depth, shininess"),
        tex("base_color", "G-buffer: base colour, metallic"),
        tex("material", "G-buffer: alpha, 1 − specular strength, vertex AO, cavity"),
        tex("emissive", "G-buffer: emissive + baked diffuse (a: lightmapped flag + packed clear coat)"),
        tex("sheen", "G-buffer: KHR_materials_sheen colour and roughness (lit under the clear coat)"),
        tex("depth", "G-buffer hardware depth (reverse Z)"),
        tex("shadow_map", "shadow.directional's atlas (without it the sun is unshadowed)", true),
        {"cascades", PortKind::Buffer, {}, true, Usage::Sampled, "shadow.directional's cascades"},
        tex("sky_sh", "A sky node's `sh`: SH9 radiance, sun illuminance (lux) and direction"),
        tex("sky", "A sky node's cubemap (background and mirror reflections), or ibl.environment's prefiltered one "
                   "(mips: rough surfaces read the mip of their roughness)"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
        tex("volume", "bake.lightmap's irradiance volume (diffuse and specular stand-in for what has no lightmap)",
            true),
        {"baked", PortKind::Buffer, {}, true, Usage::Sampled, "bake.lightmap's `layout` (with `volume`)"},
        {"scene",
         PortKind::Scene,
         {},
         true,
         Usage::Sampled,
         "The scene, for its KHR_lights_punctual point and spot lights (unshadowed); without it only the sun"},
        tex("ao",
            "Ambient visibility in r (ao.alchemy, accumulated), any size: the indirect diffuse and specular "
            "(baked or not) are multiplied by lerp(baseColor, 1, ao); none: 1",
            true),
        tex("ibl_specular", "ibl.localized's specular: replaces the indirect specular stand-in (x vertex AO x cavity)",
            true),
        tex("ibl_diffuse",
            "ibl.localized's diffuse: the indirect diffuse of pixels with neither lightmap nor irradiance volume "
            "(x vertex AO x cavity)",
            true),
        tex("brdf_lut",
            "ibl.environment's (or ibl.capture's) split-sum BRDF LUT: the sky's and the volume's indirect specular "
            "are weighed by it (f0 A + f90 B) instead of Karis' analytic fit",
            true),
    };
    OutputPort color;
    color.name = "color";
    color.size = SizeRule::ofInput("normal");
    color.doc = "HDR radiance: direct + ambient diffuse + indirect specular + emissive";
    OutputPort spec = color;
    spec.name = "specular_indirect";
    spec.doc = "The indirect specular term alone (included in color; SSR replaces it where it hits)";
    OutputPort diffuse = color;
    diffuse.name = "diffuse_indirect";
    diffuse.doc = "The indirect diffuse term alone (included in color): the lightmap's baked diffuse (with the "
                  "surface's own emission, baked together), else the irradiance volume's, ibl.localized's or the sky's "
                  "diffuse, x vertex AO x cavity, x the ao tint; what reference.diffuse_indirect estimates by tracing";
    s.outputs = {color, spec, diffuse};
    s.params = {
        {"sky_ambient",
         ParamType::Float,
         0.15,
         0.0,
         1.0,
         {},
         "Fraction of the open sky's ambient that reaches surfaces with neither a lightmap nor the irradiance volume "
         "(a stand-in for occlusion)"},
        {"shadows", ParamType::Bool, true, {}, {}, {}, "Sun shadows (off: the sun reaches everything)"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"emissive_scale",
         ParamType::Float,
         1.0,
         0.0,
         1e6,
         {},
         "Multiplier of the emissive channel where it is emission alone (lightmapped pixels carry emission and baked "
         "light together and are left as baked)"},
        {"multiscatter",
         ParamType::Enum,
         "off",
         {},
         {},
         {"off", "environment", "all"},
         "Multiple scattering between the GGX lobe's microfacets [Turquin19]: the specular times 1 + F0 (1 - E(n.v)) / "
         "E(n.v), E the single-scattering lobe's directional albedo (common/brdf.glsl ggxMultiscatter), which gives a "
         "white metal back the light single scattering loses (up to 69 % at roughness 1). all: the sun's, the lights' "
         "and the sky's specular (render.pathtrace's multiscatter traces the same lobe); environment: the sky's and "
         "the irradiance volume's alone (the glTF Sample Viewer's model, image-based light only; graphs/gltf.json); "
         "off: single scattering (the Museum's). Where the reflection comes from ibl.localized and ssr.composite, "
         "their own multiscatter compensates it"},
    };
    return s;
}

class Deferred final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.hasInput("scene")) {
            mScene = ctx.objectAs<SceneObject>("scene");
            warnLightCount(mScene->scene(), "lighting.deferred");
        }
        if (ctx.hasInput("cascades")) mCascades = ctx.objectAs<ShadowCascadesObject>("cascades");
        if (ctx.hasInput("shadow_map") != ctx.hasInput("cascades"))
            ctx.failParam("shadows", "connect both shadow_map and cascades of a shadow.directional node, or neither");
        if (ctx.hasInput("volume") != ctx.hasInput("baked"))
            ctx.failParam("sky_ambient", "connect both volume and baked (bake.lightmap's volume and layout), or neither");
        if (ctx.hasInput("baked")) mBaked = ctx.objectAs<BakedLightingObject>("baked");
        mPipeline = ctx.computePipeline("lighting/deferred.comp", multiscatterDefines(ctx.params()));
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        gpu_types::DeferredUniforms u{};
        const CameraFrame& cam = mCamera->current;
        u.invViewProj = cam.invViewProj;
        u.cameraPos = glm::vec4(cam.state.position, 1.0f);
        bool shadows = p.getBool("shadows") && mCascades;
        u.params = {p.getFloat("sky_ambient"), shadows ? 1.0f : 0.0f, p.getFloat("sun_scale"), p.getFloat("emissive_scale")};
        if (mCascades) u.shadow = mCascades->data;
        else u.shadow.params = {1.0f, 1.0f, 0.0f, 0.0f};
        if (mBaked) {
            u.volumeOrigin = glm::vec4(mBaked->volumeOrigin, mBaked->volumeSpacing);
            u.volumeCounts = glm::uvec4(mBaked->volumeCounts, 0u);
        }
        u.volumeCounts.w = (ctx.hasInput("ibl_specular") ? 1u : 0u) | (ctx.hasInput("ibl_diffuse") ? 2u : 0u) |
                           (ctx.hasInput("ao") ? 4u : 0u) | (ctx.hasInput("brdf_lut") ? 8u : 0u);
        if (mScene) u.lights = packPunctualLights(*mScene);
        ctx.setUniforms(u);
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<ShadowCascadesObject> mCascades;
    std::shared_ptr<BakedLightingObject> mBaked;
    std::shared_ptr<SceneObject> mScene;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Deferred>(); });

} // namespace
} // namespace vitrine
