// ibl.capture against answers it does not compute itself:
//   - the BRDF LUT against a CPU quadrature of the same split-sum integral (a midpoint grid over the GGX half-vector
//     distribution, core/shading's visibility term), within 1e-3;
//   - the prefiltered mips of a smooth environment against a brute-force CPU integral over every texel of the
//     captured mip 0 of sum L D(h) (n.l) dOmega / sum D(h) (n.l) dOmega (no sampling, no mip filtering), within 2 %;
//   - a probe in a box with red walls, one blue wall and a green floor sees them on the right faces (and the blue
//     wall on the left edge of the +Z face, the red one on its right: the faces are not mirrored);
//   - capture + prefilter is deterministic (bitwise), and the bake cache round-trips: a second run loads the same
//     bits, a moved probe or another sun captures again.
#include "tests/gpu/lighting_scene.hpp"

#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/shader/compiler.hpp"
#include "core/shading/brdf.hpp"
#include "core/shading/cubemap.hpp"
#include "nodes/scene/scene_node.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;
namespace fs = std::filesystem;

// Scenes built in code, with probes (glTF does not carry them yet): test.probe_scene publishes them by name.
std::map<std::string, std::shared_ptr<const scene::Scene>>& probeScenes() {
    static std::map<std::string, std::shared_ptr<const scene::Scene>> scenes;
    return scenes;
}

class ProbeSceneNode final : public SceneNode {
public:
    void setup(SetupContext& ctx) override {
        auto it = probeScenes().find(ctx.params().getString("name"));
        if (it == probeScenes().end()) ctx.failParam("name", "no such test scene");
        publish(ctx, it->second);
    }
};

NodeSchema probeSceneSchema() {
    NodeSchema s;
    s.type = "test.probe_scene";
    s.doc = "test-only: a scene built in code (with reflection probes), by name";
    s.params = {{"name", ParamType::String, "", {}, {}, {}, "key of probeScenes()"}};
    addSceneNodeSchema(s);
    return s;
}

const NodeRegistration kProbeScene(probeSceneSchema(), [] { return std::make_unique<ProbeSceneNode>(); });

class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::string& value) : mName(name) {
        if (const char* old = std::getenv(name)) mOld = old;
        setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() {
        if (mOld) setenv(mName, mOld->c_str(), 1);
        else unsetenv(mName);
    }

private:
    const char* mName;
    std::optional<std::string> mOld;
};

void addProbe(scene::Scene& s, glm::vec3 position, glm::vec3 centre, glm::vec3 half) {
    scene::ReflectionProbe p;
    p.name = "probe" + std::to_string(s.probes.size());
    p.position = position;
    p.center = centre;
    p.halfExtents = half;
    s.probes.push_back(p);
}

void registerScene(const std::string& name, scene::Scene s) {
    s.name = name;
    s.finalize();
    s.validate();
    probeScenes()[name] = std::make_shared<const scene::Scene>(std::move(s));
}

// Open-topped room x in [-2, 2], z in [-4, 4], walls 3 m high: walls red, the -X wall blue, the floor green.
scene::Scene redBox(glm::vec3 probe, glm::vec3 toSun) {
    SceneBuilder b("red_box");
    const uint32_t red = b.material("red", {0.8f, 0.05f, 0.05f}, 0.0f, 0.0f);
    const uint32_t blue = b.material("blue", {0.05f, 0.05f, 0.8f}, 0.0f, 0.0f);
    const uint32_t green = b.material("green", {0.05f, 0.8f, 0.05f}, 0.0f, 0.0f);
    auto quad = [&](const char* name, glm::vec3 c, glm::vec3 u, glm::vec3 v, glm::vec3 n, uint32_t material) {
        std::vector<Tri> t;
        addQuad(t, c, u, v, n);
        b.node(name, static_cast<int32_t>(b.mesh(name, t, material)));
    };
    quad("floor", {0, 0, 0}, {2, 0, 0}, {0, 0, 4}, {0, 1, 0}, green);
    quad("wall_px", {2, 1.5f, 0}, {0, 1.5f, 0}, {0, 0, 4}, {-1, 0, 0}, red);
    quad("wall_nx", {-2, 1.5f, 0}, {0, 1.5f, 0}, {0, 0, 4}, {1, 0, 0}, blue);
    quad("wall_pz", {0, 1.5f, 4}, {2, 0, 0}, {0, 1.5f, 0}, {0, 0, -1}, red);
    quad("wall_nz", {0, 1.5f, -4}, {2, 0, 0}, {0, 1.5f, 0}, {0, 0, 1}, red);
    b.sun(toSun);
    addProbe(b.s, probe, {0, 1.5f, 0}, {2, 1.5f, 4});
    return b.s;
}

