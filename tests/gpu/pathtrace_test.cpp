// render.pathtrace against closed-form answers and against lighting.deferred. Scenes are built in code,
// written as .glb and loaded through scene.gltf, so the whole path (glTF, GPU scene, BVH, layered
// materials, sky nodes, sky.env_cdf) is what is measured. Skies are uniform (sky.hdri of a constant
// image: no sun, cube map C everywhere) unless the sun is the subject.
//
// Closed forms used, with the shared BRDF (common/brdf.glsl: Lambert + GGX/Smith/Schlick, F0 = 0.04 for
// dielectrics, the base colour for metals). At shininess 1 (GGX alpha 0.002) the specular lobe is a
// mirror: its directional albedo under a uniform sky is Schlick's F(NoV) (G2/G1 differs from 1 by less
// than 1e-5 at the angles used). So a convex object under a uniform sky C, with no occlusion, has
//     L = C (diffuseAlbedo + F(NoV))
// and a mirror metal sphere seen from its centre reflects every ray back through the centre at normal
// incidence, so with emission Le and F0 = a the radiance after N bounces is the geometric series
//     L = Le (1 + a + ... + a^N).
#include "tests/gpu/lighting_scene.hpp"

#include "core/image/io.hpp"
#include "core/shading/brdf.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

// Every test below runs twice: on the GPU tracer (PathTrace.*, shaders/render/pathtrace.comp) and on the CPU
// tracer (PathTraceCpu.*, nodes/render/pathtrace_cpu.cpp), with the same scenes and bounds: the two evaluate the
// same estimator, materials and BRDF, and both must meet each closed form.
const char* gBackend = "gpu";

class PathTrace : public GpuTest {};
class PathTraceCpu : public GpuTest {
protected:
    void SetUp() override {
        GpuTest::SetUp();
        gBackend = "cpu";
    }
    void TearDown() override {
        gBackend = "gpu";
        GpuTest::TearDown();
    }
};

#define PATHTRACE_TEST(Name)                                                                                         \
    void Name##Body();                                                                                               \
    TEST_F(PathTrace, Name) { Name##Body(); }                                                                        \
    TEST_F(PathTraceCpu, Name) { Name##Body(); }                                                                     \
    void Name##Body()

// A uniform sky of radiance c (no sun in it) as sky.hdri over an equirect .exr written next to glb.
json uniformSky(const std::filesystem::path& glb, double c) {
    Image sky(32, 16);
    for (int y = 0; y < sky.height; ++y)
        for (int x = 0; x < sky.width; ++x) {
            float* p = sky.at(x, y);
            p[0] = p[1] = p[2] = p[3] = 1.0f;
        }
    const auto file = glb.parent_path() / (glb.stem().string() + "_sky.exr");
    writeExr(file, sky, ExrPixelType::Float);
    return {{"type", "sky.hdri"}, {"params", {{"path", file.string()}, {"intensity", c}, {"size", 16}}}};
}

json pathtraceNode(json params, bool history = false) {
    json in = {{"scene", "scene.scene"},
               {"camera", "scene.camera"},
               {"sky", "sky.cubemap"},
               {"sky_sh", "sky.sh"},
               {"env_cdf", "env_cdf.cdf"}};
    if (history) {
        in["history"] = "pt.color@prev";
        in["history_stats"] = "pt.stats@prev";
    }
    params["backend"] = gBackend;
    return {{"type", "render.pathtrace"}, {"in", in}, {"params", params}};
}

json traceGraph(const std::filesystem::path& glb, json sky, json ptParams, int w, int h, int frames = 1,
                bool history = false) {
    json nodes = {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}}}}},
                  {"sky", sky},
                  {"env_cdf", {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}}},
                  {"pt", pathtraceNode(ptParams, history)}};
    json g = graph(nodes, {{"color", "pt.color"}, {"stats", "pt.stats"}}, w, h);
    g["frame"]["frames"] = frames;
    g["frame"]["write"] = json::array({frames - 1});
    return g;
}

double schlick(double f0, double cosine) {
    return f0 + (1.0 - f0) * std::pow(1.0 - cosine, 5.0);
}

// Directional albedo of the shared BRDF (core/shading, the CPU mirror of brdf.glsl) for a view at NoV:
// the integral of brdfCosine over the hemisphere, midpoint rule in (cos theta, phi), 256 x 256 cells.
double brdfAlbedo(double NoV, glm::vec3 base, float metallic, float roughness) {
    return directionalAlbedo(NoV, 256, [&](glm::vec3 n, glm::vec3 v, glm::vec3 l) {
        return shading::brdfCosine(n, v, l, base, metallic, roughness).g;
    });
}

// White furnace: a white sphere alone under a uniform sky C. A white mirror metal returns C, a white
// smooth dielectric C (1 + F(NoV)) at every pixel (see the top of the file), and a white rough metal
// (roughness 0.65) C times the BRDF's directional albedo at NoV (single-scattering GGX loses energy; the
// CPU integrates core/shading's brdfCosine over the hemisphere): any error in the BRDF's
// sampling weights, the environment's pdf or the MIS weights shows as a departure from these. Bounds: the
// mean over the sphere's pixels within 1 %, each pixel within 25 % (64 samples per pixel), and at least
// 85 % of pixels within two of their own estimated standard errors (stats.w) of the exact value.
PATHTRACE_TEST(WhiteFurnaceSphereReturnsTheEnvironment) {
    const int W = 48, H = 48;
    const double C = 100.0, radius = 1.0;
    struct Case {
        const char* name;
        float metallic, shininess;
    };
    for (const Case& c : {Case{"white_mirror_metal", 1.0f, 1.0f}, Case{"white_smooth_dielectric", 0.0f, 1.0f},
                          Case{"white_rough_metal", 1.0f, 0.35f}}) {
        SCOPED_TRACE(c.name);
        SceneBuilder b(std::string("furnace_") + c.name);
        b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 96, 48),
                                                     b.material(c.name, glm::vec3(1.0f), c.metallic, c.shininess))));
        b.camera({0.0f, 0.5f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f);
        auto glb = b.write();
        auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 64}, {"antialias", false}}, W, H));
        const Image& img = out.at("color");
        Pinhole cam(b.s, W, H);
        // The rough lobe's albedo at 65 values of NoV in [0.2, 1], interpolated linearly (smooth in NoV).
        std::vector<double> albedo;
        if (c.shininess < 1.0f)
            for (int i = 0; i <= 64; ++i)
                albedo.push_back(
                    brdfAlbedo(0.2 + 0.8 * i / 64.0, glm::vec3(1.0f), c.metallic, 1.0f - c.shininess));
        auto roughAlbedo = [&](double NoV) {
            double f = std::clamp((NoV - 0.2) / 0.8 * 64.0, 0.0, 63.999);
            int i = static_cast<int>(f);
            return albedo[i] + (albedo[i + 1] - albedo[i]) * (f - i);
        };
        double sumRatio = 0.0, worst = 0.0, background = 0.0;
        int n = 0, within2 = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 d = cam.ray(x, y);
                double t = hitSphere(cam.position, d, glm::dvec3(0.0), radius);
                if (t < 0.0) {
                    background = std::max(background, relErr(rgb(img, x, y), glm::dvec3(C)));
                    continue;
                }
                glm::dvec3 nrm = glm::normalize(cam.position + t * d);
                double NoV = glm::dot(nrm, -d);
                if (NoV < 0.2) continue; // tessellated silhouette
                double expected = c.shininess < 1.0f  ? C * roughAlbedo(NoV)
                                  : c.metallic > 0.5f ? C
                                                      : C * (1.0 + schlick(0.04, NoV));
                glm::dvec3 got = rgb(img, x, y);
                double ratio = (got.r + got.g + got.b) / (3.0 * expected);
                double se = out.at("stats").at(x, y)[3];
                sumRatio += ratio;
                worst = std::max(worst, std::abs(ratio - 1.0));
                within2 += std::abs(got.g - expected) <= 2.0 * se + 1e-4 * expected ? 1 : 0;
                ++n;
            }
        double mean = sumRatio / n;
        std::printf(
            "furnace %s: %d pixels, mean ratio %.5f, worst pixel %.3f, within 2 standard errors %.3f, background "
            "error %.2g\n",
            c.name, n, mean, worst, double(within2) / n, background);
        ASSERT_GT(n, 500);
        EXPECT_LT(std::abs(mean - 1.0), 0.01);
        EXPECT_LT(worst, 0.25);
        EXPECT_GT(double(within2) / n, 0.85); // the per-pixel error estimate is honest (~95 % for a normal error)
        EXPECT_LT(background, 1e-3);
    }
}

// Energy after N bounces: the camera at the centre of a closed emissive mirror sphere (F0 = a). Each path
// bounces radially, so L = Le (1 + a + ... + a^N) exactly; N = 1, 3, 10 checks max_bounces, and N = 10
// runs Russian roulette from the third surface (unbiased: the mean holds). Bound 1 % on the mean over
// the image (a uniform sky outside must not leak in: the sphere is closed). The sphere is double sided; made
// single sided, the camera inside sees the sky through its culled back faces.
PATHTRACE_TEST(ClosedEmissiveMirrorSphereSumsTheGeometricSeries) {
    const int W = 24, H = 24;
    const double a = 0.7, Le = 5.0;
    SceneBuilder b("closed_sphere");
    uint32_t material = b.material("mirror", glm::vec3(static_cast<float>(a)), 1.0f, 1.0f);
    b.s.materials[material].emissiveFactor = glm::vec3(1.0f);
    b.s.materials[material].emissiveStrength = static_cast<float>(Le);
    b.s.materials[material].doubleSided = true; // seen from inside: a single-sided sphere is culled, as raster does
    b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(4.0f, 64, 32), material)));
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 1.0f);
    auto glb = b.write();
    for (int bounces : {1, 3, 10}) {
        SCOPED_TRACE(bounces);
        auto out = runGraph(traceGraph(glb, uniformSky(glb, 1000.0), {{"spp", 32}, {"max_bounces", bounces}}, W, H));
        const Image& img = out.at("color");
        double sum = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                sum += rgb(img, x, y).g;
        double mean = sum / (W * H);
        double expected = Le * (1.0 - std::pow(a, bounces + 1)) / (1.0 - a);
        std::printf("closed sphere, %d bounces: mean %.5f, expected %.5f\n", bounces, mean, expected);
        EXPECT_LT(std::abs(mean / expected - 1.0), 0.01);
    }
    // Single sided, the sphere is culled from inside (as gbuffer.layered culls it): the camera sees the sky.
    b.s.materials[material].doubleSided = false;
    b.s.name = "closed_sphere_single_sided";
    auto single = b.write();
    auto out = runGraph(traceGraph(single, uniformSky(single, 1000.0), {{"spp", 1}}, W, H));
    EXPECT_NEAR(rgb(out.at("color"), W / 2, H / 2).g, 1000.0, 1.0)
        << "back faces of a single-sided material are culled";
}

// A diffuse plane (base 0.5, smooth dielectric) under a uniform sky C receives E = pi C, so its Lambert
// term is 0.5 E / pi = 0.5 C, and its mirror-like coat adds F(NoV) C: L = C (0.5 + F(NoV)). Bounds: 2 % on
// the mean over the plane's pixels, 35 % per pixel at 32 samples, 85 % of pixels within two estimated
// standard errors.
PATHTRACE_TEST(DiffusePlaneUnderUniformSkyReceivesPiL) {
    const int W = 48, H = 32;
    const double C = 100.0, albedo = 0.5;
    SceneBuilder b("plane");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(20, 0, 0), glm::vec3(0, 0, 20), glm::vec3(0, 1, 0));
    b.node("plane", static_cast<int32_t>(
                        b.mesh("plane", quad, b.material("plane", glm::vec3(static_cast<float>(albedo)), 0.0f, 1.0f))));
    b.camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
    auto glb = b.write();
    auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 32}, {"antialias", false}}, W, H));
    const Image& img = out.at("color");
    Pinhole cam(b.s, W, H);
    double sumRatio = 0.0, worst = 0.0;
    int n = 0, within2 = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y > -0.1) continue;
            double expected = C * (albedo + schlick(0.04, -d.y));
            glm::dvec3 got = rgb(img, x, y);
            double ratio = (got.r + got.g + got.b) / (3.0 * expected);
            sumRatio += ratio;
            worst = std::max(worst, std::abs(ratio - 1.0));
            within2 += std::abs(got.g - expected) <= 2.0 * out.at("stats").at(x, y)[3] ? 1 : 0;
            ++n;
        }
    double mean = sumRatio / n;
    std::printf("plane: %d pixels, mean ratio %.5f, worst pixel %.3f, within 2 standard errors %.3f\n", n, mean, worst,
                double(within2) / n);
    ASSERT_GT(n, 300);
    EXPECT_LT(std::abs(mean - 1.0), 0.02);
    EXPECT_LT(worst, 0.35);
    EXPECT_GT(double(within2) / n, 0.85);
}

// KHR_materials_unlit: a plane of unlit colour c under a uniform sky C emits c and reflects nothing, so every sample
// of every pixel is exactly c (the sky's C = 100 would otherwise add about 0.5 C).
PATHTRACE_TEST(UnlitPlaneEmitsItsColourAndReflectsNothing) {
    const int W = 32, H = 24;
    const glm::vec3 color(0.2f, 0.5f, 0.8f);
    SceneBuilder b("unlit_plane");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(20, 0, 0), glm::vec3(0, 0, 20), glm::vec3(0, 1, 0));
    uint32_t m = b.material("unlit", color, 0.0f, 0.5f);
    b.s.materials[m].unlit = true;
    b.node("plane", static_cast<int32_t>(b.mesh("plane", quad, m)));
    b.camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
    auto glb = b.write();
    auto out = runGraph(traceGraph(glb, uniformSky(glb, 100.0), {{"spp", 4}, {"antialias", false}}, W, H));
    Pinhole cam(b.s, W, H);
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (cam.ray(x, y).y > -0.1) continue;
            EXPECT_LT(relErr(rgb(out.at("color"), x, y), glm::dvec3(color)), 1e-5) << "pixel " << x << "," << y;
            ++n;
        }
    EXPECT_GT(n, 100);
}

// Direct light only (max_bounces 1, sky off, sun on): the path tracer's sun next-event estimation against
// lighting.deferred (sky_ambient 0, no shadow map: the sphere cannot shadow its own lit side) on the
// lighting tests' sphere, rough dielectric and smooth metal. Rays through pixel centres, so both shade
// the same points. Bound 2 % per channel at every pixel with NoV >= 0.3 and NoL >= 0.2 (the G-buffer's
// UNORM8 base colour and RGBA16F octahedral normal account for up to ~1.5 % on the metal).
PATHTRACE_TEST(DirectSunMatchesDeferredLighting) {
    const int W = 64, H = 64;
    const double radius = 1.0, sunScale = 0.03;
    for (const auto& [name, base, metallic, shininess] :
         {std::tuple{"rough_dielectric", glm::vec3(0.8f, 0.5f, 0.25f), 0.0f, 0.25f},
          std::tuple{"smooth_metal", glm::vec3(0.95f, 0.64f, 0.54f), 1.0f, 0.65f}}) {
        SCOPED_TRACE(name);
        SceneBuilder b(std::string("pt_sphere_") + name);
        b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 128, 64),
                                                     b.material(name, base, metallic, shininess))));
        b.camera({0.0f, 0.4f, 3.2f}, {0.0f, 0.0f, 0.0f}, 0.8f);
        b.sun({0.55f, 0.75f, 0.6f});
        auto glb = b.write();
        json nodes = baseNodes(glb);
        nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
        nodes["env_cdf"] = {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}};
        nodes["pt"] = pathtraceNode(
            {{"spp", 1}, {"max_bounces", 1}, {"sky_scale", 0.0}, {"sun_scale", sunScale}, {"antialias", false}});
        auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"pt", "pt.color"}, {"sh", "sky.sh"}}, W, H));
        const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
        Pinhole cam(b.s, W, H);
        int n = 0;
        double worst = 0.0, worstCpu = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 d = cam.ray(x, y);
                double t = hitSphere(cam.position, d, glm::dvec3(0.0), radius);
                if (t < 0.0) continue;
                glm::dvec3 nrm = glm::normalize(cam.position + t * d);
                if (glm::dot(nrm, -d) < 0.3 || glm::dot(nrm, l) < 0.2) continue;
                glm::dvec3 pt = rgb(out.at("pt"), x, y), deferred = rgb(out.at("direct"), x, y);
                double e = relErr(pt, deferred);
                worst = std::max(worst, e);
                EXPECT_LT(e, 0.02) << "pixel " << x << "," << y << ": " << pt.r << " vs " << deferred.r;
                glm::dvec3 cpu = glm::dvec3(shading::shadeDirectional(
                    glm::vec3(nrm), glm::vec3(-d), glm::vec3(l), base, metallic,
                    shading::roughnessFromShininess(shininess),
                    glm::vec3(rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale / kPi)));
                worstCpu = std::max(worstCpu, relErr(pt, cpu));
                ++n;
            }
        std::printf("direct sun %s: %d pixels, worst relative difference to lighting.deferred %.4f, to the CPU BRDF "
                    "%.4f\n",
                    name, n, worst, worstCpu);
        EXPECT_GT(n, 400);
    }
}

// The ground of the material-extension tests below: an 80 m quad of one material (made by `material`) seen from 1 m up,
// lit by a sun 12° above the horizon in front of the camera (sun_scale 0.1), direct light only (sky off, one bounce),
// one sample per pixel through its centre, so no noise.
struct SunlitGround {
    std::map<std::string, Image> out;
    glm::dvec3 toSun, sunE;
    // Every pixel that sees the ground at least 1 m inside its edge, with its view ray.
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
};

