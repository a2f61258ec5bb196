// ssr.composite: the indirect specular of lighting.deferred replaced by SSR where it found something (MUSEUM_SPEC §5).
#include "shaders/ssr/composite.h"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "ssr.composite";
    s.doc =
        "Blends the environment's indirect specular with SSR by the SSR confidence c and writes the final "
        "colour: color - I + mix(I, E L_ssr vertexAO cavity, c), where I is lighting.deferred's "
        "specular_indirect and E the split-sum environment BRDF that weighs I: with brdf_lut connected, f0 A + f90 B "
        "from that LUT (ibl.capture's, which ibl.localized weighs the probes with), else Karis' analytic fit that "
        "lighting.deferred weighs the sky or the volume with (shaders/lighting/ambient.glsl; 16 % low for a dielectric "
        "at grazing views, NoV 0.15-0.25, 23 % high at NoV 0.7). The reflection is premultiplied (c L_ssr, c) and "
        "upsampled bilinearly, so pixels that found nothing lower the confidence of their neighbours' mix without "
        "darkening it.";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", "Lit HDR colour that includes specular_indirect (lighting.color)"),
        tex("specular_indirect", "The environment's indirect specular inside color (lighting.specular_indirect)"),
        tex("reflection",
            "ssr.hiz's reflection (or its temporal accumulation): rgb radiance x confidence, a confidence"),
        tex("normal", "G-buffer: octahedral normal, view depth, shininess"),
        tex("base_color", "G-buffer: base colour, metallic"),
        tex("material", "G-buffer: alpha, 1 − specular strength, vertex AO, cavity"),
        tex("depth", "Hardware depth, reverse Z"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
        tex("brdf_lut",
            "Split-sum BRDF LUT, (NoV, roughness) -> (A, B) (ibl.capture.brdf_lut): E = f0 A + f90 B, the factor "
            "ibl.localized weighs the probes with. Connect it where I comes from ibl.localized; without it E is "
            "Karis' fit, as lighting.deferred's sky and volume terms",
            true),
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "HDR colour with SSR in place of the environment where it is confident";
    OutputPort specular;
    specular.name = "specular_indirect";
    specular.formatFrom = "specular_indirect";
    specular.size = SizeRule::ofInput("color");
    specular.doc = "The indirect specular term now inside color, mix(I, E L_ssr vertexAO cavity, c) (0 where nothing "
                   "is drawn): what reference.reflections estimates by tracing";
    s.outputs = {color, specular};
    s.params = {
        {"multiscatter",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "SSR's reflection weighed with the GGX lobe's multiple scattering, E (1 + f0 (1 - E_fit) / E_fit) (as "
         "lighting.deferred's and ibl.localized's multiscatter; common/brdf.glsl ggxMultiscatter)"},
    };
    return s;
}

class SsrComposite final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        ShaderDefines defines;
        if (ctx.params().getBool("multiscatter")) defines.push_back({"VITRINE_MULTISCATTER_ENVIRONMENT", "1"});
        mPipeline = ctx.computePipeline("ssr/composite.comp", defines);
        mLut = ctx.hasInput("brdf_lut");
    }
    void execute(ExecuteContext& ctx) override {
        const CameraFrame& cam = mCamera->current;
        gpu_types::SsrCompositeUniforms u{};
        u.invViewProj = cam.invViewProj;
        u.cameraPos = glm::vec4(cam.state.position, 1.0f);
        u.config = {mLut ? 1u : 0u, 0u, 0u, 0u};
        ctx.setUniforms(u);
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mPipeline = 0;
    bool mLut = false;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<SsrComposite>(); });

} // namespace
} // namespace vitrine