json captureGraph(const std::string& sceneName, json sky, json params) {
    json nodes = {{"scene", {{"type", "test.probe_scene"}, {"params", {{"name", sceneName}}}}},
                  {"sky", sky},
                  {"capture", {{"type", "ibl.capture"},
                               {"in", {{"scene", "scene.scene"}, {"sky", "sky.cubemap"}, {"sky_sh", "sky.sh"}}},
                               {"params", params}}}};
    return graph(nodes, {{"lut", "capture.brdf_lut"}}, 16, 16);
}

json proceduralSky() {
    return {{"type", "sky.procedural"}, {"in", {{"scene", "scene.scene"}}}, {"params", {{"size", 16}, {"sun_in_cubemap", false}}}};
}

struct Capture {
    std::vector<std::vector<Image>> mips; // [mip][layer]
    Image lut;
};

Capture runCapture(const json& doc) {
    CompiledGraph g = compileGraph(validateGraph(doc, "ibl-capture-test.json", NodeRegistry::global()));
    ShaderCompiler shaders;
    Executor ex(gpu(), g, shaders);
    RunOptions options;
    options.progress = false;
    ex.run(options);
    Capture c;
    const GpuImage& cubes = ex.image("capture.cubes");
    c.mips.resize(cubes.desc().mipLevels);
    for (uint32_t m = 0; m < cubes.desc().mipLevels; ++m)
        for (uint32_t l = 0; l < cubes.desc().layers; ++l) c.mips[m].push_back(ex.read("capture.cubes", m, l));
    c.lut = ex.read("capture.brdf_lut");
    return c;
}

glm::dvec3 meanOf(const Image& img, int x0, int x1, int y0, int y1) {
    glm::dvec3 sum(0.0);
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += rgb(img, x, y);
    return sum / double((x1 - x0) * (y1 - y0));
}

class IblCapture : public GpuTest {};

// (A, B) of the split sum for brdf.glsl's GGX / height-correlated Smith / Schlick lobe, in double precision by a
// midpoint rule over the visible-normal distribution's parameter square [Heitz18]: (u1, u2) -> a point of the unit
// disk, warped onto the projected hemisphere of the view stretched by alpha, unstretched to a half vector h whose
// density is D_v(h) = G1(v) max(0, v.h) D(h) / (n.v). With l = reflect(-v, h) the integrand f (n.l) / pdf(l) is
// F G2(v, l) / G1(v), written here with Smith's Lambda: G1 = 1 / (1 + L(v)), G2 = 1 / (1 + L(v) + L(l)),
// L(w) = (sqrt(1 + alpha^2 tan^2 theta_w) - 1) / 2. It vanishes as n.l -> 0, so the quadrature converges smoothly
// even at grazing views (a grid over the plain NDF has a discontinuity there that halves its accuracy).
glm::dvec2 cpuLut(double NoV, double roughness) {
    const double alpha = shading::ggxAlpha(static_cast<float>(roughness));
    const glm::dvec3 v(std::sqrt(1.0 - NoV * NoV), 0.0, NoV);
    auto lambda = [alpha](double cosT) {
        const double cos2 = cosT * cosT, tan2 = std::max(1.0 - cos2, 0.0) / cos2;
        return 0.5 * (std::sqrt(1.0 + alpha * alpha * tan2) - 1.0);
    };
    const double lambdaV = lambda(NoV);
    const glm::dvec3 vh = glm::normalize(glm::dvec3(alpha * v.x, alpha * v.y, v.z));
    const glm::dvec3 t1(0.0, 1.0, 0.0); // perpendicular to vh (v lies in the xz plane)
    const glm::dvec3 t2 = glm::cross(vh, t1);
    const double s = 0.5 * (1.0 + vh.z);
    const int n1 = 512, n2 = 512;
    glm::dvec2 sum(0.0);
    for (int i = 0; i < n1; ++i) {
        const double r = std::sqrt((i + 0.5) / n1);
        for (int j = 0; j < n2; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / n2;
            const double p1 = r * std::cos(phi);
            const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * std::sin(phi);
            const glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
            const glm::dvec3 h = glm::normalize(glm::dvec3(alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)));
            const double VoH = glm::dot(v, h);
            const glm::dvec3 l = 2.0 * VoH * h - v;
            if (l.z <= 0.0 || VoH <= 0.0) continue;
            const double g2OverG1 = (1.0 + lambdaV) / (1.0 + lambdaV + lambda(l.z));
            const double fc = std::pow(1.0 - VoH, 5.0);
            sum += glm::dvec2((1.0 - fc) * g2OverG1, fc * g2OverG1);
        }
    }
    return sum / double(n1 * n2);
}