// `material` makes the ground's material (and may add more to the scene); `params` adds to or overrides the tracer's.
SunlitGround traceSunlitGround(const std::string& name, int W, int H,
                               const std::function<uint32_t(SceneBuilder&)>& material,
                               const json& params = json::object(), double sunElevationDegrees = 12.0) {
    const float groundHalf = 40.0f;
    const double sunElevation = sunElevationDegrees * kPi / 180.0, sunScale = 0.1;
    SceneBuilder b(name);
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    const uint32_t m = material(b);
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, m)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    b.sun({0.0f, static_cast<float>(std::sin(sunElevation)), static_cast<float>(-std::cos(sunElevation))});
    auto glb = b.write();
    json nodes = baseNodes(glb);
    nodes["env_cdf"] = {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}};
    json ptParams = {{"spp", 1}, {"max_bounces", 1}, {"sky_scale", 0.0}, {"sun_scale", sunScale}, {"antialias", false}};
    ptParams.update(params);
    nodes["pt"] = pathtraceNode(ptParams);
    SunlitGround g;
    g.out = runGraph(graph(nodes, {{"pt", "pt.color"}, {"sh", "sky.sh"}}, W, H));
    g.toSun = glm::normalize(rgb(g.out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    g.sunE = rgb(g.out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
    Pinhole cam(b.s, W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue;
            g.pixels.push_back({{x, y}, d});
        }
    return g;
}

// Checks the traced pixels against `expected` (per channel, relative, within `bound`) where the expected red is above
// 1 % of the brightest; returns the pixels checked and the worst error.
std::pair<int, double> expectPixels(const Image& traced, const std::vector<std::pair<glm::ivec2, glm::dvec3>>& expected,
                                    double bound) {
    double brightest = 0.0;
    for (const auto& [px, e] : expected) brightest = std::max(brightest, e.r);
    int checked = 0;
    double worst = 0.0;
    for (const auto& [px, e] : expected) {
        if (e.r < 0.01 * brightest) continue;
        glm::dvec3 got = rgb(traced, px.x, px.y);
        double err = relErr(got, e);
        worst = std::max(worst, err);
        ++checked;
        EXPECT_LT(err, bound) << "pixel " << px.x << "," << px.y << ": " << got.r << " vs " << e.r;
    }
    return {checked, worst};
}

// KHR_materials_specular in the tracers: a grey rough dielectric ground with strength k = 0.5 and colour
// c = (1, 0.5, 0.25) under the sun of traceSunlitGround. By the extension's closed form its specular is
// k (F0c + (1 - F0c)(1 - VoH)^5) D V with F0c = 0.04 c, which is k times the plain BRDF's specular lobe with F0 = F0c
// (core/shading brdfCosineF0 with no diffuse, code the extension does not touch), plus the Lambert base / pi. The
// plane's normal is exact and rays go through pixel centres: bound 1 % per channel where the expected value is above
// 1 % of the brightest, and the glare's grazing pixels (VoH <= 0.3, where F90 = k rather than 1 counts most) must be
// among them.
PATHTRACE_TEST(SpecularExtensionDirectSunMatchesItsClosedForm) {
    const float shininess = 0.55f, k = 0.5f;
    const glm::vec3 base(0.05f), color(1.0f, 0.5f, 0.25f);
    const SunlitGround g = traceSunlitGround("pt_specular_ext", 64, 64, [&](SceneBuilder& b) {
        uint32_t m = b.material("tinted", base, 0.0f, shininess);
        b.s.materials[m].specular = k;
        b.s.materials[m].specularColor = color;
        return m;
    });
    const glm::vec3 f0c = glm::min(0.04f * color, glm::vec3(1.0f));
    const float roughness = shading::roughnessFromShininess(shininess);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    for (const auto& [px, d] : g.pixels) {
        glm::vec3 n(0, 1, 0), v(-d), lf(g.toSun);
        glm::dvec3 spec(float(k) * shading::brdfCosineF0(n, v, lf, glm::vec3(0.0f), f0c, roughness));
        glm::dvec3 diffuse = glm::dvec3(base) / kPi * std::max(0.0, glm::dot(glm::dvec3(n), g.toSun));
        expected.push_back({px, (spec + diffuse) * g.sunE});
    }
    const auto [checked, worst] = expectPixels(g.out.at("pt"), expected, 0.01);
    double brightest = 0.0;
    for (const auto& [px, e] : expected) brightest = std::max(brightest, e.r);
    int grazing = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
        if (expected[i].second.r < 0.01 * brightest) continue;
        glm::dvec3 v = -g.pixels[i].second;
        if (glm::dot(v, glm::normalize(v + g.toSun)) <= 0.3) ++grazing;
    }
    std::printf("%s tracer, KHR_materials_specular ground: %d pixels (%d grazing), worst relative error %.4f\n",
                gBackend, checked, grazing, worst);
    EXPECT_GE(checked, 300);
    EXPECT_GE(grazing, 50);
}

// KHR_materials_clearcoat in the tracers, direct sun: the ground of the test above (grey 0.05, shininess 0.55) under a
// coat of strength 0.8 and roughness 0.3: the closed form is core/shading brdfCosineClearcoat (checked against the
// Khronos layering in shading.Brdf.ClearcoatMatchesTheKhronosLayering). Bound 1 % per channel where the expected value
// is above 1 % of the brightest.
PATHTRACE_TEST(ClearcoatDirectSunMatchesItsClosedForm) {
    const float shininess = 0.55f, c = 0.8f, coatRoughness = 0.3f;
    const glm::vec3 base(0.05f);
    const SunlitGround g = traceSunlitGround("pt_clearcoat", 64, 64, [&](SceneBuilder& b) {
        uint32_t m = b.material("coated", base, 0.0f, shininess);
        b.s.materials[m].clearcoat = c;
        b.s.materials[m].clearcoatRoughness = coatRoughness;
        return m;
    });
    const float roughness = shading::roughnessFromShininess(shininess);
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    double coatMatters = 0.0;
    for (const auto& [px, d] : g.pixels) {
        glm::vec3 n(0, 1, 0), v(-d), lf(g.toSun);
        glm::dvec3 e = glm::dvec3(shading::brdfCosineClearcoat(n, n, v, lf, base, 0.0f, roughness, plain,
                                                               glm::vec2(c, coatRoughness))) *
                       g.sunE;
        glm::dvec3 uncoated = glm::dvec3(shading::brdfCosine(n, v, lf, base, 0.0f, roughness)) * g.sunE;
        coatMatters = std::max(coatMatters, e.r / std::max(uncoated.r, 1e-9));
        expected.push_back({px, e});
    }
    const auto [checked, worst] = expectPixels(g.out.at("pt"), expected, 0.01);
    std::printf("%s tracer, KHR_materials_clearcoat ground: %d pixels, worst relative error %.4f, coated / uncoated "
                "up to %.1f\n",
                gBackend, checked, worst, coatMatters);
    EXPECT_GE(checked, 300);
    EXPECT_GT(coatMatters, 2.0);
}

// clearcoatNormalTexture in the tracers: the coated ground above with a coat normal map of one texel, the unit
// tangent-space normal about (0.30, -0.15, 0.94) stored as UNORM8 and scaled by 0.8 (the coat's tangent-space normal
// is (2 t - 1) with its xy scaled, as a layer's normal map), while the base keeps the vertex normal. The ground's
// tangent frame is that of lighting_scene's vertex(): t = +z, b = n x t = +x. The closed form is brdfCosineClearcoat
// with the coat normal decoded here from the stored bytes; the tilt moves the coat's highlight (checked: the untilted
// coat differs by more than 2x somewhere), so a wrong decode, a dropped scale or swapped channels all show. Bound
// 1 % per channel where the expected value is above 1 % of the brightest.
PATHTRACE_TEST(ClearcoatNormalMapTiltsOnlyTheCoat) {
    const float shininess = 0.55f, c = 0.8f, coatRoughness = 0.2f, scale = 0.8f;
    const glm::vec3 base(0.05f);
    const uint8_t texel[4] = {166, 108, 248, 255}; // (0.30, -0.15, 0.94) x 0.5 + 0.5, rounded
    const SunlitGround g = traceSunlitGround("pt_clearcoat_normal", 64, 64, [&](SceneBuilder& b) {
        scene::TextureImage img;
        img.name = "coat_normal";
        img.width = img.height = 2;
        img.pixels.resize(2 * 2 * 4);
        for (size_t i = 0; i < img.pixels.size(); ++i)
            img.pixels[i] = texel[i % 4];
        b.s.images.push_back(std::move(img));
        scene::Texture t;
        t.name = "coat_normal";
        t.image = static_cast<uint32_t>(b.s.images.size() - 1);
        t.usage = scene::TextureUsage::Normal;
        b.s.textures.push_back(t);
        uint32_t m = b.material("coated", base, 0.0f, shininess);
        b.s.materials[m].clearcoat = c;
        b.s.materials[m].clearcoatRoughness = coatRoughness;
        b.s.materials[m].clearcoatNormal.scale = scale;
        b.s.materials[m].clearcoatNormal.texture.texture = static_cast<int32_t>(b.s.textures.size() - 1);
        return m;
    });
    const glm::vec3 n(0, 1, 0), t(0, 0, 1), bt(1, 0, 0);
    glm::vec3 cts = glm::vec3(texel[0], texel[1], texel[2]) / 255.0f * 2.0f - 1.0f;
    cts = glm::normalize(glm::vec3(cts.x * scale, cts.y * scale, cts.z));
    const glm::vec3 nc = glm::normalize(t * cts.x + bt * cts.y + n * cts.z);
    const float roughness = shading::roughnessFromShininess(shininess);
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    double tiltMatters = 0.0;
    for (const auto& [px, d] : g.pixels) {
        glm::vec3 v(-d), lf(g.toSun);
        const glm::vec2 coat(c, coatRoughness);
        glm::dvec3 e =
            glm::dvec3(shading::brdfCosineClearcoat(n, nc, v, lf, base, 0.0f, roughness, plain, coat)) * g.sunE;
        glm::dvec3 flat =
            glm::dvec3(shading::brdfCosineClearcoat(n, n, v, lf, base, 0.0f, roughness, plain, coat)) * g.sunE;
        tiltMatters = std::max(tiltMatters, std::max(e.r / std::max(flat.r, 1e-9), flat.r / std::max(e.r, 1e-9)));
        expected.push_back({px, e});
    }
    const auto [checked, worst] = expectPixels(g.out.at("pt"), expected, 0.01);
    std::printf("%s tracer, clear coat with its own normal map: %d pixels, worst relative error %.4f, tilted / flat "
                "coat up to %.1fx apart\n",
                gBackend, checked, worst, tiltMatters);
    EXPECT_GE(checked, 300);
    EXPECT_GT(tiltMatters, 2.0);
}

// Energy of the coat's lobe in the tracers' sampling: a white rough dielectric sphere (shininess 0.35) under a full
// coat of roughness 0.4, alone under a uniform sky C (the furnace above). Its radiance is C times the coated BRDF's
// directional albedo at NoV, integrated here on a fine grid from core/shading brdfCosineClearcoat; a coat lobe sampled
// with a pdf other than brdfPdf's, or MIS weights that do not sum to 1, shows as a departure. Bounds as the furnace:
// mean within 1 %, each pixel within 25 % (64 samples per pixel).
// A furnace sphere (centre at the origin) under a uniform sky C: per pixel, the traced radiance over C times the
// directional albedo at its NoV, interpolated in `albedo` (33 samples from NoV 0.2 to 1); pixels nearer the
// silhouette than NoV 0.2 are left out (the tessellation). The mean and worst |ratio - 1| over n pixels.
struct FurnaceRatio {
    double mean = 0.0, worst = 0.0;
    int n = 0;
};

FurnaceRatio furnaceSphereRatio(const Image& img, const Pinhole& cam, double radius, double C,
                                const std::vector<double>& albedo) {
    auto interp = [&](double NoV) {
        double f = std::clamp((NoV - 0.2) / 0.8 * 32.0, 0.0, 31.999);
        int i = static_cast<int>(f);
        return albedo[i] + (albedo[i + 1] - albedo[i]) * (f - i);
    };
    FurnaceRatio r;
    double sumRatio = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double t = hitSphere(cam.position, d, glm::dvec3(0.0), radius);
            if (t < 0.0) continue;
            glm::dvec3 nrm = glm::normalize(cam.position + t * d);
            double NoV = glm::dot(nrm, -d);
            if (NoV < 0.2) continue; // tessellated silhouette
            glm::dvec3 got = rgb(img, x, y);
            double ratio = (got.r + got.g + got.b) / (3.0 * C * interp(NoV));
            sumRatio += ratio;
            r.worst = std::max(r.worst, std::abs(ratio - 1.0));
            ++r.n;
        }
    r.mean = sumRatio / r.n;
    return r;
}

PATHTRACE_TEST(ClearcoatFurnaceSphereReflectsItsAlbedo) {
    const int W = 48, H = 48;
    const double C = 100.0, radius = 1.0;
    const float shininess = 0.35f, coatRoughness = 0.4f;
    SceneBuilder b("furnace_clearcoat");
    uint32_t m = b.material("white_coated", glm::vec3(1.0f), 0.0f, shininess);
    b.s.materials[m].clearcoat = 1.0f;
    b.s.materials[m].clearcoatRoughness = coatRoughness;
    b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 96, 48), m)));
    b.camera({0.0f, 0.5f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f);
    auto glb = b.write();
    auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 64}, {"antialias", false}}, W, H));
    const Image& img = out.at("color");
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    auto albedoAt = [&](double NoV) {
        return directionalAlbedo(NoV, 512, [&](glm::vec3 n, glm::vec3 v, glm::vec3 l) {
            return shading::brdfCosineClearcoat(n, n, v, l, glm::vec3(1.0f), 0.0f,
                                                shading::roughnessFromShininess(shininess), plain,
                                                glm::vec2(1.0f, coatRoughness))
                .g;
        });
    };
    std::vector<double> albedo;
    for (int i = 0; i <= 32; ++i)
        albedo.push_back(albedoAt(0.2 + 0.8 * i / 32.0));
    const auto [mean, worst, n] = furnaceSphereRatio(img, Pinhole(b.s, W, H), radius, C, albedo);
    std::printf("%s tracer, clearcoat furnace: %d pixels, albedo %.4f (NoV 1) .. %.4f (NoV 0.2), mean ratio %.5f, "
                "worst pixel %.3f\n",
                gBackend, n, albedo.back(), albedo.front(), mean, worst);
    ASSERT_GT(n, 500);
    EXPECT_LT(std::abs(mean - 1.0), 0.01);
    EXPECT_LT(worst, 0.25);
}

// render.pathtrace's `multiscatter`: the white furnace sphere above of a rough white metal (roughness 0.5 and 0.8),
// traced with the lobe's multiple-scattering compensation, returns the environment C at every pixel (a white metal's
// compensated lobe reflects all it gets, [Turquin19]; single scattering returned 0.60-0.80 of it here), through the
// tracers' BRDF evaluation for the sampled direction and the sky's next-event estimate alike. Bounds: the mean over
// the sphere within 2 % (the albedo fit's relative error is up to 1.9 %, 0.6 % measured on the CPU quadrature), each
// pixel within 50 % (32 samples per pixel of a lobe this rough: the worst of some 800 pixels was measured at 28 % with
// 64). Single scattering is traced once, at roughness 0.8, to show what the bound sees.
PATHTRACE_TEST(MultiscatterFurnaceSphereReturnsTheEnvironment) {
    const int W = 40, H = 40;
    const double C = 100.0, radius = 1.0;
    for (const float shininess : {0.5f, 0.2f}) {
        SCOPED_TRACE(shininess);
        SceneBuilder b("furnace_multiscatter_" + std::to_string(static_cast<int>(shininess * 10.0f)));
        b.node("sphere",
               static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 96, 48),
                                           b.material("white_rough_metal", glm::vec3(1.0f), 1.0f, shininess))));
        b.camera({0.0f, 0.5f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f);
        auto glb = b.write();
        const std::vector<double> one(33, 1.0);
        double means[2] = {1.0, 0.0};
        for (const bool ms : {true, false}) {
            if (!ms && shininess > 0.3f) continue;
            auto out = runGraph(
                traceGraph(glb, uniformSky(glb, C), {{"spp", 32}, {"antialias", false}, {"multiscatter", ms}}, W, H));
            const auto [mean, worst, n] = furnaceSphereRatio(out.at("color"), Pinhole(b.s, W, H), radius, C, one);
            std::printf("%s tracer, furnace of a white metal of roughness %.1f, multiscatter %s: %d pixels, mean "
                        "radiance / C %.5f, worst pixel %.3f\n",
                        gBackend, 1.0 - shininess, ms ? "on" : "off", n, mean, worst);
            ASSERT_GT(n, 500);
            means[ms ? 0 : 1] = mean;
            if (ms) {
                EXPECT_LT(std::abs(mean - 1.0), 0.02);
                EXPECT_LT(worst, 0.5);
            }
        }
        if (shininess < 0.3f) {
            EXPECT_LT(means[1], 0.9) << "single scattering must lose what the compensation gives back";
        }
    }
}

