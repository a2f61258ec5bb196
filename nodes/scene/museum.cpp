// scene.museum: the built-in procedural museum (core/scene/museum), no asset files needed.
#include "core/graph/registry.hpp"
#include "core/scene/museum.hpp"
#include "nodes/scene/scene_node.hpp"

#include <map>
#include <mutex>

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

// Museums already built in this process (tests and the editor compile the same graph many times).
std::shared_ptr<const scene::Scene> museum(uint64_t seed, uint32_t size) {
    static std::mutex mutex;
    static std::map<std::pair<uint64_t, uint32_t>, std::weak_ptr<const scene::Scene>> cache;
    std::lock_guard lock(mutex);
    auto& slot = cache[{seed, size}];
    if (auto s = slot.lock()) return s;
    auto s = std::make_shared<const scene::Scene>(scene::buildMuseum({seed, size}));
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