TEST_F(IblCapture, BrdfLutMatchesCpuIntegration) {
    registerScene("lut_box", redBox({0, 1.2f, 0}, {0.3f, 1.0f, 0.2f}));
    const int n = 16;
    const Capture c = runCapture(captureGraph("lut_box", proceduralSky(), {{"size", 8}, {"lut_size", n}, {"cache", false}}));
    ASSERT_EQ(c.lut.width, n);
    double worst = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double NoV = std::max(double(i) / (n - 1), 1e-3), roughness = double(j) / (n - 1);
            const glm::dvec2 want = cpuLut(NoV, roughness);
            const float* got = c.lut.at(i, j);
            const double e = std::max(std::abs(got[0] - want.x), std::abs(got[1] - want.y));
            worst = std::max(worst, e);
            EXPECT_LT(e, 1e-3) << "NoV " << NoV << ", roughness " << roughness << ": GPU (" << got[0] << ", " << got[1]
                               << "), CPU (" << want.x << ", " << want.y << ")";
        }
    std::printf("BRDF LUT %dx%d: largest error against the CPU quadrature %.2e\n", n, n, worst);
}

// The prefilter's definition summed over every texel of a cube's mip 0 (no sampling, no mip filtering): the texel
// direction n's sum of L D(h) (n.l) dOmega / sum of D(h) (n.l) dOmega, h = normalize(n + l).
struct CubeTexel {
    glm::dvec3 dir, L;
    double omega;
};
std::vector<CubeTexel> cubeTexels(const std::vector<Image>& faces, int size) {
    std::vector<CubeTexel> texels;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                texels.push_back({shading::cubeTexelDirection(f, x, y, size), rgb(faces[f], x, y),
                                  shading::cubeTexelSolidAngle(x, y, size)});
    return texels;
}
glm::dvec3 cpuPrefilter(const std::vector<CubeTexel>& texels, glm::dvec3 n, double alpha) {
    glm::dvec3 sum(0.0);
    double weight = 0.0;
    for (const CubeTexel& t : texels) {
        const double NoL = glm::dot(n, t.dir);
        if (NoL <= 0.0) continue;
        const double NoH = glm::dot(n, glm::normalize(n + t.dir));
        const double w = shading::ggxD(static_cast<float>(NoH), static_cast<float>(alpha)) * NoL * t.omega;
        sum += w * t.L;
        weight += w;
    }
    return sum / weight;
}

// An environment smooth enough that its mip-0 texels are a fair quadrature of it: a wide coloured lobe over a
// dim constant, as an equirectangular EXR for sky.hdri.
fs::path lobeEnvironment() {
    Image env(128, 64);
    const glm::dvec3 d = glm::normalize(glm::dvec3(1.0, 0.5, 0.3));
    for (int y = 0; y < env.height; ++y)
        for (int x = 0; x < env.width; ++x) {
            const double theta = kPi * (y + 0.5) / env.height, phi = 2.0 * kPi * (x + 0.5) / env.width;
            const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            const double lobe = std::pow(std::max(0.0, glm::dot(w, d)), 4.0);
            float* p = env.at(x, y);
            p[0] = float(0.2 + 4.0 * lobe);
            p[1] = float(0.3 + 3.0 * lobe);
            p[2] = float(0.5 + 1.0 * lobe);
            p[3] = 1.0f;
        }
    const fs::path file = fs::path(VITRINE_TEST_OUT) / "ibl_lobe_env.exr";
    fs::create_directories(file.parent_path());
    writeExr(file, env, ExrPixelType::Float);
    return file;
}

