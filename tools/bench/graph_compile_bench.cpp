// CPU-side benchmarks of the render-graph compiler (no GPU): validating and compiling a
// synthetic graph of N nodes, and the aliasing planner.
#include "core/graph/compiler.hpp"
#include "core/graph/lifetimes.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace {

using nlohmann::json;

// A pattern followed by N-1 nodes, each reading one or two earlier nodes (a random DAG with a
// fixed seed) and every tenth one exported, so ordering, culling and lifetimes all have work.
json syntheticGraph(int n) {
    std::mt19937 rng(7);
    json nodes = {{"n0", {{"type", "pattern.checker"}}}};
    json outputs = json::object();
    for (int i = 1; i < n; ++i) {
        std::string src = "n" + std::to_string(std::uniform_int_distribution<int>(std::max(0, i - 4), i - 1)(rng));
        nodes["n" + std::to_string(i)] = {{"type", i % 3 ? "post.tonemap" : "aa.fxaa"}, {"in", {{"color", src + ".color"}}}};
        if (i % 10 == 0) outputs["o" + std::to_string(i)] = "n" + std::to_string(i) + ".color";
    }
    outputs["last"] = "n" + std::to_string(n - 1) + ".color";
    return {{"format", "vitrine-graph/1"}, {"frame", {{"width", 1920}, {"height", 1080}}}, {"nodes", nodes}, {"outputs", outputs}};
}

void BM_ValidateAndCompile(benchmark::State& state) {
    json doc = syntheticGraph(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        auto desc = vitrine::validateGraph(doc, "synthetic.json", vitrine::NodeRegistry::global());
        auto graph = vitrine::compileGraph(std::move(desc));
        benchmark::DoNotOptimize(graph.passes.size());
    }
}
BENCHMARK(BM_ValidateAndCompile)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMicrosecond);

void BM_PlanAliasing(benchmark::State& state) {
    std::mt19937 rng(3);
    std::vector<vitrine::AliasRequest> requests;
    for (int i = 0; i < state.range(0); ++i) {
        uint32_t first = std::uniform_int_distribution<uint32_t>(0, 60)(rng);
        requests.push_back({std::uniform_int_distribution<uint64_t>(1, 64)(rng) << 20, 65536, first,
                            first + std::uniform_int_distribution<uint32_t>(0, 8)(rng)});
    }
    for (auto _ : state) benchmark::DoNotOptimize(vitrine::planAliasing(requests).heapSize);
}
BENCHMARK(BM_PlanAliasing)->Arg(50)->Arg(500)->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
