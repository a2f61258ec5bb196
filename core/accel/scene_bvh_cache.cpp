// SceneBvh in the bake cache: the byte format and the cache key.
#include "core/accel/scene_bvh.hpp"

#include "core/scene/hash.hpp"

#include <cstring>
#include <type_traits>

namespace vitrine::accel {

namespace {

constexpr char kMagic[4] = {'V', 'B', 'V', 'H'};

struct Header {
    char magic[4];
    uint32_t version;
    uint64_t sceneHash;
    uint32_t bins, maxLeafSize;
    float traversalCost;
    uint32_t maxDepth;
    uint32_t nodes, triangles, refs, primitives, levels, dynamics;
    uint32_t transparent, reserved;
};
static_assert(sizeof(Header) == 64);

template <typename T> void append(std::vector<uint8_t>& out, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(v.data());
    out.insert(out.end(), p, p + v.size() * sizeof(T));
}

// Reads n elements at offset; false when the bytes run out.
template <typename T> bool take(std::span<const uint8_t> bytes, size_t& offset, uint32_t n, std::vector<T>& v) {
    const size_t size = static_cast<size_t>(n) * sizeof(T);
    if (bytes.size() - offset < size) return false;
    v.resize(n);
    if (size) std::memcpy(v.data(), bytes.data() + offset, size);
    offset += size;
    return true;
}

} // namespace

BakeKey SceneBvh::cacheKey(const scene::Scene& scene, const BvhBuildOptions& options) {
    scene::Hasher h;
    h.string("scene_bvh");
    h.value(kVersion);
    h.value(scene.contentHash());
    h.value(options.bins);
    h.value(options.maxLeafSize);
    h.value(options.traversalCost);
    h.value(options.maxDepth);
    h.value(options.transparent);
    return {"bvh", h.result()};
}

std::vector<uint8_t> SceneBvh::serialize() const {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kVersion;
    h.sceneHash = mSceneHash;
    h.bins = mOptions.bins;
    h.maxLeafSize = mOptions.maxLeafSize;
    h.traversalCost = mOptions.traversalCost;
    h.maxDepth = mOptions.maxDepth;
    h.transparent = mOptions.transparent ? 1u : 0u;
    h.nodes = static_cast<uint32_t>(mArrays.nodes.size());
    h.triangles = static_cast<uint32_t>(mArrays.triangles.size());
    h.refs = static_cast<uint32_t>(mArrays.refs.size());
    h.primitives = static_cast<uint32_t>(mPrimitives.size());
    h.levels = static_cast<uint32_t>(mLevels.size());
    h.dynamics = static_cast<uint32_t>(mDynamic.size());
    std::vector<uint8_t> out(sizeof h);
    std::memcpy(out.data(), &h, sizeof h);
    append(out, mArrays.nodes);
    append(out, mArrays.triangles);
    append(out, mArrays.refs);
    append(out, mPrimitives);
    append(out, mLevels);
    append(out, mDynamic);
    return out;
}

std::optional<SceneBvh> SceneBvh::deserialize(std::span<const uint8_t> bytes) {
    Header h{};
    if (bytes.size() < sizeof h) return std::nullopt;
    std::memcpy(&h, bytes.data(), sizeof h);
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.version != kVersion) return std::nullopt;
    SceneBvh bvh;
    bvh.mSceneHash = h.sceneHash;
    bvh.mOptions = {h.bins, h.maxLeafSize, h.traversalCost, h.maxDepth, h.transparent != 0u};
    size_t offset = sizeof h;
    if (!take(bytes, offset, h.nodes, bvh.mArrays.nodes) || !take(bytes, offset, h.triangles, bvh.mArrays.triangles) ||
        !take(bytes, offset, h.refs, bvh.mArrays.refs) || !take(bytes, offset, h.primitives, bvh.mPrimitives) ||
        !take(bytes, offset, h.levels, bvh.mLevels) || !take(bytes, offset, h.dynamics, bvh.mDynamic) ||
        offset != bytes.size())
        return std::nullopt;
    // What traversal relies on: links inside the arrays and trees within the stack.
    if (bvh.mLevels.empty() || h.refs != h.triangles) return std::nullopt;
    for (const BvhBottomLevel& l : bvh.mLevels)
        if (l.root >= h.nodes || l.depth > kMaxDepth || l.firstTriangle + l.triangleCount > h.triangles)
            return std::nullopt;
    for (const BvhDynamicInstance& d : bvh.mDynamic)
        if (d.level >= h.levels) return std::nullopt;
    for (const GpuBvhNode& n : bvh.mArrays.nodes)
        for (int c = 0; c < 2; ++c) {
            BvhChild child = childOf(n, c);
            if (child.absent()) continue;
            if (child.leaf() ? uint64_t(child.link) + child.count > h.triangles : child.link >= h.nodes)
                return std::nullopt;
        }
    return bvh;
}

SceneBvh SceneBvh::loadOrBuild(const scene::Scene& scene, const BakeCache& cache, const BvhBuildOptions& options,
                               CacheStatus* status) {
    CacheStatus local;
    CacheStatus& st = status ? *status : local;
    st = {};
    const BakeKey key = cacheKey(scene, options);
    if (auto bytes = cache.get(key)) {
        if (std::optional<SceneBvh> bvh = deserialize(*bytes);
            bvh && bvh->mSceneHash == scene.contentHash() && bvh->mOptions == options) {
            st.fromCache = true;
            bvh->mPrimitives = primitivesOf(scene);
            bvh->mDeformedLevels = deformedLevelsOf(scene, bvh->mDynamic);
            return std::move(*bvh);
        }
    }
    SceneBvh bvh = build(scene, options);
    st.stored = cache.put(key, bvh.serialize());
    return bvh;
}

} // namespace vitrine::accel
