// ao.alchemy against the Alchemy estimator evaluated on the CPU from the depth and normals the GPU read (McGuire et
// al. 2011), and lighting.deferred's `ao` input: it multiplies the indirect terms alone by lerp(baseColor, 1, ao).
// Scenes are built in code, written as glTF and loaded through scene.gltf + gbuffer.layered.
#include "tests/gpu/lighting_scene.hpp"

#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/octahedral.hpp"
#include "shaders/ao/alchemy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

// test.constant_ao: a uniform texture of value `value` in every channel, as a stand-in for an AO buffer.
const char* kConstantSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_color;
layout(push_constant) uniform Push { vec4 value; } pc;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    imageStore(out_color, p, pc.value);
}
)";

class ConstantAo final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipelineSource("test/constant_ao", kConstantSource); }
    void execute(ExecuteContext& ctx) override {
        const glm::vec4 value(ctx.params().getFloat("value"));
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, &value, sizeof(value), out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

NodeSchema constantSchema() {
    NodeSchema s;
    s.type = "test.constant_ao";
    s.doc = "test-only node of test_gpu";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::absolute(8, 8); // a smaller texture: the lighting samples it by uv
    out.doc = "test output";
    s.outputs = {out};
    s.params = {{"value", ParamType::Float, 1.0, 0.0, 1.0, {}, "the value"}};
    return s;
}
const NodeRegistration kConstant(constantSchema(), [] { return std::make_unique<ConstantAo>(); });

struct AoParams {
    float radius = 0.5f, intensity = 0.6f, bias = 0.002f, contrast = 2.0f;
    int samples = 12;
    std::string resolution = "full";
};

json aoGraph(const std::filesystem::path& glb, int w, int h, const AoParams& a) {
    return graph({{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}}}}},
                  {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
                  {"ao",
                   {{"type", "ao.alchemy"},
                    {"in", {{"normal", "gbuffer.normal"}, {"camera", "scene.camera"}}},
                    {"params",
                     {{"radius", a.radius},
                      {"intensity", a.intensity},
                      {"bias", a.bias},
                      {"contrast", a.contrast},
                      {"samples", a.samples},
                      {"resolution", a.resolution}}}}}},
                 {{"ao", "ao.ao"}, {"normal", "gbuffer.normal"}}, w, h);
}

// The Alchemy estimator written out on the CPU, from the G-buffer normal target the GPU read (octahedral normal, view
// depth): positions on the camera's rays through texel centres at the stored view depth, the same spiral and
// per-pixel rotation (shaders/ao/alchemy.h), in float as the shader computes it.
struct CpuAlchemy {
    const Image& g;
    Pinhole cam;
    glm::dvec3 forward;
    AoParams a;

    CpuAlchemy(const Image& normal, const scene::Scene& s, const AoParams& params)
        : g(normal), cam(s, normal.width, normal.height), a(params) {
        forward = cam.orientation * glm::dvec3(0.0, 0.0, -1.0);
    }
    glm::dvec3 position(int x, int y, double d) const {
        const glm::dvec3 r = cam.ray(x, y);
        return cam.position + r * (d / glm::dot(r, forward));
    }
    double at(int cx, int cy) const {
        const float* t = g.at(cx, cy);
        if (t[2] <= 0.0f) return 1.0;
        const double z = t[2];
        const glm::dvec3 n = glm::dvec3(shading::octDecode(glm::vec2(t[0], t[1])));
        const glm::dvec3 p = position(cx, cy, z);
        const float pxPerMetre = 0.5f * static_cast<float>(g.height) / static_cast<float>(std::tan(0.5 * cam.yfov));
        const float radiusPx = std::min(a.radius * pxPerMetre / static_cast<float>(z), float(ALCHEMY_MAX_RADIUS_PX));
        const float rotation = gpu_types::alchemyRotation(cx, cy, 0u);
        double sum = 0.0;
        for (int i = 0; i < a.samples; ++i) {
            const float s = (static_cast<float>(i) + 0.5f) / static_cast<float>(a.samples);
            const float angle = 6.28318530718f * (s * float(ALCHEMY_SPIRAL_TURNS) + rotation);
            const float ox = s * radiusPx * std::cos(angle), oy = s * radiusPx * std::sin(angle);
            const int qx = static_cast<int>(std::floor(static_cast<float>(cx) + 0.5f + ox));
            const int qy = static_cast<int>(std::floor(static_cast<float>(cy) + 0.5f + oy));
            if (qx < 0 || qy < 0 || qx >= g.width || qy >= g.height) continue;
            const double dq = g.at(qx, qy)[2];
            if (dq <= 0.0) continue;
            const glm::dvec3 v = position(qx, qy, dq) - p;
            const double vv = glm::dot(v, v);
            if (vv >= double(a.radius) * a.radius) continue;
            sum += a.radius * std::max(0.0, glm::dot(v, n) - a.bias * z) / (vv + ALCHEMY_EPSILON);
        }
        return std::pow(std::max(0.0, 1.0 - 2.0 * a.intensity / a.samples * sum), double(a.contrast));
    }
};