TEST_F(IblCapture, PrefilteredMipsMatchCpuIntegralOfTheCapture) {
    // Nothing but the sky around the probe: a speck of geometry inside the near plane (a scene needs a mesh).
    SceneBuilder b("open_sky");
    b.node("speck", static_cast<int32_t>(b.mesh("speck", boxTris(glm::vec3(0.001f)), b.material("m", glm::vec3(0.5f), 0.0f, 0.0f))),
           {0, 1, 0});
    addProbe(b.s, {0, 1, 0}, {0, 1, 0}, glm::vec3(1.0f));
    registerScene("open_sky", b.s);
    const int size = 32;
    json sky = {{"type", "sky.hdri"}, {"params", {{"path", lobeEnvironment().string()}, {"size", 64}}}};
    const Capture c = runCapture(captureGraph("open_sky", sky, {{"size", size}, {"cache", false}}));
    ASSERT_EQ(c.mips.size(), 6u);
    const std::vector<Image>& src = c.mips[0];
    const std::vector<CubeTexel> texels = cubeTexels(src, size);
    for (size_t m = 1; m < c.mips.size(); ++m) {
        const int s = size >> m;
        const double roughness = double(m) / double(c.mips.size() - 1);
        const double alpha = shading::ggxAlpha(static_cast<float>(roughness));
        double worst = 0.0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const glm::dvec3 want = cpuPrefilter(texels, shading::cubeTexelDirection(f, x, y, s), alpha),
                                     got = rgb(c.mips[m][f], x, y);
                    const double e = relErr(got, want);
                    worst = std::max(worst, e);
                    EXPECT_LT(e, 0.02) << "mip " << m << " face " << f << " texel " << x << "," << y;
                }
        std::printf("prefilter mip %zu (roughness %.2f): largest relative error %.4f\n", m, roughness, worst);
    }
}

// ibl.environment prefilters the sky itself with the same shader: its mips against the same brute-force integral,
// over the sky node's own faces, and its LUT against the CPU quadrature. The sky is the lobe environment modulated
// by a fine checker (15-degree cells, x1.6 / x0.4), the case filtered importance sampling is for: 512 samples over a
// rough lobe miss most of its mip-0 texels, and each must stand for its share of the sphere (read at the mip of that
// share). Mip 0 is the sky as given, to half float's precision (within 2e-3; measured 9.6e-4).
class IblEnvironment : public GpuTest {};

fs::path checkeredLobeEnvironment() {
    Image env(256, 128);
    const glm::dvec3 d = glm::normalize(glm::dvec3(1.0, 0.5, 0.3));
    for (int y = 0; y < env.height; ++y)
        for (int x = 0; x < env.width; ++x) {
            const double theta = kPi * (y + 0.5) / env.height, phi = 2.0 * kPi * (x + 0.5) / env.width;
            const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            const double lobe = std::pow(std::max(0.0, glm::dot(w, d)), 4.0);
            const double checker = ((x * 24 / env.width) + (y * 12 / env.height)) % 2 ? 1.6 : 0.4;
            float* p = env.at(x, y);
            p[0] = float((0.2 + 4.0 * lobe) * checker);
            p[1] = float((0.3 + 3.0 * lobe) * checker);
            p[2] = float((0.5 + 1.0 * lobe) * checker);
            p[3] = 1.0f;
        }
    const fs::path file = fs::path(VITRINE_TEST_OUT) / "ibl_checkered_lobe_env.exr";
    fs::create_directories(file.parent_path());
    writeExr(file, env, ExrPixelType::Float);
    return file;
}