// render.pathtrace's `multiscatter` for the sun (next-event estimation, one bounce): a rough metal ground (base colour
// (0.9, 0.6, 0.3), shininess 0.3) against the closed form core/shading brdfCosineSpecular with the compensation.
// Bound 1 % per channel, as the sheen's below; the compensation is measured x1.2 or more on the brightest pixels, so a
// tracer leaving it out of its sun fails.
PATHTRACE_TEST(MultiscatterDirectSunMatchesItsClosedForm) {
    const glm::vec3 base(0.9f, 0.6f, 0.3f);
    const float shininess = 0.3f;
    const SunlitGround g = traceSunlitGround(
        "pt_multiscatter_sun", 64, 64,
        [&](SceneBuilder& b) { return b.material("rough_metal", base, 1.0f, shininess); }, {{"multiscatter", true}},
        35.0);
    const float roughness = shading::roughnessFromShininess(shininess);
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    double compensation = 0.0;
    for (const auto& [px, d] : g.pixels) {
        glm::vec3 n(0, 1, 0), v(-d), lf(g.toSun);
        glm::dvec3 e = glm::dvec3(shading::brdfCosineSpecular(n, v, lf, base, 1.0f, roughness, plain, true)) * g.sunE;
        glm::dvec3 single =
            glm::dvec3(shading::brdfCosineSpecular(n, v, lf, base, 1.0f, roughness, plain, false)) * g.sunE;
        compensation = std::max(compensation, e.r / std::max(single.r, 1e-9));
        expected.push_back({px, e});
    }
    const auto [checked, worst] = expectPixels(g.out.at("pt"), expected, 0.01);
    std::printf("%s tracer, multiscatter sun on a rough metal: %d pixels, worst relative error %.4f, compensation up "
                "to x%.3f\n",
                gBackend, checked, worst, compensation);
    EXPECT_GE(checked, 300);
    EXPECT_GT(compensation, 1.1);
}

// KHR_materials_sheen in the tracers, direct sun: the ground of the tests above (grey 0.05, shininess 0.55) under a
// sheen of colour (0.9, 0.5, 0.6) and roughness 0.5: the closed form is core/shading brdfCosineSheen (its lobe checked
// against the spec's formulas in shading.Brdf.SheenLobeMatchesTheKhronosFormulas). Bound 1 % per channel where the
// expected value is above 1 % of the brightest.
PATHTRACE_TEST(SheenDirectSunMatchesItsClosedForm) {
    const float shininess = 0.55f;
    const glm::vec4 sheen(0.9f, 0.5f, 0.6f, 0.5f);
    const glm::vec3 base(0.05f);
    const SunlitGround g = traceSunlitGround("pt_sheen", 64, 64, [&](SceneBuilder& b) {
        uint32_t m = b.material("velvet", base, 0.0f, shininess);
        b.s.materials[m].sheenColor = glm::vec3(sheen);
        b.s.materials[m].sheenRoughness = sheen.a;
        return m;
    });
    const float roughness = shading::roughnessFromShininess(shininess);
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    double sheenMatters = 0.0;
    for (const auto& [px, d] : g.pixels) {
        glm::vec3 n(0, 1, 0), v(-d), lf(g.toSun);
        glm::dvec3 e =
            glm::dvec3(shading::brdfCosineSheen(n, n, v, lf, base, 0.0f, roughness, plain, glm::vec2(0.0f), sheen)) *
            g.sunE;
        glm::dvec3 bare = glm::dvec3(shading::brdfCosine(n, v, lf, base, 0.0f, roughness)) * g.sunE;
        sheenMatters = std::max(sheenMatters, e.b / std::max(bare.b, 1e-9));
        expected.push_back({px, e});
    }
    const auto [checked, worst] = expectPixels(g.out.at("pt"), expected, 0.01);
    std::printf("%s tracer, KHR_materials_sheen ground: %d pixels, worst relative error %.4f, with / without sheen "
                "up to %.1f\n",
                gBackend, checked, worst, sheenMatters);
    EXPECT_GE(checked, 300);
    EXPECT_GT(sheenMatters, 1.5);
}

// Energy of the sheen's lobe in the tracers' sampling: a rough metal sphere of base colour 0.7 (shininess 0.35; a
// metal, so that the base's mixture is GGX alone and the sheen's cosine lobe has its own directions to account for)
// under a white sheen of roughness 0.5, alone under a uniform sky C (the furnace above). Its radiance is C times the
// layered BRDF's directional albedo at NoV, sheen E + (1 - E) base, integrated here on a fine grid from core/shading
// brdfCosineSheen; a sheen lobe sampled with a pdf other than brdfPdf's, a base not scaled by 1 - E, or MIS weights
// that do not sum to 1, shows as a departure. The albedo must stay at most 1 (the sheen takes the energy it adds
// from the base). Bounds as the furnace: mean within 1 %, each pixel within 25 % (64 samples per pixel).
PATHTRACE_TEST(SheenFurnaceSphereReflectsItsAlbedo) {
    const int W = 48, H = 48;
    const double C = 100.0, radius = 1.0;
    const float shininess = 0.35f;
    const glm::vec3 base(0.7f);
    const glm::vec4 sheen(1.0f, 1.0f, 1.0f, 0.5f);
    SceneBuilder b("furnace_sheen");
    uint32_t m = b.material("metal_sheen", base, 1.0f, shininess);
    b.s.materials[m].sheenColor = glm::vec3(sheen);
    b.s.materials[m].sheenRoughness = sheen.a;
    b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 96, 48), m)));
    b.camera({0.0f, 0.5f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f);
    auto glb = b.write();
    auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 64}, {"antialias", false}}, W, H));
    const Image& img = out.at("color");
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    const float roughness = shading::roughnessFromShininess(shininess);
    auto albedoAt = [&](double NoV, glm::vec4 sh) {
        return directionalAlbedo(NoV, 512, [&](glm::vec3 n, glm::vec3 v, glm::vec3 l) {
            return shading::brdfCosineSheen(n, n, v, l, base, 1.0f, roughness, plain, glm::vec2(0.0f), sh).g;
        });
    };
    std::vector<double> albedo;
    double sheenShare = 0.0;
    for (int i = 0; i <= 32; ++i) {
        double NoV = 0.2 + 0.8 * i / 32.0;
        albedo.push_back(albedoAt(NoV, sheen));
        EXPECT_LE(albedo.back(), 1.0) << "NoV " << NoV;
        sheenShare = std::max(sheenShare, albedo.back() - albedoAt(NoV, glm::vec4(0.0f)));
    }
    const auto [mean, worst, n] = furnaceSphereRatio(img, Pinhole(b.s, W, H), radius, C, albedo);
    std::printf("%s tracer, sheen furnace: %d pixels, albedo %.4f (NoV 1) .. %.4f (NoV 0.2), sheen adds up to %.4f, "
                "mean ratio %.5f, worst pixel %.3f\n",
                gBackend, n, albedo.back(), albedo.front(), sheenShare, mean, worst);
    ASSERT_GT(n, 500);
    EXPECT_GT(sheenShare, 0.02); // the sheen changes the albedo somewhere (a base not scaled would too, upwards)
    EXPECT_LT(std::abs(mean - 1.0), 0.01);
    EXPECT_LT(worst, 0.25);
}

// Textures as ray tracers sample them (the texel pool: one buffer for all textures, scene.glsl
// VITRINE_SCENE_TEXEL_POOL) against the G-buffer's hardware samplers: two textured planes under the sun, direct
// light only, path traced and deferred-lit. The textures are small and magnified (LOD 0 in both), sRGB colour, and
// their UVs run past [0, 1] on both sides, so every wrap mode (repeat, mirrored repeat, clamp to edge) and both
// magnification filters (linear, nearest) are crossed. Bound: each pixel within 3 % of lighting.deferred (of its
// brightest channel; measured worst 2.3 % on lavapipe, at high-contrast texel transitions, where lavapipe filters
// with 8-bit weights and the G-buffer keeps an 8-bit albedo) away from the texel edges of the
// nearest-filtered plane, where a half-texel shift would show as a whole-texel error.
PATHTRACE_TEST(TexturedSurfacesMatchTheRasterisersSamplers) {
    const int W = 96, H = 64;
    const double sunScale = 0.03;
    SceneBuilder b("pt_textured");
    auto image = [&](const char* name, uint32_t size, uint32_t seed) {
        scene::TextureImage img;
        img.name = name;
        img.width = img.height = size;
        img.pixels.resize(size * size * 4);
        uint32_t state = seed;
        for (auto& byte : img.pixels) {
            state = state * 1664525u + 1013904223u;
            byte = static_cast<uint8_t>(40 + (state >> 24) % 216);
        }
        for (size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 255;
        b.s.images.push_back(std::move(img));
        return static_cast<uint32_t>(b.s.images.size() - 1);
    };
    auto texturedMaterial = [&](const char* name, uint32_t img, scene::Sampler sampler) {
        scene::Texture t;
        t.name = name;
        t.image = img;
        t.usage = scene::TextureUsage::Color;
        t.sampler = sampler;
        b.s.textures.push_back(t);
        uint32_t m = b.material(name, glm::vec3(1.0f), 0.0f, 0.3f);
        b.s.materials[m].layers[0].albedo.texture.texture = static_cast<int32_t>(b.s.textures.size() - 1);
        return m;
    };
    scene::Sampler linear;
    linear.wrapU = scene::Wrap::Repeat;
    linear.wrapV = scene::Wrap::MirroredRepeat;
    scene::Sampler nearest;
    nearest.magFilter = nearest.minFilter = scene::Filter::Nearest;
    nearest.wrapU = scene::Wrap::ClampToEdge;
    nearest.wrapV = scene::Wrap::Repeat;
    const uint32_t mLinear = texturedMaterial("linear", image("linear", 4, 7u), linear);
    const uint32_t mNearest = texturedMaterial("nearest", image("nearest", 4, 99u), nearest);
    // Two planes side by side (y = 0, facing +y), UV = (x, z) scaled so each spans about [-1.3, 1.7].
    auto plane = [&](const char* name, uint32_t material, float cx) {
        std::vector<Tri> tris;
        addQuad(tris, {cx, 0.0f, 0.0f}, {0.95f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.5f}, {0.0f, 1.0f, 0.0f});
        for (Tri& t : tris)
            for (scene::Vertex* v : {&t.a, &t.b, &t.c})
                v->uv0 = glm::vec2((v->position.x - cx) * 1.58f + 0.2f, v->position.z * 1.0f + 0.2f);
        b.node(name, static_cast<int32_t>(b.mesh(name, tris, material)));
    };
    plane("linear", mLinear, -1.0f);
    plane("nearest", mNearest, 1.0f);
    b.camera({0.0f, 3.0f, 1.2f}, {0.0f, 0.0f, 0.0f}, 0.9f);
    b.sun({0.2f, 1.0f, 0.3f});
    auto glb = b.write();
    json nodes = baseNodes(glb);
    nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
    nodes["env_cdf"] = {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}};
    nodes["pt"] = pathtraceNode(
        {{"spp", 1}, {"max_bounces", 1}, {"sky_scale", 0.0}, {"sun_scale", sunScale}, {"antialias", false}});
    auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"pt", "pt.color"}}, W, H));
    Pinhole cam(b.s, W, H);
    int n = 0, failures = 0;
    double worst = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 o = cam.position, d = cam.ray(x, y);
            if (d.y >= -1e-3) continue;
            glm::dvec3 p = o + d * (-o.y / d.y);
            const bool left = p.x < 0.0;
            const double cx = left ? -1.0 : 1.0;
            // Inside a plane, away from its border.
            if (std::abs(p.x - cx) > 0.9 || std::abs(p.z) > 1.45) continue;
            if (!left) {
                // Nearest: skip pixels within a tenth of a texel of a texel edge (4 texels per unit UV).
                double u = ((p.x - cx) * 1.58 + 0.2) * 4.0, v = (p.z + 0.2) * 4.0;
                auto nearEdge = [](double t) { return std::abs(t - std::round(t)) < 0.1; };
                if (nearEdge(u) || nearEdge(v)) continue;
            }
            glm::dvec3 pt = rgb(out.at("pt"), x, y), deferred = rgb(out.at("direct"), x, y);
            // Relative to the brightest channel: the G-buffer's 8-bit linear albedo is coarse in a dark channel.
            glm::dvec3 diff = glm::abs(pt - deferred);
            double e = std::max({diff.r, diff.g, diff.b}) / std::max({deferred.r, deferred.g, deferred.b, 1e-6});
            worst = std::max(worst, e);
            if (e > 0.03 && ++failures <= 5)
                ADD_FAILURE() << (left ? "linear" : "nearest") << " plane, pixel " << x << "," << y << ": "
                              << pt.r << "," << pt.g << "," << pt.b << " vs " << deferred.r << "," << deferred.g
                              << "," << deferred.b;
            ++n;
        }
    std::printf("textured planes: %d pixels, worst relative difference to lighting.deferred %.4f\n", n, worst);
    EXPECT_EQ(failures, 0);
    EXPECT_GT(n, 2000);
}

// A box room open at the front, as a Cornell box: white floor, ceiling and back wall, a red and a green side wall,
// a small emissive panel under the ceiling, a uniform sky outside. Most light reaches the walls after several
// bounces, so the whole estimator (BRDF sampling, sky sampling and MIS, emitters found by BRDF sampling, Russian
// roulette, the back-face rule) is exercised.
std::filesystem::path boxRoom(float whiteAlbedo = 0.75f, glm::vec3 eye = {0.0f, 0.0f, 3.4f},
                              const std::string& name = "pt_box_room") {
    SceneBuilder b(name);
    const uint32_t white = b.material("white", glm::vec3(whiteAlbedo), 0.0f, 0.3f);
    const uint32_t red = b.material("red", glm::vec3(0.7f, 0.1f, 0.08f), 0.0f, 0.4f);
    const uint32_t green = b.material("green", glm::vec3(0.12f, 0.6f, 0.1f), 0.0f, 0.4f);
    const uint32_t metal = b.material("metal", glm::vec3(0.9f, 0.8f, 0.6f), 1.0f, 0.7f);
    const uint32_t lamp = b.material("lamp", glm::vec3(0.0f), 0.0f, 0.0f);
    b.s.materials[lamp].emissiveFactor = glm::vec3(40.0f, 36.0f, 30.0f);
    auto quads = [&](const char* name, uint32_t material, std::initializer_list<std::array<glm::vec3, 4>> list) {
        std::vector<Tri> tris;
        for (const auto& q : list) addQuad(tris, q[0], q[1], q[2], q[3]);
        b.node(name, static_cast<int32_t>(b.mesh(name, tris, material)));
    };
    // The room spans x, y in [-1, 1], z in [-1, 1]; it is open towards +z, where the camera is.
    quads("white", white,
          {{glm::vec3(0, -1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)},
           {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, -1, 0)},
           {glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)}});
    quads("red", red, {{glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0)}});
    quads("green", green, {{glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0)}});
    quads("lamp", lamp, {{glm::vec3(0, 0.98f, -0.2f), glm::vec3(0.3f, 0, 0), glm::vec3(0, 0, 0.3f), glm::vec3(0, -1, 0)}});
    std::vector<Tri> box = boxTris(glm::vec3(0.25f, 0.45f, 0.25f));
    for (Tri& t : box)
        for (scene::Vertex* v : {&t.a, &t.b, &t.c}) v->position += glm::vec3(0.35f, -0.55f, -0.35f);
    b.node("block", static_cast<int32_t>(b.mesh("block", box, metal)));
    b.camera(eye, {0.0f, 0.0f, 0.0f}, 0.7f);
    return b.write();
}

// Mean luminance and the standard error of that mean over each 8x8 block, from the node's colour and stats.
struct BlockMeans {
    std::vector<double> mean, error;
};
BlockMeans blockMeans(const Image& color, const Image& stats, int block) {
    BlockMeans m;
    for (int by = 0; by + block <= color.height; by += block)
        for (int bx = 0; bx + block <= color.width; bx += block) {
            double sum = 0.0, var = 0.0;
            for (int y = by; y < by + block; ++y)
                for (int x = bx; x < bx + block; ++x) {
                    const float* c = color.at(x, y);
                    sum += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    var += static_cast<double>(stats.at(x, y)[3]) * stats.at(x, y)[3];
                }
            const double n = static_cast<double>(block) * block;
            m.mean.push_back(sum / n);
            m.error.push_back(std::sqrt(var) / n);
        }
    return m;
}

// The CPU tracer and the GPU tracer are two implementations of one estimator: in the box room each 8x8 block's
// mean luminance agrees within 4 combined standard errors (from each tracer's own stats), and the whole frame
// within 2 %.
TEST_F(PathTrace, CpuAndGpuTracersAgreeInABoxRoom) {
    const int W = 48, H = 48;
    const auto glb = boxRoom();
    std::map<std::string, BlockMeans> blocks;
    for (const char* backend : {"gpu", "cpu"}) {
        gBackend = backend;
        auto out = runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", 64}, {"seed", 7}}, W, H));
        blocks[backend] = blockMeans(out.at("color"), out.at("stats"), 8);
    }
    gBackend = "gpu";
    const BlockMeans &g = blocks["gpu"], &c = blocks["cpu"];
    double sumG = 0.0, sumC = 0.0, worstZ = 0.0;
    for (size_t i = 0; i < g.mean.size(); ++i) {
        const double z = std::abs(g.mean[i] - c.mean[i]) / std::sqrt(g.error[i] * g.error[i] + c.error[i] * c.error[i] + 1e-12);
        worstZ = std::max(worstZ, z);
        EXPECT_LT(z, 4.0) << "block " << i << ": GPU " << g.mean[i] << " +- " << g.error[i] << ", CPU " << c.mean[i]
                          << " +- " << c.error[i];
        sumG += g.mean[i];
        sumC += c.mean[i];
    }
    std::printf("box room: mean luminance GPU %.4f, CPU %.4f (ratio %.4f); worst block %.2f standard errors\n",
                sumG / g.mean.size(), sumC / c.mean.size(), sumC / sumG, worstZ);
    EXPECT_NEAR(sumC / sumG, 1.0, 0.02);
}

