// Scene::contentHash() and Scene::validate(): the two whole-scene walks.

#include "core/scene/hash.hpp"
#include "core/scene/probes.hpp"
#include "core/scene/scene.hpp"

#include "core/base/error.hpp"

#include <algorithm>
#include <string>

namespace vitrine::scene {

namespace {

void hashRef(Hasher& h, const TextureRef& r) {
    h.value(r.texture);
    h.value(r.uvSet);
    h.value(r.transform.offset);
    h.value(r.transform.scale);
    h.value(r.transform.rotation);
}

void hashScalar(Hasher& h, const ScalarParam& p) {
    h.value(p.factor);
    h.value(p.atZero);
    h.value(p.channel);
    hashRef(h, p.texture);
}

void hashMaterial(Hasher& h, const Material& m) {
    h.string(m.name);
    h.value(m.layers.size());
    for (const MaterialLayer& l : m.layers) {
        h.string(l.name);
        h.value(l.albedo.factor);
        hashRef(h, l.albedo.texture);
        h.value(l.normal.scale);
        hashRef(h, l.normal.texture);
        hashScalar(h, l.shininess);
        hashScalar(h, l.metallic);
        hashScalar(h, l.cavity);
        h.value(l.overrides);
        h.value(l.mask.factor);
        h.value(l.mask.channel);
        hashRef(h, l.mask.texture);
    }
    h.value(m.emissiveFactor);
    h.value(m.emissiveStrength);
    hashRef(h, m.emissiveTexture);
    h.value(m.alphaMode);
    h.value(m.alphaCutoff);
    h.value(m.doubleSided);
    // Hashed only when set, so that the keys of scenes without them (bake caches) did not change.
    if (m.unlit || m.transmission != 0.0f || m.ior != 1.5f) {
        h.value(m.unlit);
        h.value(m.transmission);
        h.value(m.ior);
    }
    if (m.hasSpecular()) {
        h.value(m.specular);
        hashRef(h, m.specularTexture);
        h.value(m.specularColor);
        hashRef(h, m.specularColorTexture);
    }
    if (m.hasClearcoat()) {
        h.value(m.clearcoat);
        hashRef(h, m.clearcoatTexture);
        h.value(m.clearcoatRoughness);
        hashRef(h, m.clearcoatRoughnessTexture);
        h.value(m.clearcoatNormal.scale);
        hashRef(h, m.clearcoatNormal.texture);
    }
    if (m.hasSheen()) {
        h.value(m.sheenColor);
        hashRef(h, m.sheenColorTexture);
        h.value(m.sheenRoughness);
        hashRef(h, m.sheenRoughnessTexture);
    }
    if (m.hasVolume()) {
        h.value(m.thickness);
        hashRef(h, m.thicknessTexture);
        h.value(m.attenuationDistance);
        h.value(m.attenuationColor);
    }
}

void hashCamera(Hasher& h, const Camera& c) {
    h.string(c.name);
    h.value(c.projection);
    for (float v : {c.yfov, c.aspectRatio, c.znear, c.zfar, c.xmag, c.ymag, c.sensorWidthMm, c.sensorHeightMm,
                    c.fNumber, c.focusDistance, c.shutterTime, c.iso}) {
        h.value(v);
    }
    h.value(c.apertureBlades);
}

} // namespace

bool usesUvSet(const Material& m, uint32_t uvSet) {
    auto uses = [&](const TextureRef& r) { return r.valid() && r.uvSet == uvSet; };
    for (const MaterialLayer& l : m.layers) {
        if (uses(l.albedo.texture) || uses(l.normal.texture) || uses(l.shininess.texture) || uses(l.metallic.texture) ||
            uses(l.cavity.texture) || uses(l.mask.texture)) {
            return true;
        }
    }
    return uses(m.emissiveTexture) || uses(m.specularTexture) || uses(m.specularColorTexture) ||
           uses(m.clearcoatTexture) || uses(m.clearcoatRoughnessTexture) || uses(m.clearcoatNormal.texture) ||
           uses(m.sheenColorTexture) || uses(m.sheenRoughnessTexture) || uses(m.thicknessTexture);
}

bool usesNormalMap(const Material& m) {
    return m.clearcoatNormal.texture.valid() ||
           std::any_of(m.layers.begin(), m.layers.end(),
                       [](const MaterialLayer& l) { return l.normal.texture.valid(); });
}

uint64_t Scene::contentHash() const {
    return hashContent(true, true);
}

uint64_t Scene::lightTransportHash() const {
    return hashContent(false, false);
}

uint64_t Scene::lightmapHash() const {
    return hashContent(false, true);
}

uint64_t Scene::hashContent(bool withProbes, bool withLightmapUvs) const {
    Hasher h;
    h.string(name);
    if (withLightmapUvs) {
        h.array(vertices);
    } else { // uv1 as (0, 0) wherever no material samples texture set 1
        std::vector<Vertex> transport = vertices;
        for (const Primitive& p : primitives) {
            if (p.material < materials.size() && usesUvSet(materials[p.material], 1)) continue;
            for (uint32_t v = 0; v < p.vertexCount && p.vertexOffset + v < transport.size(); ++v)
                transport[p.vertexOffset + v].uv1 = glm::vec2(0.0f);
        }
        h.array(transport);
    }
    h.array(indices);
    h.value(primitives.size());
    for (const Primitive& p : primitives) {
        for (uint32_t v : {p.firstIndex, p.indexCount, p.vertexOffset, p.vertexCount, p.material,
                           static_cast<uint32_t>(p.lightmapUvs)})
            h.value(v);
    }
    h.value(meshes.size());
    for (const Mesh& m : meshes) {
        h.string(m.name);
        h.value(m.firstPrimitive);
        h.value(m.primitiveCount);
        if (withLightmapUvs && m.lightmapChartGap != 0.0f) h.value(m.lightmapChartGap); // absent before: hashes stay
    }
    h.value(materials.size());
    for (const Material& m : materials)
        hashMaterial(h, m);
    h.value(textures.size());
    for (const Texture& t : textures) {
        h.string(t.name);
        h.value(t.image);
        h.value(t.sampler);
        h.value(t.usage);
    }
    h.value(images.size());
    for (const TextureImage& image : images) {
        h.string(image.name);
        h.value(image.width);
        h.value(image.height);
        h.array(image.pixels);
    }
    h.value(nodes.size());
    for (const Node& n : nodes) {
        h.string(n.name);
        h.value(n.local.translation);
        h.value(n.local.rotation);
        h.value(n.local.scale);
        h.array(n.children);
        h.value(n.mesh);
        h.value(n.camera);
    }
    h.array(roots);
    h.value(cameras.size());
    for (const Camera& c : cameras)
        hashCamera(h, c);
    h.value(cameraPaths.size());
    for (const CameraPath& p : cameraPaths) {
        h.string(p.name);
        h.value(p.camera);
        h.value(p.smooth);
        h.value(p.loop);
        h.array(p.keys);
    }
    h.value(animations.size());
    for (const Animation& a : animations) {
        h.string(a.name);
        h.value(a.loop);
        h.value(a.samplers.size());
        for (const AnimationSampler& s : a.samplers) {
            h.value(s.interpolation);
            h.array(s.times);
            h.array(s.values);
            if (s.width != 1) h.value(s.width); // morph weights; absent before, so older hashes stay
        }
        h.value(a.channels.size());
        for (const AnimationChannel& ch : a.channels) {
            h.value(ch.node); // field by field: the struct has padding bytes
            h.value(ch.path);
            h.value(ch.sampler);
        }
    }
    if (!morphDeltas.empty()) { // only with morph targets, so the hashes of scenes without stay what they were
        h.array(morphDeltas);
        for (const Primitive& p : primitives) {
            h.value(p.firstDelta);
            h.value(p.targetCount);
        }
        for (const Mesh& m : meshes)
            h.array(m.weights);
    }
    if (!skins.empty()) { // only with skins, so the hashes of scenes without stay what they were
        h.array(skinVertices);
        for (const Primitive& p : primitives) {
            h.value(static_cast<uint32_t>(p.skinned));
            h.value(p.firstSkinVertex);
        }
        for (const Skin& skin : skins) {
            h.string(skin.name);
            h.array(skin.joints);
            h.array(skin.inverseBind);
        }
        for (const Node& n : nodes)
            h.value(n.skin);
    }
    h.value(hasSun);
    if (hasSun) h.value(sun);
    if (!lights.empty()) {
        h.value(lights.size());
        for (const PunctualLight& l : lights) {
            h.string(l.name);
            h.value(l.type);
            h.value(l.color);
            for (float v : {l.intensity, l.range, l.innerConeAngle, l.outerConeAngle})
                h.value(v);
            h.value(l.node);
        }
    }
    h.value(rooms.size());
    for (const Room& r : rooms) {
        h.string(r.name);
        h.value(r.bounds);
    }
    if (withProbes && !probes.empty()) { // hashed only when present, so scenes without probes keep their hashes
        h.value(probes.size());
        for (const ReflectionProbe& p : probes) {
            h.string(p.name);
            h.value(p.position);
            h.value(p.shape);
            h.value(p.center);
            h.value(p.halfExtents);
            h.value(p.rotation);
            h.value(p.fade);
            h.value(p.priority);
            if (p.hasProjection()) { // hashed only when set, so probes without a proxy keep their hashes
                h.value(p.projectionCenter);
                h.value(p.projectionHalfExtents);
            }
        }
    }
    return h.result();
}

namespace {

class Checker {
public:
    explicit Checker(const Scene& scene) : mScene(scene) {}

    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw InternalError("scene '" + mScene.name + "': " + element + ": " + what);
    }
    void index(const std::string& element, int64_t value, size_t count, const char* what) const {
        if (value < 0 || static_cast<size_t>(value) >= count) {
            fail(element,
                 "index " + std::to_string(value) + " out of range (" + std::to_string(count) + " " + what + ")");
        }
    }
    void ref(const std::string& element, const TextureRef& r, TextureUsage usage, uint32_t channel = 0) const {
        if (!r.valid()) return;
        index(element + ".texture", r.texture, mScene.textures.size(), "textures");
        if (r.uvSet > 1) fail(element + ".uvSet", "expected 0 or 1, got " + std::to_string(r.uvSet));
        TextureUsage actual = mScene.textures[r.texture].usage;
        // Alpha is never sRGB-encoded, so data may come from a colour texture's alpha channel.
        bool ok = actual == usage || (usage == TextureUsage::Data && actual == TextureUsage::Color && channel == 3);
        if (!ok) fail(element, "textures[" + std::to_string(r.texture) + "] has the wrong usage (colour space)");
    }
    void scalar(const std::string& element, const ScalarParam& p) const {
        if (p.channel > 3) fail(element + ".channel", "expected 0..3");
        ref(element, p.texture, TextureUsage::Data, p.channel);
    }

private:
    const Scene& mScene;
};

} // namespace

