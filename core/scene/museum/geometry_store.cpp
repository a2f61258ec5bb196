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
    // The count of a list whose elements follow one by one.
    template <typename T> bool sequence(const std::vector<T>& v, size_t) {
        value(static_cast<uint64_t>(v.size()));
        return true;
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
    // The count of a list whose elements follow one by one, each taking at least `minBytes`: `v` is sized to it, or
    // the read fails when the bytes left cannot hold that many.
    template <typename T> bool sequence(std::vector<T>& v, size_t minBytes) {
        uint64_t n = 0;
        value(n);
        if (ok && n > (mBytes.size() - mAt) / minBytes) ok = false;
        if (ok) v.resize(n);
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

// One description of the format for both directions: IO is Writer (S = const Scene) or Reader (S = Scene). Every
// element of a list takes at least 8 bytes (a string's or an array's count).
template <typename IO, typename S> bool transferGeometry(IO& io, S& s) {
    io.array(s.vertices);
    io.array(s.indices);
    io.array(s.primitives);
    if (!io.sequence(s.meshes, 8)) return false;
    for (auto& m : s.meshes) {
        io.string(m.name);
        io.value(m.firstPrimitive);
        io.value(m.primitiveCount);
        io.value(m.bounds);
        io.array(m.weights);
        io.value(m.lightmapChartGap);
    }
    if (!io.sequence(s.nodes, 8)) return false;
    for (auto& node : s.nodes) {
        io.string(node.name);
        io.value(node.local);
        io.value(node.parent);
        io.array(node.children);
        io.value(node.mesh);
        io.value(node.camera);
        io.value(node.skin);
        io.value(node.dynamic);
    }
    if (!io.sequence(s.animations, 8)) return false;
    for (auto& a : s.animations) {
        io.string(a.name);
        if (!io.sequence(a.samplers, 8)) return false;
        for (auto& sampler : a.samplers) {
            io.value(sampler.interpolation);
            io.array(sampler.times);
            io.array(sampler.values);
            io.value(sampler.width);
        }
        io.array(a.channels);
        io.value(a.loop);
    }
    return true;
}

} // namespace

std::optional<std::vector<uint8_t>> serializeGeometry(const Scene& s) {
    // The museum has no skins or morph targets; a scene with them is not stored (the format has no place for them).
    if (!s.skins.empty() || !s.skinVertices.empty() || !s.morphDeltas.empty()) return std::nullopt;
    Writer w;
    w.value(kMagic);
    transferGeometry(w, s);
    return std::move(w.bytes);
}

bool deserializeGeometry(std::span<const uint8_t> bytes, Scene& s) {
    Reader r(bytes);
    uint32_t magic = 0;
    r.value(magic);
    if (!r.ok || magic != kMagic) return false;
    Scene g; // read aside, so that a refused payload leaves `s` as it was
    if (!transferGeometry(r, g)) return false;
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
