// The scene nodes and the GPU scene on a real device: Toksvig normal-map mips as uploaded, the museum's
// G-buffer from its own cameras (statistics that a broken G-buffer fails), and the user errors of
// scene.gltf / scene.museum. The CPU determinism of the museum (same seed, same contentHash; other seed,
// other hash) is tests/unit/scene/test_museum.cpp's IsDeterministicFromTheSeed and is not repeated here.
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/gpu/transfer.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/shader/compiler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace sc = vitrine::scene;

class SceneGpu : public GpuTest {};

// ---------------------------------------------------------------------------------------------
// Toksvig mips, read back from the uploaded texture

// A finalized scene of one triangle whose material's only layer is normal-mapped by `image` (a TextureUsage::Normal
// texture, so GpuScene builds its Toksvig mip chain).
sc::Scene sceneWithNormalMap(const std::string& name, const sc::TextureImage& image) {
    sc::Scene s;
    s.name = name;
    s.images.push_back(image);
    sc::Texture tex;
    tex.name = image.name;
    tex.usage = sc::TextureUsage::Normal;
    s.textures.push_back(tex);
    sc::Material m;
    m.name = "normal_mapped";
    m.layers.resize(1);
    m.layers[0].normal.texture.texture = 0;
    s.materials.push_back(m);
    for (int i = 0; i < 3; ++i) {
        sc::Vertex v;
        v.position = glm::vec3(i == 1, i == 2, 0);
        v.normal = {0, 0, 1};
        s.vertices.push_back(v);
        s.indices.push_back(static_cast<uint32_t>(i));
    }
    s.primitives.push_back({0, 3, 0, 3, 0, {}});
    s.meshes.push_back({"tri", 0, 1, {}});
    sc::Node node;
    node.name = "tri";
    node.mesh = 0;
    s.nodes.push_back(node);
    s.finalize();
    s.validate();
    return s;
}

// An n x n normal map: texel (x, y) (visited row by row) holds normal(x, y).first, normalised and encoded to 8 bits,
// and .second as its alpha.
template <class Normal> sc::TextureImage normalMapImage(const char* name, uint32_t n, Normal normal) {
    sc::TextureImage img;
    img.name = name;
    img.width = img.height = n;
    img.pixels.resize(n * n * 4);
    for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
            const auto [direction, alpha] = normal(x, y);
            const glm::dvec3 e = glm::round((glm::normalize(direction) * 0.5 + 0.5) * 255.0);
            uint8_t* p = img.at(x, y);
            p[0] = static_cast<uint8_t>(e.x);
            p[1] = static_cast<uint8_t>(e.y);
            p[2] = static_cast<uint8_t>(e.z);
            p[3] = alpha;
        }
    return img;
}

