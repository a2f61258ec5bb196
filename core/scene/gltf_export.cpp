// exportGlb(): the scene as one self-contained .glb that loadGltf() reads back to the same contentHash().

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"
#include "core/scene/probe_json.hpp"
#include "core/scene/tangents.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <fstream>
#include <span>

#include <glm/gtc/constants.hpp>
#include <stb/stb_image_write.h>

namespace vitrine::scene {

namespace {

using gltf::Json;

constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

Json vec(const glm::vec3& v) {
    return Json::array({v.x, v.y, v.z});
}
Json vec(const glm::vec4& v) {
    return Json::array({v.x, v.y, v.z, v.w});
}
Json vec(const glm::quat& q) {
    return Json::array({q.x, q.y, q.z, q.w});
}

// The shortest rotation taking unit vector a onto unit vector b.
glm::quat rotationBetween(const glm::vec3& a, const glm::vec3& b) {
    float d = glm::dot(a, b);
    if (d < -0.999999f) {
        glm::vec3 axis = std::abs(a.x) < 0.9f ? glm::cross(a, glm::vec3(1, 0, 0)) : glm::cross(a, glm::vec3(0, 1, 0));
        return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
    }
    glm::vec3 c = glm::cross(a, b);
    return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

int filterCode(Filter f) {
    return f == Filter::Nearest ? 9728 : 9729;
}

int minFilterCode(const Sampler& s) {
    bool nearest = s.minFilter == Filter::Nearest;
    switch (s.mipFilter) {
    case MipFilter::None:
        return nearest ? 9728 : 9729;
    case MipFilter::Nearest:
        return nearest ? 9984 : 9985;
    default:
        return nearest ? 9986 : 9987;
    }
}

int wrapCode(Wrap w) {
    return w == Wrap::ClampToEdge ? 33071 : w == Wrap::MirroredRepeat ? 33648 : 10497;
}

float channelMean(const Scene& scene, const TextureRef& ref, uint32_t channel) {
    const TextureImage& image = scene.images[scene.textures[ref.texture].image];
    uint64_t sum = 0;
    size_t count = size_t(image.width) * image.height;
    for (size_t p = 0; p < count; ++p)
        sum += image.pixels[p * 4 + channel];
    return count ? float(sum) / (255.0f * count) : 1.0f;
}

// TEXCOORD_1 is the lightmap parameterisation (or a UV set a material samples); TEXCOORD_0 is written when a texture
// samples it or when TEXCOORD_1 is written (glTF's TEXCOORD_n must be continuous from 0).
bool writesUv1(const Scene& scene, const Primitive& p) {
    return p.lightmapUvs || usesUvSet(scene.materials[p.material], 1);
}
bool writesUv0(const Scene& scene, const Primitive& p) {
    return usesUvSet(scene.materials[p.material], 0) || writesUv1(scene, p);
}

class Exporter {
public:
    explicit Exporter(const Scene& scene) : mScene(scene) {}

    std::vector<uint8_t> run();

private:
    size_t append(const void* data, size_t size) {
        while (mBin.size() % 4)
            mBin.push_back(0);
        size_t at = mBin.size();
        mBin.resize(at + size);
        if (size) std::memcpy(mBin.data() + at, data, size);
        return at;
    }
    int view(size_t offset, size_t length, int stride = 0, int target = 0) {
        Json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
        if (stride) v["byteStride"] = stride;
        if (target) v["target"] = target;
        mDoc["bufferViews"].push_back(v);
        return static_cast<int>(mDoc["bufferViews"].size()) - 1;
    }
    int accessor(int bufferView, size_t offset, int componentType, size_t count, const char* type) {
        mDoc["accessors"].push_back({{"bufferView", bufferView},
                                     {"byteOffset", offset},
                                     {"componentType", componentType},
                                     {"count", count},
                                     {"type", type}});
        return static_cast<int>(mDoc["accessors"].size()) - 1;
    }
    // Float data in a view of its own (animation keys; morph targets with target = kArrayBuffer).
    int floats(const std::vector<float>& data, int components, const char* type, bool withBounds, int target = 0) {
        size_t at = append(data.data(), data.size() * sizeof(float));
        int a = accessor(view(at, data.size() * sizeof(float), 0, target), 0, kFloat, data.size() / components, type);
        if (withBounds) {
            Json mn = Json::array(), mx = Json::array();
            for (int c = 0; c < components; ++c) {
                float lo = data[c], hi = data[c];
                for (size_t i = c; i < data.size(); i += components)
                    lo = std::min(lo, data[i]), hi = std::max(hi, data[i]);
                mn.push_back(lo);
                mx.push_back(hi);
            }
            mDoc["accessors"][a]["min"] = mn;
            mDoc["accessors"][a]["max"] = mx;
        }
        return a;
    }

    void meshes();
    void morphTargets(uint32_t primitive, Json& jp);
    void images();
    void materials();
    Json material(const Material& m) const;
    void cameras();
    void nodesAndScene();
    void skins();
    void animations();
    void cameraPathAnimation(const CameraPath& path, int node);

    const Scene& mScene;
    Json mDoc;
    std::vector<uint8_t> mBin;
    std::vector<Json> mHelperNodes;
};

void Exporter::meshes() {
    if (mScene.vertices.empty()) return;
    size_t vat = append(mScene.vertices.data(), mScene.vertices.size() * sizeof(Vertex));
    int vertexView = view(vat, mScene.vertices.size() * sizeof(Vertex), sizeof(Vertex), kArrayBuffer);
    size_t iat = append(mScene.indices.data(), mScene.indices.size() * sizeof(uint32_t));
    int indexView = view(iat, mScene.indices.size() * sizeof(uint32_t), 0, kElementArrayBuffer);
    for (size_t m = 0; m < mScene.meshes.size(); ++m) {
        const Mesh& mesh = mScene.meshes[m];
        if (mesh.primitiveCount == 0) {
            throw UserError("exportGlb: meshes[" + std::to_string(m) + "] '" + mesh.name +
                            "' has no primitives; glTF cannot store an empty mesh");
        }
        Json jm = {{"primitives", Json::array()}};
        if (!mesh.name.empty()) jm["name"] = mesh.name;
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            const Primitive& p = mScene.primitives[mesh.firstPrimitive + k];
            size_t base = size_t(p.vertexOffset) * sizeof(Vertex);
            const Material& material = mScene.materials[p.material];
            Json attributes = {
                {"COLOR_0", accessor(vertexView, base + offsetof(Vertex, color), kFloat, p.vertexCount, "VEC3")},
                {"_AO", accessor(vertexView, base + offsetof(Vertex, color) + 12, kFloat, p.vertexCount, "SCALAR")}};
            if (p.targetCount == 0 && !p.skinned) { // else POSITION and NORMAL are its base, see morphTargets()
                Aabb box;
                for (uint32_t v = 0; v < p.vertexCount; ++v)
                    box.expand(mScene.vertices[p.vertexOffset + v].position);
                int position = accessor(vertexView, base + offsetof(Vertex, position), kFloat, p.vertexCount, "VEC3");
                mDoc["accessors"][position]["min"] = vec(box.min);
                mDoc["accessors"][position]["max"] = vec(box.max);
                attributes["POSITION"] = position;
                attributes["NORMAL"] = accessor(vertexView, base + offsetof(Vertex, normal), kFloat, p.vertexCount, "VEC3");
            }
            // Only what the material uses (dropUnusedAttributes() says what the loader makes of the rest): tangents
            // for a normal map, TEXCOORD_0 for a texture that samples it.
            if (usesNormalMap(material))
                attributes["TANGENT"] = accessor(vertexView, base + offsetof(Vertex, tangent), kFloat, p.vertexCount, "VEC4");
            if (writesUv0(mScene, p))
                attributes["TEXCOORD_0"] = accessor(vertexView, base + offsetof(Vertex, uv0), kFloat, p.vertexCount, "VEC2");
            // TEXCOORD_1 is the lightmap parameterisation (or a UV set a material samples); without it the
            // loader marks the primitive as not lightmapped.
            if (writesUv1(mScene, p))
                attributes["TEXCOORD_1"] =
                    accessor(vertexView, base + offsetof(Vertex, uv1), kFloat, p.vertexCount, "VEC2");
            int indices = accessor(indexView, size_t(p.firstIndex) * 4, kUnsignedInt, p.indexCount, "SCALAR");
            Json jp = {{"attributes", attributes}, {"indices", indices}, {"material", p.material}, {"mode", 4}};
            if (p.targetCount > 0 || p.skinned) morphTargets(mesh.firstPrimitive + k, jp);
            jm["primitives"].push_back(jp);
        }
        if (!mesh.weights.empty()) jm["weights"] = mesh.weights;
        // The gap between its lightmap charts (TEXCOORD_1), so that the atlas keeps it wide after a round trip.
        if (mesh.lightmapChartGap > 0.0f) jm["extras"][gltf::kExtrasKey]["lightmapChartGap"] = mesh.lightmapChartGap;
        mDoc["meshes"].push_back(jm);
    }
}

// glTF morphs from the unmorphed base, the scene stores the rest pose (Mesh::weights applied): POSITION and NORMAL are
// written as the base (weights 0) in views of their own, then each target's displacements.
// A skinned primitive's base is its bind-space vertices, with JOINTS_0 (unsigned short) and WEIGHTS_0.
void Exporter::morphTargets(uint32_t primitive, Json& jp) {
    const Primitive& p = mScene.primitives[primitive];
    std::vector<Vertex> base(p.vertexCount);
    mScene.morphVertices(primitive, std::vector<float>(p.targetCount, 0.0f), base);
    if (p.skinned) {
        const Mesh* mesh = nullptr;
        for (const Mesh& m : mScene.meshes) {
            if (primitive >= m.firstPrimitive && primitive < m.firstPrimitive + m.primitiveCount) mesh = &m;
        }
        std::vector<uint16_t> joints;
        std::vector<float> weights;
        for (uint32_t v = 0; v < p.vertexCount; ++v) {
            const SkinVertex& sv = mScene.skinVertices[p.firstSkinVertex + v];
            glm::vec3 position = sv.position, normal = sv.normal;
            for (uint32_t t = 0; mesh && t < p.targetCount; ++t) { // bind space holds the rest morph weights
                const MorphDelta& d = mScene.morphDeltas[p.firstDelta + size_t(t) * p.vertexCount + v];
                position -= mesh->weights[t] * d.position;
                normal -= mesh->weights[t] * d.normal;
            }
            base[v].position = position;
            base[v].normal = glm::length(normal) > 0.0f ? glm::normalize(normal) : sv.normal;
            for (int k = 0; k < 4; ++k) {
                joints.push_back(static_cast<uint16_t>(sv.joints[k]));
                weights.push_back(sv.weights[k]);
            }
        }
        size_t at = append(joints.data(), joints.size() * sizeof(uint16_t));
        jp["attributes"]["JOINTS_0"] =
            accessor(view(at, joints.size() * sizeof(uint16_t), 0, kArrayBuffer), 0, 5123, p.vertexCount, "VEC4");
        jp["attributes"]["WEIGHTS_0"] = floats(weights, 4, "VEC4", false, kArrayBuffer);
    }
    std::vector<float> position, normal;
    for (const Vertex& v : base) {
        position.insert(position.end(), {v.position.x, v.position.y, v.position.z});
        normal.insert(normal.end(), {v.normal.x, v.normal.y, v.normal.z});
    }
    jp["attributes"]["POSITION"] = floats(position, 3, "VEC3", true, kArrayBuffer);
    jp["attributes"]["NORMAL"] = floats(normal, 3, "VEC3", false, kArrayBuffer);
    bool tangents = jp["attributes"].contains("TANGENT");
    for (uint32_t t = 0; t < p.targetCount; ++t) {
        const MorphDelta* d = mScene.morphDeltas.data() + p.firstDelta + size_t(t) * p.vertexCount;
        std::vector<float> dp, dn, dt;
        for (uint32_t v = 0; v < p.vertexCount; ++v) {
            dp.insert(dp.end(), {d[v].position.x, d[v].position.y, d[v].position.z});
            dn.insert(dn.end(), {d[v].normal.x, d[v].normal.y, d[v].normal.z});
            dt.insert(dt.end(), {d[v].tangent.x, d[v].tangent.y, d[v].tangent.z});
        }
        Json target = {{"POSITION", floats(dp, 3, "VEC3", true, kArrayBuffer)},
                       {"NORMAL", floats(dn, 3, "VEC3", false, kArrayBuffer)}};
        if (tangents) target["TANGENT"] = floats(dt, 3, "VEC3", false, kArrayBuffer);
        jp["targets"].push_back(target);
    }
}

void Exporter::images() {
    for (const TextureImage& image : mScene.images) {
        std::vector<uint8_t> png;
        auto write = [](void* context, void* data, int size) {
            auto* out = static_cast<std::vector<uint8_t>*>(context);
            out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
        };
        if (!stbi_write_png_to_func(write, &png, int(image.width), int(image.height), 4, image.pixels.data(),
                                    int(image.width) * 4)) {
            throw InternalError("exportGlb: PNG encoding of image '" + image.name + "' failed");
        }
        Json j = {{"mimeType", "image/png"}, {"bufferView", view(append(png.data(), png.size()), png.size())}};
        if (!image.name.empty()) j["name"] = image.name;
        mDoc["images"].push_back(j);
    }
    std::vector<Sampler> samplers;
    for (const Texture& t : mScene.textures) {
        size_t s = std::find(samplers.begin(), samplers.end(), t.sampler) - samplers.begin();
        if (s == samplers.size()) {
            samplers.push_back(t.sampler);
            mDoc["samplers"].push_back({{"magFilter", filterCode(t.sampler.magFilter)},
                                        {"minFilter", minFilterCode(t.sampler)},
                                        {"wrapS", wrapCode(t.sampler.wrapU)},
                                        {"wrapT", wrapCode(t.sampler.wrapV)}});
        }
        Json j = {{"source", t.image}, {"sampler", s}};
        if (!t.name.empty()) j["name"] = t.name;
        j["extras"][gltf::kExtrasKey]["usage"] = gltf::usageName(t.usage);
        mDoc["textures"].push_back(j);
    }
}

Json Exporter::material(const Material& m) const {
    using gltf::writeTextureInfo;
    Json j;
    if (!m.name.empty()) j["name"] = m.name;
    const MaterialLayer& base = m.layers.front();

    // The fallback for viewers without our extension: layer 0 in glTF's metallic-roughness terms.
    // glTF keeps factors in [0, 1]; our layers may brighten a dark texture with a factor above 1.
    // `core` is what the loader makes of the core material written here (readMetallicRoughness, the same float
    // operations): when it is the whole stack, VITRINE_material_layers is left out.
    MaterialLayer core;
    core.name = "base";
    core.albedo.factor = glm::clamp(base.albedo.factor, 0.0f, 1.0f);
    Json pbr = {{"baseColorFactor", vec(core.albedo.factor)}};
    if (base.albedo.texture.valid()) {
        pbr["baseColorTexture"] = writeTextureInfo(base.albedo.texture, base.albedo.texture.texture);
        core.albedo.texture = base.albedo.texture;
    }
    const ScalarParam& sh = base.shininess;
    const ScalarParam& me = base.metallic;
    bool packed = sh.texture.valid() && sh.texture == me.texture && sh.channel == 1 && sh.atZero == 1.0f &&
                  me.channel == 2 && me.atZero == 0.0f;
    float roughness, metallic;
    if (packed) {
        roughness = glm::clamp(1.0f - sh.factor, 0.0f, 1.0f);
        metallic = glm::clamp(me.factor, 0.0f, 1.0f);
        pbr["metallicRoughnessTexture"] = writeTextureInfo(sh.texture, sh.texture.texture);
        core.shininess.texture = core.metallic.texture = sh.texture;
        core.shininess.channel = 1;
        core.metallic.channel = 2;
    } else {
        // Textures that glTF cannot express become their average value.
        auto mean = [&](const ScalarParam& p) {
            return p.texture.valid() ? p.evaluate(channelMean(mScene, p.texture, p.channel)) : p.factor;
        };
        roughness = glm::clamp(1.0f - mean(sh), 0.0f, 1.0f);
        metallic = glm::clamp(mean(me), 0.0f, 1.0f);
    }
    pbr["roughnessFactor"] = roughness;
    pbr["metallicFactor"] = metallic;
    core.shininess.factor = 1.0f - roughness;
    core.shininess.atZero = 1.0f;
    core.metallic.factor = metallic;
    j["pbrMetallicRoughness"] = pbr;
    if (base.normal.texture.valid()) {
        j["normalTexture"] = writeTextureInfo(base.normal.texture, base.normal.texture.texture);
        j["normalTexture"]["scale"] = base.normal.scale;
        core.normal = base.normal;
    }
    if (base.cavity.texture.valid() && base.cavity.factor == 1.0f && base.cavity.channel == 0) {
        float strength = glm::clamp(1.0f - base.cavity.atZero, 0.0f, 1.0f);
        j["occlusionTexture"] = writeTextureInfo(base.cavity.texture, base.cavity.texture.texture);
        j["occlusionTexture"]["strength"] = strength;
        core.cavity = ScalarParam{1.0f, 1.0f - strength, {}, 0};
        core.cavity.texture = base.cavity.texture;
    }

    if (m.emissiveFactor != glm::vec3(0.0f)) j["emissiveFactor"] = vec(m.emissiveFactor); // [0,1]: strength is apart
    if (m.emissiveTexture.valid())
        j["emissiveTexture"] = writeTextureInfo(m.emissiveTexture, m.emissiveTexture.texture);
    if (m.emissiveStrength != 1.0f)
        j["extensions"][gltf::kEmissiveStrength] = {{"emissiveStrength", m.emissiveStrength}};
    if (m.alphaMode != AlphaMode::Opaque) j["alphaMode"] = m.alphaMode == AlphaMode::Mask ? "MASK" : "BLEND";
    if (m.alphaCutoff != 0.5f) j["alphaCutoff"] = m.alphaCutoff;
    if (m.doubleSided) j["doubleSided"] = true;
    if (m.unlit) j["extensions"][gltf::kUnlit] = Json::object();
    if (m.transmission != 0.0f) j["extensions"][gltf::kTransmission] = {{"transmissionFactor", m.transmission}};
    if (m.ior != 1.5f) j["extensions"][gltf::kIor] = {{"ior", m.ior}};
    if (m.hasSpecular()) {
        Json sp = {{"specularFactor", m.specular}, {"specularColorFactor", vec(m.specularColor)}};
        if (m.specularTexture.valid())
            sp["specularTexture"] = writeTextureInfo(m.specularTexture, m.specularTexture.texture);
        if (m.specularColorTexture.valid())
            sp["specularColorTexture"] = writeTextureInfo(m.specularColorTexture, m.specularColorTexture.texture);
        j["extensions"][gltf::kSpecular] = sp;
    }
    if (m.hasClearcoat()) {
        Json cc = {{"clearcoatFactor", m.clearcoat}, {"clearcoatRoughnessFactor", m.clearcoatRoughness}};
        if (m.clearcoatTexture.valid())
            cc["clearcoatTexture"] = writeTextureInfo(m.clearcoatTexture, m.clearcoatTexture.texture);
        if (m.clearcoatRoughnessTexture.valid()) {
            cc["clearcoatRoughnessTexture"] =
                writeTextureInfo(m.clearcoatRoughnessTexture, m.clearcoatRoughnessTexture.texture);
        }
        if (m.clearcoatNormal.texture.valid()) {
            cc["clearcoatNormalTexture"] =
                writeTextureInfo(m.clearcoatNormal.texture, m.clearcoatNormal.texture.texture);
            cc["clearcoatNormalTexture"]["scale"] = m.clearcoatNormal.scale;
        }
        j["extensions"][gltf::kClearcoat] = cc;
    }
    if (m.hasSheen()) {
        Json sh = {{"sheenColorFactor", {m.sheenColor.r, m.sheenColor.g, m.sheenColor.b}},
                   {"sheenRoughnessFactor", m.sheenRoughness}};
        if (m.sheenColorTexture.valid())
            sh["sheenColorTexture"] = writeTextureInfo(m.sheenColorTexture, m.sheenColorTexture.texture);
        if (m.sheenRoughnessTexture.valid())
            sh["sheenRoughnessTexture"] = writeTextureInfo(m.sheenRoughnessTexture, m.sheenRoughnessTexture.texture);
        j["extensions"][gltf::kSheen] = sh;
    }
    if (m.hasVolume()) {
        Json vo = {{"thicknessFactor", m.thickness},
                   {"attenuationColor", {m.attenuationColor.r, m.attenuationColor.g, m.attenuationColor.b}}};
        if (std::isfinite(m.attenuationDistance)) vo["attenuationDistance"] = m.attenuationDistance; // absent: +inf
        if (m.thicknessTexture.valid())
            vo["thicknessTexture"] = writeTextureInfo(m.thicknessTexture, m.thicknessTexture.texture);
        j["extensions"][gltf::kVolume] = vo;
    }

    if (m.layers.size() == 1 && base == core) return j; // the core material says it all

    auto scalar = [](const ScalarParam& p) {
        Json s = {{"factor", p.factor}, {"atZero", p.atZero}, {"channel", p.channel}};
        if (p.texture.valid()) s["texture"] = writeTextureInfo(p.texture, p.texture.texture);
        return s;
    };
    Json layers = Json::array();
    for (size_t i = 0; i < m.layers.size(); ++i) {
        const MaterialLayer& l = m.layers[i];
        Json jl;
        if (!l.name.empty()) jl["name"] = l.name;
        jl["albedo"] = {{"factor", vec(l.albedo.factor)}};
        if (l.albedo.texture.valid())
            jl["albedo"]["texture"] = writeTextureInfo(l.albedo.texture, l.albedo.texture.texture);
        jl["normal"] = {{"scale", l.normal.scale}};
        if (l.normal.texture.valid())
            jl["normal"]["texture"] = writeTextureInfo(l.normal.texture, l.normal.texture.texture);
        jl["shininess"] = scalar(l.shininess);
        jl["metallic"] = scalar(l.metallic);
        jl["cavity"] = scalar(l.cavity);
        if (l.overrides != kLayerAll) {
            Json names = Json::array();
            const char* kNames[] = {"albedo", "normal", "shininess", "metallic", "cavity"};
            for (int b = 0; b < 5; ++b) {
                if (l.overrides & (1u << b)) names.push_back(kNames[b]);
            }
            jl["overrides"] = names;
        }
        if (i > 0 || l.mask != LayerMask()) {
            jl["mask"] = {{"factor", l.mask.factor}, {"channel", l.mask.channel}};
            if (l.mask.texture.valid())
                jl["mask"]["texture"] = writeTextureInfo(l.mask.texture, l.mask.texture.texture);
        }
        layers.push_back(jl);
    }
    j["extensions"][kLayersExtension] = {{"layers", layers}};
    return j;
}

void Exporter::materials() {
    for (const Material& m : mScene.materials)
        mDoc["materials"].push_back(material(m));
}

void Exporter::cameras() {
    for (const Camera& c : mScene.cameras) {
        Json j;
        if (!c.name.empty()) j["name"] = c.name;
        if (c.projection == Projection::Orthographic) {
            j["type"] = "orthographic";
            j["orthographic"] = {{"xmag", c.xmag}, {"ymag", c.ymag}, {"znear", c.znear}, {"zfar", c.zfar}};
        } else {
            j["type"] = "perspective";
            j["perspective"] = {{"yfov", c.yfov}, {"znear", c.znear}};
            if (c.zfar > 0.0f) j["perspective"]["zfar"] = c.zfar;
            if (c.aspectRatio > 0.0f) j["perspective"]["aspectRatio"] = c.aspectRatio;
        }
        j["extras"][gltf::kExtrasKey] = {
            {"sensorWidthMm", c.sensorWidthMm},  {"sensorHeightMm", c.sensorHeightMm}, {"fNumber", c.fNumber},
            {"focusDistance", c.focusDistance},  {"shutterTime", c.shutterTime},       {"iso", c.iso},
            {"apertureBlades", c.apertureBlades}};
        mDoc["cameras"].push_back(j);
    }
}

void Exporter::nodesAndScene() {
    // KHR_lights_punctual: the sun is light 0 when there is one, the point and spot lights follow.
    std::vector<int> lightOf(mScene.nodes.size(), -1);
    Json lights = Json::array();
    if (mScene.hasSun) {
        const Sun& sun = mScene.sun;
        lights.push_back({{"name", "sun"}, {"type", "directional"}, {"color", vec(sun.color)}, {"intensity", sun.illuminance}});
    }
    for (const PunctualLight& l : mScene.lights) {
        if (lightOf[l.node] >= 0) throw UserError("scene '" + mScene.name + "': node " + std::to_string(l.node) +
                                                  " carries two lights; glTF allows one per node");
        lightOf[l.node] = static_cast<int>(lights.size());
        Json j = {{"type", l.type == LightType::Spot ? "spot" : "point"}, {"color", vec(l.color)}, {"intensity", l.intensity}};
        if (!l.name.empty()) j["name"] = l.name;
        if (l.range > 0.0f) j["range"] = l.range;
        if (l.type == LightType::Spot) j["spot"] = {{"innerConeAngle", l.innerConeAngle}, {"outerConeAngle", l.outerConeAngle}};
        lights.push_back(j);
    }
    if (!lights.empty()) mDoc["extensions"][gltf::kLightsPunctual]["lights"] = lights;
    for (size_t i = 0; i < mScene.nodes.size(); ++i) {
        const Node& n = mScene.nodes[i];
        Json j = Json::object();
        if (lightOf[i] >= 0) j["extensions"][gltf::kLightsPunctual] = {{"light", lightOf[i]}};
        if (!n.name.empty()) j["name"] = n.name;
        if (n.local.translation != glm::vec3(0.0f)) j["translation"] = vec(n.local.translation);
        if (n.local.rotation != glm::quat(1, 0, 0, 0)) j["rotation"] = vec(n.local.rotation);
        if (n.local.scale != glm::vec3(1.0f)) j["scale"] = vec(n.local.scale);
        if (!n.children.empty()) j["children"] = n.children;
        if (n.mesh >= 0) j["mesh"] = n.mesh;
        if (n.camera >= 0) j["camera"] = n.camera;
        if (n.skin >= 0) j["skin"] = n.skin;
        mDoc["nodes"].push_back(j);
    }
    Json roots = Json::array();
    if (mScene.roots.empty()) {
        std::vector<bool> child(mScene.nodes.size(), false);
        for (const Node& n : mScene.nodes) {
            for (uint32_t c : n.children)
                child[c] = true;
        }
        for (size_t i = 0; i < child.size(); ++i) {
            if (!child[i]) roots.push_back(i);
        }
    } else {
        roots = mScene.roots;
    }
    Json ours = Json::object();
    for (const CameraPath& path : mScene.cameraPaths) {
        // A camera node the path animates; viewers show it as an animated camera.
        Json j = {{"name", path.name},
                  {"camera", path.camera},
                  {"translation", vec(path.keys.front().position)},
                  {"rotation", vec(path.keys.front().orientation)}};
        j["extras"][gltf::kExtrasKey]["role"] = "cameraPath";
        roots.push_back(mDoc["nodes"].size());
        mDoc["nodes"].push_back(j);
        cameraPathAnimation(path, static_cast<int>(mDoc["nodes"].size()) - 1);
    }
    if (mScene.hasSun) {
        const Sun& sun = mScene.sun;
        // A directional light shines down its node's -Z: rotate +Z onto the direction towards the sun.
        glm::quat q = rotationBetween(glm::vec3(0, 0, 1), glm::normalize(sun.toSun));
        Json j = {{"name", "sun"}, {"rotation", vec(q)}};
        j["extensions"][gltf::kLightsPunctual] = {{"light", 0}};
        j["extras"][gltf::kExtrasKey]["role"] = "sun";
        roots.push_back(mDoc["nodes"].size());
        mDoc["nodes"].push_back(j);
        ours["sun"] = {{"toSun", vec(sun.toSun)},
                       {"color", vec(sun.color)},
                       {"illuminance", sun.illuminance},
                       {"angularDiameter", sun.angularDiameter}};
    }
    if (!mScene.rooms.empty()) {
        for (const Room& r : mScene.rooms) {
            ours["rooms"].push_back({{"name", r.name}, {"min", vec(r.bounds.min)}, {"max", vec(r.bounds.max)}});
        }
    }
    Json scene = Json::object();
    if (!roots.empty()) scene["nodes"] = roots; // glTF forbids an empty list
    if (!mScene.name.empty()) scene["name"] = mScene.name;
    if (!ours.empty()) scene["extras"][gltf::kExtrasKey] = ours;
    if (!mScene.probes.empty()) scene["extensions"][kProbesExtension] = {{"probes", probejson::write(mScene.probes)}};
    mDoc["scenes"] = Json::array({scene});
    mDoc["scene"] = 0;
}

void Exporter::skins() {
    for (const Skin& skin : mScene.skins) {
        std::vector<float> matrices;
        for (const glm::mat4& m : skin.inverseBind)
            for (int c = 0; c < 16; ++c)
                matrices.push_back(m[c / 4][c % 4]);
        Json j = {{"joints", skin.joints}, {"inverseBindMatrices", floats(matrices, 16, "MAT4", false)}};
        if (!skin.name.empty()) j["name"] = skin.name;
        mDoc["skins"].push_back(j);
    }
}

void Exporter::cameraPathAnimation(const CameraPath& path, int node) {
    std::vector<float> times, positions, rotations;
    Json fov = Json::array();
    // glTF's CUBICSPLINE needs two keys or more; one key is a still camera whichever way it is interpolated.
    bool cubic = path.smooth && path.keys.size() >= 2;
    for (size_t k = 0; k < path.keys.size(); ++k) {
        const CameraKey& key = path.keys[k];
        times.push_back(key.time);
        glm::vec3 tangent = path.tangent(k);
        if (cubic) positions.insert(positions.end(), {tangent.x, tangent.y, tangent.z});
        positions.insert(positions.end(), {key.position.x, key.position.y, key.position.z});
        if (cubic) positions.insert(positions.end(), {tangent.x, tangent.y, tangent.z});
        rotations.insert(rotations.end(), {key.orientation.x, key.orientation.y, key.orientation.z, key.orientation.w});
        fov.push_back(key.yfov);
    }
    int input = floats(times, 1, "SCALAR", true);
    Json samplers =
        Json::array({{{"input", input},
                      {"output", floats(positions, 3, "VEC3", false)},
                      {"interpolation", cubic ? "CUBICSPLINE" : "LINEAR"}},
                     {{"input", input}, {"output", floats(rotations, 4, "VEC4", false)}, {"interpolation", "LINEAR"}}});
    Json channels = Json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", "translation"}}}},
                                 {{"sampler", 1}, {"target", {{"node", node}, {"path", "rotation"}}}}});
    Json j = {{"name", path.name}, {"samplers", samplers}, {"channels", channels}};
    j["extras"][gltf::kExtrasKey]["cameraPath"] = {
        {"camera", path.camera}, {"smooth", path.smooth}, {"loop", path.loop}, {"yfov", fov}};
    mDoc["animations"].push_back(j);
}