TEST_F(IblEnvironment, PrefilteredMipsMatchCpuIntegralOfTheSky) {
    const int size = 32;
    json nodes = {
        {"sky", {{"type", "sky.hdri"}, {"params", {{"path", checkeredLobeEnvironment().string()}, {"size", size}}}}},
        {"environment",
         {{"type", "ibl.environment"},
          {"in", {{"sky", "sky.cubemap"}, {"sky_sh", "sky.sh"}}},
          {"params", {{"lut_size", 16}}}}}};
    CompiledGraph g = compileGraph(validateGraph(graph(nodes, {{"lut", "environment.brdf_lut"}}, 16, 16),
                                                 "ibl-environment-test.json", NodeRegistry::global()));
    ShaderCompiler shaders;
    Executor ex(gpu(), g, shaders);
    RunOptions options;
    options.progress = false;
    ex.run(options);
    const GpuImage& cube = ex.image("environment.cubemap");
    ASSERT_EQ(cube.desc().mipLevels, 6u);
    std::vector<Image> sky;
    double mip0Error = 0.0;
    for (int f = 0; f < 6; ++f) {
        sky.push_back(ex.read("sky.cubemap", 0, f));
        const Image mip0 = ex.read("environment.cubemap", 0, f);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                mip0Error = std::max(mip0Error, relErr(rgb(mip0, x, y), rgb(sky[f], x, y)));
    }
    const std::vector<CubeTexel> texels = cubeTexels(sky, size);
    std::printf("environment mip 0: largest relative difference from the sky %.2e\n", mip0Error);
    EXPECT_LT(mip0Error, 2e-3) << "mip 0 is the sky itself (read at its texel centres, stored as half floats)";
    for (uint32_t m = 1; m < cube.desc().mipLevels; ++m) {
        const int s = size >> m;
        const double roughness = double(m) / double(cube.desc().mipLevels - 1);
        const double alpha = shading::ggxAlpha(static_cast<float>(roughness));
        double worst = 0.0, mean = 0.0;
        int n = 0;
        for (int f = 0; f < 6; ++f) {
            const Image got = ex.read("environment.cubemap", m, f);
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const double e =
                        relErr(rgb(got, x, y), cpuPrefilter(texels, shading::cubeTexelDirection(f, x, y, s), alpha));
                    worst = std::max(worst, e);
                    mean += e;
                    ++n;
                }
        }
        mean /= n;
        std::printf("environment mip %u (roughness %.2f): relative error mean %.4f, largest %.4f\n", m, roughness, mean,
                    worst);
        // Mip 1's lobe (alpha 0.04) spans a few of the sky's texels, which makes the texel sum a coarse quadrature
        // of it: measured mean 1.5 %, largest 5.3 %. The rougher mips: mean 0.3-0.7 %, largest 1.0-1.4 % (reading
        // only the source's mip 0: 0.7-2.1 % and 2.4-3.3 %).
        EXPECT_LT(mean, m == 1 ? 0.02 : 0.01) << "mip " << m;
        EXPECT_LT(worst, m == 1 ? 0.06 : 0.02) << "mip " << m;
    }
    const Image lut = ex.read("environment.brdf_lut");
    double worst = 0.0;
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) {
            const glm::dvec2 want = cpuLut(std::max(i / 15.0, 1e-3), j / 15.0);
            const float* got = lut.at(i, j);
            worst = std::max(worst, std::max(std::abs(got[0] - want.x), std::abs(got[1] - want.y)));
        }
    std::printf("environment BRDF LUT 16x16: largest error against the CPU quadrature %.2e\n", worst);
    EXPECT_LT(worst, 2e-3);
}