TEST_F(SceneGpu, NormalMapMipsAreUnnormalisedAverages) {
    // 16x16 normal map: columns alternate ±45° about +Y, with an irregular y tilt per texel, so the
    // 2x2 footprints differ and the averages are clearly shorter than 1.
    const uint32_t n = 16;
    uint32_t state = 99;
    const sc::TextureImage img = normalMapImage("ridges", n, [&](uint32_t x, uint32_t) {
        state = state * 1664525u + 1013904223u;
        double ty = ((state >> 24) / 255.0 - 0.5) * 0.6;
        double sx = x % 2 ? 1.0 : -1.0;
        // Alpha: junk, a normal texture's alpha means nothing.
        return std::pair{glm::dvec3(sx, ty, 1.0), static_cast<uint8_t>((state >> 8) & 0xff)};
    });
    // Alpha of level m: sqrt(1 - L), L the agreement of the core of the normals under the texel (toksvig_mip.comp):
    // a level-0 texel has L = 1 and its decoded normal's direction (the bytes' own lengths are rounding, not
    // disagreement); a texel of level m+1 has the direction of the plain mean of the decoded normals under it and
    // L = (the largest L of its four children) x |mean of the children's unit directions|.
    struct Texel {
        glm::dvec3 direction;
        double agreement;
    };
    std::function<Texel(uint32_t, uint32_t, uint32_t)> texel = [&](uint32_t level, uint32_t x, uint32_t y) -> Texel {
        if (level == 0) {
            const uint8_t* p = img.at(x, y);
            return {glm::normalize(glm::dvec3(p[0], p[1], p[2]) / 255.0 * 2.0 - 1.0), 1.0};
        }
        glm::dvec3 sum(0.0);
        const uint32_t k = 1u << level;
        for (uint32_t j = 0; j < k; ++j)
            for (uint32_t i = 0; i < k; ++i) {
                const uint8_t* p = img.at(x * k + i, y * k + j);
                sum += glm::dvec3(p[0], p[1], p[2]) / 255.0 * 2.0 - 1.0;
            }
        glm::dvec3 directions(0.0);
        double core = 0.0;
        for (uint32_t c = 0; c < 4; ++c) {
            const Texel child = texel(level - 1, 2 * x + c % 2, 2 * y + c / 2);
            directions += child.direction;
            core = std::max(core, child.agreement);
        }
        return {glm::normalize(sum), core * glm::length(directions / 4.0)};
    };
    auto expectedAlpha = [&](uint32_t level, uint32_t x, uint32_t y) {
        return std::sqrt(std::max(1.0 - texel(level, x, y).agreement, 0.0));
    };
    const sc::Scene s = sceneWithNormalMap("toksvig_mips", img);

    ShaderCompiler shaders;
    GpuScene gpuScene(gpu(), shaders, s);
    const GpuImage& image = gpuScene.texture(0);
    ASSERT_EQ(image.desc().mipLevels, 5u);

    // Level m+1 from the bytes of level m (the GPU's own level m from 2 on): the plain average of the
    // decoded normals, re-encoded. Decoding and re-encoding cancel, so the expected byte is the mean of
    // the four bytes; a tie (x.5) may round either way.
    std::vector<double> below(img.pixels.begin(), img.pixels.end()); // bytes, level 0
    double worst = 0.0, meanLength = 0.0, worstAlpha = 0.0, meanAlpha = 0.0;
    {
        Image level0 = readImage(gpu(), image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0);
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) worstAlpha = std::max(worstAlpha, double(level0.at(x, y)[3]) * 255.0);
    }
    for (uint32_t level = 1; level < 5; ++level) {
        const uint32_t s0 = n >> (level - 1), s1 = n >> level;
        Image got = readImage(gpu(), image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, level);
        ASSERT_EQ(got.width, static_cast<int>(s1));
        std::vector<double> bytes(s1 * s1 * 4);
        for (uint32_t y = 0; y < s1; ++y)
            for (uint32_t x = 0; x < s1; ++x) {
                const double alpha = expectedAlpha(level, x, y);
                worstAlpha = std::max(worstAlpha, std::fabs(got.at(x, y)[3] * 255.0 - alpha * 255.0));
                meanAlpha += alpha / (s1 * s1) / 4.0;
                for (int c = 0; c < 3; ++c) {
                    double sum = 0.0;
                    for (int k = 0; k < 4; ++k) sum += below[((2 * y + k / 2) * s0 + 2 * x + k % 2) * 4 + c];
                    double g = std::round(got.at(x, y)[c] * 255.0);
                    worst = std::max(worst, std::fabs(g - sum / 4.0));
                    bytes[(y * s1 + x) * 4 + c] = g;
                }
                if (level == 1) {
                    const float* t = got.at(x, y);
                    meanLength += glm::length(glm::dvec3(t[0], t[1], t[2]) * 2.0 - 1.0) / (s1 * s1);
                }
            }
        below = std::move(bytes);
    }
    std::printf("toksvig mips: max deviation from the 2x2 byte mean %.3f (ties: 0.5), mean |n| of level 1 %.4f; alpha: "
                "worst %.2f of 255 from sqrt(1 - L of the core) (mean %.3f), level 0 must be 0\n",
                worst, meanLength, worstAlpha, meanAlpha);
    EXPECT_LE(worst, 0.5 + 1e-6);
    // Alpha is rounded once per level from the level below (rounded directions and alphas): measured 0.9 here.
    EXPECT_LE(worstAlpha, 1.5);
    EXPECT_GT(meanAlpha, 0.3); // the levels really disagree
    // ±45° columns average to ~cos 45°: not renormalised.
    EXPECT_NEAR(meanLength, 0.71, 0.03);
}

