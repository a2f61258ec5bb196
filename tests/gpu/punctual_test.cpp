// KHR_lights_punctual point and spot lights and KHR_materials_unlit through the deferred path, against CPU values:
// a wall lit only by a point light (with glTF's range window) and a spot light (with its cone), by core/shading's
// BRDF; an unlit quad whose radiance is its base colour. The scene is written as a .glb (exportGlb) and loaded
// through scene.gltf, so the file's light nodes, cones and material extensions are what is measured.
#include "tests/gpu/lighting_scene.hpp"

#include "core/shading/brdf.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

class Punctual : public GpuTest {};

// glTF's recommended falloff: the illuminance (rgb, lux) of light L at p, facing it.
glm::dvec3 cpuIlluminance(const scene::PunctualLight& L, glm::dvec3 lightPos, glm::dvec3 p, glm::dvec3& toLight) {
    glm::dvec3 d = lightPos - p;
    double dist = glm::length(d);
    toLight = d / dist;
    double window = 1.0;
    if (L.range > 0.0f) window = std::pow(std::clamp(1.0 - std::pow(dist / L.range, 4.0), 0.0, 1.0), 2.0);
    double e = L.intensity * window / (dist * dist);
    if (L.type == scene::LightType::Spot) {
        double cd = glm::dot(glm::dvec3(0, 0, -1), -toLight); // the node is unrotated: the spot shines down -Z
        double cosOuter = std::cos(L.outerConeAngle), cosInner = std::cos(L.innerConeAngle);
        double t = std::clamp((cd - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
        e *= t * t;
    }
    return glm::dvec3(L.color) * e;
}

TEST_F(Punctual, PointAndSpotLightsAndUnlitMatchCpu) {
    const int W = 80, H = 80;
    const glm::vec3 wallColor(153.0f / 255.0f, 128.0f / 255.0f, 102.0f / 255.0f), unlitColor(0.25f, 0.5f, 0.75f);
    const float wallShininess = 0.5f;
    SceneBuilder b("punctual_unlit");
    std::vector<Tri> wall, sticker;
    addQuad(wall, glm::vec3(0.0f), glm::vec3(1.5f, 0, 0), glm::vec3(0, 1.5f, 0), glm::vec3(0, 0, 1));
    addQuad(sticker, glm::vec3(-0.7f, 0.7f, 0.3f), glm::vec3(0.25f, 0, 0), glm::vec3(0, 0.25f, 0), glm::vec3(0, 0, 1));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, b.material("wall", wallColor, 0.0f, wallShininess))));
    uint32_t unlit = b.material("sticker", unlitColor, 0.0f, 0.5f);
    b.s.materials[unlit].unlit = true;
    b.node("sticker", static_cast<int32_t>(b.mesh("sticker", sticker, unlit)));
    scene::PunctualLight point, spot;
    point.color = {1.0f, 0.9f, 0.8f};
    point.intensity = 5.0f;
    point.range = 2.0f; // the window reaches zero inside the frame
    spot.type = scene::LightType::Spot;
    spot.color = {0.6f, 0.8f, 1.0f};
    spot.intensity = 8.0f;
    spot.innerConeAngle = 0.15f;
    spot.outerConeAngle = 0.3f;
    const glm::dvec3 pointPos(0.5, 0.3, 0.8), spotPos(-0.3, -0.4, 1.2);
    b.node("bulb", -1, glm::vec3(pointPos));
    point.node = static_cast<uint32_t>(b.s.nodes.size() - 1);
    b.node("spot", -1, glm::vec3(spotPos));
    spot.node = static_cast<uint32_t>(b.s.nodes.size() - 1);
    b.s.lights = {point, spot};
    b.camera({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.9f);

    json nodes = baseNodes(b.write());
    nodes["lighting"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", 0.0}}, false);
    nodes["lighting"]["in"]["scene"] = "scene.scene";
    nodes["no_lights"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", 0.0}}, false);
    auto out = runGraph(graph(
        nodes,
        {{"lit", "lighting.color"}, {"dark", "no_lights.color"}, {"base", "gbuffer.base_color"}, {"mat", "gbuffer.material"}},
        W, H));

    Pinhole cam(b.s, W, H);
    int wallPixels = 0, unlitPixels = 0, spotPixels = 0, beyondRange = 0;
    double worstWall = 0.0, worstUnlit = 0.0;
    const double roughness = shading::roughnessFromShininess(wallShininess);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            glm::dvec3 got = rgb(out.at("lit"), x, y);
            double ts = (0.3 - cam.position.z) / d.z;
            glm::dvec3 ps = cam.position + ts * d;
            if (std::abs(ps.x + 0.7) < 0.22 && std::abs(ps.y - 0.7) < 0.22) {
                // R11G11B10: 6 (5 for blue) mantissa bits, half a step is under 1.6 %.
                double e = relErr(got, glm::dvec3(unlitColor));
                worstUnlit = std::max(worstUnlit, e);
                EXPECT_LT(e, 0.016) << "unlit pixel " << x << "," << y << ": " << got.r << " vs " << unlitColor.r;
                // No light term may add to it, whatever scales with base colour or cavity (lightmaps too): both zero.
                EXPECT_EQ(rgb(out.at("base"), x, y), glm::dvec3(0.0)) << "unlit base colour, " << x << "," << y;
                EXPECT_EQ(out.at("mat").at(x, y)[3], 0.0f) << "unlit cavity, " << x << "," << y;
                ++unlitPixels;
                continue;
            }
            if (std::abs(ps.x + 0.7) < 0.28 && std::abs(ps.y - 0.7) < 0.28) continue; // the sticker's edge
            double t = -cam.position.z / d.z;
            glm::dvec3 p = cam.position + t * d;
            if (std::abs(p.x) > 1.45 || std::abs(p.y) > 1.45) continue;
            glm::dvec3 expected(0.0);
            glm::dvec3 l;
            glm::dvec3 ep = cpuIlluminance(point, pointPos, p, l);
            expected += ep * glm::dvec3(shading::brdfCosine(glm::vec3(0, 0, 1), glm::vec3(-d), glm::vec3(l),
                                                            unorm8(wallColor), 0.0f, static_cast<float>(roughness)));
            glm::dvec3 es = cpuIlluminance(spot, spotPos, p, l);
            expected += es * glm::dvec3(shading::brdfCosine(glm::vec3(0, 0, 1), glm::vec3(-d), glm::vec3(l),
                                                            unorm8(wallColor), 0.0f, static_cast<float>(roughness)));
            if (es.g > 0.0) ++spotPixels;
            if (ep.g == 0.0) ++beyondRange;
            // Where the lit value is tiny (cone and range edges) compare absolutely: RGBA16F and the 16-bit normal.
            double e = glm::length(got - expected) / std::max(glm::length(expected), 0.02);
            worstWall = std::max(worstWall, e);
            EXPECT_LT(e, 0.01) << "wall pixel " << x << "," << y << ": " << got.r << " vs " << expected.r;
            EXPECT_EQ(rgb(out.at("dark"), x, y), glm::dvec3(0.0))
                << "without the scene input no light, " << x << "," << y;
            ++wallPixels;
        }
    std::printf("punctual: %d wall pixels (%d in the spot's cone, %d beyond the point's range), max error %.2g; unlit: "
                "%d pixels, max relative error %.2g\n",
                wallPixels, spotPixels, beyondRange, worstWall, unlitPixels, worstUnlit);
    EXPECT_GE(wallPixels, 3000);
    EXPECT_GE(spotPixels, 100);
    EXPECT_GE(beyondRange, 100);
    EXPECT_GE(unlitPixels, 50);
}

} // namespace
} // namespace vitrine::test