// The estimator is consistent: in the box room, the RMS error against a run at 16x the samples of the largest
// count falls as 1/sqrt(spp) over 4 doublings (8 to 64 spp; the reference's own variance, 1/16 of the
// 64-spp run's, is part of the expectation). On the CPU tracer (the GPU tracer takes 40 s for the same on lavapipe;
// it is held to the CPU one by CpuAndGpuTracersAgreeInABoxRoom).
TEST_F(PathTraceCpu, ErrorFallsAsOneOverSqrtSamples) {
    const int W = 24, H = 24;
    const auto glb = boxRoom();
    auto render = [&](int spp, int seed) {
        return runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", spp}, {"seed", seed}}, W, H)).at("color");
    };
    const Image reference = render(1024, 1000);
    std::vector<double> rms;
    for (int spp : {8, 16, 32, 64}) {
        const Image img = render(spp, spp);
        double sum = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int ch = 0; ch < 3; ++ch) {
                    double d = img.at(x, y)[ch] - reference.at(x, y)[ch];
                    sum += d * d;
                }
        rms.push_back(std::sqrt(sum / (W * H * 3)));
    }
    for (size_t i = 0; i + 1 < rms.size(); ++i) {
        const double spp = 8.0 * std::pow(2.0, static_cast<double>(i));
        const double expected = std::sqrt((1.0 / spp + 1.0 / 1024.0) / (1.0 / (2.0 * spp) + 1.0 / 1024.0));
        std::printf("spp %.0f -> %.0f: RMS error %.4f -> %.4f, ratio %.3f (expected %.3f)\n", spp, 2 * spp, rms[i],
                    rms[i + 1], rms[i] / rms[i + 1], expected);
        EXPECT_NEAR(rms[i] / rms[i + 1], expected, 0.2 * expected);
    }
    const double expectedAll = std::sqrt((1.0 / 8.0 + 1.0 / 1024.0) / (1.0 / 64.0 + 1.0 / 1024.0));
    EXPECT_NEAR(rms.front() / rms.back(), expectedAll, 0.15 * expectedAll);
}

// target_noise: a converged result is stored in the bake cache and loaded, not traced, by the next run with the same
// inputs (the log says so and the image is bit-identical); changing the sky, a material, the camera or the seed traces
// again. The cache is a scratch folder (VITRINE_CACHE_DIR).
TEST_F(PathTraceCpu, ConvergedResultIsCachedAndTracedAgainWhenAnInputChanges) {
    const auto cacheDir = std::filesystem::temp_directory_path() / "vitrine_test_reference_cache";
    std::filesystem::remove_all(cacheDir);
    const char* old = std::getenv("VITRINE_CACHE_DIR");
    const std::string saved = old ? old : "";
    setenv("VITRINE_CACHE_DIR", cacheDir.c_str(), 1);
    const int W = 24, H = 24;
    const auto base = boxRoom();
    auto run = [&](const std::filesystem::path& glb, double sky, int seed, std::string& log) {
        testing::internal::CaptureStderr();
        auto out = runGraph(traceGraph(glb, uniformSky(glb, sky),
                                       {{"spp", 8}, {"seed", seed}, {"target_noise", 0.25}, {"min_spp", 16}}, W, H));
        log = testing::internal::GetCapturedStderr();
        return out.at("color");
    };
    auto traced = [](const std::string& log) { return log.find("render.pathtrace: converged after") != std::string::npos; };
    auto loaded = [](const std::string& log) { return log.find("loaded from the bake cache") != std::string::npos; };
    std::string log;
    const Image first = run(base, 1.0, 0, log);
    EXPECT_TRUE(traced(log)) << log;
    const Image second = run(base, 1.0, 0, log);
    EXPECT_TRUE(loaded(log)) << log;
    EXPECT_FALSE(traced(log)) << log;
    EXPECT_EQ(first.pixels, second.pixels);
    run(base, 1.2, 0, log);
    EXPECT_TRUE(traced(log)) << "sky changed:\n" << log;
    run(base, 1.0, 1, log);
    EXPECT_TRUE(traced(log)) << "seed changed:\n" << log;
    run(boxRoom(0.7f, {0.0f, 0.0f, 3.4f}, "pt_box_room_material"), 1.0, 0, log);
    EXPECT_TRUE(traced(log)) << "material changed:\n" << log;
    run(boxRoom(0.75f, {0.1f, 0.0f, 3.4f}, "pt_box_room_camera"), 1.0, 0, log);
    EXPECT_TRUE(traced(log)) << "camera moved:\n" << log;
    if (old) setenv("VITRINE_CACHE_DIR", saved.c_str(), 1);
    else unsetenv("VITRINE_CACHE_DIR");
    std::filesystem::remove_all(cacheDir);
}

// target_noise in pieces: a run asked to stop (RunOptions::stop, what Ctrl-C sets in `vitrine run`) part way ends after
// its batch, keeps its partial result in the bake cache (not as converged) and the next run resumes it from there;
// batch b has the same seed whichever run traces it, so the result is bit for bit that of one run straight through
// (a second scratch cache). On both tracers: the GPU one gets the partial result uploaded into its outputs first.
PATHTRACE_TEST(AStoppedConvergenceIsResumedToTheResultOfOneRun) {
    const int W = 16, H = 16;
    const auto glb = boxRoom();
    const json params = {{"spp", 8}, {"seed", 3}, {"target_noise", 0.25}, {"min_spp", 48}};
    auto inCache = [](const char* name) {
        const auto dir = std::filesystem::temp_directory_path() / name;
        std::filesystem::remove_all(dir);
        setenv("VITRINE_CACHE_DIR", dir.c_str(), 1);
        return dir;
    };
    auto count = [](const std::filesystem::path& dir, const char* kind) {
        size_t n = 0;
        std::error_code ec;
        for (const auto& e : std::filesystem::directory_iterator(dir / "bake" / kind, ec))
            n += e.path().extension() == ".bin";
        return n;
    };
    const char* old = std::getenv("VITRINE_CACHE_DIR");
    const std::string saved = old ? old : "";
    const auto straightDir = inCache("vitrine_test_resume_straight");
    testing::internal::CaptureStderr();
    const Image straight = runGraph(traceGraph(glb, uniformSky(glb, 1.0), params, W, H)).at("color");
    std::string log = testing::internal::GetCapturedStderr();
    ASSERT_NE(log.find("render.pathtrace: converged after"), std::string::npos) << log;
    const auto dir = inCache("vitrine_test_resume_pieces");
    int asked = 0;
    testing::internal::CaptureStderr();
    runGraph(traceGraph(glb, uniformSky(glb, 1.0), params, W, H), [&] { return ++asked >= 2; });
    log = testing::internal::GetCapturedStderr();
    EXPECT_NE(log.find("stopped (asked to stop) after 16 spp"), std::string::npos) << log;
    EXPECT_EQ(count(dir, "reference"), 0u) << log;
    EXPECT_EQ(count(dir, "reference_partial"), 1u) << log;
    // Another render of the same size in between (1 sample, no cache): the resumed run must start from the cache's
    // partial result, not from whatever its outputs' memory held (the driver may hand the stopped run's memory on).
    runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", 1}, {"seed", 9}}, W, H));
    testing::internal::CaptureStderr();
    const Image resumed = runGraph(traceGraph(glb, uniformSky(glb, 1.0), params, W, H)).at("color");
    log = testing::internal::GetCapturedStderr();
    EXPECT_NE(log.find("resuming the partial result an earlier run stopped with (16 spp"), std::string::npos) << log;
    EXPECT_NE(log.find("render.pathtrace: converged after"), std::string::npos) << log;
    EXPECT_EQ(resumed.pixels, straight.pixels) << "resumed in pieces differs from one run";
    EXPECT_EQ(count(dir, "reference"), 1u) << log;
    EXPECT_EQ(count(dir, "reference_partial"), 0u) << log;
    if (old)
        setenv("VITRINE_CACHE_DIR", saved.c_str(), 1);
    else
        unsetenv("VITRINE_CACHE_DIR");
    std::filesystem::remove_all(straightDir);
    std::filesystem::remove_all(dir);
}

// Accumulation through color@prev / stats@prev with a still camera: after 16 frames of 4 samples the
// count is 64, the estimated standard error is ~1/4 of one frame's (1/sqrt(N)), and the means agree (the
// rough plane has no closed form; one frame's mean over the plane is within 5 % of 16 frames'). With the camera moving
// (a glTF animation of the camera node) every frame restarts: the count stays at 4.
PATHTRACE_TEST(AccumulationConvergesAndRestartsWhenTheCameraMoves) {
    const int W = 32, H = 24;
    const double C = 100.0, albedo = 0.5;
    auto build = [&](bool moving) {
        SceneBuilder b(moving ? "plane_moving" : "plane_still");
        std::vector<Tri> quad;
        addQuad(quad, glm::vec3(0.0f), glm::vec3(20, 0, 0), glm::vec3(0, 0, 20), glm::vec3(0, 1, 0));
        b.node("plane", static_cast<int32_t>(b.mesh(
                            "plane", quad, b.material("plane", glm::vec3(static_cast<float>(albedo)), 0.0f, 0.5f))));
        b.camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
        if (moving) {
            scene::Animation anim;
            anim.name = "dolly";
            scene::AnimationSampler s;
            s.times = {0.0f, 10.0f};
            s.values = {glm::vec4(0.0f, 2.0f, 3.0f, 0.0f), glm::vec4(2.0f, 2.0f, 3.0f, 0.0f)};
            anim.samplers.push_back(s);
            anim.channels.push_back(
                {static_cast<uint32_t>(b.s.nodes.size() - 1), scene::AnimationPath::Translation, 0});
            b.s.animations.push_back(anim);
        }
        return std::pair{b.write(), b.s};
    };
    auto [glb, s] = build(false);
    json sky = uniformSky(glb, C);
    json params = {{"spp", 4}, {"antialias", false}};
    auto one = runGraph(traceGraph(glb, sky, params, W, H, 1, true));
    // The progress line of every frame reports the samples accumulated so far and the estimated noise.
    ::testing::internal::CaptureStderr();
    auto many = runGraph(traceGraph(glb, sky, params, W, H, 16, true));
    const std::string log = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(log.find("render.pathtrace: 4 spp accumulated"), std::string::npos) << log;
    EXPECT_NE(log.find("render.pathtrace: 64 spp accumulated"), std::string::npos) << log;
    EXPECT_NE(log.find("of the pixel's mean (median)"), std::string::npos) << log;
    Pinhole cam(s, W, H);
    double seOne = 0.0, seMany = 0.0, sumOne = 0.0, sumMany = 0.0;
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y > -0.1) continue;
            EXPECT_EQ(one.at("stats").at(x, y)[0], 4.0f);
            EXPECT_EQ(many.at("stats").at(x, y)[0], 64.0f);
            seOne += one.at("stats").at(x, y)[3];
            seMany += many.at("stats").at(x, y)[3];
            // Grey: the luminance mean of the stats is the colour's green.
            double mean = many.at("color").at(x, y)[1];
            EXPECT_NEAR(many.at("stats").at(x, y)[1], mean, 1e-3 * mean);
            sumOne += one.at("color").at(x, y)[1];
            sumMany += mean;
            ++n;
        }
    double ratio = seOne / seMany;
    std::printf("accumulation: %d pixels, mean standard error 1 frame %.4f, 16 frames %.4f (ratio %.3f, 1/sqrt(N) "
                "predicts 4); mean radiance %.4f vs %.4f\n",
                n, seOne / n, seMany / n, ratio, sumOne / n, sumMany / n);
    EXPECT_GT(ratio, 3.4);
    EXPECT_LT(ratio, 4.6);
    EXPECT_LT(std::abs(sumOne / sumMany - 1.0), 0.05);

    auto [movingGlb, movingScene] = build(true);
    auto moving = runGraph(traceGraph(movingGlb, uniformSky(movingGlb, C), params, W, H, 3, true));
    auto still = runGraph(traceGraph(glb, sky, params, W, H, 3, true));
    EXPECT_EQ(moving.at("stats").at(W / 2, H - 2)[0], 4.0f) << "a moving camera restarts the accumulation";
    EXPECT_EQ(still.at("stats").at(W / 2, H - 2)[0], 12.0f);
}

// --- render.pathtrace's `transparent`: what forward.transparent draws, traced (alpha coverage, KHR_materials_
// transmission as thin-walled glass, KHR_materials_volume's attenuation), for paths and shadow rays ---

// A pane facing +z, 3 m in front of the camera (which looks at it obliquely, so the pixels see it at 0-40 degrees),
// under a uniform sky C, traced through pixel centres. `materials` makes the pane's material(s); with two, the left
// half (x < 0) gets the first. Returns every pixel whose ray crosses the pane at least 1 m inside its edges, with its
// unit ray, in `pixels` (left half) and `right`.
struct PaneTrace {
    std::map<std::string, Image> out;
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels, right;
};

PaneTrace tracePane(const std::string& name, double C, json params,
                    const std::function<std::vector<uint32_t>(SceneBuilder&)>& materials,
                    glm::vec3 scale = glm::vec3(1.0f)) {
    const int W = 40, H = 30;
    const float half = 10.0f, depth = 3.0f;
    SceneBuilder b(name);
    const std::vector<uint32_t> m = materials(b);
    for (size_t i = 0; i < m.size(); ++i) {
        std::vector<Tri> quad;
        const float w = m.size() == 1 ? half : half / 2.0f, cx = m.size() == 1 ? 0.0f : (i == 0 ? -w : w);
        addQuad(quad, glm::vec3(cx / scale.x, 0, 0), glm::vec3(w / scale.x, 0, 0), glm::vec3(0, half / scale.y, 0),
                glm::vec3(0, 0, 1));
        b.node("pane" + std::to_string(i), static_cast<int32_t>(b.mesh("pane" + std::to_string(i), quad, m[i])),
               glm::vec3(0, 0, -depth));
        b.s.nodes.back().local.scale = scale;
    }
    b.camera({0.0f, 0.0f, 0.0f}, {0.4f, 0.3f, -depth}, 1.2f);
    auto glb = b.write();
    params["antialias"] = false;
    PaneTrace t;
    t.out = runGraph(traceGraph(glb, uniformSky(glb, C), params, W, H));
    Pinhole cam(b.s, W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.z >= 0.0) continue;
            glm::dvec3 p = d * (-depth / d.z);
            if (std::abs(p.x) > half - 1.0 || std::abs(p.y) > half - 1.0 || (m.size() > 1 && std::abs(p.x) < 1.0))
                continue;
            (m.size() > 1 && p.x > 0.0 ? t.right : t.pixels).push_back({{x, y}, d});
        }
    return t;
}

// Per channel, the mean over the pixels of traced / expected(ray); the largest departure from 1 is returned.
double meanRatioError(const Image& traced, const std::vector<std::pair<glm::ivec2, glm::dvec3>>& pixels,
                      const std::function<glm::dvec3(glm::dvec3)>& expected, const char* what) {
    glm::dvec3 sum(0.0);
    for (const auto& [px, d] : pixels)
        sum += rgb(traced, px.x, px.y) / expected(d);
    const glm::dvec3 mean = sum / static_cast<double>(pixels.size());
    std::printf("%s tracer, %s: %zu pixels, mean traced / expected per channel %.4f %.4f %.4f\n", gBackend, what,
                pixels.size(), mean.r, mean.g, mean.b);
    return std::max({std::abs(mean.r - 1.0), std::abs(mean.g - 1.0), std::abs(mean.b - 1.0)});
}

// What each pixel of a traced SunlitGround of grey 0.5 (roughness 1) shows when the sun reaches it through a
// transmittance `through`: core/shading's sun radiance (shadeDirectional, intensity E / pi) times it.
std::vector<std::pair<glm::ivec2, glm::dvec3>> sunOnGreyGround(const SunlitGround& g, glm::dvec3 through) {
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    for (const auto& [px, d] : g.pixels)
        expected.push_back(
            {px, glm::dvec3(shading::shadeDirectional(glm::vec3(0, 1, 0), glm::vec3(-d), glm::vec3(g.toSun),
                                                      glm::vec3(0.5f), 0.0f, 1.0f, glm::vec3(g.sunE / kPi))) *
                     through});
    return expected;
}

// KHR_materials_transmission: smooth (shininess 1) tinted glass panes of base colour c under a uniform sky C. On the
// left, transmission 1: its specular reflects C F(NoV) (Schlick, F0 0.04 from the IOR 1.5: the uniform sky through a
// mirror lobe, see the top of the file) and it lets (1 - F(NoV)) c of the sky behind pass, so every pixel is
// C (F + (1 - F) c) per channel. On the right, transmission t = 0.6, metallic m = 0.3 and IOR 2 (F0 1/9): the glTF
// spec's mixture of the metal (m: C Schlick(c, NoV)), the opaque dielectric ((1 - m)(1 - t): C (c + F), its diffuse
// lit by the sky over the front) and the transmissive one ((1 - m) t: as on the left). Bound: the mean over each pane's pixels within 1 %
// per channel (dropping 1 - F moves the left's red by 4 %, a swapped channel by far more).
PATHTRACE_TEST(ThinGlassPaneReflectsFresnelAndPassesTheRestTinted) {
    const double C = 100.0, t = 0.6, m = 0.3;
    const glm::vec3 c(1.0f, 0.5f, 0.25f);
    const PaneTrace p = tracePane("pt_glass", C, {{"spp", 64}}, [&](SceneBuilder& b) {
        uint32_t glass = b.material("glass", c, 0.0f, 1.0f);
        b.s.materials[glass].transmission = 1.0f;
        uint32_t mixed = b.material("mixed", c, static_cast<float>(m), 1.0f);
        b.s.materials[mixed].transmission = static_cast<float>(t);
        b.s.materials[mixed].ior = 2.0f;
        return std::vector<uint32_t>{glass, mixed};
    });
    const glm::dvec3 cd(c);
    auto transmissive = [&](double F) { return C * (F + (1.0 - F) * cd); };
    const double err = meanRatioError(
        p.out.at("color"), p.pixels, [&](glm::dvec3 d) { return transmissive(schlick(0.04, -d.z)); }, "thin glass");
    const double errMixed = meanRatioError(
        p.out.at("color"), p.right,
        [&](glm::dvec3 d) {
            const double F = schlick(1.0 / 9.0, -d.z); // KHR_materials_ior 2: F0 = ((2 - 1) / (2 + 1))^2
            const glm::dvec3 metal = C * glm::dvec3(schlick(cd.r, -d.z), schlick(cd.g, -d.z), schlick(cd.b, -d.z));
            return m * metal + (1.0 - m) * (1.0 - t) * C * (cd + F) + (1.0 - m) * t * transmissive(F);
        },
        "glass, metal and opaque dielectric mixed");
    EXPECT_GE(p.pixels.size(), 150u);
    EXPECT_GE(p.right.size(), 150u);
    EXPECT_LT(err, 0.01);
    EXPECT_LT(errMixed, 0.01);
}

