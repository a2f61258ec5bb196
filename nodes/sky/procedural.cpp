// sky.procedural: the Preetham analytic daylight sky in absolute units, as an HDR cube map plus
// its SH9 irradiance and the sun (derived from the same turbidity) for the directional light.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "shaders/sky/sky.h"

#include <cmath>
#include <numbers>
#include <optional>

namespace vitrine {
namespace {

constexpr double kSunAngularRadiusDeg = 0.2665;

NodeSchema schema() {
    NodeSchema s;
    s.type = "sky.procedural";
    s.doc = "Preetham 1999 daylight (Perez distribution, zenith luminance and chromaticity from turbidity) in "
            "cd/m^2 as linear Rec.709, with the sun disk and a Lambertian ground. The sun's illuminance comes from "
            "the same turbidity (Rayleigh, aerosol and ozone transmittance of a 5778 K sun). Y up; sun azimuth "
            "from -Z toward +X.";
    OutputPort cube;
    cube.name = "cubemap";
    cube.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    cube.size = SizeRule::absolute(64, 64);
    cube.persistent = true;
    cube.doc = "Sky radiance cube map (RGBA32F, 6 layers, cd/m^2): the sun disk overflows half floats";
    OutputPort sh;
    sh.name = "sh";
    sh.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    sh.size = SizeRule::absolute(SKY_SH_WIDTH, 1);
    sh.persistent = true;
    sh.doc = "16x1: texels 0-8 SH9 radiance of the sky without the sun, 9 sun illuminance (lux), 10 direction to "
             "the sun, 11 (sun luminance, angular radius, turbidity, 0)";
    s.outputs = {cube, sh};
    s.inputs = {{"scene", PortKind::Scene, {}, true, Usage::Sampled,
                 "When connected, the sun direction is the scene's sun (sun_elevation/sun_azimuth are ignored)"}};
    s.params = {
        {"turbidity",
         ParamType::Float,
         3.0,
         1.7,
         10.0,
         {},
         "Atmospheric turbidity (2 very clear, 3 clear, 6 hazy, 10 murky)"},
        {"sun_elevation", ParamType::Float, 45.0, 0.0, 90.0, {}, "Sun elevation above the horizon, degrees"},
        {"sun_azimuth",
         ParamType::Float,
         0.0,
         -360.0,
         360.0,
         {},
         "Sun azimuth in the XZ plane, degrees from -Z toward +X"},
        {"ground_albedo", ParamType::Float, 0.3, 0.0, 1.0, {}, "Albedo of the Lambertian ground below the horizon"},
        {"intensity", ParamType::Float, 1.0, 1e-4, 1e4, {},
         "Scale of all the sky's light (sky, sun and ground): a brighter or dimmer day, e.g. for camera.physical's "
         "program line to react to; 1 = Preetham's absolute values"},
        {"size", ParamType::Int, 64, 4.0, 2048.0, {}, "Cube map face size in texels"},
        {"sun_in_cubemap",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Draw the sun disk into the cube map (the SH never holds it; off when the sun is lit as a directional light "
         "and the cube map feeds specular IBL)"},
    };
    return s;
}

class Procedural final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto size = static_cast<uint32_t>(ctx.params().getInt("size"));
        ImageDesc& cube = ctx.output("cubemap");
        cube.width = cube.height = size;
        cube.layers = 6;
        cube.cube = true;
        mCubePipeline = ctx.computePipeline("sky/procedural.comp");
        mShPipeline = ctx.computePipeline("sky/procedural_sh.comp");
        if (ctx.hasInput("scene")) {
            auto scene = ctx.objectAs<SceneObject>("scene");
            if (scene->scene().hasSun) mSceneSun = glm::normalize(scene->scene().sun.toSun);
        }
    }
    void execute(ExecuteContext& ctx) override {
        // Both outputs are persistent and depend on params only: one evaluation serves every frame.
        if (ctx.frameIndex() != 0) return;
        const auto& p = ctx.params();
        const double deg = std::numbers::pi / 180.0;
        const double e = p.getFloat("sun_elevation") * deg, a = p.getFloat("sun_azimuth") * deg;
        gpu_types::SkyProceduralPush push{};
        push.toSun =
            glm::vec4(std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a), p.getFloat("turbidity"));
        if (mSceneSun) push.toSun = glm::vec4(*mSceneSun, p.getFloat("turbidity"));
        push.groundAlbedo = p.getFloat("ground_albedo");
        push.sunAngularRadius = static_cast<float>(kSunAngularRadiusDeg * deg);
        push.size = static_cast<uint32_t>(p.getInt("size"));
        push.sunInCubemap = p.getBool("sun_in_cubemap") ? 1u : 0u;
        push.intensity = p.getFloat("intensity");
        ctx.dispatch(mCubePipeline, &push, sizeof(push), push.size, push.size, 6);
        ctx.dispatch(mShPipeline, push, 1, 1);
    }

private:
    PipelineId mCubePipeline = 0;
    PipelineId mShPipeline = 0;
    std::optional<glm::vec3> mSceneSun;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Procedural>(); });

} // namespace
} // namespace vitrine