// A flat normal map with one narrow V-groove (columns 4 and 5 tilted 45° to either side, the museum floor's grout in
// miniature). Where the groove is resolved (level 1: the texel holding both columns) its disagreement counts:
// |mean| = cos 45°, alpha = sqrt(1 - 0.707) = 0.54. Above that the groove's texel points straight up like its
// flat siblings, so the core agrees (alpha 0), where plain Toksvig (the mean of all the unit normals under the
// texel) would still read 1 - L = 0.073 on level 2 (alpha 0.27) and 0.018 on level 4: a lobe widened over the whole
// footprint by a few steep texels.
TEST_F(SceneGpu, NormalMapMipsKeepTheCoresSpreadNotAGroovesAbove) {
    const uint32_t n = 16;
    const sc::TextureImage img = normalMapImage("groove", n, [](uint32_t x, uint32_t) {
        const double sx = x == 4 ? -1.0 : x == 5 ? 1.0 : 0.0;
        return std::pair{glm::dvec3(sx, 0.0, 1.0), uint8_t(255)};
    });
    const sc::Scene s = sceneWithNormalMap("toksvig_groove", img);

    ShaderCompiler shaders;
    GpuScene gpuScene(gpu(), shaders, s);
    const GpuImage& image = gpuScene.texture(0);
    ASSERT_EQ(image.desc().mipLevels, 5u);
    const Image level1 = readImage(gpu(), image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 1);
    const double grooveAlpha = std::sqrt(1.0 - std::sqrt(0.5));
    for (uint32_t y = 0; y < n / 2; ++y)
        for (uint32_t x = 0; x < n / 2; ++x)
            EXPECT_NEAR(level1.at(x, y)[3], x == 2 ? grooveAlpha : 0.0, 1.5 / 255.0)
                << "level 1, texel " << x << ", " << y;
    for (uint32_t level = 2; level < 5; ++level) {
        const Image got = readImage(gpu(), image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, level);
        for (int y = 0; y < got.height; ++y)
            for (int x = 0; x < got.width; ++x)
                EXPECT_LE(got.at(x, y)[3], 1.5 / 255.0) << "level " << level << ", texel " << x << ", " << y;
    }
}

// ---------------------------------------------------------------------------------------------
// The museum's G-buffer