TEST_F(IblCapture, ProbeInARedBoxSeesItsWallsOnTheRightFaces) {
    registerScene("red_box", redBox({0, 1.2f, 0}, {0.3f, 1.0f, 0.2f}));
    const int size = 16;
    const Capture c = runCapture(captureGraph("red_box", proceduralSky(), {{"size", size}, {"cache", false}}));
    const std::vector<Image>& faces = c.mips.at(0);
    ASSERT_EQ(faces.size(), 6u);
    // The six faces side by side (+X, -X, +Y, -Y, +Z, -Z), to look at.
    Image strip(6 * size, size);
    double peak = 0.0;
    for (const Image& f : faces)
        for (float v : f.pixels) peak = std::max(peak, double(v));
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                for (int k = 0; k < 4; ++k) strip.at(f * size + x, y)[k] = k == 3 ? 1.0f : float(faces[f].at(x, y)[k] / peak);
    writePng(fs::path(VITRINE_TEST_OUT) / "ibl_red_box_faces.png", strip);
    auto dominant = [](glm::dvec3 v, int channel) {
        return v[channel] > 2.0 * v[(channel + 1) % 3] && v[channel] > 2.0 * v[(channel + 2) % 3];
    };
    // The middle of the side faces is wall (their top corners see the open sky, their bottom the floor).
    const int a = size / 4, b = 3 * size / 4;
    const glm::dvec3 px = meanOf(faces[0], a, b, a, b), nx = meanOf(faces[1], a, b, a, b);
    const glm::dvec3 ny = meanOf(faces[3], 0, size, 0, size), py = meanOf(faces[2], 0, size, 0, size);
    EXPECT_TRUE(dominant(px, 0)) << "+X sees the red wall: " << px.x << " " << px.y << " " << px.z;
    EXPECT_TRUE(dominant(nx, 2)) << "-X sees the blue wall: " << nx.x << " " << nx.y << " " << nx.z;
    EXPECT_TRUE(dominant(ny, 1)) << "-Y sees the green floor: " << ny.x << " " << ny.y << " " << ny.z;
    EXPECT_FALSE(dominant(py, 0) || dominant(py, 1)) << "+Y sees the open sky: " << py.x << " " << py.y << " " << py.z;
    EXPECT_GT(py.z, py.x) << "+Y sees the open sky";
    // Looking down the room (+Z), the +X wall is on the face's right, the -X wall on its left; the far wall (red) in
    // the middle.
    for (int f : {4, 5}) {
        const glm::dvec3 left = meanOf(faces[f], 0, 2, size / 2 - 2, size / 2 + 2);
        const glm::dvec3 right = meanOf(faces[f], size - 2, size, size / 2 - 2, size / 2 + 2);
        EXPECT_TRUE(dominant(f == 4 ? right : left, 0)) << "face " << f << ": +X wall";
        EXPECT_TRUE(dominant(f == 4 ? left : right, 2)) << "face " << f << ": -X wall";
        EXPECT_TRUE(dominant(meanOf(faces[f], size / 2 - 2, size / 2 + 2, size / 2 - 2, size / 2 + 2), 0)) << "face " << f;
    }
    // The floor is the lower half of the side faces.
    EXPECT_TRUE(dominant(meanOf(faces[4], 4, size - 4, size - 2, size), 1)) << "+Z face: floor at the bottom";
    EXPECT_TRUE(dominant(meanOf(faces[0], 4, size - 4, size - 2, size), 1)) << "+X face: floor at the bottom";
}

TEST_F(IblCapture, EveryProbePrefiltersItsOwnFaces) {
    // Two probes that see different rooms: one inside the red box, one 8 m above it in the open. Each probe's
    // prefiltered mips must come from its own faces (probe i reads source layers [6i, 6i + 6)).
    scene::Scene s = redBox({0, 1.2f, 0}, {0.3f, 1.0f, 0.2f});
    addProbe(s, {0, 8.0f, 0}, {0, 8.0f, 0}, {1, 1, 1});
    registerScene("two_probes", std::move(s));
    const int size = 8;
    const Capture c = runCapture(captureGraph("two_probes", proceduralSky(), {{"size", size}, {"cache", false}}));
    ASSERT_GE(c.mips.size(), 2u);
    ASSERT_EQ(c.mips[1].size(), 12u);
    for (int mip : {0, 1}) {
        const int n = size >> mip;
        const glm::dvec3 inside = meanOf(c.mips[mip][0], n / 4, n - n / 4, n / 4, n - n / 4);
        const glm::dvec3 above = meanOf(c.mips[mip][6], 0, n, 0, n);
        std::printf("mip %d +X: box probe %.1f %.1f %.1f, probe above %.1f %.1f %.1f\n", mip, inside.x, inside.y, inside.z,
                    above.x, above.y, above.z);
        // Red leads inside the box (its +X wall; the green floor bleeds into the rougher mip); sky and ground above.
        EXPECT_GT(inside.x, 1.3 * inside.y) << "mip " << mip << ": the box's probe sees its red +X wall";
        EXPECT_GT(inside.x, 2.0 * inside.z) << "mip " << mip << ": the box's probe sees its red +X wall";
        EXPECT_GT(above.z, above.x) << "mip " << mip << ": the probe above the box sees sky and ground on +X";
    }
}

void expectSame(const Capture& a, const Capture& b) {
    ASSERT_EQ(a.mips.size(), b.mips.size());
    for (size_t m = 0; m < a.mips.size(); ++m)
        for (size_t l = 0; l < a.mips[m].size(); ++l) ASSERT_EQ(a.mips[m][l].pixels, b.mips[m][l].pixels) << m << " " << l;
}