void Scene::validate() const {
    Checker c(*this);
    for (size_t i = 0; i < primitives.size(); ++i) {
        const Primitive& p = primitives[i];
        std::string e = "primitives[" + std::to_string(i) + "]";
        if (uint64_t(p.firstIndex) + p.indexCount > indices.size() || p.indexCount % 3 != 0) {
            c.fail(e, "index range is outside the index buffer or not whole triangles");
        }
        if (uint64_t(p.vertexOffset) + p.vertexCount > vertices.size()) c.fail(e, "vertex range is outside");
        c.index(e + ".material", p.material, materials.size(), "materials");
        for (uint32_t k = 0; k < p.indexCount; ++k) {
            if (indices[p.firstIndex + k] >= p.vertexCount) c.fail(e, "an index exceeds the vertex range");
        }
        if (uint64_t(p.firstDelta) + uint64_t(p.targetCount) * p.vertexCount > morphDeltas.size())
            c.fail(e, "morph target range is outside morphDeltas");
        if (p.skinned && uint64_t(p.firstSkinVertex) + p.vertexCount > skinVertices.size())
            c.fail(e, "skinned vertex range is outside skinVertices");
    }
    for (size_t i = 0; i < meshes.size(); ++i) {
        if (uint64_t(meshes[i].firstPrimitive) + meshes[i].primitiveCount > primitives.size()) {
            c.fail("meshes[" + std::to_string(i) + "]", "primitive range is outside");
        }
        for (uint32_t k = 0; k < meshes[i].primitiveCount && meshes[i].firstPrimitive + k < primitives.size(); ++k) {
            if (primitives[meshes[i].firstPrimitive + k].targetCount != meshes[i].weights.size())
                c.fail("meshes[" + std::to_string(i) + "]", "a primitive's morph target count differs from weights");
        }
    }
    for (size_t i = 0; i < images.size(); ++i) {
        if (images[i].pixels.size() != size_t(images[i].width) * images[i].height * 4) {
            c.fail("images[" + std::to_string(i) + "]", "pixel count does not match width × height × 4");
        }
    }
    for (size_t i = 0; i < textures.size(); ++i) {
        c.index("textures[" + std::to_string(i) + "].image", textures[i].image, images.size(), "images");
    }
    for (size_t i = 0; i < materials.size(); ++i) {
        const Material& m = materials[i];
        std::string e = "materials[" + std::to_string(i) + "]";
        if (m.layers.empty()) c.fail(e, "has no layers");
        for (size_t l = 0; l < m.layers.size(); ++l) {
            const MaterialLayer& layer = m.layers[l];
            std::string le = e + ".layers[" + std::to_string(l) + "]";
            c.ref(le + ".albedo", layer.albedo.texture, TextureUsage::Color);
            c.ref(le + ".normal", layer.normal.texture, TextureUsage::Normal);
            c.scalar(le + ".shininess", layer.shininess);
            c.scalar(le + ".metallic", layer.metallic);
            c.scalar(le + ".cavity", layer.cavity);
            if (layer.mask.channel > 3) c.fail(le + ".mask.channel", "expected 0..3");
            c.ref(le + ".mask", layer.mask.texture, TextureUsage::Data, layer.mask.channel);
            if ((layer.overrides & ~uint32_t(kLayerAll)) != 0) c.fail(le + ".overrides", "unknown bits");
        }
        c.ref(e + ".emissiveTexture", m.emissiveTexture, TextureUsage::Color);
        c.ref(e + ".specularTexture", m.specularTexture, TextureUsage::Data, 3);
        c.ref(e + ".specularColorTexture", m.specularColorTexture, TextureUsage::Color);
        c.ref(e + ".clearcoatTexture", m.clearcoatTexture, TextureUsage::Data, 0);
        c.ref(e + ".clearcoatRoughnessTexture", m.clearcoatRoughnessTexture, TextureUsage::Data, 1);
        c.ref(e + ".clearcoatNormal", m.clearcoatNormal.texture, TextureUsage::Normal);
        c.ref(e + ".sheenColorTexture", m.sheenColorTexture, TextureUsage::Color);
        c.ref(e + ".sheenRoughnessTexture", m.sheenRoughnessTexture, TextureUsage::Data, 3);
        c.ref(e + ".thicknessTexture", m.thicknessTexture, TextureUsage::Data, 1);
    }
    for (size_t i = 0; i < nodes.size(); ++i) {
        const Node& n = nodes[i];
        std::string e = "nodes[" + std::to_string(i) + "]";
        if (n.mesh >= 0) c.index(e + ".mesh", n.mesh, meshes.size(), "meshes");
        if (n.skin >= 0) c.index(e + ".skin", n.skin, skins.size(), "skins");
        if (n.camera >= 0) c.index(e + ".camera", n.camera, cameras.size(), "cameras");
        for (uint32_t child : n.children)
            c.index(e + ".children", child, nodes.size(), "nodes");
    }
    for (uint32_t r : roots)
        c.index("roots", r, nodes.size(), "nodes");
    for (size_t i = 0; i < lights.size(); ++i)
        c.index("lights[" + std::to_string(i) + "].node", lights[i].node, nodes.size(), "nodes");
    for (size_t i = 0; i < probes.size(); ++i) {
        const ReflectionProbe& p = probes[i];
        std::string e = "probes[" + std::to_string(i) + "] '" + p.name + "'";
        if (!(p.halfExtents.x > 0.0f) || (p.shape == ProbeShape::Box && !(p.halfExtents.y > 0.0f && p.halfExtents.z > 0.0f)))
            c.fail(e, "influence volume has no extent");
        if (!(p.fade >= 0.0f)) c.fail(e, "fade is negative");
        if (p.hasProjection()) {
            if (p.shape != ProbeShape::Box) c.fail(e, "has a projection box but is a sphere (its proxy is the sphere)");
            if (!(p.projectionHalfExtents.x > 0.0f && p.projectionHalfExtents.y > 0.0f &&
                  p.projectionHalfExtents.z > 0.0f))
                c.fail(e, "projection box has no extent");
            else if (projectionDepth(p, p.position) < -1e-3f)
                c.fail(e, "capture point lies outside its projection box");
        }
    }
    for (size_t i = 0; i < cameraPaths.size(); ++i) {
        const CameraPath& p = cameraPaths[i];
        std::string e = "cameraPaths[" + std::to_string(i) + "] '" + p.name + "'";
        c.index(e + ".camera", p.camera, cameras.size(), "cameras");
        if (p.keys.empty()) c.fail(e, "has no keys");
        for (size_t k = 1; k < p.keys.size(); ++k) {
            if (p.keys[k].time < p.keys[k - 1].time) c.fail(e, "key times decrease");
        }
    }
    for (size_t i = 0; i < skins.size(); ++i) {
        for (uint32_t j : skins[i].joints)
            c.index("skins[" + std::to_string(i) + "].joints", j, nodes.size(), "nodes");
    }
    for (size_t i = 0; i < animations.size(); ++i) {
        const Animation& a = animations[i];
        std::string e = "animations[" + std::to_string(i) + "]";
        for (size_t s = 0; s < a.samplers.size(); ++s) {
            const AnimationSampler& smp = a.samplers[s];
            size_t per = (smp.interpolation == Interpolation::CubicSpline ? 3 : 1) * size_t(smp.width);
            if (smp.values.size() != smp.times.size() * per) {
                c.fail(e + ".samplers[" + std::to_string(s) + "]", "value count does not match the key count");
            }
        }
        for (size_t ch = 0; ch < a.channels.size(); ++ch) {
            std::string ce = e + ".channels[" + std::to_string(ch) + "]";
            c.index(ce + ".node", a.channels[ch].node, nodes.size(), "nodes");
            c.index(ce + ".sampler", a.channels[ch].sampler, a.samplers.size(), "samplers");
        }
    }
}

} // namespace vitrine::scene
