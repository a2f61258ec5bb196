// Every graph shipped under graphs/ (variants included) is loaded, validated, compiled and run for its own frame
// count at a small size, with validation (synchronization included) on: a shipped file that no longer loads, or
// a node that raises a validation message in the pipeline users actually run, fails here. The list is read from
// the source tree when the test binary starts, so a new graph is covered without touching this file.
#include "tests/gpu/gpu_test.hpp"

#include "core/graph/loader.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace vitrine::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> shippedGraphs() {
    std::vector<std::string> files;
    const fs::path root = fs::path(VITRINE_SOURCE_DIR) / "graphs";
    for (const auto& entry : fs::recursive_directory_iterator(root))
        if (entry.is_regular_file() && entry.path().extension() == ".json" &&
            !entry.path().filename().string().ends_with(".schema.json") && // vitrine-graph.schema.json is not a graph
            !entry.path().filename().string().ends_with(".sweep.json") &&  // nor are `vitrine sweep` files
            !entry.path().filename().string().ends_with(".regions.json"))  // nor `compare --regions` files
            files.push_back(fs::relative(entry.path(), root).generic_string());
    std::sort(files.begin(), files.end());
    return files;
}

class ShippedGraph : public GpuTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(ShippedGraph, ValidatesAndRunsAtPreviewSize) {
    const fs::path file = fs::path(VITRINE_SOURCE_DIR) / "graphs" / GetParam();
    std::vector<std::string> sets = {"frame.width=64", "frame.height=36"};
    // Bakes at preview quality too (the shipped quality is measured by the golden and bake tests).
    // The document lives in a variable: a range-for over loadGraphDocument(file)["nodes"].items() iterates a destroyed
    // temporary (only the range's last object has its life extended before C++23), and the preview overrides were lost.
    const nlohmann::json document = loadGraphDocument(file);
    for (const auto& [id, node] : document["nodes"].items()) {
        if (node.value("type", "") == "bake.lightmap")
            for (const char* p : {".params.samples=2", ".params.texels_per_meter=1", ".params.probe_spacing=10"})
                sets.push_back(id + p);
        // A few samples, not converged and cached (museum_reference converges for minutes).
        // The ray-traced twins (reference.*) likewise; reference.substitute has no such params.
        const std::string type = node.value("type", "");
        if (type == "render.pathtrace" || (type.starts_with("reference.") && type != "reference.substitute"))
            for (const char* p : {".params.target_noise=0", ".params.spp=4"}) sets.push_back(id + p);
    }
    const auto outputs = runGraphFile(file.string(), sets);
    ASSERT_FALSE(outputs.empty()) << file;
    for (const auto& [name, image] : outputs) {
        EXPECT_EQ(image.width, 64) << name;
        EXPECT_EQ(image.height, 36) << name;
        size_t nonFinite = 0;
        for (float v : image.pixels)
            nonFinite += std::isfinite(v) ? 0 : 1;
        EXPECT_EQ(nonFinite, 0u) << GetParam() << ": output " << name << " has NaN or Inf values";
    }
}

std::string testName(const ::testing::TestParamInfo<std::string>& info) {
    std::string name = info.param.substr(0, info.param.size() - 5); // without ".json"
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(Graphs, ShippedGraph, ::testing::ValuesIn(shippedGraphs()), testName);

} // namespace
} // namespace vitrine::test