// The coat and the sheen over glass: the tinted glass of the test above (c, transmission 1, smooth) under a clear coat
// of strength 1 and roughness 0 on the left, and under a white sheen of roughness 0.5 on the right. What the glass
// passes is seen through them as what it reflects is: the coat's 1 - Fc(NoV) (Fc Schlick of F0 0.04) and the sheen's
// albedo scaling s = 1 - E(NoV) (core/shading sheenScaling). Under the uniform sky C the left is
// C (Fc + (1 - Fc)(F + (1 - F) c)) and the right C (A(NoV) + s (F + (1 - F) c)), A the sheen lobe's directional
// albedo (core/shading sheenCosine integrated over the hemisphere here). Bounds 1 % (left) and 2 % (right: E is a
// fit of A) per channel of the mean; without the layering on what passes, blue moves by 3 % (coat) and about 15 %
// (sheen).
PATHTRACE_TEST(CoatAndSheenOverGlassLayerWhatPassesToo) {
    const double C = 100.0, sheenRoughness = 0.5;
    const glm::vec3 c(1.0f, 0.5f, 0.25f);
    const PaneTrace p = tracePane("pt_glass_layers", C, {{"spp", 128}}, [&](SceneBuilder& b) {
        uint32_t coated = b.material("coated", c, 0.0f, 1.0f);
        b.s.materials[coated].transmission = 1.0f;
        b.s.materials[coated].clearcoat = 1.0f;
        uint32_t sheened = b.material("sheened", c, 0.0f, 1.0f);
        b.s.materials[sheened].transmission = 1.0f;
        b.s.materials[sheened].sheenColor = glm::vec3(1.0f);
        b.s.materials[sheened].sheenRoughness = static_cast<float>(sheenRoughness);
        return std::vector<uint32_t>{coated, sheened};
    });
    const glm::dvec3 cd(c);
    auto glass = [&](double F) { return F + (1.0 - F) * cd; };
    const double errCoat = meanRatioError(
        p.out.at("color"), p.pixels,
        [&](glm::dvec3 d) {
            const double F = schlick(0.04, -d.z);
            return C * (F + (1.0 - F) * glass(F));
        },
        "glass under a clear coat");
    const double errSheen = meanRatioError(
        p.out.at("color"), p.right,
        [&](glm::dvec3 d) {
            const double NoV = -d.z;
            const double lobe = directionalAlbedo(NoV, 256, [&](glm::vec3 n, glm::vec3 v, glm::vec3 l) {
                return shading::sheenCosine(n, v, l, glm::vec3(1.0f), static_cast<float>(sheenRoughness)).g;
            });
            const double scaling =
                shading::sheenScaling(glm::vec3(1.0f), static_cast<float>(NoV), static_cast<float>(sheenRoughness));
            return C * (lobe + scaling * glass(schlick(0.04, NoV)));
        },
        "glass under a sheen");
    EXPECT_GE(p.pixels.size(), 150u);
    EXPECT_GE(p.right.size(), 150u);
    EXPECT_LT(errCoat, 0.01);
    EXPECT_LT(errSheen, 0.02);
}

// A closed box of half extents `half` whose triangles all wind counter-clockwise seen from outside (the path tracer's
// front faces): lighting_scene's boxTris, whose three faces on the negative axes wind inwards, turned.
std::vector<Tri> closedBox(glm::vec3 half) {
    std::vector<Tri> tris = boxTris(half);
    for (Tri& t : tris)
        if (glm::dot(glm::cross(t.b.position - t.a.position, t.c.position - t.a.position), t.a.normal) < 0.0f)
            std::swap(t.b, t.c);
    return tris;
}

// A smooth clear glass material (base white, transmission 1, IOR 1.5) bounding a volume (thicknessFactor > 0: the
// path tracer refracts at its real faces).
uint32_t volumeGlass(SceneBuilder& b, const std::string& name, float shininess = 1.0f) {
    uint32_t m = b.material(name, glm::vec3(1.0f), 0.0f, shininess);
    b.s.materials[m].transmission = 1.0f;
    b.s.materials[m].thickness = 1.0f;
    return m;
}

// volumeGlass of IOR `ior` whose medium attenuates by attenuationColor `color` over attenuationDistance `distance`.
uint32_t absorbingVolume(SceneBuilder& b, const std::string& name, glm::vec3 color, double distance, double ior = 1.5) {
    const uint32_t m = volumeGlass(b, name);
    b.s.materials[m].ior = static_cast<float>(ior);
    b.s.materials[m].attenuationColor = color;
    b.s.materials[m].attenuationDistance = static_cast<float>(distance);
    return m;
}

// A closed box of half extents `half` about `at` (a node named and meshed `name`): what the volume tests fill with a
// volume material.
void volumeBox(SceneBuilder& b, const std::string& name, glm::dvec3 half, uint32_t material, glm::dvec3 at) {
    b.node(name, static_cast<int32_t>(b.mesh(name, closedBox(glm::vec3(half)), material)), glm::vec3(at));
}

// An unlit white wall facing +z at z, 2 half wide: what the volume tests see through their glass, with no sky.
void unlitWhiteWall(SceneBuilder& b, float z, float half) {
    const uint32_t white = b.material("wall", glm::vec3(1.0f), 0.0f, 0.0f);
    b.s.materials[white].unlit = true;
    std::vector<Tri> wall;
    addQuad(wall, glm::vec3(0.0f, 0.0f, z), glm::vec3(half, 0, 0), glm::vec3(0, half, 0), glm::vec3(0, 0, 1));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, white)));
}

// KHR_materials_volume: a closed smooth glass slab 0.5 m thick (a box 20 m wide, its front 3 m from the camera), of
// attenuationColor a = (0.25, 0.5, 1) and attenuationDistance 0.25, under a uniform sky C. A path refracts into it
// (F = Schlick(0.04, cos i) reflects C at the front), crosses the thickness along the refracted direction, length
// L = 0.5 / cos t (Snell: sin t = sin i / 1.5), keeping A = a^(L / 0.25) (Beer's law), and at the back leaves with
// 1 - F (the same F: Schlick at the outer side's cosine) or is reflected back, crossing again, and so on; every way
// out sees C. So C (F + (1 - F)^2 A / (1 - F A)) per channel, computed here per pixel (the geometric series of
// internal reflections). Bound 1 % per channel of the mean over the slab's pixels; a slab attenuating by the
// thickness along the view ray instead (no refraction, L = 0.5 / cos i) is 2.5 % off in red at these angles. 256 spp:
// red is mostly the Fresnel reflection, drawn in 5 % of the samples (the mean's standard error about 0.35 %).
PATHTRACE_TEST(VolumeSlabAbsorbsByBeersLawAlongTheRefractedPath) {
    const double C = 100.0, thickness = 0.5, distance = 0.25, depth = 3.0, half = 10.0;
    const glm::vec3 a(0.25f, 0.5f, 1.0f);
    const int W = 40, H = 30;
    SceneBuilder b("pt_volume_slab");
    const uint32_t m = volumeGlass(b, "volume");
    b.s.materials[m].attenuationColor = a;
    b.s.materials[m].attenuationDistance = static_cast<float>(distance);
    b.node("slab", static_cast<int32_t>(b.mesh("slab", closedBox(glm::vec3(half, half, thickness / 2.0)), m)),
           glm::vec3(0.0f, 0.0f, static_cast<float>(-depth - thickness / 2.0)));
    b.camera({0.0f, 0.0f, 0.0f}, {0.4f, 0.3f, static_cast<float>(-depth)}, 1.2f);
    auto glb = b.write();
    const auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 256}, {"antialias", false}}, W, H));
    Pinhole cam(b.s, W, H);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            glm::dvec3 p = d * (-depth / d.z);
            if (d.z < 0.0 && std::abs(p.x) < half - 2.0 && std::abs(p.y) < half - 2.0) pixels.push_back({{x, y}, d});
        }
    const double err = meanRatioError(
        out.at("color"), pixels,
        [&](glm::dvec3 d) {
            const double cosI = -d.z, F = schlick(0.04, cosI);
            const double cosT = std::sqrt(1.0 - (1.0 - cosI * cosI) / (1.5 * 1.5));
            const glm::dvec3 A = glm::pow(glm::dvec3(a), glm::dvec3(thickness / cosT / distance));
            return C * (F + (1.0 - F) * (1.0 - F) * A / (1.0 - F * A));
        },
        "volume slab");
    EXPECT_GE(pixels.size(), 300u);
    EXPECT_LT(err, 0.01);
}

// Refraction through a volume: a smooth clear glass slab 1 m thick, turned 35° about +y, 3 m in front of the camera
// and a wall of vertical stripes 0.5 m wide 6 m away (unlit: (1, 0.2, 0.05) and (0.05, 0.3, 1) alternately), no sky.
// A ray refracts in (Snell, IOR 1.5) and out through the parallel back face, so it leaves parallel to itself but
// shifted sideways by about 0.2 m, and about one in seven of the pixels checked sees the other stripe than straight on.
// Computed here per pixel with glm::refract and glm::reflect: the stripe the refracted ray meets times (1 - F)^2, plus
// the light reflected inside twice (back, then front face) before it leaves, F^2 (1 - F)^2 times the stripe it meets
// (F = Schlick(0.04, cos i) at every crossing: the outer side's cosine). Pixels whose ray leaves through the slab's
// rim, or meets the wall within 10 cm of a stripe's edge, are left out: the glass's GGX lobe (alpha 0.002) has a
// tail that takes about 1 % of the light over the edge within 2 cm of it (measured at 1,024 spp: the other stripe's
// colour 2 % too strong there, 0.4 % beyond 10 cm). Bounds: per pixel, the stripe's own colour
// channel (red, or blue) within 15 % (64 spp of the Fresnel choices) and its other colour channel below a third of it
// (the right stripe); per channel, the mean of traced / expected within 1.5 %.
PATHTRACE_TEST(VolumeSlabShiftsWhatIsSeenThroughItBySnellsLaw) {
    const int W = 64, H = 48;
    const double thickness = 1.0, slabHalf = 2.5, stripe = 0.5, wallZ = -6.0, angle = 35.0 * kPi / 180.0;
    const glm::dvec3 centre(0.0, 0.0, -3.0);
    const glm::vec3 colours[2] = {{1.0f, 0.2f, 0.05f}, {0.05f, 0.3f, 1.0f}};
    SceneBuilder b("pt_volume_refraction");
    const uint32_t glass = volumeGlass(b, "glass");
    for (int k = 0; k < 2; ++k) {
        uint32_t m = b.material("stripe" + std::to_string(k), colours[k], 0.0f, 0.0f);
        b.s.materials[m].unlit = true;
        std::vector<Tri> tris;
        for (int i = k; i < 24; i += 2)
            addQuad(tris, glm::vec3(static_cast<float>(-6.0 + (i + 0.5) * stripe), 0.0f, static_cast<float>(wallZ)),
                    glm::vec3(static_cast<float>(stripe / 2.0), 0, 0), glm::vec3(0, 5, 0), glm::vec3(0, 0, 1));
        b.node("wall" + std::to_string(k), static_cast<int32_t>(b.mesh("wall" + std::to_string(k), tris, m)));
    }
    const glm::dquat turn = glm::angleAxis(angle, glm::dvec3(0, 1, 0));
    b.node("slab",
           static_cast<int32_t>(b.mesh("slab", closedBox(glm::vec3(slabHalf, slabHalf, thickness / 2.0)), glass)),
           glm::vec3(centre));
    b.s.nodes.back().local.rotation = glm::quat(turn);
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
    auto glb = b.write();
    const auto out =
        runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", 64}, {"antialias", false}, {"sky_scale", 0.0}}, W, H));
    const Image& traced = out.at("color");
    Pinhole cam(b.s, W, H);
    const glm::dvec3 n = turn * glm::dvec3(0, 0, 1), u = turn * glm::dvec3(1, 0, 0);
    const glm::dvec3 front = centre + n * (thickness / 2.0), back = centre - n * (thickness / 2.0);
    auto onPlane = [&](glm::dvec3 o, glm::dvec3 d, glm::dvec3 q) {
        return o + d * (glm::dot(q - o, n) / glm::dot(d, n));
    };
    auto inside = [&](glm::dvec3 p) {
        return std::abs(glm::dot(p - centre, u)) < slabHalf - 0.1 && std::abs(p.y) < slabHalf - 0.1;
    };
    auto stripeAt = [&](glm::dvec3 p, glm::dvec3 d, double& edge) {
        const double at = (p.x + d.x * ((wallZ - p.z) / d.z) + 6.0) / stripe;
        edge = std::abs(at - std::round(at)) * stripe;
        return static_cast<int>(std::floor(at)) % 2;
    };
    int checked = 0, shifted = 0, bad = 0;
    glm::dvec3 sum(0.0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const glm::dvec3 p1 = onPlane(glm::dvec3(0.0), d, front);
            const glm::dvec3 r1 = glm::refract(d, n, 1.0 / 1.5);
            const glm::dvec3 p2 = onPlane(p1, r1, back);
            const glm::dvec3 r2 = glm::refract(r1, n, 1.5);
            // Reflected at the back, then at the front, out through the back further along.
            const glm::dvec3 p3 = onPlane(p2, glm::reflect(r1, n), front), p4 = onPlane(p3, r1, back);
            if (!inside(p1) || !inside(p2) || !inside(p4)) continue;
            double edge = 0.0, edge2 = 0.0, straightEdge = 0.0;
            const int k = stripeAt(p2, r2, edge), k2 = stripeAt(p4, r2, edge2);
            if (edge < 0.1 || edge2 < 0.1) continue;
            if (k != stripeAt(glm::dvec3(0.0), d, straightEdge)) ++shifted;
            const double F = schlick(0.04, -glm::dot(d, n));
            const glm::dvec3 expected =
                (1.0 - F) * (1.0 - F) * (glm::dvec3(colours[k]) + F * F * glm::dvec3(colours[k2]));
            const glm::dvec3 got = rgb(traced, x, y);
            sum += got / expected;
            ++checked;
            const int own = k == 0 ? 0 : 2, other = 2 - own;
            if (std::abs(got[own] / expected[own] - 1.0) > 0.15 || got[other] > got[own] / 3.0) {
                if (bad++ < 5)
                    std::printf("  pixel (%d, %d): traced %.4f %.4f %.4f, expected %.4f %.4f %.4f\n", x, y, got.r,
                                got.g, got.b, expected.r, expected.g, expected.b);
            }
        }
    const glm::dvec3 mean = sum / std::max(1.0, static_cast<double>(checked));
    std::printf("%s tracer, refraction through a slab: %d pixels (%d see the other stripe than straight on), %d off, "
                "mean traced / expected %.4f %.4f %.4f\n",
                gBackend, checked, shifted, bad, mean.r, mean.g, mean.b);
    EXPECT_GE(checked, 600);
    EXPECT_GE(shifted, 80);
    EXPECT_EQ(bad, 0);
    EXPECT_LT(std::max({std::abs(mean.r - 1.0), std::abs(mean.g - 1.0), std::abs(mean.b - 1.0)}), 0.015);
}

