#include "tests/gpu/test_nodes.hpp"

#include "core/gpu/context.hpp"
#include "core/gpu/descriptors.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/scene.hpp"
#include "nodes/scene/scene_node.hpp"

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <bit>

#include <string>

namespace vitrine::test {
namespace {

const char* kOctahedralSource = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "common/octahedral.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    const int n = 128, h = 64;
    if (p.x >= 2 * n || p.y >= h) return;
    if (p.x < n) {
        float theta = (float(p.y) + 0.5) / float(h) * 3.14159265358979;
        float phi = (float(p.x) + 0.5) / float(n) * 6.28318530717959;
        vec3 d = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
        imageStore(out_result, p, vec4(octEncode(d), 0.0, 1.0));
    } else {
        vec2 e = vec2((float(p.x - n) + 0.5) / float(n), (float(p.y) + 0.5) / float(h)) * 2.0 - 1.0;
        imageStore(out_result, p, vec4(octDecode(e), 1.0));
    }
}
)";

const char* kFurnaceSource = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "common/brdf.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_albedo;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= 16 || p.y >= 16) return;
    float NoV = (float(p.x) + 0.5) / 16.0;
    float alpha = ggxAlpha((float(p.y) + 0.5) / 16.0);
    vec3 v = vec3(sqrt(1.0 - NoV * NoV), 0.0, NoV);
    const int m = 64;
    float spec = 0.0, lambert = 0.0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            // Stratified: one sample at the centre of each of m x m cells.
            float u1 = (float(i) + 0.5) / float(m), u2 = (float(j) + 0.5) / float(m);
            // Visible-normal sampling of h [Heitz18] (pdf_l = G1(v) D / (4 NoV)); with F = 1
            // the estimator f NoL / pdf_l is G2 / G1(v) = 4 V NoL NoV / G1(v).
            vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
            vec3 t1 = vec3(0.0, 1.0, 0.0); // vh lies in the XZ plane
            vec3 t2 = cross(vh, t1);
            float r = sqrt(u1), phi = 2.0 * kPi * u2;
            float p1 = r * cos(phi), p2 = r * sin(phi);
            float s = 0.5 * (1.0 + vh.z);
            p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * p2;
            vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
            vec3 h = normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
            float VoH = dot(v, h);
            vec3 l = 2.0 * VoH * h - v;
            float g1 = 2.0 * NoV / (NoV + sqrt(alpha * alpha + (1.0 - alpha * alpha) * NoV * NoV));
            if (l.z > 0.0) spec += 4.0 * smithGgxVisibility(NoV, l.z, alpha) * l.z * NoV / g1;
            // Cosine-weighted sampling of l for Lambert: f cos / pdf = (1/pi) cos / (cos / pi).
            float cosL = sqrt(1.0 - u1);
            lambert += lambertDiffuse() * cosL / (cosL / kPi);
        }
    // z: the fitted albedo (common/ggx_albedo.h); w: the lobe with its multiple-scattering compensation (F0 = 1).
    spec /= float(m * m);
    imageStore(out_albedo, p, vec4(spec, lambert / float(m * m), ggxAlbedo(NoV, alpha),
                                   spec * ggxMultiscatter(vec3(1.0), NoV, alpha).r));
}
)";

const char* kUnfoldSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) readonly uniform imageCube in_cube;
layout(binding = 1) writeonly uniform image2D out_faces;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 s = imageSize(out_faces);
    if (p.x >= s.x || p.y >= s.y) return;
    int n = s.y;
    imageStore(out_faces, p, imageLoad(in_cube, ivec3(p.x % n, p.y, p.x / n)));
}
)";

const char* kSampleSource = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "common/cubemap.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform samplerCube in_cube;
layout(binding = 1) writeonly uniform image2D out_faces;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 s = imageSize(out_faces);
    if (p.x >= s.x || p.y >= s.y) return;
    int n = s.y;
    vec3 d = cubeTexelDirection(uint(p.x / n), ivec2(p.x % n, p.y), n);
    imageStore(out_faces, p, textureLod(in_cube, d, 0.0));
}
)";

OutputPort floatOutput(const std::string& name, uint32_t w, uint32_t h) {
    OutputPort out;
    out.name = name;
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::absolute(w, h);
    out.doc = "test output";
    return out;
}

class SourceNode final : public Node {
public:
    SourceNode(std::string name, const char* source, std::string output, bool fromCube)
        : mName(std::move(name)), mSource(source), mOutput(std::move(output)), mFromCube(fromCube) {}
    void setup(SetupContext& ctx) override {
        if (mFromCube) {
            ImageDesc& out = ctx.output(mOutput);
            out.width = 6 * ctx.input("cube").width;
            out.height = ctx.input("cube").height;
        }
        mPipeline = ctx.computePipelineSource(mName, mSource);
    }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output(mOutput).desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    std::string mName;
    const char* mSource;
    std::string mOutput;
    bool mFromCube;
    PipelineId mPipeline = 0;
};

