// sky.hdri: an equirectangular HDR image as the sky: cube map, SH9 without the sun, and the sun
// found in the image (direction and illuminance) for the directional light.
#include "core/base/error.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/shading/environment.hpp"
#include "shaders/sky/sky.h"

#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "sky.hdri";
    s.doc = "Equirectangular .hdr/.exr sky (centre looks down -Z, Y up) as a cube map and the sky nodes' `sh` "
            "texture. The sun is the bright region around the brightest pixel; its illuminance is integrated and "
            "removed from the SH. No sun (nothing 100x above the median) gives sun illuminance 0.";
    OutputPort cube;
    cube.name = "cubemap";
    cube.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    cube.size = SizeRule::absolute(64, 64);
    cube.usage = Usage::TransferDst;
    cube.persistent = true;
    cube.doc = "Environment radiance cube map (RGBA32F, 6 layers), the file's values times intensity";
    OutputPort sh;
    sh.name = "sh";
    sh.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    sh.size = SizeRule::absolute(SKY_SH_WIDTH, 1);
    sh.usage = Usage::TransferDst;
    sh.persistent = true;
    sh.doc = "16x1: texels 0-8 SH9 radiance without the sun, 9 sun illuminance, 10 direction to the sun, 11 (sun "
             "mean radiance luminance, equivalent angular radius, 0, 0)";
    s.outputs = {cube, sh};
    s.inputs = {{"scene", PortKind::Scene, {}, true, Usage::Sampled,
                 "When connected and the scene has a sun (its directional light, or scene.gltf's key_light), that is "
                 "the sun: its direction and colour, sun_illuminance lux (the image's own sun, if any, stays out of "
                 "the SH and is not the light), so the light matches shadow.directional's"}};
    s.params = {
        {"path", ParamType::Path, "", {}, {}, {}, "Equirectangular .hdr or .exr, relative to the graph file"},
        {"intensity", ParamType::Float, 1.0, 0.0, 1e9, {}, "Multiplier taking the file's values to cd/m^2"},
        {"size", ParamType::Int, 64, 4.0, 2048.0, {}, "Cube map face size in texels"},
        {"sun_in_cubemap", ParamType::Bool, true, {}, {}, {}, "Keep the sun in the cube map (the SH never holds it)"},
        {"sun_illuminance", ParamType::Float, 100000.0, 0.0, 1e7, {},
         "With a scene sun (the scene input): its illuminance in lux on a surface facing it (x the sun's colour)"},
    };
    return s;
}

class Hdri final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        std::string path = p.getString("path");
        if (path.empty()) ctx.failParam("path", "expected the path of an equirectangular .hdr or .exr file");
        Image image;
        try {
            image = loadImage(ctx.resolvePath(path));
        } catch (const UserError& e) {
            ctx.failParam("path", e.what());
        }
        const int size = p.getInt("size");
        shading::EnvironmentBake bake = shading::bakeEquirect(image.pixels.data(), image.width, image.height, size,
                                                              p.getFloat("intensity"), p.getBool("sun_in_cubemap"));
        for (int face = 0; face < 6; ++face) {
            mFaces[face] = Image(size, size);
            mFaces[face].pixels = std::move(bake.faces[face]);
        }
        mSh = Image(SKY_SH_WIDTH, 1);
        auto set = [&](int texel, glm::dvec3 v, double w) {
            float* t = mSh.at(texel, 0);
            t[0] = static_cast<float>(v.x);
            t[1] = static_cast<float>(v.y);
            t[2] = static_cast<float>(v.z);
            t[3] = static_cast<float>(w);
        };
        for (int i = 0; i < 9; ++i)
            set(i, bake.sh.c[i], 0.0);
        set(SKY_TEXEL_SUN_ILLUMINANCE, bake.sun.illuminance, 0.0);
        set(SKY_TEXEL_SUN_DIRECTION, bake.sun.direction, 0.0);
        if (bake.sun.found) {
            double omega = bake.sun.solidAngle;
            double radiance = (0.2126729 * bake.sun.illuminance.x + 0.7151522 * bake.sun.illuminance.y +
                               0.0721750 * bake.sun.illuminance.z) /
                              omega;
            set(SKY_TEXEL_SUN_INFO, {radiance, std::acos(1.0 - omega / (2.0 * 3.14159265358979323846)), 0.0}, 0.0);
        }
        if (ctx.hasInput("scene")) {
            const scene::Scene& scene = ctx.objectAs<SceneObject>("scene")->scene();
            if (scene.hasSun) {
                const glm::dvec3 illuminance = glm::dvec3(scene.sun.color) * static_cast<double>(p.getFloat("sun_illuminance"));
                const double radius = 0.5 * scene.sun.angularDiameter;
                const double omega = 2.0 * 3.14159265358979323846 * (1.0 - std::cos(radius));
                const double luminance = 0.2126729 * illuminance.x + 0.7151522 * illuminance.y + 0.0721750 * illuminance.z;
                set(SKY_TEXEL_SUN_ILLUMINANCE, illuminance, 0.0);
                set(SKY_TEXEL_SUN_DIRECTION, glm::normalize(glm::dvec3(scene.sun.toSun)), 0.0);
                set(SKY_TEXEL_SUN_INFO, {luminance / omega, radius, 0.0}, 0.0);
            }
        }
        ImageDesc& cube = ctx.output("cubemap");
        cube.width = cube.height = static_cast<uint32_t>(size);
        cube.layers = 6;
        cube.cube = true;
    }
    void execute(ExecuteContext& ctx) override {
        // Both outputs are persistent: one upload serves every frame.
        if (ctx.frameIndex() != 0) return;
        for (uint32_t face = 0; face < 6; ++face)
            ctx.upload("cubemap", mFaces[face], face);
        ctx.upload("sh", mSh);
    }

private:
    Image mFaces[6];
    Image mSh;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Hdri>(); });

} // namespace
} // namespace vitrine