// A rough boundary crossed once: the camera inside a glass sphere (radius 2 m, IOR 1.5, roughness 0.6: GGX alpha
// 0.36; KHR_materials_specular colour (1, 0.5, 0.25): F0 = 0.04 x that colour, F90 1) filled with a medium that
// absorbs everything beyond a few millimetres (attenuationColor 0.01, attenuationDistance 0.01), a uniform sky C
// outside. The camera sits 5 cm inside the wall looking along it, so its rays meet the boundary from inside at
// incidence cosines from 0.22 to 0.75. What the microfacets let out sees C; what they reflect back dies in the medium.
// So a pixel is C times the expected weight of one crossing at its incidence mu (the ray against the sphere's normal,
// computed here): the integral over microfacet normals h of their density as drawn from v's visible normals,
// G1(v) (v.h) D(h) / mu, times (1 - F) (Schlick per channel at the cosine outside; 0 past the critical angle, where
// h reflects all light) times Smith's G2(v, l) / G1(v) = (1 + Lambda(v)) / (1 + Lambda(v) + Lambda(l)), for l
// refracted through h and leaving on the far side (else 0): a quadrature over (theta_h, phi_h) per mu here,
// independent of the tracer's sampling (pathtrace/volume.glsl). Bounds per channel of the mean of traced / expected:
// 1.5 % over the frame (48 x 36 pixels, 1024 spp), 2 % over its 372 pixels of incidence cosine below 0.3, where
// directions refracted through a steep microfacet most often come out on the near side (they end the path: keeping
// them adds 3.2 to 3.9 % there, 1.0 to 1.2 % over the frame). Three seeds of the CPU tracer stayed within 0.2 % over
// the frame and 0.55 % below 0.3, the GPU's one seed within 0.2 % and 0.13 %. The quadrature without the masking term
// is printed beside it.
PATHTRACE_TEST(RoughBoundaryLetsOutWhatItsMicrofacetsRefract) {
    const double C = 100.0, eta = 1.5, radius = 2.0;
    const glm::dvec3 eye(1.95, 0.0, 0.0), tint(1.0, 0.5, 0.25);
    const int W = 48, H = 36;
    for (double roughness : {0.6}) {
        SceneBuilder b("pt_rough_boundary_" + std::to_string(static_cast<int>(roughness * 10)));
        const uint32_t glass = volumeGlass(b, "glass", static_cast<float>(1.0 - roughness));
        b.s.materials[glass].specularColor = glm::vec3(tint);
        b.s.materials[glass].attenuationColor = glm::vec3(0.01f);
        b.s.materials[glass].attenuationDistance = 0.01f;
        b.node("sphere",
               static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 192, 96), glass)));
        b.camera(glm::vec3(eye), glm::vec3(eye) + glm::vec3(0.0f, 0.0f, -1.0f), 1.4f);
        auto glb = b.write();
        const auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 1024}, {"antialias", false}}, W, H));

        // One crossing's expected weight per channel at incidence mu, tabulated over mu.
        const double alpha = roughness * roughness, a2 = alpha * alpha;
        auto lambda = [&](double c) { return (std::sqrt(1.0 + a2 * (1.0 - c * c) / (c * c)) - 1.0) / 2.0; };
        const int nodes = 256, nt = 400, np = 200;
        std::vector<glm::dvec3> table(nodes + 1), unmaskedTable(nodes + 1);
        double worstNorm = 0.0;
        for (int k = 0; k <= nodes; ++k) {
            const double mu = std::max(static_cast<double>(k) / nodes, 1e-3);
            const glm::dvec3 v(std::sqrt(1.0 - mu * mu), 0.0, mu);
            const double g1 = 1.0 / (1.0 + lambda(mu));
            glm::dvec3 sum(0.0), unmasked(0.0);
            double norm = 0.0;
            for (int i = 0; i < nt; ++i) {
                const double theta = (i + 0.5) / nt * kPi / 2.0, c = std::cos(theta), q = c * c * (a2 - 1.0) + 1.0;
                const double D = a2 / (kPi * q * q);
                for (int j = 0; j < np; ++j) {
                    const double phi = (j + 0.5) / np * kPi; // half the circle, doubled: symmetric about v's plane
                    const glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), c);
                    const double vh = glm::dot(v, h);
                    if (vh <= 0.0) continue;
                    const double w = g1 * vh * D / mu * std::sin(theta) * (kPi / 2.0 / nt) * (kPi / np) * 2.0;
                    norm += w;
                    const double sin2T = eta * eta * (1.0 - vh * vh);
                    if (sin2T >= 1.0) continue;
                    const glm::dvec3 l = glm::refract(-v, h, eta);
                    if (l.z >= 0.0) continue;
                    const double m = std::pow(1.0 - std::sqrt(1.0 - sin2T), 5.0);
                    const glm::dvec3 F = 0.04 * tint + (1.0 - 0.04 * tint) * m;
                    sum += w * (1.0 - F) * (1.0 + lambda(mu)) / (1.0 + lambda(mu) + lambda(-l.z));
                    unmasked += w * (1.0 - F);
                }
            }
            table[k] = sum / norm;
            unmaskedTable[k] = unmasked / norm;
            if (mu >= 0.05) worstNorm = std::max(worstNorm, std::abs(norm - 1.0));
        }
        auto lookup = [&](const std::vector<glm::dvec3>& t, double mu) {
            const double x = std::clamp(mu, 0.0, 1.0) * nodes;
            const int k = std::min(static_cast<int>(x), nodes - 1);
            return glm::mix(t[k], t[k + 1], x - k);
        };
        // Each pixel's incidence: where its ray from the eye leaves the sphere.
        auto incidence = [&](glm::dvec3 d) {
            const double bq = glm::dot(eye, d), t = -bq + std::sqrt(bq * bq - (glm::dot(eye, eye) - radius * radius));
            return glm::dot(d, (eye + t * d) / radius);
        };
        Pinhole cam(b.s, W, H);
        std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
        double lo = 1.0, hi = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const glm::dvec3 d = cam.ray(x, y);
                pixels.push_back({{x, y}, d});
                lo = std::min(lo, incidence(d));
                hi = std::max(hi, incidence(d));
            }
        const double err = meanRatioError(
            out.at("color"), pixels, [&](glm::dvec3 d) { return C * lookup(table, incidence(d)); }, "a rough boundary");
        std::printf(
            "  roughness %.1f, incidence cosines %.2f to %.2f: one crossing at mu 0.3 / 0.9 lets out %.4f / %.4f "
            "(red; %.4f / %.4f without Smith's masking); the visible normals' norm within %.1e of 1 (mu >= 0.05)\n",
            roughness, lo, hi, lookup(table, 0.3).r, lookup(table, 0.9).r, lookup(unmaskedTable, 0.3).r,
            lookup(unmaskedTable, 0.9).r, worstNorm);
        // The steepest incidences alone, where microfacets most often turn a refracted direction back.
        std::vector<std::pair<glm::ivec2, glm::dvec3>> grazing;
        for (const auto& px : pixels)
            if (incidence(px.second) < 0.3) grazing.push_back(px);
        const double grazingErr = meanRatioError(
            out.at("color"), grazing, [&](glm::dvec3 d) { return C * lookup(table, incidence(d)); },
            "a rough boundary at incidence cosines below 0.3");
        EXPECT_LT(worstNorm, 2e-3);
        EXPECT_LT(lo, 0.35) << "the frame must reach steep incidence";
        EXPECT_LT(err, 0.015) << "roughness " << roughness;
        EXPECT_GE(grazing.size(), 200u);
        EXPECT_LT(grazingErr, 0.02) << "roughness " << roughness;
    }
}

// The sun through a volume: traceSunlitGround's ground under a roof of smooth glass 0.2 m thick (a closed box bounding
// a volume, 3 m up, wider than the view's shadow) of attenuationColor a = (0.25, 0.5, 1) and attenuationDistance 0.5,
// the sun 60° up, no sky. The sun's light through a volume is a caustic that neither a path (the sun is a delta
// light) nor next-event estimation can find, so the sun's shadow rays pass it straight on: core/shading's sun
// radiance of the ground (shadeDirectional) times (1 - F)^2 a^(0.2 / sin 60° / 0.5) per channel, F = Schlick(0.04,
// sin 60°) at both faces and Beer's law over the straight chord. Deterministic (one bounce, no sky): 1 % per pixel.
PATHTRACE_TEST(SunPassesAVolumeStraightOnByFresnelAndBeersLaw) {
    const glm::vec3 a(0.25f, 0.5f, 1.0f);
    const double thickness = 0.2, distance = 0.5;
    const SunlitGround g = traceSunlitGround(
        "pt_volume_roof", 48, 48,
        [&](SceneBuilder& b) {
            volumeBox(b, "roof", {120.0, thickness / 2.0, 120.0}, absorbingVolume(b, "glass", a, distance),
                      {0.0, 3.0, 0.0});
            return b.material("ground", glm::vec3(0.5f), 0.0f, 0.0f);
        },
        {{"spp", 4}}, 60.0);
    const double F = schlick(0.04, g.toSun.y);
    const glm::dvec3 through =
        (1.0 - F) * (1.0 - F) * glm::pow(glm::dvec3(a), glm::dvec3(thickness / g.toSun.y / distance));
    const auto [checked, worst] = expectPixels(g.out.at("pt"), sunOnGreyGround(g, through), 0.01);
    std::printf("%s tracer, the sun through a volume's roof: %d pixels, worst relative error %.4f\n", gBackend, checked,
                worst);
    EXPECT_GE(checked, 300);
}

// Nested volumes (pathtrace/media.glsl): light crossing a stack of parallel planar layers, incoherently: each layer's
// reflectance from the front and from the back and its transmittance (the same both ways), per channel, combined by the
// adding equations (the geometric series of the reflections between two layers).
struct Layers {
    glm::dvec3 front{0.0}, back{0.0}, through{1.0};
};
Layers interfaceOf(double F) {
    return {glm::dvec3(F), glm::dvec3(F), glm::dvec3(1.0 - F)};
}
Layers mediumOf(glm::dvec3 transmittance) {
    return {glm::dvec3(0.0), glm::dvec3(0.0), transmittance};
}
Layers operator+(const Layers& a, const Layers& b) {
    const glm::dvec3 k = 1.0 / (1.0 - a.back * b.front);
    return {a.front + a.through * a.through * b.front * k, b.back + b.through * b.through * a.back * k,
            a.through * b.through * k};
}

// Fresnel F0 between two media of IORs a and b.
double interfaceF0(double a, double b) {
    return (a - b) * (a - b) / ((a + b) * (a + b));
}

// A stack of parallel layers normal to z seen by the camera of b along -z against an unlit wall (nothing else lit, no
// sky): the camera's W x H image at 256 spp through the pixel centres against `through(ray)`, the layers' transmittance
// per pixel; the largest departure from 1 of the mean of traced / expected per channel (meanRatioError).
double traceLayersAgainstWall(SceneBuilder& b, int W, int H, const std::function<glm::dvec3(glm::dvec3)>& through,
                              const char* what) {
    auto glb = b.write();
    const auto out =
        runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", 256}, {"antialias", false}, {"sky_scale", 0.0}}, W, H));
    Pinhole cam(b.s, W, H);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (cam.ray(x, y).z < 0.0) pixels.push_back({{x, y}, cam.ray(x, y)});
    EXPECT_GE(pixels.size(), 1000u);
    return meanRatioError(out.at("color"), pixels, through, what);
}

// Water in glass: a closed smooth glass slab 1 m thick (IOR 1.5, attenuationColor ag = (0.9, 0.5, 0.9), distance 1 m)
// holding a closed water slab 0.4 m thick (IOR 1.33, aw = (0.4, 0.9, 0.9)) in its middle, 3-4 m in front of the camera,
// and an unlit white wall behind, no sky. A path refracts air -> glass -> water -> glass -> air (Snell with each pair
// of IORs: the angle in water is the one from air by 1.33, not by 1.5 x 1.33), reflects by F = Schlick(F0, cosine on
// the rarer side) with F0 of each interface's two IORs (0.04 against air, ((1.5 - 1.33) / 2.83)^2 = 0.0036 between
// glass and water) and pays Beer's law in each medium over its own way through it: the glass's over its two 0.3 m
// parts, the water's over 0.4 m. What is seen is the wall through the seven layers (computed here per pixel by the
// adding equations: every internal reflection). Bound: per channel, the mean over the pixels within 0.3 % (256 spp;
// measured within 0.06 % by both tracers on lavapipe). The water's F0 against air (0.02) instead of glass is 3 % off;
// one medium per path (the glass's forgotten after the water) 21 % in green; the water left into the wrong medium
// (the slot above the stack's top read, which holds material 0: the water, made first for this) 0.6 % in green.
PATHTRACE_TEST(NestedVolumesBendReflectAndAbsorbByTheMediaOnBothSides) {
    const double thickness = 1.0, inner = 0.4, depth = 3.0, nGlass = 1.5, nWater = 1.33;
    const glm::vec3 ag(0.9f, 0.5f, 0.9f), aw(0.4f, 0.9f, 0.9f);
    const int W = 40, H = 30;
    SceneBuilder b("pt_nested_volumes");
    // The water's material first: an empty slot of a path's media stack holds material 0, so a read one past the
    // stack's top (for the medium around the innermost) must not find the glass there by chance.
    const uint32_t water = absorbingVolume(b, "water", aw, 1.0, nWater), glass = absorbingVolume(b, "glass", ag, 1.0);
    const glm::dvec3 centre(0.0, 0.0, -depth - thickness / 2.0);
    volumeBox(b, "glass", {10.0, 10.0, thickness / 2.0}, glass, centre);
    volumeBox(b, "water", {9.5, 9.5, inner / 2.0}, water, centre);
    unlitWhiteWall(b, -6.0f, 30.0f);
    b.camera({0.0f, 0.0f, 0.0f}, {0.4f, 0.3f, static_cast<float>(-depth)}, 1.2f);
    const double f0Water = interfaceF0(nGlass, nWater);
    const double err = traceLayersAgainstWall(
        b, W, H,
        [&](glm::dvec3 d) {
            const double cosI = -d.z, sin2 = 1.0 - cosI * cosI;
            const double cosG = std::sqrt(1.0 - sin2 / (nGlass * nGlass)),
                         cosW = std::sqrt(1.0 - sin2 / (nWater * nWater));
            const Layers air = interfaceOf(schlick(0.04, cosI)), wet = interfaceOf(schlick(f0Water, cosW));
            const Layers g = mediumOf(glm::pow(glm::dvec3(ag), glm::dvec3((thickness - inner) / 2.0 / cosG)));
            const Layers w = mediumOf(glm::pow(glm::dvec3(aw), glm::dvec3(inner / cosW)));
            return (air + g + wet + w + wet + g + air).through;
        },
        "water in glass");
    EXPECT_LT(err, 0.003);
}

// Overlapping volumes (glTF gives them no priorities: the one entered last wins): a closed glass slab A (IOR 1.5,
// attenuationColor aA = (0.5, 0.9, 0.9) over 1 m) 3-4 m in front of the camera and a closed slab B of IOR 1 (aB =
// (0.9, 0.9, 0.4) over 1 m) 3.5-4.5 m, overlapping A's back half, an unlit white wall behind, no sky. A path enters A
// (F0 0.04 from air), then B from A (F0 0.04 between 1.5 and 1: the direction returns to the air's), and is in B from
// there on; leaving A while in B crosses no interface (F0 0, no bending); it leaves B into air (F0 0). So the wall is
// seen through: Schlick(0.04) interfaces at 3 m and 3.5 m with A's medium between them (over 0.5 m / cos in glass),
// then B's medium over 1 m / cos in air, and the F0-0 interfaces (Schlick's (1 - cos)^5) at 4 m and 4.5 m (the adding
// equations, per pixel). Bound: per channel, the mean within 1 % (256 spp). Leaving A while in B taken for an
// interface between B and A is 4 % off; the overlap in A's medium, 8 % in red.
PATHTRACE_TEST(OverlappingVolumesTakeTheMediumEnteredLast) {
    const glm::vec3 aA(0.5f, 0.9f, 0.9f), aB(0.9f, 0.9f, 0.4f);
    const int W = 40, H = 30;
    SceneBuilder b("pt_overlapping_volumes");
    const uint32_t glass = absorbingVolume(b, "a", aA, 1.0), hollow = absorbingVolume(b, "b", aB, 1.0, 1.0);
    volumeBox(b, "a", {10.0, 10.0, 0.5}, glass, {0.0, 0.0, -3.5});
    volumeBox(b, "b", {9.0, 9.0, 0.5}, hollow, {0.0, 0.0, -4.0});
    unlitWhiteWall(b, -6.0f, 30.0f);
    b.camera({0.0f, 0.0f, 0.0f}, {0.4f, 0.3f, -3.0f}, 1.2f);
    const double err = traceLayersAgainstWall(
        b, W, H,
        [&](glm::dvec3 d) {
            const double cosI = -d.z, cosG = std::sqrt(1.0 - (1.0 - cosI * cosI) / (1.5 * 1.5));
            const Layers glassy = interfaceOf(schlick(0.04, cosI)), matched = interfaceOf(schlick(0.0, cosI));
            const Layers inA = mediumOf(glm::pow(glm::dvec3(aA), glm::dvec3(0.5 / cosG)));
            const Layers inB = mediumOf(glm::pow(glm::dvec3(aB), glm::dvec3(1.0 / cosI)));
            return (glassy + inA + glassy + inB + matched + matched).through;
        },
        "overlapping volumes");
    EXPECT_LT(err, 0.01);
}

// The sun through nested volumes: traceSunlitGround's ground under a roof of smooth glass 0.6 m thick (a closed box,
// IOR 1.5, attenuationColor ag = (0.9, 0.5, 0.9) over 0.5 m, 2.7-3.3 m up) holding water 0.2 m thick (a closed box,
// IOR 1.33, aw = (0.4, 0.9, 0.9) over 0.5 m, 3.0-3.2 m up), the sun 60° up, no sky. The sun's shadow rays pass
// volumes straight on (SunPassesAVolumeStraightOnByFresnelAndBeersLaw), crossing each interface by 1 - F with
// F = Schlick(F0, sin 60°) of its two IORs (0.04 against air, 0.0036 between glass and water) and paying each medium's
// Beer's law over its own part of the chord: ag over (0.3 + 0.1) m / sin 60°, aw over 0.2 m / sin 60°.
// Deterministic: 1 % per pixel. One medium per ray (the last entered, from where it was entered) is 13.5 % off.
PATHTRACE_TEST(SunPassesNestedVolumesAttenuatedByEachMedium) {
    const glm::vec3 ag(0.9f, 0.5f, 0.9f), aw(0.4f, 0.9f, 0.9f);
    const double glassThickness = 0.6, waterThickness = 0.2, distance = 0.5;
    const SunlitGround g = traceSunlitGround(
        "pt_nested_roof", 48, 48,
        [&](SceneBuilder& b) {
            volumeBox(b, "roof", {120.0, glassThickness / 2.0, 120.0}, absorbingVolume(b, "glass", ag, distance),
                      {0.0, 3.0, 0.0});
            volumeBox(b, "water", {110.0, waterThickness / 2.0, 110.0}, absorbingVolume(b, "water", aw, distance, 1.33),
                      {0.0, 3.1, 0.0});
            return b.material("ground", glm::vec3(0.5f), 0.0f, 0.0f);
        },
        {{"spp", 4}}, 60.0);
    const double Fa = schlick(0.04, g.toSun.y), Fw = schlick(interfaceF0(1.5, 1.33), g.toSun.y);
    const glm::dvec3 through =
        (1.0 - Fa) * (1.0 - Fa) * (1.0 - Fw) * (1.0 - Fw) *
        glm::pow(glm::dvec3(ag), glm::dvec3((glassThickness - waterThickness) / g.toSun.y / distance)) *
        glm::pow(glm::dvec3(aw), glm::dvec3(waterThickness / g.toSun.y / distance));
    const auto [checked, worst] = expectPixels(g.out.at("pt"), sunOnGreyGround(g, through), 0.01);
    std::printf("%s tracer, the sun through water in a glass roof: %d pixels, worst relative error %.4f\n", gBackend,
                checked, worst);
    EXPECT_GE(checked, 300);
}