class Ao : public GpuTest {};

// A floor meeting a wall at a right angle, seen from the front: the crease is a horizontal line of the image. Per
// pixel and per image row (the occlusion profile across the crease), the GPU's AO matches the CPU estimator on the
// same depth buffer within 2 %, at full and at half resolution (each half-resolution pixel reads the G-buffer texel
// under its centre). The profile must really dip (the test sees occlusion) and be 1 far from the crease.
TEST_F(Ao, CornerProfileMatchesCpuEstimator) {
    SceneBuilder b("ao_corner");
    const uint32_t grey = b.material("grey", glm::vec3(0.5f), 0.0f, 0.3f);
    std::vector<Tri> floor, wall;
    addQuad(floor, {0.0f, 0.0f, -2.0f}, {5.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 3.0f}, {0.0f, 1.0f, 0.0f});
    addQuad(wall, {0.0f, 2.5f, -4.0f}, {5.0f, 0.0f, 0.0f}, {0.0f, 2.5f, 0.0f}, {0.0f, 0.0f, 1.0f});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floor, grey)));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, grey)));
    b.camera({0.3f, 1.0f, 0.5f}, {0.0f, 0.2f, -4.0f}, 0.8f);
    const auto glb = b.write();
    const int w = 96, h = 64;
    for (const std::string resolution : {"full", "half"}) {
        AoParams a;
        a.resolution = resolution;
        auto out = runGraph(aoGraph(glb, w, h, a));
        const Image& ao = out.at("ao");
        const Image& g = out.at("normal");
        ASSERT_EQ(ao.width, resolution == "full" ? w : w / 2);
        CpuAlchemy cpu(g, b.s, a);
        double worst = 0.0, worstRow = 0.0, lowest = 1.0, highest = 0.0;
        int beyond = 0;
        for (int y = 0; y < ao.height; ++y) {
            double gpuRow = 0.0, cpuRow = 0.0;
            for (int x = 0; x < ao.width; ++x) {
                const int cx = std::min(static_cast<int>((x + 0.5) * g.width / ao.width), g.width - 1);
                const int cy = std::min(static_cast<int>((y + 0.5) * g.height / ao.height), g.height - 1);
                const double expected = cpu.at(cx, cy), got = ao.at(x, y)[0];
                worst = std::max(worst, std::fabs(got - expected));
                beyond += std::fabs(got - expected) > 0.02;
                gpuRow += got / ao.width;
                cpuRow += expected / ao.width;
            }
            worstRow = std::max(worstRow, std::fabs(gpuRow - cpuRow));
            lowest = std::min(lowest, gpuRow);
            highest = std::max(highest, gpuRow);
        }
        std::printf("%s resolution: AO row profile from %.3f to %.3f; worst row |GPU - CPU| %.2e, worst pixel %.2e "
                    "(%d pixels beyond 0.02)\n",
                    resolution.c_str(), lowest, highest, worstRow, worst, beyond);
        EXPECT_LT(worstRow, 0.02);
        EXPECT_LE(beyond, ao.width * ao.height / 200); // float rounding may move a rare sample by a texel
        EXPECT_LT(lowest, 0.6);                        // the crease occludes
        EXPECT_GT(highest, 0.999);                     // far from it nothing does
    }
}

// A plane alone does not occlude itself: AO = 1 everywhere (v . n = 0 up to the half-float depth, which the bias
// absorbs), at a grazing angle too.
TEST_F(Ao, FlatPlaneIsUnoccluded) {
    SceneBuilder b("ao_plane");
    const uint32_t grey = b.material("grey", glm::vec3(0.5f), 0.0f, 0.3f);
    std::vector<Tri> floor;
    addQuad(floor, {0.0f, 0.0f, -20.0f}, {30.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 20.0f}, {0.0f, 1.0f, 0.0f});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floor, grey)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -6.0f}, 0.8f);
    const auto glb = b.write();
    AoParams a;
    a.intensity = 2.0f;
    auto out = runGraph(aoGraph(glb, 96, 64, a));
    double lowest = 1.0;
    int drawn = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 96; ++x) {
            lowest = std::min(lowest, double(out.at("ao").at(x, y)[0]));
            drawn += out.at("normal").at(x, y)[2] > 0.0f;
        }
    std::printf("flat plane: lowest AO %.6f over %d drawn pixels\n", lowest, drawn);
    EXPECT_GT(drawn, 96 * 20);
    EXPECT_GE(lowest, 1.0 - 1e-3);
}