NodeSchema testSchema(const std::string& type, std::vector<InputPort> inputs, OutputPort out) {
    NodeSchema s;
    s.type = type;
    s.doc = "test-only node of test_gpu";
    s.inputs = std::move(inputs);
    s.outputs = {std::move(out)};
    return s;
}

const NodeRegistration kOctahedral(testSchema("test.octahedral", {}, floatOutput("result", 2 * kOctGrid, 64)), [] {
    return std::make_unique<SourceNode>("test/octahedral", kOctahedralSource, "result", false);
});
const NodeRegistration kFurnace(testSchema("test.furnace", {}, floatOutput("albedo", 16, 16)), [] {
    return std::make_unique<SourceNode>("test/furnace", kFurnaceSource, "albedo", false);
});
const NodeRegistration
    kUnfold(testSchema("test.cube_unfold", {{"cube", PortKind::Texture, {}, false, Usage::StorageRead, "cube map"}},
                       floatOutput("faces", 6, 1)),
            [] { return std::make_unique<SourceNode>("test/cube_unfold", kUnfoldSource, "faces", true); });
const NodeRegistration
    kSample(testSchema("test.cube_sample", {{"cube", PortKind::Texture, {}, false, Usage::Sampled, "cube map"}},
                       floatOutput("faces", 6, 1)),
            [] { return std::make_unique<SourceNode>("test/cube_sample", kSampleSource, "faces", true); });

} // namespace
} // namespace vitrine::test

// ---------------------------------------------------------------------------------------------
// Stand-ins for ibl.localized's tests (tests/gpu/ibl_localized_test.cpp): ibl.capture's outputs and probes in a
// glTF file (the other lanes' work) are replaced by these.

namespace vitrine::test {
namespace {

// A cube-map array (RGBA16F, one mip, 6 layers per probe, at least 2 probes' worth so the view is always a cube
// array) whose probe i holds `values[i]` everywhere ("constant"), or on face f texel (x, y) the colour
// (f, x + 0.5, y + 0.5) ("texels": bilinear lookups inside a face read back the continuous texel coordinate), or
// ("levels") a full mip chain holding m on every texel of mip m.
const char* kProbeCubesSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform imageCubeArray out_cubes;
layout(binding = 1) uniform Uniforms { vec4 values[64]; ivec4 mode; } u;
void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    ivec2 size = imageSize(out_cubes).xy;
    if (p.x >= size.x || p.y >= size.y) return;
    int probe = p.z / 6, face = p.z % 6;
    vec4 c = u.mode.x == 0 ? u.values[min(probe, 63)] : vec4(float(face), vec2(p.xy) + 0.5, 1.0);
    imageStore(out_cubes, p, c);
}
)";

// "levels": a full mip chain whose every texel of mip m is (m, m, m): trilinear lookups at lod L read L back.
const char* kProbeCubeLevelsSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 1, binding = 0, rgba16f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { int size; int mip; int layers; } pc;
void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    if (g.x >= pc.size || g.y >= pc.size * pc.layers) return;
    imageStore(target, ivec3(g.x, g.y % pc.size, g.y / pc.size), vec4(vec3(float(pc.mip)), 1.0));
}
)";

class ProbeCubes final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        ImageDesc& out = ctx.output("cubes");
        uint32_t size = static_cast<uint32_t>(p.getInt("size"));
        out.width = out.height = size;
        mLevels = p.getString("mode") == "levels";
        if (mLevels) {
            out.mipLevels = static_cast<uint32_t>(std::bit_width(size));
            mLevelsPipeline = ctx.computePipelineSource("test/probe_cube_levels", kProbeCubeLevelsSource, 1);
        }
        auto values = nlohmann::json::parse(p.getString("values"));
        mUniforms.mode = {p.getString("mode") == "texels" ? 1 : 0, 0, 0, 0};
        for (size_t i = 0; i < values.size() && i < 64; ++i)
            mUniforms.values[i] = {values[i][0].get<float>(), values[i][1].get<float>(), values[i][2].get<float>(),
                                   1.0f};
        out.layers = 6 * std::max<uint32_t>(2, static_cast<uint32_t>(values.size()));
        out.cube = true;
        mPipeline = ctx.computePipelineSource("test/probe_cubes", kProbeCubesSource);
    }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("cubes").desc();
        if (!mLevels) {
            ctx.setUniforms(mUniforms);
            ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height, out.layers);
            return;
        }
        if (!mSets) {
            const VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                                                       nullptr};
            mSets = DescriptorSets(ctx.gpu(), std::span(&binding, 1), 16, {}, "test.probe_cubes");
        }
        mSets.reset();
        const std::array<VkDescriptorSetLayout, 1> layouts = {mSets.layout()};
        for (uint32_t m = 0; m < out.mipLevels; ++m) {
            const VkDescriptorSet set = mSets.allocate();
            DescriptorWrites(set)
                .image(0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, {VK_NULL_HANDLE, ctx.output("cubes").mipView(m), VK_IMAGE_LAYOUT_GENERAL})
                .update(ctx.gpu().device());
            struct {
                int32_t size, mip, layers;
            } push{static_cast<int32_t>(std::max(out.width >> m, 1u)), static_cast<int32_t>(m),
                   static_cast<int32_t>(out.layers)};
            ctx.dispatchWithSets(mLevelsPipeline, &push, sizeof(push), push.size, push.size * out.layers, layouts,
                                 std::array<VkDescriptorSet, 1>{set});
        }
    }

