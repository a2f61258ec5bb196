// The museum's glass cases through the Museum pipeline (shadows, sky, deferred lighting, forward.transparent) from the
// static camera: image statistics that a broken glass pass fails. The glass changes pixels only inside the projected
// boxes of the cases, it changes enough of them to be seen, and what is behind it stays visible (thin clear glass
// passes most of the light: the luminance ratio with/without glass stays near 1, never black, never blown out).
#include "tests/gpu/gpu_test.hpp"

#include "core/scene/museum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace vitrine::test {
namespace {

using nlohmann::json;

class MuseumGlass : public GpuTest {};

double luma(const float* p) {
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

TEST_F(MuseumGlass, GlassCasesPassTheMuseumImageStatistics) {
    const int W = 320, H = 180;
    json in = {{"scene", "scene.scene"}, {"camera", "scene.camera"}};
    json graph = {
        {"format", "vitrine-graph/1"},
        {"frame", {{"width", W}, {"height", H}}},
        {"nodes",
         {{"scene", {{"type", "scene.museum"}, {"params", {{"texture_size", 64}, {"camera", "static"}}}}},
          {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
          {"shadow", {{"type", "shadow.directional"}, {"in", in}, {"params", {{"resolution", 512}, {"cascades", 2}}}}},
          {"sky",
           {{"type", "sky.procedural"},
            {"in", {{"scene", "scene.scene"}}},
            {"params", {{"size", 16}, {"sun_in_cubemap", false}}}}},
          {"lighting",
           {{"type", "lighting.deferred"},
            {"in",
             {{"normal", "gbuffer.normal"},
              {"base_color", "gbuffer.base_color"},
              {"material", "gbuffer.material"},
              {"emissive", "gbuffer.emissive"},
              {"sheen", "gbuffer.sheen"},
              {"depth", "gbuffer.depth"},
              {"shadow_map", "shadow.shadow_map"},
              {"cascades", "shadow.cascades"},
              {"sky_sh", "sky.sh"},
              {"sky", "sky.cubemap"},
              {"camera", "scene.camera"}}}}},
          {"transparent",
           {{"type", "forward.transparent"},
            {"in",
             {{"scene", "scene.scene"},
              {"color", "lighting.color"},
              {"depth", "gbuffer.depth"},
              {"shadow_map", "shadow.shadow_map"},
              {"cascades", "shadow.cascades"},
              {"sky_sh", "sky.sh"},
              {"sky", "sky.cubemap"},
              {"camera", "scene.camera"}}}}}}},
        {"outputs", {{"opaque", "lighting.color"}, {"glass", "transparent.color"}}}};
    auto out = runGraph(graph);
    const Image& opaque = out.at("opaque");
    const Image& glass = out.at("glass");
    ASSERT_EQ(glass.width, W);

    // Where the cases are on screen: the projected corners of their world boxes (the static camera at t = 0).
    scene::MuseumOptions options;
    options.textureSize = 64;
    scene::Scene s = scene::buildMuseum(options);
    scene::CameraState cam = s.cameraAt("static", 0.0);
    glm::mat4 viewProj = cam.projection(static_cast<float>(W) / H, true) * cam.view;
    std::vector<glm::vec4> boxes; // pixel rectangles: x0, y0, x1, y1
    int cases = 0;
    for (const scene::MeshInstance& inst : s.instances) {
        const scene::Mesh& m = s.meshes[inst.mesh];
        if (!s.materials[s.primitives[m.firstPrimitive].material].transparent()) continue;
        ++cases;
        EXPECT_FALSE(s.primitives[m.firstPrimitive].lightmapUvs) << "glass gets no lightmap UVs";
        glm::vec4 r(1e9f, 1e9f, -1e9f, -1e9f);
        bool behind = false;
        for (int c = 0; c < 8; ++c) {
            glm::vec3 p((c & 1) ? inst.worldBounds.max.x : inst.worldBounds.min.x,
                        (c & 2) ? inst.worldBounds.max.y : inst.worldBounds.min.y,
                        (c & 4) ? inst.worldBounds.max.z : inst.worldBounds.min.z);
            glm::vec4 clip = viewProj * glm::vec4(p, 1.0f);
            if (clip.w <= 0.0f) behind = true;
            glm::vec2 px = (glm::vec2(clip) / clip.w * 0.5f + 0.5f) * glm::vec2(W, H);
            r = glm::vec4(glm::min(glm::vec2(r), px), glm::max(glm::vec2(r.z, r.w), px));
        }
        if (!behind) boxes.push_back(r + glm::vec4(-2.0f, -2.0f, 2.0f, 2.0f));
    }
    EXPECT_EQ(cases, 3); // amphora, ring, medallion
    ASSERT_FALSE(boxes.empty()) << "no glass case in front of the static camera";

    int changed = 0, outside = 0, inBoxes = 0, nonFinite = 0;
    std::vector<double> ratios;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float *g = glass.at(x, y), *o = opaque.at(x, y);
            if (!std::isfinite(g[0]) || !std::isfinite(g[1]) || !std::isfinite(g[2])) ++nonFinite;
            bool inside = std::any_of(boxes.begin(), boxes.end(), [&](const glm::vec4& r) {
                return x + 0.5f >= r.x && x + 0.5f <= r.z && y + 0.5f >= r.y && y + 0.5f <= r.w;
            });
            inBoxes += inside;
            double lg = luma(g), lo = luma(o);
            bool differs = std::abs(lg - lo) > 0.005 * std::max(lo, 1e-3);
            if (!differs) continue;
            if (!inside) {
                ++outside;
                continue;
            }
            ++changed;
            if (lo > 1.0) ratios.push_back(lg / lo);
        }
    std::sort(ratios.begin(), ratios.end());
    auto quantile = [&](double q) {
        return ratios.empty() ? 0.0 : ratios[static_cast<size_t>(q * (ratios.size() - 1))];
    };
    std::printf("museum glass: %zu cases in view (%d px in their boxes), %d px changed by the glass, %d outside; "
                "luminance with/without glass: p5 %.3f, median %.3f, p95 %.3f\n",
                boxes.size(), inBoxes, changed, outside, quantile(0.05), quantile(0.5), quantile(0.95));
    EXPECT_EQ(nonFinite, 0);
    EXPECT_EQ(outside, 0) << "the transparent pass changed pixels away from the glass";
    EXPECT_GT(changed, 100) << "the glass cases are not drawn";
    ASSERT_GT(ratios.size(), 50u);
    // Clear glass: a few percent lost to reflection away, a few gained from reflections of the bright hall.
    EXPECT_GT(quantile(0.5), 0.8);
    EXPECT_LT(quantile(0.5), 1.2);
    EXPECT_GT(quantile(0.05), 0.5); // nothing behind the glass goes dark
    EXPECT_LT(quantile(0.95), 2.0); // nor is it washed out
}

} // namespace
} // namespace vitrine::test