json museumGraph(const std::string& camera, double start = 0.0) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", 160}, {"height", 90}}},
            {"nodes",
             {{"scene", {{"type", "scene.museum"}, {"params", {{"texture_size", 64}, {"camera", camera}, {"start", start}}}}},
              {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
            {"outputs",
             {{"normal", "gbuffer.normal"},
              {"base", "gbuffer.base_color"},
              {"material", "gbuffer.material"},
              {"velocity", "gbuffer.velocity"},
              {"depth", "gbuffer.depth"}}}};
}

struct GbufferStats {
    int pixels = 0, covered = 0;
    double minDepth = 1e30, maxDepth = 0.0, meanLuma = 0.0, minLuma = 1e30, maxLuma = 0.0;
    double worstHwDepth = 0.0, maxSpeed = 0.0;
    int badCodes = 0, metallicPixels = 0, movingPixels = 0, skyLow = 0, upFacing = 0, badRange = 0, distinctColours = 0;
};

// A valid octahedral code lies in [-1, 1]^2 (inner diamond: z >= 0, corners: z < 0); every such code
// decodes to a unit vector, so what a broken encoder shows is a code outside it, or NaN.
bool validOctCode(double ex, double ey) { return std::fabs(ex) <= 1.0 + 1e-3 && std::fabs(ey) <= 1.0 + 1e-3; }

glm::dvec3 octDecode(double ex, double ey) {
    glm::dvec3 n(ex, ey, 1.0 - std::fabs(ex) - std::fabs(ey));
    if (n.z < 0.0) {
        double x = n.x, y = n.y;
        n.x = (1.0 - std::fabs(y)) * (x >= 0.0 ? 1.0 : -1.0);
        n.y = (1.0 - std::fabs(x)) * (y >= 0.0 ? 1.0 : -1.0);
    }
    return glm::normalize(n);
}

GbufferStats museumStats(std::map<std::string, Image>& out, double znear) {
    GbufferStats st;
    const Image& nrm = out["normal"];
    st.pixels = nrm.width * nrm.height;
    std::vector<uint32_t> colours;
    for (int y = 0; y < nrm.height; ++y)
        for (int x = 0; x < nrm.width; ++x) {
            double hw = out["depth"].at(x, y)[0];
            if (hw <= 0.0) {
                // Sky shows through windows and skylights only: never in the lower 40 % of the frame,
                // where the floor is (the cameras stand at eye height and look about level).
                st.skyLow += y >= 0.6 * nrm.height;
                continue;
            }
            ++st.covered;
            const float* g = nrm.at(x, y);
            const float* b = out["base"].at(x, y);
            const float* v = out["velocity"].at(x, y);
            double depth = g[2];
            st.minDepth = std::min(st.minDepth, depth);
            st.maxDepth = std::max(st.maxDepth, depth);
            // Reverse Z with an infinite far plane: hardware depth = near / view depth.
            st.worstHwDepth = std::max(st.worstHwDepth, std::fabs(hw * depth / znear - 1.0));
            st.badCodes += !validOctCode(g[0], g[1]);
            if (octDecode(g[0], g[1]).y > 0.9) ++st.upFacing;
            for (int c = 0; c < 4; ++c) st.badRange += !(b[c] >= 0.0f && b[c] <= 1.0f);
            st.badRange += !(g[3] >= 0.0f && g[3] <= 1.0f);
            double luma = 0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2];
            st.meanLuma += luma;
            st.minLuma = std::min(st.minLuma, luma);
            st.maxLuma = std::max(st.maxLuma, luma);
            st.metallicPixels += b[3] > 0.5f;
            double speed = std::hypot(static_cast<double>(v[0]), static_cast<double>(v[1]));
            st.maxSpeed = std::max(st.maxSpeed, speed);
            st.movingPixels += speed > 0.01;
            colours.push_back(static_cast<uint32_t>(b[0] * 15.0f + 0.5f) << 8 | static_cast<uint32_t>(b[1] * 15.0f + 0.5f) << 4 |
                              static_cast<uint32_t>(b[2] * 15.0f + 0.5f));
        }
    if (st.covered) st.meanLuma /= st.covered;
    std::sort(colours.begin(), colours.end());
    st.distinctColours = static_cast<int>(std::unique(colours.begin(), colours.end()) - colours.begin());
    return st;
}

void printStats(const char* camera, const GbufferStats& st, double seconds) {
    std::printf("museum %s: %.1f%% covered, depth %.2f..%.2f m, base luma %.3f (%.3f..%.3f), %d colours, %d metallic px, "
                "%d up-facing px, max |v| %.2f px, %d moving px, hw depth rel err %.1e (%.1f s)\n",
                camera, 100.0 * st.covered / st.pixels, st.minDepth, st.maxDepth, st.meanLuma, st.minLuma, st.maxLuma,
                st.distinctColours, st.metallicPixels, st.upFacing, st.maxSpeed, st.movingPixels, st.worstHwDepth, seconds);
}