// lighting.deferred with a uniform `ao` of 0.3 against the same node without it, on a coloured sphere over a floor
// lit by sun and sky: the indirect light (sun off) is multiplied by lerp(baseColor, 1, ao) per channel, and so is the
// specular_indirect output; the direct light (with the sun, minus the sun-less image) is unchanged.
TEST_F(Ao, LightingAppliesAoToIndirectTermsOnly) {
    SceneBuilder b("ao_lighting");
    const glm::vec3 base(0.8f, 0.4f, 0.1f);
    const uint32_t orange = b.material("orange", base, 0.0f, 0.6f);
    std::vector<Tri> floor;
    addQuad(floor, {0.0f, 0.0f, -3.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.0f}, {0.0f, 1.0f, 0.0f});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floor, orange)));
    b.node("ball", static_cast<int32_t>(b.mesh("ball", sphereTris(0.8f, 24, 12), orange)), {0.0f, 0.8f, -3.0f});
    b.camera({0.0f, 1.5f, 1.0f}, {0.0f, 0.5f, -3.0f}, 0.9f);
    b.sun(glm::normalize(glm::vec3(0.4f, 1.0f, 0.3f)));
    const auto glb = b.write();
    const float aoValue = 0.3f;
    auto run = [&](bool sun, bool ao) {
        json nodes = baseNodes(glb);
        nodes["lighting"] = lightingNode({{"sun_scale", sun ? 1.0 : 0.0}, {"sky_ambient", 1.0}}, false);
        if (ao) {
            nodes["constant"] = {{"type", "test.constant_ao"}, {"params", {{"value", aoValue}}}};
            nodes["lighting"]["in"]["ao"] = "constant.color";
        }
        return runGraph(graph(nodes, {{"color", "lighting.color"}, {"spec", "lighting.specular_indirect"},
                                      {"base", "gbuffer.base_color"}},
                              64, 48));
    };
    auto indirect = run(false, false), indirectAo = run(false, true), full = run(true, false), fullAo = run(true, true);
    double worstIndirect = 0.0, worstSpec = 0.0, worstDirect = 0.0, darkened = 0.0;
    int lit = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
            const glm::dvec3 stored = rgb(indirect.at("base"), x, y); // the G-buffer's UNORM8 base colour
            const glm::dvec3 tint = glm::mix(stored, glm::dvec3(1.0), double(aoValue));
            const glm::dvec3 i0 = rgb(indirect.at("color"), x, y), i1 = rgb(indirectAo.at("color"), x, y);
            if (stored == glm::dvec3(0.0)) continue; // the sky
            worstIndirect = std::max(worstIndirect, relErr(i1, i0 * tint));
            worstSpec = std::max(worstSpec, relErr(rgb(indirectAo.at("spec"), x, y), rgb(indirect.at("spec"), x, y) * tint));
            const glm::dvec3 direct = rgb(full.at("color"), x, y) - i0;
            const glm::dvec3 directAo = rgb(fullAo.at("color"), x, y) - i1;
            if (glm::length(direct) > 0.5 * glm::length(i0)) { // sunlit: half-float rounding of i0 stays small
                worstDirect = std::max(worstDirect, relErr(directAo, direct));
                ++lit;
            }
            darkened = std::max(darkened, 1.0 - i1.b / std::max(i0.b, 1e-9));
        }
    std::printf("ao %.1f: indirect vs CPU tint %.2e, specular_indirect %.2e, direct changed by %.2e (%d sunlit pixels), "
                "blue indirect darkened by up to %.3f\n",
                aoValue, worstIndirect, worstSpec, worstDirect, lit, darkened);
    EXPECT_LT(worstIndirect, 2e-3); // RGBA16F outputs
    EXPECT_LT(worstSpec, 2e-3);
    EXPECT_LT(worstDirect, 1e-2);
    EXPECT_GT(lit, 100);
    EXPECT_GT(darkened, 0.5); // the blue channel of an orange surface: tint 0.3 + 0.7 x 0.1 (the test sees the AO)
}

} // namespace
} // namespace vitrine::test
