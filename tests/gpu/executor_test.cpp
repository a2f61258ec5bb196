// The executor on a real device: aliased transients stay correct, memory is actually shared,
// timestamps are produced, and multi-frame runs are repeatable.
#include "tests/gpu/gpu_test.hpp"

#include "core/graph/compiler.hpp"
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

} // namespace
} // namespace vitrine::test
