// The glTF test corpus (tests/data/gltf/corpus/, validated by ctest gltf.validator) rendered: a camera's authored
// aspectRatio does not stretch the image (issue #29 item 5). The marker quad's coverage in the G-buffer is found where
// a pinhole projection written here puts its centre; a morph target moves the silhouette.
#include "tests/gpu/gpu_test.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

namespace vitrine::test {
namespace {

using nlohmann::json;

std::filesystem::path corpus(const std::string& name) {
    return std::filesystem::path(VITRINE_SOURCE_DIR) / "tests" / "data" / "gltf" / "corpus" / name;
}

glm::dvec3 expectedMarker(const std::string& file) {
    std::ifstream in(corpus(file));
    json doc = json::parse(in);
    const json& p = doc["asset"]["extras"]["expect"]["marker_view_space"];
    return {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()};
}

// Centroid (pixel units, origin top-left corner) of the pixels that the marker covers in gbuffer.depth.
glm::dvec2 markerCentroid(const std::string& file, int w, int h, int& pixels) {
    json graph = {{"format", "vitrine-graph/1"},
                  {"frame", {{"width", w}, {"height", h}}},
                  {"nodes",
                   {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", corpus(file).string()}, {"jitter", "off"}}}}},
                    {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
                  {"outputs", {{"depth", "gbuffer.depth"}}}};
    Image depth = runGraph(graph).at("depth"); // reverse Z: 0 where nothing was drawn
    glm::dvec2 sum(0.0);
    pixels = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (depth.at(x, y)[0] > 0.0f) {
                sum += glm::dvec2(x + 0.5, y + 0.5);
                ++pixels;
            }
    return pixels ? sum / double(pixels) : glm::dvec2(-1.0);
}

class GltfCorpus : public GpuTest {};

TEST_F(GltfCorpus, PerspectiveCameraKeepsItsVerticalFieldOfViewInASquareFrame) {
    // yfov 0.8, aspectRatio 1.5 in the file; the frame is square. Camera at the origin looking down -Z.
    const int w = 128, h = 128;
    glm::dvec3 p = expectedMarker("camera_aspect.gltf");
    double g = 1.0 / std::tan(0.4), frameAspect = double(w) / h;
    glm::dvec2 ndc(g * p.x / -p.z / frameAspect, -g * p.y / -p.z);
    glm::dvec2 want((ndc.x + 1) * 0.5 * w, (ndc.y + 1) * 0.5 * h);
    int pixels = 0;
    glm::dvec2 got = markerCentroid("camera_aspect.gltf", w, h, pixels);
    // Stretched by the authored 1.5 the marker would sit at x = (0.4 + 1) / 2 × 128 = 89.6 and be 2/3 as wide.
    std::printf("perspective marker: centroid (%.2f, %.2f), expected (%.2f, %.2f), %d pixels\n", got.x, got.y, want.x,
                want.y, pixels);
    double side = 2 * 0.15 * g / -p.z * 0.5 * h; // the marker's edge in pixels, square when unstretched
    EXPECT_NEAR(pixels, side * side, 0.2 * side * side);
    EXPECT_LT(glm::distance(got, want), 0.3);
}

TEST_F(GltfCorpus, OrthographicCameraFitsItsAuthoredWidthInASquareFrame) {
    // xmag 2, ymag 1 in the file; square frame: xmag kept, ymag = xmag (the Sample Viewer's rule).
    const int w = 128, h = 128;
    glm::dvec3 p = expectedMarker("camera_ortho.gltf");
    glm::dvec2 ndc(p.x / 2.0, -p.y / 2.0);
    glm::dvec2 want((ndc.x + 1) * 0.5 * w, (ndc.y + 1) * 0.5 * h);
    int pixels = 0;
    glm::dvec2 got = markerCentroid("camera_ortho.gltf", w, h, pixels);
    std::printf("orthographic marker: centroid (%.2f, %.2f), expected (%.2f, %.2f), %d pixels\n", got.x, got.y, want.x,
                want.y, pixels);
    double side = 2 * 0.15 / 2.0 * 0.5 * w;
    EXPECT_NEAR(pixels, side * side, 0.25 * side * side);
    EXPECT_LT(glm::distance(got, want), 0.3);
}

// Covered pixels in the middle row of gbuffer.depth for a morph corpus file at time `start`.
int middleRowWidth(const std::string& file, int w, int h, double start, int frames) {
    json graph = {{"format", "vitrine-graph/1"},
                  {"frame", {{"width", w}, {"height", h}, {"frames", frames}}},
                  {"nodes",
                   {{"scene",
                     {{"type", "scene.gltf"},
                      {"params", {{"path", corpus(file).string()}, {"jitter", "off"}, {"start", start}, {"fps", 1}}}}},
                    {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
                  {"outputs", {{"depth", "gbuffer.depth"}}}};
    Image depth = runGraph(graph).at("depth"); // reverse Z: 0 where nothing was drawn
    int covered = 0;
    for (int x = 0; x < w; ++x)
        covered += depth.at(x, h / 2)[0] > 0.0f;
    return covered;
}

// The cube spans x in [-0.5, 0.5] plus 1 × weight on its +X face; the orthographic camera shows 4 m across W pixels.
TEST_F(GltfCorpus, MorphTargetAtWeightHalfMovesTheSilhouetteHalfAUnit) {
    const int w = 128, h = 128;
    auto pixelsFor = [&](double weight) { return (0.5 + weight + 0.5) / 4.0 * w; };
    int still = middleRowWidth("morph_cube.gltf", w, h, 0.0, 1);
    // Animated weights 0 -> 1 over 2 s: frame 1 at fps 1 from start 0 is t = 1, weight 0.5; frame 0 (t = 0) is 0.
    int animatedAtZero = middleRowWidth("morph_animated.gltf", w, h, 0.0, 1);
    int animatedAtOne = middleRowWidth("morph_animated.gltf", w, h, 0.0, 2);
    std::printf("middle row: default weight 0.5 %d px, animated t=0 %d px, t=1 %d px (expected %.0f, %.0f, %.0f)\n",
                still, animatedAtZero, animatedAtOne, pixelsFor(0.5), pixelsFor(0.0), pixelsFor(0.5));
    EXPECT_NEAR(still, pixelsFor(0.5), 1.0);
    EXPECT_NEAR(animatedAtZero, pixelsFor(0.0), 1.0);
    EXPECT_NEAR(animatedAtOne, pixelsFor(0.5), 1.0);
}

// skin_bend.gltf at t = 0 (straight) and t = 1 (joint 1 turned 90°): the orthographic camera (xmag = ymag = 2 at
// (0, 1, 5)) maps (x, y) to pixel ((x + 2) / 4 × W, (3 − y) / 4 × H). CPU skinning puts the bent upper bone along
// y = 1 from x = 0 to −1 (0.2 wide): the pixel at (−0.73, 0.98) is covered at t = 1 only, (0, 1.73) at t = 0 only.
TEST_F(GltfCorpus, SkinnedTwoBoneBendDrawsWhereCpuSkinningPutsIt) {
    const int w = 128, h = 128;
    auto depthAt = [&](int frames) {
        json graph = {{"format", "vitrine-graph/1"},
                      {"frame", {{"width", w}, {"height", h}, {"frames", frames}}},
                      {"nodes",
                       {{"scene",
                         {{"type", "scene.gltf"},
                          {"params", {{"path", corpus("skin_bend.gltf").string()}, {"jitter", "off"}, {"fps", 1}}}}},
                        {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
                      {"outputs", {{"depth", "gbuffer.depth"}}}};
        return runGraph(graph).at("depth");
    };
    auto covered = [&](const Image& depth, double x, double y) {
        int px = static_cast<int>((x + 2.0) / 4.0 * w), py = static_cast<int>((3.0 - y) / 4.0 * h);
        return depth.at(px, py)[0] > 0.0f;
    };
    Image straight = depthAt(1), bent = depthAt(2);
    std::printf("skin: straight (0, 1.73) %d (-0.73, 0.98) %d; bent (0, 1.73) %d (-0.73, 0.98) %d\n",
                covered(straight, 0.0, 1.73), covered(straight, -0.73, 0.98), covered(bent, 0.0, 1.73),
                covered(bent, -0.73, 0.98));
    EXPECT_TRUE(covered(straight, 0.0, 1.73));
    EXPECT_FALSE(covered(straight, -0.73, 0.98));
    EXPECT_FALSE(covered(bent, 0.0, 1.73));
    EXPECT_TRUE(covered(bent, -0.73, 0.98));
    EXPECT_TRUE(covered(bent, 0.0, 0.5)); // the lower bone stays
}

// gbuffer.velocity (pixels, this frame minus last) of vertices the CPU deforms every frame (fps 1) against the motion
// of the same surface point between the two frames worked out here:
// - morph_animated.gltf at frame 2 (t = 2 s, the last at t = 1; the rest weight is 0, so last frame is not the rest
//   pose): the front face spans x in [-0.5, 0.5 + w(t)], w = t / 2 (the orthographic camera shows 4 m across W pixels
//   from x = -2); the point at fraction f of the face moves by f (w(2) - w(1)) = f / 2 m to the right;
// - skin_bend.gltf at frame 1 (t = 1, the last at t = 0):
//   the upper bone (rows 1.5-2, weight 1 on joint 1) turned 90° about Z round the joint at (0, 1), so
//   the point p at t = 1 was at (0, 1) + R(-90°)(p - (0, 1)) = (p.y - 1, 1 - p.x) at t = 0.
TEST_F(GltfCorpus, VelocityFollowsMorphedAndSkinnedVertices) {
    const int w = 128, h = 128;
    auto velocity = [&](const std::string& file, int frames) {
        json graph = {
            {"format", "vitrine-graph/1"},
            {"frame", {{"width", w}, {"height", h}, {"frames", frames}}},
            {"nodes",
             {{"scene",
               {{"type", "scene.gltf"},
                {"params", {{"path", corpus(file).string()}, {"jitter", "off"}, {"start", 0.0}, {"fps", 1}}}}},
              {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
            {"outputs", {{"velocity", "gbuffer.velocity"}, {"depth", "gbuffer.depth"}}}};
        return runGraph(graph);
    };
    // Half-float velocities of up to 24 px: steps of 1/64 px.
    const double tolerance = 0.05;
    {
        auto images = velocity("morph_animated.gltf", 3);
        const Image& v = images.at("velocity");
        int checked = 0;
        for (int px = 0; px < w; px += 3) {
            const double x1 = (px + 0.5) / w * 4.0 - 2.0;
            if (x1 < -0.45 || x1 > 1.45) continue; // on the front face at t = 2, away from its edges
            ASSERT_GT(images.at("depth").at(px, h / 2)[0], 0.0f) << px;
            const double f = (x1 + 0.5) / 2.0, x0 = -0.5 + f * 1.5;
            const double want = (x1 - x0) / 4.0 * w;
            EXPECT_NEAR(v.at(px, h / 2)[0], want, tolerance) << "morph: pixel " << px;
            EXPECT_NEAR(v.at(px, h / 2)[1], 0.0, tolerance) << "morph: pixel " << px;
            ++checked;
        }
        EXPECT_GE(checked, 10);
    }
    {
        auto images = velocity("skin_bend.gltf", 2);
        const Image& v = images.at("velocity");
        int checked = 0;
        for (int px = 0; px < w; ++px) {
            for (int py = 0; py < h; ++py) {
                const double x1 = (px + 0.5) / w * 4.0 - 2.0, y1 = 3.0 - (py + 0.5) / h * 4.0;
                if (x1 < -0.95 || x1 > -0.55 || std::abs(y1 - 1.0) > 0.08) continue; // the upper bone's outer half
                ASSERT_GT(images.at("depth").at(px, py)[0], 0.0f) << px << ", " << py;
                const double x0 = y1 - 1.0, y0 = 1.0 - x1;
                EXPECT_NEAR(v.at(px, py)[0], (x1 - x0) / 4.0 * w, tolerance) << "skin: pixel " << px << ", " << py;
                EXPECT_NEAR(v.at(px, py)[1], (y0 - y1) / 4.0 * h, tolerance) << "skin: pixel " << px << ", " << py;
                ++checked;
            }
        }
        EXPECT_GE(checked, 20);
    }
}

} // namespace
} // namespace vitrine::test
