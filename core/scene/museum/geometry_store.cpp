// The museum's generated geometry as bytes, for the bake cache (MuseumOptions::loadGeometry / storeGeometry): what
// buildArchitecture, buildExhibits, buildDecor and buildRobot add to the scene (vertices, indices, primitives, meshes,
// nodes, animations), before Scene::finalize(). The format is this file's (its source is part of the cache key), so it
// has no version of its own; a payload that does not parse back exactly is refused and the geometry is built.
#include "core/scene/museum/geometry_store.hpp"

#include <cstring>
#include <type_traits>

namespace vitrine::scene::museum {

namespace {

constexpr uint32_t kMagic = 0x4F45474Du; // "MGEO"

class Writer {
public:
    template <typename T> void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        bytes.insert(bytes.end(), p, p + sizeof(T));
    }
    template <typename T> void array(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        value(static_cast<uint64_t>(v.size()));
        const auto* p = reinterpret_cast<const uint8_t*>(v.data());
        bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
    }
    void string(const std::string& s) {
        value(static_cast<uint64_t>(s.size()));
        bytes.insert(bytes.end(), s.begin(), s.end());
    }
    std::vector<uint8_t> bytes;
};

// Every read checks that the bytes hold it; a failed read leaves `ok` false and reads nothing more.
class Reader {
public:
    explicit Reader(std::span<const uint8_t> b) : mBytes(b) {}
    template <typename T> void value(T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        if (!take(sizeof(T))) return;
        std::memcpy(&v, mBytes.data() + mAt - sizeof(T), sizeof(T));
    }
    template <typename T> void array(std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        uint64_t n = 0;
        value(n);
        if (!ok || n > (mBytes.size() - mAt) / sizeof(T)) {
            ok = false;
            return;
        }
        v.resize(n);
        if (n) std::memcpy(v.data(), mBytes.data() + mAt, n * sizeof(T));
        mAt += n * sizeof(T);
    }
    void string(std::string& s) {
        uint64_t n = 0;
        value(n);
        if (!ok || !take(n)) {
            ok = false;
            return;
        }
        s.assign(reinterpret_cast<const char*>(mBytes.data() + mAt - n), n);
    }
    // A count of elements that each take at least `minBytes`: refused when the bytes cannot hold them.
    bool count(uint64_t& n, size_t minBytes) {
        value(n);
        if (ok && n > (mBytes.size() - mAt) / minBytes) ok = false;
        return ok;
    }
    bool atEnd() const { return ok && mAt == mBytes.size(); }
    bool ok = true;

private:
    bool take(size_t n) {
        if (!ok || n > mBytes.size() - mAt) return ok = false;
        mAt += n;
        return true;
    }
    std::span<const uint8_t> mBytes;
    size_t mAt = 0;
};

} // namespace

std::optional<std::vector<uint8_t>> serializeGeometry(const Scene& s) {
    // The museum has no skins or morph targets; a scene with them is not stored (the format has no place for them).
    if (!s.skins.empty() || !s.skinVertices.empty() || !s.morphDeltas.empty()) return std::nullopt;
    Writer w;
    w.value(kMagic);
    w.array(s.vertices);
    w.array(s.indices);
    w.array(s.primitives);
    w.value(static_cast<uint64_t>(s.meshes.size()));
    for (const Mesh& m : s.meshes) {
        w.string(m.name);
        w.value(m.firstPrimitive);
        w.value(m.primitiveCount);
        w.value(m.bounds);
        w.array(m.weights);
        w.value(m.lightmapChartGap);
    }
    w.value(static_cast<uint64_t>(s.nodes.size()));
    for (const Node& n : s.nodes) {
        w.string(n.name);
        w.value(n.local);
        w.value(n.parent);
        w.array(n.children);
        w.value(n.mesh);
        w.value(n.camera);
        w.value(n.skin);
        w.value(n.dynamic);
    }
    w.value(static_cast<uint64_t>(s.animations.size()));
    for (const Animation& a : s.animations) {
        w.string(a.name);
        w.value(static_cast<uint64_t>(a.samplers.size()));
        for (const AnimationSampler& sampler : a.samplers) {
            w.value(sampler.interpolation);
            w.array(sampler.times);
            w.array(sampler.values);
            w.value(sampler.width);
        }
        w.array(a.channels);
        w.value(a.loop);
    }
    return std::move(w.bytes);
}

bool deserializeGeometry(std::span<const uint8_t> bytes, Scene& s) {
    Reader r(bytes);
    uint32_t magic = 0;
    r.value(magic);
    if (!r.ok || magic != kMagic) return false;
    Scene g; // read aside, so that a refused payload leaves `s` as it was
    r.array(g.vertices);
    r.array(g.indices);
    r.array(g.primitives);
    uint64_t n = 0;
    if (!r.count(n, 8)) return false;
    g.meshes.resize(n);
    for (Mesh& m : g.meshes) {
        r.string(m.name);
        r.value(m.firstPrimitive);
        r.value(m.primitiveCount);
        r.value(m.bounds);
        r.array(m.weights);
        r.value(m.lightmapChartGap);
    }
    if (!r.count(n, 8)) return false;
    g.nodes.resize(n);
    for (Node& node : g.nodes) {
        r.string(node.name);
        r.value(node.local);
        r.value(node.parent);
        r.array(node.children);
        r.value(node.mesh);
        r.value(node.camera);
        r.value(node.skin);
        r.value(node.dynamic);
    }
    if (!r.count(n, 8)) return false;
    g.animations.resize(n);
    for (Animation& a : g.animations) {
        r.string(a.name);
        uint64_t samplers = 0;
        if (!r.count(samplers, 8)) return false;
        a.samplers.resize(samplers);
        for (AnimationSampler& sampler : a.samplers) {
            r.value(sampler.interpolation);
            r.array(sampler.times);
            r.array(sampler.values);
            r.value(sampler.width);
        }
        r.array(a.channels);
        r.value(a.loop);
    }
    if (!r.atEnd()) return false;
    s.vertices = std::move(g.vertices);
    s.indices = std::move(g.indices);
    s.primitives = std::move(g.primitives);
    s.meshes = std::move(g.meshes);
    s.nodes = std::move(g.nodes);
    s.animations = std::move(g.animations);
    return true;
}

} // namespace vitrine::scene::museum