// Checks shared by both cameras. The ranges are what any correct G-buffer of this museum satisfies and
// what typical breakage (missing geometry, garbage depth, unencoded normals, unblended materials, sRGB
// decoded twice or not at all) does not.
void expectPlausibleMuseum(const GbufferStats& st) {
    // A closed building: sky only through the south windows and the louvred skylights (1.6 % and
    // 0.5 % of the frame when written), and not below the horizon (doorway thresholds close the floor
    // across the walls' thickness).
    EXPECT_GT(st.covered, 0.95 * st.pixels);
    EXPECT_EQ(st.skyLow, 0);
    // View depth: nothing within a metre of the cameras, which stand in open floor; nothing farther
    // than the building's extent (hall 32 m plus side galleries < 60 m).
    EXPECT_GT(st.minDepth, 1.0);
    EXPECT_LT(st.maxDepth, 60.0);
    // The linear depth in normal.z and the D32 reverse-Z buffer (near / depth for an infinite far plane)
    // describe the same surfaces, to binary16 precision (< 2^-10 relative).
    EXPECT_LT(st.worstHwDepth, 2e-3);
    EXPECT_EQ(st.badCodes, 0); // octahedral codes in [-1, 1]^2, no NaN: each decodes to a unit normal
    EXPECT_EQ(st.badRange, 0); // base colour, metallic and shininess in [0, 1]
    // The floor (polished marble) fills much of the lower frame: normals straight up.
    EXPECT_GT(st.upFacing, 0.1 * st.pixels);
    // Base colour is linear albedo: marble chequer, plaster, stone, wood average well inside (0.2, 0.8);
    // all-black or all-white means textures or blending are broken.
    EXPECT_GT(st.meanLuma, 0.2);
    EXPECT_LT(st.meanLuma, 0.8);
    EXPECT_GT(st.distinctColours, 40); // textured and varied (of 4096 possible at 4 bits per channel)
    // Metals (exhibits, brass railings, frames) are visible from both cameras but are a small part of an
    // architecture of stone and plaster.
    EXPECT_GT(st.metallicPixels, 0);
    EXPECT_LT(st.metallicPixels, 0.2 * st.pixels);
}

TEST_F(SceneGpu, MuseumGbufferFromTheStaticCameraIsPlausible) {
    auto start = std::chrono::steady_clock::now();
    auto out = runGraph(museumGraph("static"));
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    GbufferStats st = museumStats(out, 0.05);
    printStats("static", st, seconds);
    expectPlausibleMuseum(st);
    // From the west end of the hall, looking east along it at eye height: the floor at the bottom
    // edge is ~4.8 m away (view depth), the east wall and the doorway beyond it 30–45 m.
    EXPECT_LT(st.minDepth, 5.0);
    EXPECT_GT(st.maxDepth, 25.0);
    // A still camera: only the walking robot moves, a small part of the frame.
    EXPECT_LT(st.movingPixels, 0.05 * st.pixels);
    EXPECT_LT(st.maxSpeed, 5.0);
}

TEST_F(SceneGpu, MuseumGbufferFromTheWalkthroughIsPlausible) {
    auto start = std::chrono::steady_clock::now();
    // 12.5 s: walking east through the hall, between two keys (at t = 0 the path is clamped, so the
    // camera would not move between the frame and the one before).
    auto out = runGraph(museumGraph("walkthrough", 12.5));
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    GbufferStats st = museumStats(out, 0.05);
    printStats("walkthrough", st, seconds);
    expectPlausibleMuseum(st);
    EXPECT_GT(st.maxDepth, 15.0); // looking along the hall
    // The camera walks (~1.6 m/s, 24 fps) and turns: almost every pixel moves, by well under a frame.
    EXPECT_GT(st.movingPixels, 0.9 * st.covered);
    EXPECT_GT(st.maxSpeed, 0.3);
    EXPECT_LT(st.maxSpeed, 20.0);
}