// The sun on what lies inside a volume: traceSunlitGround's ground (grey 0.5, roughness 1) under 0.5 m of water (a
// closed box of IOR 1.33 from 2 m below the ground to 0.5 m above it, attenuationColor aw = (0.4, 0.7, 0.9) over
// 0.5 m), the camera above it, the sun 60° up, no sky, one bounce. A path refracts into the water (1 - F(cos i),
// F0 ((1.33 - 1) / 2.33)^2), crosses 0.5 m / cos t of it to the ground and sees it lit by the sun, whose shadow ray
// starts in the water the path is in: (1 - F(sin 60°)) out of its surface (the chord's cosine) and Beer's law over
// 0.5 m / sin 60° of it. So core/shading's sun radiance of the ground seen along the refracted ray, times both
// transmittances, per pixel. Bound: per channel, the mean over the pixels within 1 % (64 spp of the Fresnel choice at
// the surface). A shadow ray that does not know it starts in the water (no Beer's law on the sun's way) is 2.9× too
// bright in red.
PATHTRACE_TEST(SunLightsWhatLiesInsideAVolumeThroughItsMedium) {
    const glm::vec3 aw(0.4f, 0.7f, 0.9f);
    const double depth = 0.5, distance = 0.5, nWater = 1.33;
    const SunlitGround g = traceSunlitGround(
        "pt_under_water", 48, 48,
        [&](SceneBuilder& b) {
            volumeBox(b, "water", {60.0, 1.25, 60.0}, absorbingVolume(b, "water", aw, distance, nWater),
                      {0.0, depth - 1.25, 0.0});
            return b.material("ground", glm::vec3(0.5f), 0.0f, 0.0f);
        },
        {{"spp", 64}}, 60.0);
    const double f0 = (nWater - 1.0) * (nWater - 1.0) / ((nWater + 1.0) * (nWater + 1.0));
    const glm::dvec3 sun =
        (1.0 - schlick(f0, g.toSun.y)) * glm::pow(glm::dvec3(aw), glm::dvec3(depth / g.toSun.y / distance));
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
    for (const auto& [px, d] : g.pixels)
        if (std::abs(d.x / d.y) < 20.0 && std::abs(d.z / d.y) < 20.0) pixels.push_back({px, d});
    const double err = meanRatioError(
        g.out.at("pt"), pixels,
        [&](glm::dvec3 d) {
            const glm::dvec3 r = glm::refract(d, glm::dvec3(0, 1, 0), 1.0 / nWater);
            const glm::dvec3 view =
                (1.0 - schlick(f0, -d.y)) * glm::pow(glm::dvec3(aw), glm::dvec3(depth / -r.y / distance));
            const glm::dvec3 lit(shading::shadeDirectional(glm::vec3(0, 1, 0), glm::vec3(-r), glm::vec3(g.toSun),
                                                           glm::vec3(0.5f), 0.0f, 1.0f, glm::vec3(g.sunE / kPi)));
            return lit * view * sun;
        },
        "the sun under water");
    EXPECT_GE(pixels.size(), 500u);
    EXPECT_LT(err, 0.01);
}

// An air bubble in glass: a closed clear glass block 2 m thick (IOR 1.5) 2-4 m in front of the camera, holding a
// closed slab of air 0.1 m thick (a volume of IOR 1; 2.4 m x 1 m) turned 45° about +y, and a square unlit white wall
// 6 m away (8 m wide), no sky. A ray in the glass meets the bubble from the denser side: past the critical angle
// (41.8°) all of it is reflected, sideways, away from the wall, so those pixels are black; below it the bubble lets
// (1 - F) / (1 + F) pass (its two faces and the reflections between them), F = Schlick(0.04, cosine in the air), times
// what the block's faces let pass, (1 - Fa) / (1 + Fa) with Fa = Schlick(0.04, cosine in front). Beside the bubble
// the wall is seen through the block alone. Bounds: black pixels (incidence over 45°) below 0.003 in the mean and 0.1
// each (the smooth glass's GGX lobe, alpha 0.002, has microfacets tilted enough to let one of a pixel's 64 samples
// through in about 3 % of them: 1/64 there); the means of traced / expected beside the bubble within 1.5 % and through
// it (incidence 25°-40°) within 2 % (64 spp). Fresnel at the glass's cosine instead of the air's lets 7 % more
// through the bubble there (the bubble's own F0, 0, instead of the interface's 0.04: 8 %).
PATHTRACE_TEST(AirBubbleInGlassReflectsWholePastTheCriticalAngle) {
    const int W = 64, H = 64;
    const double angle = 45.0 * kPi / 180.0, bubbleHalf = 0.05, bubbleWidth = 1.2, bubbleHeight = 0.5;
    const glm::dvec3 centre(0.0, 0.0, -3.0);
    SceneBuilder b("pt_bubble");
    const uint32_t glass = volumeGlass(b, "glass");
    const uint32_t air = volumeGlass(b, "bubble");
    b.s.materials[air].ior = 1.0f;
    volumeBox(b, "block", {10.0, 10.0, 1.0}, glass, centre);
    const glm::dquat turn = glm::angleAxis(angle, glm::dvec3(0, 1, 0));
    volumeBox(b, "bubble", {bubbleWidth, bubbleHeight, bubbleHalf}, air, centre);
    b.s.nodes.back().local.rotation = glm::quat(turn);
    unlitWhiteWall(b, -6.0f, 4.0f);
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
    auto glb = b.write();
    const auto out =
        runGraph(traceGraph(glb, uniformSky(glb, 1.0), {{"spp", 64}, {"antialias", false}, {"sky_scale", 0.0}}, W, H));
    const Image& traced = out.at("color");
    Pinhole cam(b.s, W, H);
    const glm::dvec3 n = turn * glm::dvec3(0, 0, 1), u = turn * glm::dvec3(1, 0, 0), z(0, 0, 1);
    const glm::dvec3 front = centre + n * bubbleHalf;
    int black = 0, blackOff = 0;
    double worstBlack = 0.0, sumBlack = 0.0;
    glm::dvec3 sumBeside(0.0), sumThrough(0.0);
    int beside = 0, through = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const double cosI = -d.z;
            const glm::dvec3 p1 = d * (2.0 / cosI); // into the block's front face (z = -2)
            const glm::dvec3 r1 = glm::refract(d, z, 1.0 / 1.5);
            const glm::dvec3 wallHit = d * (6.0 / cosI); // where the ray would meet the wall straight on
            if (std::abs(wallHit.x) > 3.5 || std::abs(wallHit.y) > 3.5) continue;
            const glm::dvec3 p2 = p1 + r1 * (glm::dot(front - p1, n) / glm::dot(r1, n));
            const double across = std::abs(glm::dot(p2 - centre, u)), up = std::abs(p2.y);
            const double Fa = schlick(0.04, cosI), block = (1.0 - Fa) / (1.0 + Fa);
            const glm::dvec3 got = rgb(traced, x, y);
            if (up > bubbleHeight + 0.15) { // beside the bubble: the block alone
                sumBeside += got / block;
                ++beside;
                continue;
            }
            if (up > bubbleHeight - 0.1 || across > bubbleWidth - 0.1) continue;
            const double cosB = -glm::dot(r1, n), incidence = std::acos(cosB) * 180.0 / kPi;
            if (incidence > 45.0) {
                const double m = std::max({got.r, got.g, got.b});
                worstBlack = std::max(worstBlack, m);
                ++black;
                sumBlack += m;
                if (m > 0.1) ++blackOff;
            } else if (incidence > 25.0 && incidence < 40.0) {
                const double sinAir = 1.5 * std::sqrt(1.0 - cosB * cosB);
                const double F = schlick(0.04, std::sqrt(1.0 - sinAir * sinAir));
                sumThrough += got / (block * (1.0 - F) / (1.0 + F));
                ++through;
            }
        }
    const glm::dvec3 meanBeside = sumBeside / std::max(1.0, static_cast<double>(beside));
    const glm::dvec3 meanThrough = sumThrough / std::max(1.0, static_cast<double>(through));
    const double meanBlack = sumBlack / std::max(1, black);
    std::printf("%s tracer, air bubble in glass: %d pixels past the critical angle (mean %.5f, brightest %.5f, %d over "
                "0.1); beside it %d pixels, traced / expected %.4f %.4f %.4f; through it %d pixels, %.4f %.4f %.4f\n",
                gBackend, black, meanBlack, worstBlack, blackOff, beside, meanBeside.r, meanBeside.g, meanBeside.b,
                through, meanThrough.r, meanThrough.g, meanThrough.b);
    EXPECT_GE(black, 100);
    EXPECT_EQ(blackOff, 0);
    EXPECT_LT(meanBlack, 0.003);
    EXPECT_GE(beside, 100);
    EXPECT_GE(through, 100);
    EXPECT_LT(std::max({std::abs(meanBeside.r - 1.0), std::abs(meanBeside.g - 1.0), std::abs(meanBeside.b - 1.0)}),
              0.015);
    EXPECT_LT(std::max({std::abs(meanThrough.r - 1.0), std::abs(meanThrough.g - 1.0), std::abs(meanThrough.b - 1.0)}),
              0.02);
}

// The sky through a volume reaches what lies behind it by refracted paths alone: a Lambertian floor (albedo 0.5,
// KHR_materials_specular 0: no specular lobe; 400 m wide) under a roof of clear smooth glass 0.2 m thick (a closed
// box, 3 m up, 1 km wide: the floor's light the roof mirrors back falls on the floor but at grazing angles), a
// uniform sky C, no sun. The sky's shadow rays stop at the roof (else its light would count twice);
// what a path refracted through the slab finds counts in full. A parallel slab passes each direction unchanged with
// T = (1 - F)^2 / (1 - F^2) (the internal reflections' series, F = Schlick(0.04, cos)) and mirrors R = 1 - T of the
// floor's own light back, so the floor's radiance is L = rho C Tc / (1 - rho Rc), Tc and Rc the cosine-weighted means
// of T and R over the hemisphere (computed here). Bound 1 % per channel of the mean over the floor within 15 m (64
// spp); the sky's shadow rays let through would make it about 60 % brighter, the sky's MIS weight kept for paths
// through the glass about 20 % darker.
PATHTRACE_TEST(SkyReachesAFloorUnderAVolumeRoofThroughRefractedPaths) {
    const double C = 100.0, rho = 0.5;
    const int W = 40, H = 30;
    SceneBuilder b("pt_volume_sky");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(200, 0, 0), glm::vec3(0, 0, 200), glm::vec3(0, 1, 0));
    const uint32_t floor = b.material("floor", glm::vec3(static_cast<float>(rho)), 0.0f, 0.0f);
    b.s.materials[floor].specular = 0.0f;
    b.node("floor", static_cast<int32_t>(b.mesh("floor", quad, floor)));
    b.node("roof",
           static_cast<int32_t>(b.mesh("roof", closedBox(glm::vec3(500.0f, 0.1f, 500.0f)), volumeGlass(b, "glass"))),
           glm::vec3(0.0f, 3.0f, 0.0f));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    auto glb = b.write();
    const auto out = runGraph(traceGraph(glb, uniformSky(glb, C), {{"spp", 64}, {"antialias", false}}, W, H));
    double Tc = 0.0;
    const int steps = 4096;
    for (int i = 0; i < steps; ++i) {
        const double mu = (i + 0.5) / steps, F = schlick(0.04, mu);
        Tc += (1.0 - F) * (1.0 - F) / (1.0 - F * F) * 2.0 * mu / steps;
    }
    const double L = rho * C * Tc / (1.0 - rho * (1.0 - Tc));
    Pinhole cam(b.s, W, H);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> pixels;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            const glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) < 15.0 && std::abs(p.z) < 15.0) pixels.push_back({{x, y}, d});
        }
    const double err = meanRatioError(
        out.at("color"), pixels, [&](glm::dvec3) { return glm::dvec3(L); }, "floor under a volume's roof, sky only");
    std::printf("  cosine-weighted transmittance of the slab %.4f, expected radiance %.3f (the open sky's %.3f)\n", Tc,
                L, rho * C);
    EXPECT_GE(pixels.size(), 300u);
    EXPECT_LT(err, 0.01);
}

// Alpha blending: a grey (0.5) smooth pane of alpha 0.3 emitting E = 50 covers 30 % of the sky behind it, so
// C (1 - a) + a (C (0.5 + F) + E) (the covered part is a diffuse + mirror dielectric under the uniform sky, as in
// DiffusePlaneUnderUniformSky..., and emits where it covers, as forward.transparent blends it). With `transparent`
// off the pane is left out of the scene: every pixel is the sky, C. Bounds 1 %.
PATHTRACE_TEST(BlendedPaneCoversByItsAlphaAndIsLeftOutWithoutTransparent) {
    const double C = 100.0, alpha = 0.3, grey = 0.5, E = 50.0;
    auto material = [&](SceneBuilder& b) {
        uint32_t m = b.material("blend", glm::vec3(static_cast<float>(grey)), 0.0f, 1.0f);
        b.s.materials[m].emissiveFactor = glm::vec3(1.0f);
        b.s.materials[m].emissiveStrength = static_cast<float>(E);
        b.s.materials[m].layers[0].albedo.factor.a = static_cast<float>(alpha);
        b.s.materials[m].alphaMode = scene::AlphaMode::Blend;
        return std::vector<uint32_t>{m};
    };
    const PaneTrace t = tracePane("pt_blend", C, {{"spp", 64}}, material);
    const double err = meanRatioError(
        t.out.at("color"), t.pixels,
        [&](glm::dvec3 d) { return glm::dvec3(C * (1.0 - alpha) + alpha * (C * (grey + schlick(0.04, -d.z)) + E)); },
        "alpha blend");
    EXPECT_GE(t.pixels.size(), 400u);
    EXPECT_LT(err, 0.01);
    const PaneTrace off = tracePane("pt_blend_off", C, {{"spp", 4}, {"transparent", false}}, material);
    const double errOff = meanRatioError(
        off.out.at("color"), off.pixels, [&](glm::dvec3) { return glm::dvec3(C); }, "alpha blend, transparent off");
    EXPECT_LT(errOff, 1e-4);
}

// Alpha masks: two grey smooth panes with alphaMode MASK (cut-off 0.5), alpha 0.3 on the left (cut away: the sky C in
// every sample) and 0.7 on the right (drawn: C (0.5 + F)). Bounds 1e-4 on the left (no sample may differ), 1 % on
// the right.
PATHTRACE_TEST(AlphaMaskCutsAwayWhatIsBelowItsCutoff) {
    const double C = 100.0, grey = 0.5;
    const PaneTrace t = tracePane("pt_mask", C, {{"spp", 32}}, [&](SceneBuilder& b) {
        std::vector<uint32_t> m;
        for (float alpha : {0.3f, 0.7f}) {
            m.push_back(b.material("mask", glm::vec3(static_cast<float>(grey)), 0.0f, 1.0f));
            b.s.materials[m.back()].layers[0].albedo.factor.a = alpha;
            b.s.materials[m.back()].alphaMode = scene::AlphaMode::Mask;
        }
        return m;
    });
    const double cut = meanRatioError(
        t.out.at("color"), t.pixels, [&](glm::dvec3) { return glm::dvec3(C); }, "mask, alpha below the cut-off");
    const double kept = meanRatioError(
        t.out.at("color"), t.right, [&](glm::dvec3 d) { return glm::dvec3(C * (grey + schlick(0.04, -d.z))); },
        "mask, alpha above the cut-off");
    EXPECT_GE(t.pixels.size(), 150u);
    EXPECT_GE(t.right.size(), 150u);
    EXPECT_LT(cut, 1e-4);
    EXPECT_LT(kept, 0.01);
}

