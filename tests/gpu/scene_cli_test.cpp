// `vitrine run graphs/gltf.json --scene FILE`: a small glTF written by the test (a red ball far from the origin, no
// camera, no lights of its own) renders centred by the automatic framing and exposed within a band by the graph's
// metered exposure; the graph's key light (kept by --scene) and studio look; --scene's user errors. The real binary, validation on, at a small size.
#include "tests/gpu/cli.hpp"
#include "tests/gpu/lighting_scene.hpp"

#include "core/image/io.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>

namespace vitrine::test {
namespace {

namespace fs = std::filesystem;
using namespace lighting;

const std::string kSource = VITRINE_SOURCE_DIR;

class SceneCli : public GpuTest {};

TEST_F(SceneCli, SceneShorthandFramesAndExposesASmallModel) {
    const int W = 96, H = 64;
    SceneBuilder b("red_ball");
    const glm::vec3 centre(5.0f, 2.0f, -3.0f);
    b.node("ball",
           static_cast<int32_t>(
               b.mesh("ball", sphereTris(0.3f, 48, 24), b.material("red", {0.8f, 0.08f, 0.05f}, 0.0f, 0.4f))),
           centre);
    const fs::path glb = b.write();
    const fs::path out = fs::path(VITRINE_TEST_OUT) / "scene_shorthand";
    fs::remove_all(out);
    const CliResult r =
        vitrine("run " + quote(kSource + "/graphs/gltf.json") + " --scene " + quote(glb.string()) +
                " --set frame.width=" + std::to_string(W) + " --set frame.height=" + std::to_string(H) +
                " --validate --quiet --exr float --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    // The tone-mapped image (display-linear [0, 1]) from the EXR.
    Image img = loadExrLayer(out / "frame.0000.exr", "final");
    ASSERT_EQ(img.width, W);
    double sx = 0.0, sy = 0.0, red = 0.0;
    int n = 0, clipped = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* p = img.at(x, y);
            if (p[0] < 2.5f * p[1] || p[0] < 2.5f * p[2] || p[0] < 0.01f) continue; // the ball: red
            sx += x + 0.5;
            sy += y + 0.5;
            red += p[0];
            clipped += p[0] > 0.98f;
            ++n;
        }
    ASSERT_GT(n, 0) << "no red pixel: the ball is not in view";
    const double cx = sx / n / W, cy = sy / n / H, meanRed = red / n;
    std::printf("--scene: ball covers %.1f %% of the frame, centroid (%.3f, %.3f), mean red %.3f, %.1f %% clipped\n",
                100.0 * n / (W * H), cx, cy, meanRed, 100.0 * clipped / n);
    EXPECT_NEAR(cx, 0.5, 0.05);
    EXPECT_NEAR(cy, 0.5, 0.05);
    EXPECT_GT(n, W * H / 20); // framed, not a dot
    // Exposure: the lit ball (red albedo 0.8, lit by the key light from the camera side) neither dark nor blown out:
    // PBR Neutral shows a surface under about unit light near its albedo, so the mean stays below 0.8. The tone
    // mapper's output is display-linear: 0.08..0.8 is 0.31..0.91 after the sRGB encoding.
    EXPECT_GT(meanRed, 0.08);
    EXPECT_LT(meanRed, 0.8);
    EXPECT_LT(clipped, n / 5);
}

// scene.gltf's key_light: a file without a directional light gets a sun key_light_elevation above the horizon and
// key_light_azimuth to the camera's right of the direction back to the camera; sky.hdri given the scene lights with
// it (sh texels 9 and 10); a file with its own directional light keeps it.
TEST_F(SceneCli, KeyLightComesFromTheCameraSide) {
    const fs::path dir = freshDir("key_light");
    Image env(16, 8);
    for (size_t i = 0; i < env.pixels.size(); ++i) env.pixels[i] = 1.0f;
    writeExr(dir / "grey.exr", env, ExrPixelType::Float);
    const glm::vec3 eye(3.0f, 1.5f, 4.0f);
    for (bool ownSun : {false, true}) {
        SceneBuilder b(ownSun ? "key_light_own_sun" : "key_light");
        std::vector<Tri> tris;
        addQuad(tris, glm::vec3(0.0f), {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 0.0f, 1.0f});
        b.node("quad", static_cast<int32_t>(b.mesh("quad", tris, b.material("white", glm::vec3(1.0f), 0.0f, 0.1f))));
        b.camera(eye, glm::vec3(0.0f), 0.8f);
        const glm::vec3 fileSun = glm::normalize(glm::vec3(-1.0f, 2.0f, -0.5f));
        if (ownSun) b.sun(fileSun);
        const fs::path glb = b.write();
        const nlohmann::json g = {
            {"format", "vitrine-graph/1"},
            {"frame", {{"width", 8}, {"height", 8}}},
            {"nodes",
             {{"scene", {{"type", "scene.gltf"},
                         {"params", {{"path", glb.string()}, {"key_light", true}, {"key_light_elevation", 35.0},
                                     {"key_light_azimuth", 30.0}}}}},
              {"sky", {{"type", "sky.hdri"},
                       {"in", {{"scene", "scene.scene"}}},
                       {"params", {{"path", (dir / "grey.exr").string()}, {"sun_illuminance", 1234.0}, {"size", 8}}}}}}},
            {"outputs", {{"sh", "sky.sh"}}}};
        const Image sh = runGraph(g).at("sh");
        const glm::dvec3 toSun(sh.at(10, 0)[0], sh.at(10, 0)[1], sh.at(10, 0)[2]);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(sh.at(9, 0)[c], 1234.0, 0.01) << "illuminance channel " << c;
        if (ownSun) {
            EXPECT_NEAR(glm::distance(toSun, glm::dvec3(fileSun)), 0.0, 1e-5) << "the file's directional light stays";
            continue;
        }
        // Elevation above the horizon, then the horizontal angle from the direction back to the camera, on the
        // side of the camera's right (its local +X).
        EXPECT_NEAR(std::asin(toSun.y) * 180.0 / kPi, 35.0, 0.01);
        const glm::dvec3 flat = glm::normalize(glm::dvec3(toSun.x, 0.0, toSun.z));
        const glm::dvec3 back = glm::normalize(glm::dvec3(eye.x, 0.0, eye.z));
        EXPECT_NEAR(std::acos(glm::dot(flat, back)) * 180.0 / kPi, 30.0, 0.01);
        const glm::dvec3 right = glm::dvec3(lookRotation(eye, glm::vec3(0.0f)) * glm::vec3(1.0f, 0.0f, 0.0f));
        EXPECT_GT(glm::dot(flat, right), 0.3);
    }
}

// graphs/gltf.json's default look through --scene (which keeps the graph's key light): a white matte quad facing
// the camera comes out bright and neutral (key light 100 klux at cos 35 deg x cos 30 deg, the grey studio
// environment, PBR Neutral at -15 EV: about 0.85 display-linear; without the key light it would be about 0.25).
TEST_F(SceneCli, GltfViewerShowsAWhiteFrontFaceNearWhite) {
    const int W = 64, H = 64;
    SceneBuilder b("white_front");
    std::vector<Tri> tris;
    addQuad(tris, glm::vec3(0.0f), {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f});
    b.node("quad", static_cast<int32_t>(b.mesh("quad", tris, b.material("white", glm::vec3(1.0f), 0.0f, 0.0f))));
    b.camera({0.0f, 0.0f, 2.0f}, glm::vec3(0.0f), 0.6f);
    const fs::path glb = b.write();
    const fs::path out = freshDir("white_front");
    const CliResult r = vitrine("run " + quote(kSource + "/graphs/gltf.json") + " --scene " + quote(glb.string()) +
                                " --set frame.width=" + std::to_string(W) + " --set frame.height=" + std::to_string(H) +
                                " --validate --quiet --exr float --overwrite --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    const Image img = loadExrLayer(out / "frame.0000.exr", "final");
    glm::dvec3 mean(0.0);
    int n = 0;
    for (int y = H / 4; y < 3 * H / 4; ++y)
        for (int x = W / 4; x < 3 * W / 4; ++x, ++n)
            for (int c = 0; c < 3; ++c) mean[c] += img.at(x, y)[c];
    mean /= static_cast<double>(n);
    std::printf("gltf.json: white front face (%.3f, %.3f, %.3f) display-linear\n", mean.r, mean.g, mean.b);
    EXPECT_GT(mean.g, 0.7);
    EXPECT_LT(mean.g, 0.95);
    EXPECT_NEAR(mean.r, mean.g, 0.01);
    EXPECT_NEAR(mean.b, mean.g, 0.01);
}

TEST_F(SceneCli, SceneShorthandErrorsNameWhatIsWrong) {
    const CliResult missing = vitrine("validate " + quote(kSource + "/graphs/gltf.json") + " --scene /nonexistent/x.glb");
    EXPECT_EQ(missing.status, 1) << missing.output;
    EXPECT_NE(missing.output.find("--scene /nonexistent/x.glb: file not found"), std::string::npos) << missing.output;
    SceneBuilder b("any");
    b.node("ball", static_cast<int32_t>(
                       b.mesh("ball", sphereTris(0.3f, 8, 4), b.material("red", {0.8f, 0.1f, 0.1f}, 0.0f, 0.4f))));
    const fs::path glb = b.write();
    const CliResult none =
        vitrine("validate " + quote(kSource + "/graphs/fxaa_zoneplate.json") + " --scene " + quote(glb.string()));
    EXPECT_EQ(none.status, 1) << none.output;
    EXPECT_NE(none.output.find("expected exactly one scene node (type scene.*) to replace, found 0"), std::string::npos)
        << none.output;
    const CliResult ok =
        vitrine("validate " + quote(kSource + "/graphs/museum.json") + " --scene " + quote(glb.string()));
    EXPECT_EQ(ok.status, 0) << ok.output; // the museum's scene node (scene.museum) becomes scene.gltf with its params
}

// The glTF loader's warnings reach stderr once each; --strict makes them errors (exit 1) on validate/run (the scene
// node's param strict) and on export-scene. A triangle that uses an extension vitrine does not implement.
TEST_F(SceneCli, GltfWarningsArePrintedAndStrictRefuses) {
    const fs::path dir = freshDir("gltf_strict");
    const fs::path file = dir / "anisotropy.gltf";
    {
        std::FILE* f = std::fopen(file.c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs(R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_anisotropy"],
 "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
 "materials": [{"extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 1}}}],
 "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
 "bufferViews": [{"buffer": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]}
)",
                   f);
        std::fclose(f);
    }
    auto count = [](const std::string& text, const std::string& s) {
        size_t n = 0;
        for (size_t at = text.find(s); at != std::string::npos; at = text.find(s, at + 1))
            ++n;
        return n;
    };
    const std::string graph = quote(kSource + "/graphs/gltf.json");
    const CliResult warned = vitrine("validate " + graph + " --scene " + quote(file.string()));
    EXPECT_EQ(warned.status, 0) << warned.output;
    EXPECT_EQ(
        count(warned.output, "warning: " + file.string() + ": extensionsUsed[0]: extension 'KHR_materials_anisotropy'"),
        1u)
        << warned.output;
    const CliResult strict = vitrine("validate " + graph + " --scene " + quote(file.string()) + " --strict");
    EXPECT_EQ(strict.status, 1) << strict.output;
    EXPECT_NE(strict.output.find("1 warning, which strict loading"), std::string::npos) << strict.output;
    EXPECT_NE(strict.output.find("KHR_materials_anisotropy"), std::string::npos) << strict.output;

    const CliResult exported = vitrine("export-scene " + quote(file.string()) + " " + quote((dir / "a.glb").string()));
    EXPECT_EQ(exported.status, 0) << exported.output;
    EXPECT_EQ(count(exported.output, "KHR_materials_anisotropy"), 1u) << exported.output;
    const CliResult refused =
        vitrine("export-scene " + quote(file.string()) + " " + quote((dir / "b.glb").string()) + " --strict");
    EXPECT_EQ(refused.status, 1) << refused.output;
    EXPECT_NE(refused.output.find("KHR_materials_anisotropy"), std::string::npos) << refused.output;
    EXPECT_FALSE(fs::exists(dir / "b.glb"));
}

// scene.museum's procedural textures go into the bake cache (kind museum_textures), and its geometry (kind
// museum_geometry): the second build of the same museum loads them instead of generating them (what makes a second
// `run` start quickly), and a damaged texture entry is generated again without a word to the user beyond the debug log.
TEST_F(SceneCli, MuseumTexturesComeFromTheBakeCacheOnTheSecondBuild) {
    const fs::path cache = fs::path(VITRINE_TEST_OUT) / "museum_texture_cache";
    fs::remove_all(cache);
    const std::string env = "VITRINE_CACHE_DIR=" + quote(cache.string());
    // A texture size no other test uses, so the process-wide museum of another test cannot answer instead.
    const std::string args = "validate " + quote(kSource + "/graphs/museum.json") +
                             " --set scene.params.texture_size=32 --set scene.params.seed=7 --verbose";
    const CliResult first = vitrine(args, env);
    ASSERT_EQ(first.status, 0) << first.output;
    EXPECT_NE(first.output.find("procedural textures generated and stored in the bake cache"), std::string::npos)
        << first.output;
    const fs::path dir = cache / "bake" / "museum_textures";
    ASSERT_TRUE(fs::is_directory(dir)) << first.output;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
    ASSERT_EQ(files.size(), 1u);
    EXPECT_NE(first.output.find("geometry generated and stored in the bake cache"), std::string::npos) << first.output;
    size_t geometryFiles = 0;
    for (const auto& e : fs::directory_iterator(cache / "bake" / "museum_geometry"))
        geometryFiles += e.path().extension() == ".bin";
    EXPECT_EQ(geometryFiles, 1u);
    const CliResult second = vitrine(args, env);
    ASSERT_EQ(second.status, 0) << second.output;
    EXPECT_NE(second.output.find("procedural textures loaded from the bake cache"), std::string::npos)
        << second.output;
    EXPECT_NE(second.output.find("geometry loaded from the bake cache"), std::string::npos) << second.output;
    // Damaged (truncated): generated again, stored again, no failure.
    fs::resize_file(files[0], fs::file_size(files[0]) / 2);
    const CliResult third = vitrine(args, env);
    ASSERT_EQ(third.status, 0) << third.output;
    EXPECT_NE(third.output.find("procedural textures generated and stored"), std::string::npos) << third.output;
    const CliResult fourth = vitrine(args, env);
    EXPECT_NE(fourth.output.find("procedural textures loaded from the bake cache"), std::string::npos)
        << fourth.output;
    // Damaged inside (one byte of the pixels flipped, the size and header intact): the checksum, run on a second
    // thread while the geometry is built, fails before the scene is used; generated again, stored again.
    {
        std::fstream f(files[0], std::ios::in | std::ios::out | std::ios::binary);
        const std::streamoff at = static_cast<std::streamoff>(fs::file_size(files[0]) - 100);
        f.seekg(at);
        const char c = static_cast<char>(f.get());
        f.seekp(at);
        f.put(static_cast<char>(c ^ 0x40));
    }
    const CliResult fifth = vitrine(args, env);
    ASSERT_EQ(fifth.status, 0) << fifth.output;
    EXPECT_NE(fifth.output.find("fail their checksum"), std::string::npos) << fifth.output;
    EXPECT_NE(fifth.output.find("procedural textures generated and stored"), std::string::npos) << fifth.output;
    const CliResult sixth = vitrine(args, env);
    EXPECT_NE(sixth.output.find("procedural textures loaded from the bake cache"), std::string::npos) << sixth.output;
    EXPECT_EQ(sixth.output.find("fail their checksum"), std::string::npos) << sixth.output;
}

// KHR_materials_variants from the command line: --set scene.params.material_variant=NAME on graphs/gltf.json with
// --scene; a name the file lacks is an error (exit 1) naming the param and listing the file's variants.
TEST_F(SceneCli, MaterialVariantFromTheCommandLine) {
    const std::string graph = quote(kSource + "/graphs/gltf.json");
    const std::string file = quote(kSource + "/tests/data/gltf/corpus/variants.gltf");
    const CliResult blue =
        vitrine("validate " + graph + " --scene " + file + " --set scene.params.material_variant=blue --strict");
    EXPECT_EQ(blue.status, 0) << blue.output;
    const CliResult green =
        vitrine("validate " + graph + " --scene " + file + " --set scene.params.material_variant=green");
    EXPECT_EQ(green.status, 1) << green.output;
    EXPECT_NE(green.output.find("material_variant"), std::string::npos) << green.output;
    EXPECT_NE(green.output.find("no variant named 'green'"), std::string::npos) << green.output;
    EXPECT_NE(green.output.find("'red', 'blue'"), std::string::npos) << green.output;
}

} // namespace
} // namespace vitrine::test