TEST_F(IblCapture, DeterministicAndCachedByScenePlacementAndSun) {
    const fs::path cacheDir = fs::path(VITRINE_TEST_OUT) / "ibl_capture_cache";
    fs::remove_all(cacheDir);
    ScopedEnv env("VITRINE_CACHE_DIR", cacheDir.string());
    registerScene("cached_box", redBox({0, 1.2f, 0}, {0.3f, 1.0f, 0.2f}));
    const json params = {{"size", 8}, {"samples", 16}};
    json uncached = params;
    uncached["cache"] = false;
    const Capture a = runCapture(captureGraph("cached_box", proceduralSky(), uncached));
    const Capture b = runCapture(captureGraph("cached_box", proceduralSky(), uncached));
    expectSame(a, b);
    ASSERT_FALSE(fs::exists(cacheDir / "bake" / "probes")) << "cache: false stores nothing";

    auto files = [&] {
        std::vector<fs::path> out;
        for (const auto& e : fs::directory_iterator(cacheDir / "bake" / "probes")) out.push_back(e.path());
        return out;
    };
    const Capture first = runCapture(captureGraph("cached_box", proceduralSky(), params));
    expectSame(first, a);
    ASSERT_EQ(files().size(), 1u);
    const fs::path file = files()[0];
    const auto stamp = fs::last_write_time(file);
    // Another capture in between (not cached), so that memory the next run is given holds other texels than the
    // cached ones: a load that leaves texels unwritten must not pass on what the last capture left there.
    registerScene("other_box", redBox({-0.4f, 0.8f, 0.6f}, {0.3f, 1.0f, 0.2f}));
    ASSERT_NE(runCapture(captureGraph("other_box", proceduralSky(), uncached)).mips[0][1].pixels, a.mips[0][1].pixels);
    const Capture second = runCapture(captureGraph("cached_box", proceduralSky(), params));
    expectSame(second, a);
    EXPECT_EQ(fs::last_write_time(file), stamp) << "the second run captured again";

    // recapture: captured again although cached, the same bits, the file replaced.
    json again = params;
    again["recapture"] = true;
    expectSame(runCapture(captureGraph("cached_box", proceduralSky(), again)), a);
    EXPECT_NE(fs::last_write_time(file), stamp);

    // A moved probe and another sun are other captures.
    registerScene("cached_box", redBox({0.5f, 1.0f, 1.0f}, {0.3f, 1.0f, 0.2f}));
    const Capture moved = runCapture(captureGraph("cached_box", proceduralSky(), params));
    EXPECT_EQ(files().size(), 2u);
    EXPECT_NE(moved.mips[0][0].pixels, a.mips[0][0].pixels);
    registerScene("cached_box", redBox({0.5f, 1.0f, 1.0f}, {-0.5f, 1.0f, 0.4f}));
    const Capture sun = runCapture(captureGraph("cached_box", proceduralSky(), params));
    EXPECT_EQ(files().size(), 3u);
    EXPECT_NE(sun.mips[0][3].pixels, moved.mips[0][3].pixels);
    json hazy = proceduralSky();
    hazy["params"]["turbidity"] = 6.0;
    const Capture sky = runCapture(captureGraph("cached_box", hazy, params));
    EXPECT_EQ(files().size(), 4u) << "another sky must not reuse the capture";
    EXPECT_NE(sky.mips[0][2].pixels, sun.mips[0][2].pixels);

    // The capture renders through the G-buffer, lighting and scene shaders: a shader tree with one file edited (a
    // comment added to the Toksvig mip shader) must not reuse it, the same tree again must.
    const fs::path tree = fs::path(VITRINE_TEST_OUT) / "ibl_capture_shaders";
    fs::remove_all(tree);
    fs::copy(defaultShaderDir(), tree, fs::copy_options::recursive);
    {
        std::ofstream edit(tree / "scene" / "toksvig_mip.comp", std::ios::app);
        edit << "\n// an edit\n";
    }
    ScopedEnv shaderDir("VITRINE_SHADER_DIR", tree.string());
    expectSame(runCapture(captureGraph("cached_box", hazy, params)), sky);
    EXPECT_EQ(files().size(), 5u) << "a capture by other shaders must not reuse the cached one";
    runCapture(captureGraph("cached_box", hazy, params));
    EXPECT_EQ(files().size(), 5u) << "the same shaders must reuse it";
}

} // namespace
} // namespace vitrine::test
