// scene.museum: the built-in procedural museum (core/scene/museum), no asset files needed.
#include "core/bake/cache.hpp"
#include "core/base/log.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/museum.hpp"
#include "core/shader/compiler.hpp"
#include "nodes/scene/scene_node.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <future>
#include <map>
#include <mutex>
#include <span>
#include <system_error>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "scene.museum";
    s.doc = "The procedural museum of MUSEUM_SPEC: a sunlit hall with polished stone, columns and arches, three "
            "galleries, exhibits spanning the material space, thin railings and a walking robot. Deterministic "
            "from its seed.";
    s.pass = PassKind::Transfer;
    s.params = {
        {"seed", ParamType::Int, 1, 0.0, 2147483647.0, {}, "Seed of textures, paintings, placement jitter and gait"},
        {"texture_size", ParamType::Int, 1024, 16.0, 4096.0, {}, "Edge of every procedural texture (power of two)"},
    };
    addSceneNodeSchema(s);
    for (auto& param : s.params)
        if (param.name == "camera") param.defaultValue = "walkthrough";
    return s;
}

// The procedural textures in the bake cache (kind "museum_textures"): a header (magic, count), then per image its
// name length, name, width, height and RGBA8 pixels. A payload that does not parse is ignored (they are generated).
constexpr uint32_t kTexturesMagic = 0x5854554du; // "MUTX"

std::vector<uint8_t> serializeTextures(const std::vector<scene::TextureImage>& images) {
    std::vector<uint8_t> out;
    auto put32 = [&](uint32_t v) {
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        out.insert(out.end(), p, p + 4);
    };
    put32(kTexturesMagic);
    put32(static_cast<uint32_t>(images.size()));
    for (const scene::TextureImage& image : images) {
        put32(static_cast<uint32_t>(image.name.size()));
        out.insert(out.end(), image.name.begin(), image.name.end());
        put32(image.width);
        put32(image.height);
        out.insert(out.end(), image.pixels.begin(), image.pixels.end());
    }
    return out;
}

// The images of a stored texture set. Their pixels are views of `bytes` (kept alive by `keepAlive`, the mapped cache
// file): nothing is copied into fresh memory (PixelBuffer).
std::optional<std::vector<scene::TextureImage>> deserializeTextures(std::span<const uint8_t> bytes,
                                                                    const std::shared_ptr<const void>& keepAlive) {
    size_t at = 0;
    auto get32 = [&](uint32_t& v) {
        if (bytes.size() - at < 4) return false;
        std::memcpy(&v, bytes.data() + at, 4);
        at += 4;
        return true;
    };
    uint32_t magic = 0, count = 0;
    if (!get32(magic) || magic != kTexturesMagic || !get32(count) || count > 1024) return std::nullopt;
    std::vector<scene::TextureImage> images(count);
    for (scene::TextureImage& image : images) {
        uint32_t length = 0;
        if (!get32(length) || bytes.size() - at < length) return std::nullopt;
        image.name.assign(reinterpret_cast<const char*>(bytes.data() + at), length);
        at += length;
        if (!get32(image.width) || !get32(image.height) || image.width > 16384 || image.height > 16384)
            return std::nullopt;
        const size_t n = static_cast<size_t>(image.width) * image.height * 4;
        if (bytes.size() - at < n) return std::nullopt;
        image.pixels = scene::PixelBuffer::view(bytes.subspan(at, n), keepAlive);
        at += n;
    }
    if (at != bytes.size()) return std::nullopt;
    return images;
}

// Museums already built in this process (tests and the editor compile the same graph many times).
std::shared_ptr<const scene::Scene> museum(uint64_t seed, uint32_t size) {
    static std::mutex mutex;
    static std::map<std::pair<uint64_t, uint32_t>, std::weak_ptr<const scene::Scene>> cache;
    std::lock_guard lock(mutex);
    auto& slot = cache[{seed, size}];
    if (auto s = slot.lock()) return s;
    scene::MuseumOptions options{seed, size, {}, {}};
    // The textures (about 90 % of the build) come from the bake cache when an earlier run made them. Their 64 MiB
    // are checked against their checksum on a second thread while this one builds the geometry; a damaged entry is
    // found before the scene is published, and the museum is then built again with fresh textures.
    const BakeCache bake(defaultCacheDir());
    const auto start = std::chrono::steady_clock::now();
    auto ms = [&] { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(); };
    bool loaded = false;
    std::future<bool> intact;
    options.loadTextures = [&](uint64_t key) -> std::optional<std::vector<scene::TextureImage>> {
        std::optional<BakeView> mapped = bake.mapUnverified(BakeKey{"museum_textures", key});
        const bool checkLater = mapped.has_value();
        if (!mapped) mapped = bake.map(BakeKey{"museum_textures", key}); // none, or the older format (checked here)
        if (!mapped) return std::nullopt;
        // The mapping lives as long as the last image viewing it (the scene, or a copy of an image).
        auto view = std::make_shared<const BakeView>(std::move(*mapped));
        if (checkLater) {
            try {
                intact = std::async(std::launch::async, [view] { return view->intact(); });
            } catch (const std::system_error&) { // no second thread: check here
                if (!view->intact()) return std::nullopt;
            }
        }
        auto images = deserializeTextures(view->bytes(), view);
        loaded = images.has_value();
        return images;
    };
    options.storeTextures = [&](uint64_t key, const std::vector<scene::TextureImage>& images) {
        if (!bake.put(BakeKey{"museum_textures", key}, serializeTextures(images)))
            logWarning("scene 'museum': could not store the procedural textures in the bake cache under " +
                       bake.dir().string());
    };
    // The geometry (most of the rest) comes from the bake cache too, mapped and checked (12 MiB).
    bool geometryLoaded = false;
    options.loadGeometry = [&](uint64_t key) -> std::optional<scene::StoredBytes> {
        std::optional<BakeView> mapped = bake.map(BakeKey{"museum_geometry", key});
        if (!mapped) return std::nullopt;
        auto view = std::make_shared<const BakeView>(std::move(*mapped));
        geometryLoaded = true;
        return scene::StoredBytes{view->bytes(), view};
    };
    options.storeGeometry = [&](uint64_t key, const std::vector<uint8_t>& bytes) {
        geometryLoaded = false;
        if (!bake.put(BakeKey{"museum_geometry", key}, bytes))
            logWarning("scene 'museum': could not store its geometry in the bake cache under " + bake.dir().string());
    };
    auto s = std::make_shared<const scene::Scene>(scene::buildMuseum(options));
    if (intact.valid() && !intact.get()) {
        logDebug(
            "scene 'museum': the procedural textures in the bake cache fail their checksum; generating them again");
        options.loadTextures = nullptr;
        loaded = false;
        s = std::make_shared<const scene::Scene>(scene::buildMuseum(options));
    }
    char line[200];
    std::snprintf(line, sizeof line, "scene 'museum': built in %.0f ms (procedural textures %s, geometry %s)", ms(),
                  loaded ? "loaded from the bake cache" : "generated and stored in the bake cache",
                  geometryLoaded ? "loaded from the bake cache" : "generated and stored in the bake cache");
    logDebug(line);
    slot = s;
    return s;
}

class Museum final : public SceneNode {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        int size = p.getInt("texture_size");
        if (size & (size - 1)) ctx.failParam("texture_size", "expected a power of two, got " + std::to_string(size));
        publish(ctx, museum(static_cast<uint64_t>(p.getInt("seed")), static_cast<uint32_t>(size)));
    }
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Museum>(); });

} // namespace
} // namespace vitrine