private:
    bool mLevels = false;
    PipelineId mLevelsPipeline = 0;
    DescriptorSets mSets;
    struct Uniforms {
        glm::vec4 values[64];
        glm::ivec4 mode;
    } mUniforms{};
    PipelineId mPipeline = 0;
};

// A stand-in BRDF LUT (RGBA16F, 32 x 32) linear in both coordinates, so that bilinear lookups at iblLutUv are
// exact: A = 0.25 + 0.5 NoV, B = 0.2 roughness (kLutA / kLutB in test_nodes.hpp).
const char* kLutSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_lut;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_lut);
    if (p.x >= size.x || p.y >= size.y) return;
    vec2 t = vec2(p) / vec2(size - 1);
    imageStore(out_lut, p, vec4(0.25 + 0.5 * t.x, 0.2 * t.y, 0.0, 1.0));
}
)";

NodeSchema probeCubesSchema() {
    NodeSchema s;
    s.type = "test.probe_cubes";
    s.doc = "test-only node of test_gpu: a probe cube-map array of known content";
    OutputPort out;
    out.name = "cubes";
    out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    out.size = SizeRule::absolute(16, 16);
    out.persistent = true;
    out.doc = "cube-map array, 6 layers per probe";
    s.outputs = {out};
    s.params = {{"size", ParamType::Int, 16, 1.0, 1024.0, {}, "face size"},
                {"mode", ParamType::Enum, "constant", {}, {}, {"constant", "texels", "levels"},
                 "content (levels: a full mip chain, mip m holding m)"},
                {"values", ParamType::String, "[[1,1,1]]", {}, {}, {}, "JSON array of RGB, one per probe"}};
    return s;
}

NodeSchema lutSchema() {
    NodeSchema s;
    s.type = "test.brdf_lut";
    s.doc = "test-only node of test_gpu: a BRDF LUT linear in NoV and roughness";
    OutputPort out;
    out.name = "lut";
    out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    out.size = SizeRule::absolute(32, 32);
    out.doc = "(A, B) = (0.25 + 0.5 NoV, 0.2 roughness)";
    s.outputs = {out};
    return s;
}

// scene.gltf plus reflection probes given as JSON (`probe_list`: [{"center": [x, y, z], "half": [x, y, z],
// "rotation": [w, x, y, z], "position": [x, y, z], "sphere": bool, "fade": f, "priority": i, "projection_center":
// [x, y, z], "projection_half": [x, y, z]}, ...]).
class GltfProbes final : public SceneNode {
public:
    void setup(SetupContext& ctx) override {
        auto s = std::make_shared<scene::Scene>(scene::loadGltf(ctx.resolvePath(ctx.params().getString("path"))));
        for (const auto& j : nlohmann::json::parse(ctx.params().getString("probe_list"))) {
            scene::ReflectionProbe p;
            p.name = "probe" + std::to_string(s->probes.size());
            auto v3 = [&](const char* key, glm::vec3 d) {
                return j.contains(key)
                           ? glm::vec3(j[key][0].get<float>(), j[key][1].get<float>(), j[key][2].get<float>())
                           : d;
            };
            p.center = v3("center", glm::vec3(0.0f));
            p.halfExtents = v3("half", glm::vec3(1.0f));
            p.position = v3("position", p.center);
            if (j.contains("rotation"))
                p.rotation = glm::quat(j["rotation"][0].get<float>(), j["rotation"][1].get<float>(),
                                       j["rotation"][2].get<float>(), j["rotation"][3].get<float>());
            p.shape = j.value("sphere", false) ? scene::ProbeShape::Sphere : scene::ProbeShape::Box;
            p.fade = j.value("fade", 0.5f);
            p.priority = j.value("priority", 0);
            p.projectionCenter = v3("projection_center", glm::vec3(0.0f));
            p.projectionHalfExtents = v3("projection_half", glm::vec3(0.0f));
            s->probes.push_back(p);
        }
        publish(ctx, std::move(s));
    }
};

NodeSchema gltfProbesSchema() {
    NodeSchema s;
    s.type = "test.gltf_probes";
    s.doc = "test-only node of test_gpu: scene.gltf with reflection probes from a param";
    s.pass = PassKind::Transfer;
    s.params = {{"path", ParamType::Path, "", {}, {}, {}, "the .glb"},
                {"probe_list", ParamType::String, "[]", {}, {}, {}, "JSON array of probes"}};
    addSceneNodeSchema(s);
    return s;
}

const NodeRegistration kProbeCubes(probeCubesSchema(), [] { return std::make_unique<ProbeCubes>(); });
const NodeRegistration kLut(lutSchema(),
                            [] { return std::make_unique<SourceNode>("test/brdf_lut", kLutSource, "lut", false); });
const NodeRegistration kGltfProbes(gltfProbesSchema(), [] { return std::make_unique<GltfProbes>(); });

} // namespace
} // namespace vitrine::test