void Exporter::animations() {
    for (size_t a = 0; a < mScene.animations.size(); ++a) {
        const Animation& anim = mScene.animations[a];
        Json samplers = Json::array();
        for (size_t s = 0; s < anim.samplers.size(); ++s) {
            const AnimationSampler& smp = anim.samplers[s];
            if (smp.times.empty()) {
                throw UserError("exportGlb: animations[" + std::to_string(a) + "].samplers[" + std::to_string(s) +
                                "] has no keys; glTF cannot store it");
            }
            bool rotation = true, weights = false;
            for (const AnimationChannel& c : anim.channels) {
                if (c.sampler == s) rotation = c.path == AnimationPath::Rotation, weights = c.path == AnimationPath::Weights;
            }
            // CUBICSPLINE needs two keys or more (glTF 2.0 §3.11); one key is a constant, written LINEAR.
            bool oneKeyCubic = smp.interpolation == Interpolation::CubicSpline && smp.times.size() < 2;
            std::vector<float> values;
            for (size_t i = oneKeyCubic ? smp.width : 0; i < (oneKeyCubic ? 2 * smp.width : smp.values.size()); ++i) {
                const glm::vec4& v = smp.values[i];
                values.insert(values.end(), {v.x, v.y, v.z, v.w});
            }
            if (weights) { // SCALAR on disk, `width` per key
                std::vector<float> x;
                for (size_t i = 0; i < values.size(); i += 4)
                    x.push_back(values[i]);
                values = x;
            } else if (!rotation) { // VEC3 on disk
                std::vector<float> xyz;
                for (size_t i = 0; i < values.size(); i += 4)
                    xyz.insert(xyz.end(), {values[i], values[i + 1], values[i + 2]});
                values = xyz;
            }
            const char* mode = smp.interpolation == Interpolation::Step                     ? "STEP"
                               : smp.interpolation == Interpolation::Linear || oneKeyCubic ? "LINEAR"
                                                                            : "CUBICSPLINE";
            samplers.push_back({{"input", floats(smp.times, 1, "SCALAR", true)},
                                {"output", weights    ? floats(values, 1, "SCALAR", false)
                                           : rotation ? floats(values, 4, "VEC4", false)
                                                      : floats(values, 3, "VEC3", false)},
                                {"interpolation", mode}});
        }
        Json channels = Json::array();
        for (const AnimationChannel& c : anim.channels) {
            const char* path = c.path == AnimationPath::Translation ? "translation"
                               : c.path == AnimationPath::Rotation  ? "rotation"
                               : c.path == AnimationPath::Scale     ? "scale"
                                                                    : "weights";
            channels.push_back({{"sampler", c.sampler}, {"target", {{"node", c.node}, {"path", path}}}});
        }
        Json j = {{"samplers", samplers}, {"channels", channels}};
        if (!anim.name.empty()) j["name"] = anim.name;
        if (anim.loop) j["extras"][gltf::kExtrasKey]["loop"] = true;
        mDoc["animations"].push_back(j);
    }
}