// scene.hold: every frame is the instant `start`. Four frames of the walkthrough held at 12.5 s (where the camera
// walks and turns and the robot moves) give the G-buffer of frame 0 exactly, with no velocity; the jitter still
// moves the projection each frame (what TAA and aa.accumulate need of a held shot).
TEST_F(SceneGpu, HoldShowsOneInstantInEveryFrame) {
    auto graph = [](bool hold, int frames, const char* jitter) {
        json g = museumGraph("walkthrough", 12.5);
        g["frame"]["frames"] = frames;
        g["nodes"]["scene"]["params"]["hold"] = hold;
        g["nodes"]["scene"]["params"]["jitter"] = jitter;
        return g;
    };
    auto first = runGraph(graph(false, 1, "off"));
    auto held = runGraph(graph(true, 4, "off"));
    auto moving = runGraph(graph(false, 4, "off"));
    auto heldJittered = runGraph(graph(true, 4, "halton"));
    auto maxDiff = [](const Image& a, const Image& b, int channels) {
        double d = 0.0;
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x)
                for (int c = 0; c < channels; ++c)
                    d = std::max(d, std::fabs(double(a.at(x, y)[c]) - b.at(x, y)[c]));
        return d;
    };
    auto maxSpeed = [](const Image& v) {
        double s = 0.0;
        for (int y = 0; y < v.height; ++y)
            for (int x = 0; x < v.width; ++x)
                s = std::max(s, std::hypot(double(v.at(x, y)[0]), double(v.at(x, y)[1])));
        return s;
    };
    for (const char* name : {"normal", "base", "material", "depth"})
        EXPECT_EQ(maxDiff(held[name], first[name], 4), 0.0) << name << ": frame 3 of the held shot is not frame 0";
    EXPECT_EQ(maxSpeed(held["velocity"]), 0.0);
    // Without hold the same frames move: the test sees motion where there is some.
    EXPECT_GT(maxDiff(moving["depth"], first["depth"], 1), 0.01);
    EXPECT_GT(maxSpeed(moving["velocity"]), 0.3);
    EXPECT_GT(maxSpeed(first["velocity"]), 0.3); // frame 0 of the walk has the motion of the frame before
    // Held and jittered: the projection moves by the sub-pixel jitter, the scene does not.
    EXPECT_GT(maxDiff(heldJittered["depth"], first["depth"], 1), 1e-4);
    EXPECT_LT(maxSpeed(heldJittered["velocity"]), 1e-3);
}

// ---------------------------------------------------------------------------------------------
// User errors

std::string userErrorOf(const json& graph) {
    try {
        runGraph(graph);
    } catch (const UserError& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a UserError";
    return {};
}

TEST_F(SceneGpu, MissingGltfFileNamesTheFileAndTheParam) {
    const std::string missing = (std::filesystem::temp_directory_path() / "vitrine_no_such_scene.glb").string();
    std::string message = userErrorOf(
        {{"format", "vitrine-graph/1"},
         {"frame", {{"width", 32}, {"height", 32}}},
         {"nodes",
          {{"hall", {{"type", "scene.gltf"}, {"params", {{"path", missing}}}}},
           {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "hall.scene"}}}}}}},
         {"outputs", {{"normal", "gbuffer.normal"}}}});
    EXPECT_NE(message.find("vitrine_no_such_scene.glb"), std::string::npos) << message;
    EXPECT_NE(message.find("/nodes/hall/params/path"), std::string::npos) << message;
}

TEST_F(SceneGpu, UnknownMuseumCameraListsTheKnownPaths) {
    std::string message = userErrorOf(
        {{"format", "vitrine-graph/1"},
         {"frame", {{"width", 32}, {"height", 32}}},
         {"nodes",
          {{"museum", {{"type", "scene.museum"}, {"params", {{"texture_size", 16}, {"camera", "nope"}}}}},
           {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "museum.scene"}}}}}}},
         {"outputs", {{"normal", "gbuffer.normal"}}}});
    for (const char* part : {"/nodes/museum/params/camera", "nope", "walkthrough", "dolly", "static"})
        EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
}

} // namespace
} // namespace vitrine::test