// Shadow rays through glass: traceSunlitGround's ground (grey 0.5, roughness 1; the sun 60 degrees up) under a glass
// roof (tinted c, alpha-blended with alpha a = 0.9, transmission t = 0.8, metallic m = 0.25, smooth) 3 m up, wider than
// the view's shadow. The sun's light reaches the ground through it: core/shading's sun radiance of the ground
// (shadeDirectional, the base unquantised) times (1 - a) + a t (1 - m) (1 - F(n.l)) c per channel (the roof's normal
// is the ground's; sky off, one bounce). With `transparent` off the roof is left out: shadeDirectional alone. Bound 1 %
// per pixel, both.
PATHTRACE_TEST(SunThroughAGlassRoofIsTintedByItsTransmittance) {
    const glm::vec3 c(1.0f, 0.5f, 0.25f);
    const double alpha = 0.9, transmission = 0.8, metallic = 0.25;
    for (bool transparent : {true, false}) {
        const SunlitGround g = traceSunlitGround(
            transparent ? "pt_roof" : "pt_roof_off", 48, 48,
            [&](SceneBuilder& b) {
                std::vector<Tri> roof;
                addQuad(roof, glm::vec3(0.0f, 3.0f, 0.0f), glm::vec3(120, 0, 0), glm::vec3(0, 0, 120),
                        glm::vec3(0, 1, 0));
                uint32_t glass = b.material("glass", c, static_cast<float>(metallic), 1.0f);
                b.s.materials[glass].transmission = static_cast<float>(transmission);
                b.s.materials[glass].alphaMode = scene::AlphaMode::Blend;
                b.s.materials[glass].layers[0].albedo.factor.a = static_cast<float>(alpha);
                b.node("roof", static_cast<int32_t>(b.mesh("roof", roof, glass)));
                return b.material("ground", glm::vec3(0.5f), 0.0f, 0.0f);
            },
            {{"spp", 16}, {"transparent", transparent}}, 60.0);
        const glm::dvec3 through = transparent ? (1.0 - alpha) + alpha * transmission * (1.0 - metallic) *
                                                                     (1.0 - schlick(0.04, g.toSun.y)) * glm::dvec3(c)
                                               : glm::dvec3(1.0);
        const auto [checked, worst] = expectPixels(g.out.at("pt"), sunOnGreyGround(g, through), 0.01);
        std::printf("%s tracer, sun through a glass roof (transparent %d): %d pixels, worst relative error %.4f\n",
                    gBackend, transparent ? 1 : 0, checked, worst);
        EXPECT_GE(checked, 300);
    }
}

// The backlit scenes below: the camera at the origin looking at (0.2, 0.1, -3), the sun behind what it sees (towards
// (0.15, 0.35, -1)), no sky, one bounce, no antialiasing. Returns the traced image, the direction to the sun and its
// illuminance times sunScale.
struct Backlit {
    std::map<std::string, Image> out;
    glm::dvec3 toSun, sunE;
};
Backlit traceBacklit(SceneBuilder& b, int spp, int W, int H, double sunScale) {
    b.camera({0.0f, 0.0f, 0.0f}, {0.2f, 0.1f, -3.0f}, 0.8f);
    b.sun({0.15f, 0.35f, -1.0f});
    auto glb = b.write();
    json nodes = baseNodes(glb);
    nodes["env_cdf"] = {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}};
    nodes["pt"] = pathtraceNode(
        {{"spp", spp}, {"max_bounces", 1}, {"sky_scale", 0.0}, {"sun_scale", sunScale}, {"antialias", false}});
    Backlit r;
    r.out = runGraph(graph(nodes, {{"pt", "pt.color"}, {"sh", "sky.sh"}}, W, H));
    r.toSun = glm::normalize(rgb(r.out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    r.sunE = rgb(r.out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
    return r;
}

// The sun behind rough thin glass, seen through it: panes of roughness 0.6 (tinted c, IOR 1.5) facing the camera,
// the sun 19° up behind them, no sky; left pure glass, right a mixture (transmission 0.6, metallic 0.3); an opaque
// wall 3 m behind shades part of the left pane from the sun. Both tracers pass the glass straight on, so the only
// light a pixel of a pane shows is the sun scattered towards the camera by the glass's transmission lobe, added at
// the pane by next-event estimation for the transmissive share (1 − metallic) × transmission: that share × c × the
// thin-walled BTDF of KHR_materials_transmission (tests/gpu/lighting_scene's thinTransmissionLobe, written from the
// extension's description) × E, as forward.transparent draws it (Transparent.LightBehindRoughGlassShinesThrough…).
// Deterministic at 1 spp (the lobe is added whichever component the path then draws): 0.1 % per pixel; the shaded
// pixels (a band of 0.1 m around the wall's shadow edge left out) black.
PATHTRACE_TEST(SunBehindRoughGlassShinesThroughItsTransmissionLobe) {
    const int W = 40, H = 30;
    const glm::vec3 c(1.0f, 0.5f, 0.25f);
    const float shininess = 0.4f;
    const double sunScale = 0.1, share = 0.6 * (1.0 - 0.3), wallX = -0.2;
    SceneBuilder b("pt_glass_backlit");
    std::vector<Tri> left, right, wall;
    addQuad(left, glm::vec3(-1, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 1));
    addQuad(right, glm::vec3(1, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 1));
    addQuad(wall, glm::vec3(-4.1f, 0, 0), glm::vec3(3.9f, 0, 0), glm::vec3(0, 8, 0), glm::vec3(0, 0, 1));
    uint32_t glass = b.material("glass", c, 0.0f, shininess);
    b.s.materials[glass].transmission = 1.0f;
    uint32_t mixed = b.material("mixed", c, 0.3f, shininess);
    b.s.materials[mixed].transmission = 0.6f;
    b.node("left", static_cast<int32_t>(b.mesh("left", left, glass)), glm::vec3(0, 0, -3));
    b.node("right", static_cast<int32_t>(b.mesh("right", right, mixed)), glm::vec3(0, 0, -3));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, b.material("wall", glm::vec3(0.5f), 0.0f, 0.0f))),
           glm::vec3(0, 0, -6));
    const auto [out, toSun, sunE] = traceBacklit(b, 1, W, H, sunScale);
    const float alpha = shading::ggxAlpha(shading::roughnessFromShininess(shininess));
    const glm::dvec3 n(0.0, 0.0, 1.0);
    Pinhole cam(b.s, W, H);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    std::vector<glm::ivec2> shaded;
    int rightCount = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const glm::dvec3 p = d * (-3.0 / d.z);
            if (d.z >= 0.0 || std::abs(p.x) > 1.9 || std::abs(p.y) > 1.9 || std::abs(p.x) < 0.1) continue;
            // Where the sun ray from p meets the wall's plane (z = -6).
            const double xWall = p.x + toSun.x * (-3.0 / toSun.z);
            if (std::abs(xWall - wallX) < 0.1) continue;
            if (xWall < wallX) {
                shaded.push_back({x, y});
                continue;
            }
            rightCount += p.x > 0.0;
            const double s = p.x > 0.0 ? share : 1.0;
            expected.push_back({{x, y}, s * glm::dvec3(c) * thinTransmissionLobe(n, -d, toSun, 0.04, alpha) * sunE});
        }
    const auto [checked, worst] = expectPixels(out.at("pt"), expected, 0.001);
    double brightest = 0.0, darkest = 0.0;
    for (const auto& [px, e] : expected)
        brightest = std::max(brightest, e.g);
    for (const glm::ivec2& px : shaded)
        darkest = std::max(darkest, rgb(out.at("pt"), px.x, px.y).g);
    std::printf("%s tracer, sun behind rough glass: %d pixels (%d of the mixture), worst relative error %.5f, "
                "brightest %.1f; %zu shaded pixels, the brightest %.3g\n",
                gBackend, checked, rightCount, worst, brightest, shaded.size(), darkest);
    EXPECT_GE(checked, 300);
    EXPECT_GE(rightCount, 150);
    EXPECT_GE(shaded.size(), 100u);
    EXPECT_GT(brightest, 10.0) << "the lobe must show";
    EXPECT_LT(darkest, 1e-3 * brightest) << "the wall's shadow";
}

// The sun behind rough glass that bounds a volume: the scene above with the left pane a closed box 0.3 m thick of the
// same rough glass (KHR_materials_volume), no wall, no sky. The thin-walled lobe is not added at a volume (its light
// would reach the camera through two refractions, a caustic of the delta sun); the paths refract through the box and
// find nothing behind, and the sun reflects off its front only from the camera's side. So every pixel of the box is
// black (below 1e-6 of the thin pane's lobe at the same place, computed as above), on both tracers.
PATHTRACE_TEST(SunBehindARoughVolumeAddsNoThinWalledLobe) {
    const int W = 40, H = 30;
    const float shininess = 0.4f;
    const double sunScale = 0.1;
    SceneBuilder b("pt_volume_backlit");
    const uint32_t glass = volumeGlass(b, "glass", shininess);
    b.node("box", static_cast<int32_t>(b.mesh("box", closedBox(glm::vec3(2.0f, 2.0f, 0.15f)), glass)),
           glm::vec3(0.0f, 0.0f, -3.15f));
    const auto [out, toSun, sunE] = traceBacklit(b, 4, W, H, sunScale);
    const float alpha = shading::ggxAlpha(shading::roughnessFromShininess(shininess));
    Pinhole cam(b.s, W, H);
    double lobe = 0.0, brightest = 0.0;
    int checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const glm::dvec3 p = d * (-3.0 / d.z);
            if (d.z >= 0.0 || std::abs(p.x) > 1.8 || std::abs(p.y) > 1.8) continue;
            lobe = std::max(lobe, (thinTransmissionLobe(glm::dvec3(0, 0, 1), -d, toSun, 0.04, alpha) * sunE).g);
            brightest = std::max(brightest, rgb(out.at("pt"), x, y).g);
            ++checked;
        }
    std::printf("%s tracer, sun behind a rough volume: %d pixels, brightest %.3g (a thin pane's lobe up to %.3g)\n",
                gBackend, checked, brightest, lobe);
    EXPECT_GE(checked, 300);
    EXPECT_GT(lobe, 10.0);
    EXPECT_LT(brightest, 1e-6 * lobe);
}

// KHR_materials_volume on faces that bound nothing (core/scene/closed_mesh.hpp): traceSunlitGround's ground under a
// roof that is a single quad of smooth glass of base colour c = (1, 0.8, 0.6), thicknessFactor 0.2 drawn at scale 2,
// attenuationColor a = (0.25, 0.5, 1), attenuationDistance 0.5, the sun 60° up, no sky. A quad refracted into as a
// volume is never left; the tracers take it for thin-walled glass tinted as forward.transparent tints it (the Sample
// Viewer's approximation): the ground's sun radiance (shadeDirectional) times (1 - F) c a^(0.2 x 2 / 0.5) per channel,
// F = Schlick(0.04, sin 60°) once, Beer's law over the thickness times the node's scale (the Sample Viewer's
// transmission ray is the unit refracted direction times both, so not the slant). Deterministic: 1 % per pixel.
PATHTRACE_TEST(SunThroughAnOpenVolumeRoofIsThinGlassTintedOverItsThickness) {
    const glm::vec3 c(1.0f, 0.8f, 0.6f), a(0.25f, 0.5f, 1.0f);
    const double thickness = 0.2, scale = 2.0, distance = 0.5;
    const SunlitGround g = traceSunlitGround(
        "pt_open_volume_roof", 48, 48,
        [&](SceneBuilder& b) {
            const uint32_t glass = b.material("glass", c, 0.0f, 1.0f);
            b.s.materials[glass].transmission = 1.0f;
            b.s.materials[glass].thickness = static_cast<float>(thickness);
            b.s.materials[glass].attenuationColor = a;
            b.s.materials[glass].attenuationDistance = static_cast<float>(distance);
            std::vector<Tri> roof;
            addQuad(roof, glm::vec3(0.0f), glm::vec3(60, 0, 0), glm::vec3(0, 0, 60), glm::vec3(0, 1, 0));
            b.node("roof", static_cast<int32_t>(b.mesh("roof", roof, glass)), glm::vec3(0.0f, 3.0f, 0.0f));
            b.s.nodes.back().local.scale = glm::vec3(static_cast<float>(scale));
            return b.material("ground", glm::vec3(0.5f), 0.0f, 0.0f);
        },
        json::object(), 60.0);
    const glm::dvec3 through = (1.0 - schlick(0.04, g.toSun.y)) * glm::dvec3(c) *
                               glm::pow(glm::dvec3(a), glm::dvec3(thickness * scale / distance));
    const auto [checked, worst] = expectPixels(g.out.at("pt"), sunOnGreyGround(g, through), 0.01);
    std::printf("%s tracer, the sun through an open volume's roof: %d pixels, worst relative error %.4f\n", gBackend,
                checked, worst);
    EXPECT_GE(checked, 300);
}

// The sun behind rough glass whose volume is not closed: traceBacklit's scene with one pane, a single quad 4 m wide
// 3 m in front of the camera, of roughness 0.6, base colour c, thicknessFactor 0.3, attenuationColor a and
// attenuationDistance 0.5. As thin-walled glass it shows the sun scattered through its transmission lobe, as the
// thin pane of SunBehindRoughGlassShinesThroughItsTransmissionLobe, tinted by a^(0.3 / 0.5) as well (a closed volume
// of the same glass shows nothing there: SunBehindARoughVolumeAddsNoThinWalledLobe). Deterministic: 0.1 % per pixel.
PATHTRACE_TEST(SunBehindAnOpenVolumePaneShinesThroughItsTintedLobe) {
    const int W = 40, H = 30;
    const glm::vec3 c(1.0f, 0.5f, 0.25f), a(0.25f, 0.5f, 1.0f);
    const float shininess = 0.4f;
    const double sunScale = 0.1, thickness = 0.3, distance = 0.5;
    SceneBuilder b("pt_open_volume_backlit");
    std::vector<Tri> pane;
    addQuad(pane, glm::vec3(0.0f), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 1));
    const uint32_t glass = b.material("glass", c, 0.0f, shininess);
    b.s.materials[glass].transmission = 1.0f;
    b.s.materials[glass].thickness = static_cast<float>(thickness);
    b.s.materials[glass].attenuationColor = a;
    b.s.materials[glass].attenuationDistance = static_cast<float>(distance);
    b.node("pane", static_cast<int32_t>(b.mesh("pane", pane, glass)), glm::vec3(0, 0, -3));
    const auto [out, toSun, sunE] = traceBacklit(b, 1, W, H, sunScale);
    const float alpha = shading::ggxAlpha(shading::roughnessFromShininess(shininess));
    const glm::dvec3 tint = glm::dvec3(c) * glm::pow(glm::dvec3(a), glm::dvec3(thickness / distance));
    Pinhole cam(b.s, W, H);
    std::vector<std::pair<glm::ivec2, glm::dvec3>> expected;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const glm::dvec3 p = d * (-3.0 / d.z);
            if (d.z >= 0.0 || std::abs(p.x) > 1.9 || std::abs(p.y) > 1.9) continue;
            expected.push_back(
                {{x, y}, tint * thinTransmissionLobe(glm::dvec3(0, 0, 1), -d, toSun, 0.04, alpha) * sunE});
        }
    const auto [checked, worst] = expectPixels(out.at("pt"), expected, 0.001);
    std::printf("%s tracer, sun behind an open volume's rough pane: %d pixels, worst relative error %.5f\n", gBackend,
                checked, worst);
    EXPECT_GE(checked, 300);
}

// Meshes that deform are traced where they are posed, by both tracers: the BVH refits the levels of deforming meshes
// every frame (accel::SceneBvh::refit) and the CPU tracer builds its Embree scene from the posed vertices
// (scene::Deformation). The corpus's white unlit meshes (they emit 1) under a uniform sky of 100, through their
// orthographic cameras (xmag = ymag = 2: 4 m across the frame, centred on the camera's x and y; both tracers start
// such a camera's rays on its near plane, parallel):
// - skin_bend.gltf at frame 1 (t = 1, fps 1; camera at y = 1): the upper bone turned 90° about the joint at (0, 1) and
//   lies along y = 1 from x = 0 to -1, 0.2 thick; at rest it stood along x = 0 from y = 1 to 2;
// - morph_animated.gltf at frame 2 (t = 2; camera at y = 0; a static node, so only the morph moves it): the front face
//   spans x from -0.5 to 1.5 (weight 1), where it reached 0.5 at rest (weight 0), over y from -0.5 to 0.5.
PATHTRACE_TEST(DeformedMeshesAreTracedWherePosed) {
    const int W = 64, H = 64;
    const double C = 100.0;
    struct Case {
        const char* file;
        int frame;
        double cameraY;
        std::vector<glm::dvec2> surface, sky; // world (x, y)
    };
    const Case cases[] = {
        {"skin_bend.gltf", 1, 1.0, {{-0.73, 0.98}, {-0.45, 1.04}, {0.0, 0.5}}, {{0.0, 1.73}, {0.0, 1.4}, {-1.5, 1.0}}},
        {"morph_animated.gltf", 2, 0.0, {{1.2, 0.0}, {0.9, 0.3}, {-0.3, 0.0}}, {{1.75, 0.0}, {-0.8, 0.0}}},
    };
    const auto skyFile = scratchDir() / "pt_deformed.glb";
    std::filesystem::create_directories(skyFile.parent_path());
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        const auto file = std::filesystem::path(VITRINE_SOURCE_DIR) / "tests" / "data" / "gltf" / "corpus" / c.file;
        json g = traceGraph(file, uniformSky(skyFile, C), {{"spp", 4}, {"antialias", false}}, W, H, c.frame + 1);
        g["nodes"]["scene"]["params"]["fps"] = 1;
        g["nodes"]["scene"]["params"]["start"] = 0.0;
        const Image img = runGraph(g).at("color");
        auto radiance = [&](glm::dvec2 p) {
            const int x = static_cast<int>((p.x + 2.0) / 4.0 * W),
                      y = static_cast<int>((c.cameraY + 2.0 - p.y) / 4.0 * H);
            return static_cast<double>(img.at(x, y)[1]);
        };
        for (glm::dvec2 p : c.surface)
            EXPECT_NEAR(radiance(p), 1.0, 0.01)
                << gBackend << " tracer: the posed mesh at (" << p.x << ", " << p.y << ")";
        for (glm::dvec2 p : c.sky)
            EXPECT_NEAR(radiance(p), C, 0.01 * C) << gBackend << " tracer: the sky at (" << p.x << ", " << p.y << ")";
    }
}

} // namespace
} // namespace vitrine::test