std::vector<uint8_t> Exporter::run() {
    mDoc["asset"] = {{"version", "2.0"}, {"generator", "vitrine exportGlb"}};
    meshes();
    images();
    materials();
    cameras();
    animations(); // before the camera-path animations that nodesAndScene() adds
    nodesAndScene();
    skins();

    Json used = Json::array();
    bool transforms = false, strength = false;
    for (const Material& m : mScene.materials)
        strength = strength || m.emissiveStrength != 1.0f;
    std::string text = mDoc.dump();
    if (text.find(kLayersExtension) != std::string::npos) used.push_back(kLayersExtension);
    transforms = text.find(gltf::kTextureTransform) != std::string::npos;
    if (transforms) used.push_back(gltf::kTextureTransform);
    if (strength) used.push_back(gltf::kEmissiveStrength);
    if (mScene.hasSun || !mScene.lights.empty()) used.push_back(gltf::kLightsPunctual);
    bool unlit = false, transmission = false, ior = false, specular = false, clearcoat = false, sheen = false,
         volume = false;
    for (const Material& m : mScene.materials) {
        specular = specular || m.hasSpecular();
        clearcoat = clearcoat || m.hasClearcoat();
        sheen = sheen || m.hasSheen();
        volume = volume || m.hasVolume();
        unlit = unlit || m.unlit;
        transmission = transmission || m.transmission != 0.0f;
        ior = ior || m.ior != 1.5f;
    }
    if (unlit) used.push_back(gltf::kUnlit);
    if (transmission) used.push_back(gltf::kTransmission);
    if (ior) used.push_back(gltf::kIor);
    if (specular) used.push_back(gltf::kSpecular);
    if (clearcoat) used.push_back(gltf::kClearcoat);
    if (sheen) used.push_back(gltf::kSheen);
    if (volume) used.push_back(gltf::kVolume);
    if (!mScene.probes.empty()) used.push_back(kProbesExtension);
    if (!used.empty()) mDoc["extensionsUsed"] = used; // glTF forbids an empty list
    while (mBin.size() % 4)
        mBin.push_back(0);
    if (!mBin.empty()) mDoc["buffers"] = Json::array({{{"byteLength", mBin.size()}}});

    text = mDoc.dump();
    while (text.size() % 4)
        text.push_back(' ');
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) {
        for (int i = 0; i < 4; ++i)
            out.push_back(static_cast<uint8_t>(v >> (8 * i)));
    };
    size_t total = 12 + 8 + text.size() + (mBin.empty() ? 0 : 8 + mBin.size());
    if (total > 0xffffffffull) throw UserError("exportGlb: the scene needs more than 4 GiB, which GLB cannot hold");
    out.reserve(total);
    u32(0x46546C67u); // "glTF"
    u32(2);
    u32(static_cast<uint32_t>(total));
    u32(static_cast<uint32_t>(text.size()));
    u32(0x4E4F534Au); // JSON
    out.insert(out.end(), text.begin(), text.end());
    if (!mBin.empty()) {
        u32(static_cast<uint32_t>(mBin.size()));
        u32(0x004E4942u); // BIN
        out.insert(out.end(), mBin.begin(), mBin.end());
    }
    return out;
}

} // namespace

void dropUnusedAttributes(Scene& scene) {
    for (const Primitive& p : scene.primitives) {
        const Material& material = scene.materials[p.material];
        std::span<Vertex> vertices(scene.vertices.data() + p.vertexOffset, p.vertexCount);
        if (!writesUv0(scene, p)) {
            for (Vertex& v : vertices)
                v.uv0 = glm::vec2(0.0f);
        }
        if (!usesNormalMap(material))
            generateTangents(vertices, std::span<const uint32_t>(scene.indices.data() + p.firstIndex, p.indexCount));
    }
}

void exportGlb(const Scene& scene, const std::filesystem::path& file) {
    scene.validate();
    std::vector<uint8_t> bytes = Exporter(scene).run();
    writeFileAtomically(file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

} // namespace vitrine::scene
