// The executor on a real device: aliased transients stay correct, memory is actually shared,
// timestamps are produced, and multi-frame runs are repeatable.
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/descriptor_pools.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/shader/compiler.hpp"

namespace vitrine::test {
namespace {

using nlohmann::json;

class ExecutorGpu : public GpuTest {};

json chain() {
    // Exposure steps that cancel out: the output must equal the source, while the four
    // intermediate textures have disjoint lifetimes and can share memory.
    json nodes = {{"src", {{"type", "pattern.checker"}, {"params", {{"supersample", 2}, {"cell_size", 3.0}}}}}};
    std::string prev = "src";
    const double ev[] = {1.0, -2.0, 0.5, 0.5};
    for (int i = 0; i < 4; ++i) {
        std::string id = "t" + std::to_string(i);
        nodes[id] = {{"type", "post.tonemap"},
                     {"params", {{"operator", "linear"}, {"exposure", ev[i]}}},
                     {"in", {{"color", prev + ".color"}}}};
        prev = id;
    }
    nodes["copy"] = {{"type", "post.tonemap"}, {"params", {{"operator", "linear"}}}, {"in", {{"color", "src.color"}}}};
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", 64}, {"height", 48}, {"frames", 3}}},
            {"nodes", nodes},
            {"outputs", {{"chain", prev + ".color"}, {"reference", "copy.color"}}}};
}

TEST_F(ExecutorGpu, AliasedChainMatchesDirectPathAndSharesMemory) {
    CompiledGraph graph = compileGraph(validateGraph(chain(), "chain.json", NodeRegistry::global()));
    ShaderCompiler shaders;
    Executor executor(gpu(), graph, shaders);
    std::map<std::string, Image> out;
    RunOptions options;
    options.progress = false;
    options.onOutput = [&](uint32_t, const std::string& name, const Image& image) { out[name] = image; };
    executor.run(options);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_LT(maxAbsDiff(out["chain"], out["reference"]), 1e-6);
    // src, t0, t1, t2 are transient; t0 and t2 (and src and t1...) never live at once.
    EXPECT_LT(executor.memory().transientAliased, executor.memory().transientUnaliased);
    ASSERT_EQ(executor.timings().size(), 3u);
    for (const auto& t : executor.timings()) {
        ASSERT_EQ(t.passGpuMs.size(), graph.passes.size());
        for (double ms : t.passGpuMs) EXPECT_GE(ms, 0.0);
    }
}

TEST_F(ExecutorGpu, RunsAreRepeatable) {
    auto a = runGraph(chain());
    auto b = runGraph(chain());
    EXPECT_EQ(maxAbsDiff(a["chain"], b["chain"]), 0.0);
}

// The NVIDIA driver refuses a descriptor set past a pool's sizes (VK_ERROR_OUT_OF_POOL_MEMORY: render.pathtrace
// converging for hundreds of batches in one frame on an H200); lavapipe never does. The pools count for themselves and
// move on to the next pool at the same point on every device, and a reset makes all of them available again.
TEST_F(ExecutorGpu, DescriptorPoolsMoveToTheNextPoolBeforeOneIsFull) {
    VkDevice device = gpu().device();
    std::array<VkDescriptorSetLayoutBinding, 2> bindings{};
    for (uint32_t i = 0; i < bindings.size(); ++i) {
        bindings[i].binding = i;
        bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    info.bindingCount = static_cast<uint32_t>(bindings.size());
    info.pBindings = bindings.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateDescriptorSetLayout(device, &info, nullptr, &layout), VK_SUCCESS);
    {
        DescriptorPools::Capacity capacity;
        capacity.sets = 4;
        capacity.descriptors = {0, 0, 7, 0, 0}; // three sets of two storage images fit a pool, not four
        DescriptorPools pools(device, capacity);
        const std::array<VkDescriptorType, 2> types = {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
        const DescriptorPools::Counts counts = DescriptorPools::countsOf(types);
        EXPECT_EQ(counts[2], 2u);
        for (int i = 0; i < 10; ++i) EXPECT_NE(pools.allocate(layout, counts), VkDescriptorSet{VK_NULL_HANDLE});
        EXPECT_EQ(pools.poolCount(), 4u); // 3 + 3 + 3 + 1
        pools.reset();
        for (int i = 0; i < 9; ++i) pools.allocate(layout, counts);
        EXPECT_EQ(pools.poolCount(), 4u) << "a reset pool is used again, not a new one created";
        capacity.descriptors[2] = 1;
        DescriptorPools small(device, capacity);
        EXPECT_THROW(small.allocate(layout, counts), InternalError);
    }
    vkDestroyDescriptorSetLayout(device, layout, nullptr);
}

} // namespace
} // namespace vitrine::test
