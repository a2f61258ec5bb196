// `vitrine validate` on the malformed graphs in tests/data/bad_graphs and on the shipped good
// ones: exit status 1 for a user error, with a message naming the file, the JSON pointer (or
// line:column) and what was wrong. Runs the real CLI with the real node types; no GPU.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

namespace {

const std::string kSource = VITRINE_SOURCE_DIR;
const std::string kBadGraphs = kSource + "/tests/data/bad_graphs/";

std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

struct CliResult {
    int status = -1; // exit status, or -1 when the program did not exit normally
    std::string output;
};

// Runs `vitrine ARGS` with stderr merged into stdout.
CliResult vitrine(const std::string& args) {
    std::string command = quote(VITRINE_BINARY) + " " + args + " 2>&1";
    CliResult r;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;)
        r.output.append(buffer, n);
    int status = pclose(pipe);
    if (WIFEXITED(status)) r.status = WEXITSTATUS(status);
    return r;
}

struct BadGraph {
    std::string file;    // under tests/data/bad_graphs, or relative to the source dir with a '/'
    std::string args;    // extra arguments after the file
    std::string located; // what must follow the file name: ": /json/pointer: " or ":line:column: "
    std::string phrase;  // what was wrong
};

std::ostream& operator<<(std::ostream& os, const BadGraph& b) {
    return os << b.file << " " << b.args;
}

class GraphCliBadGraph : public testing::TestWithParam<BadGraph> {};

TEST_P(GraphCliBadGraph, ValidateExitsOneNamingFileAndPointer) {
    const BadGraph& b = GetParam();
    std::string path = b.file.find('/') == std::string::npos ? kBadGraphs + b.file : kSource + "/" + b.file;
    CliResult r = vitrine("validate " + quote(path) + " " + b.args);
    EXPECT_EQ(r.status, 1) << r.output;
    std::string name = path.substr(path.rfind('/') + 1);
    EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(name + b.located), std::string::npos)
        << "expected \"" << name + b.located << "\" in: " << r.output;
    EXPECT_NE(r.output.find(b.phrase), std::string::npos) << "expected \"" << b.phrase << "\" in: " << r.output;
}

// One row per file. The line:column of syntax_error.json is where its single-quoted string
// starts (line 5, column 25).
const BadGraph kBadGraphRows[] = {
    {"syntax_error.json", "", ":5:25: ", "JSON syntax error"},
    {"not_an_object.json", "", ": /: ", "expected a JSON object"},
    {"unknown_top_level_key.json", "", ": /node: ", "unknown key"},
    {"wrong_format_version.json", "", ": /format: ", "expected \"vitrine-graph/1\", got \"vitrine-graph/2\""},
    {"unknown_node_type.json", "",
     ": /nodes/pattern/type: ", "unknown node type \"pattern.zoneplat\"; did you mean \"pattern.zoneplate\"?"},
    {"missing_type.json", "", ": /nodes/pattern/type: ", "missing"},
    {"bad_node_id.json", "", ": /nodes/zone-plate: ", "node ids are letters, digits and '_'"},
    {"unknown_param.json", "", ": /nodes/pattern/params/max_freq: ", "has no param 'max_freq'"},
    {"param_wrong_type.json", "", ": /nodes/fxaa/params/subpix: ", "expected a number"},
    {"param_out_of_range.json", "", ": /nodes/checker/params/supersample: ", "got 64"},
    {"vec_param_wrong_length.json", "", ": /nodes/view/params/range: ", "expected an array of 2 numbers, got [0,1,2]"},
    {"enum_not_allowed.json", "",
     ": /nodes/tonemap/params/operator: ", "\"reinhard\", \"reinhard_max\", \"aces_fit\", \"pbr_neutral\", got \"filmic\""},
    {"setup_rejects_param.json", "", ": /nodes/tonemap/params/inverse: ", "not invertible"},
    {"unknown_input_port.json", "", ": /nodes/tonemap/in/colour: ", "has no input 'colour'; its inputs: color"},
    {"input_missing_node.json", "", ": /nodes/tonemap/in/color: ", "no node 'fxaa'"},
    {"input_missing_output_port.json", "", ": /nodes/view/in/texture: ", "has no output 'depth'; its outputs: color"},
    {"malformed_reference.json", "",
     ": /nodes/tonemap/in/color: ", "expected \"node.port\" or \"node.port@prev\", got \"pattern:color\""},
    {"missing_required_input.json", "", ": /nodes/fxaa/in/color: ", "missing required input 'color'"},
    {"output_missing_node.json", "", ": /outputs/final: ", "no node 'tonemap'"},
    {"output_empty_reference.json", "", ": /outputs/final: ", "expected \"node.port\", got \"\""},
    {"prev_in_outputs.json", "", ": /outputs/final: ", "cannot read last frame's value (@prev)"},
    {"no_outputs.json", "", ": /outputs: ", "expected a non-empty object"},
    {"empty_outputs.json", "", ": /outputs: ", "expected a non-empty object"},
    {"extends_missing.json", "", ": /extends: ", "no_such_base.json does not exist"},
    {"extends_cycle_a.json", "",
     ": /extends: ", "extends_cycle_a.json -> extends_cycle_b.json -> extends_cycle_a.json"},
    {"extends_cycle_b.json", "",
     ": /extends: ", "extends_cycle_b.json -> extends_cycle_a.json -> extends_cycle_b.json"},
    {"frame_width_zero.json", "", ": /frame/width: ", "expected an integer in [1, 16384], got 0"},
    {"frame_write_out_of_range.json", "", ": /frame/write/1: ", "expected an integer in [0, 3], got 4"},
    {"graphs/fxaa_zoneplate.json", "--set nosuch.params.x=1", ": /nodes/nosuch: ", "the graph has no node 'nosuch'"},
    {"graphs/fxaa_zoneplate.json", "--set tonemap.params.exposure=100",
     ": /nodes/tonemap/params/exposure: ", "got 100"},
    // Numbers a double cannot hold are the user's input (exit 1 with the position), not an internal error.
    {"number_too_large.json", "", ":3:22: ", "the number '1e309' is too large"},
    {"graphs/fxaa_zoneplate.json", "--set fxaa.params.subpix=1e309",
     ": --set fxaa.params.subpix=1e309: ", "the number '1e309' is too large"},
    {"graphs/fxaa_zoneplate.json", "--set frame.width.x=1", ": /frame/width: ", "cannot set 'x' inside 640"},
    {"graphs/fxaa_zoneplate.json", "--set 'frame.write=[0]' --set frame.write.01=1",
     ": /frame/write/01: ", "expected an array index in [0, 1]"},
    // The glTF errors name the glTF file (the path is relative to the graph) and what is wrong in it.
    {"gltf_number_too_large.json", "",
     ": /nodes/scene/params/path: ", "number_too_large.gltf: JSON line 10, column 55: the number '1e309' is too large"},
    {"gltf_bad_magic.json", "",
     ": /nodes/scene/params/path: ", "bad_magic.glb: GLB header: magic is 'glTX' (0x58546C67); expected 'glTF'"},
    // A probe file's error names the param, then the probe file and the JSON pointer inside it.
    {"probes_bad_radius.json", "",
     ": /nodes/scene/params/probes: ", "bad_radius.json: /probes/1/radius: expected a number > 0 (metres), got 0"},
    // --frames is frame.frames before validation: frame.write may name frames the file alone does not have.
    {"graphs/fxaa_zoneplate.json", "--frames 4 --set 'frame.write=[0,4]'",
     ": /frame/write/1: ", "expected an integer in [0, 3], got 4"},
};

std::string rowName(const testing::TestParamInfo<BadGraph>& info) {
    std::string name = info.param.file.substr(info.param.file.rfind('/') + 1);
    name = name.substr(0, name.rfind('.'));
    if (!info.param.args.empty()) name += "_set" + std::to_string(info.index);
    for (char& c : name)
        if (!isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(BadGraphs, GraphCliBadGraph, testing::ValuesIn(kBadGraphRows), rowName);

TEST(GraphCli, EveryBadGraphFileHasARow) {
    std::set<std::string> rows;
    for (const auto& b : kBadGraphRows)
        rows.insert(b.file);
    FILE* ls = popen(("ls " + quote(kBadGraphs)).c_str(), "r");
    ASSERT_NE(ls, nullptr);
    char line[512];
    int files = 0;
    while (fgets(line, sizeof line, ls)) {
        std::string f(line);
        f.erase(f.find_last_not_of("\n") + 1);
        ++files;
        if (f != "cycle.json") {
            EXPECT_TRUE(rows.count(f)) << f << " has no row in kBadGraphRows";
        }
    }
    pclose(ls);
    EXPECT_GE(files, 15);
}

TEST(GraphCli, CycleErrorListsTheNodesOnTheCycle) {
    CliResult r = vitrine("validate " + quote(kBadGraphs + "cycle.json"));
    EXPECT_EQ(r.status, 1) << r.output;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        r.output, m,
        std::regex(
            R"(cycle\.json: /nodes/([abc])/in/color: the graph has a cycle: (\w+) -> (\w+) -> (\w+) -> (\w+) )")))
        << r.output;
    // Edges producer -> consumer: b reads a, c reads b, a reads c.
    const std::set<std::pair<std::string, std::string>> edges = {{"a", "b"}, {"b", "c"}, {"c", "a"}};
    std::vector<std::string> names = {m[2], m[3], m[4], m[5]};
    EXPECT_EQ(names.front(), names.back()) << r.output;
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), (std::set<std::string>{"a", "b", "c"})) << r.output;
    for (size_t i = 0; i + 1 < names.size(); ++i)
        EXPECT_TRUE(edges.count({names[i], names[i + 1]})) << names[i] << " -> " << names[i + 1] << " in " << r.output;
}

TEST(GraphCli, ValidateListsEveryIndependentError) {
    // Two errors in different nodes, given by --set on a good graph: both reported, each with its pointer.
    CliResult r = vitrine("validate " + quote(kSource + "/graphs/fxaa_zoneplate.json") +
                          " --set fxaa.params.subpix=lots --set tonemap.params.exposure=bright");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("fxaa_zoneplate.json: /nodes/fxaa/params/subpix: expected"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("fxaa_zoneplate.json: /nodes/tonemap/params/exposure: expected"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("2 errors"), std::string::npos) << r.output;
}

TEST(GraphCli, ShippedGraphsValidate) {
    CliResult full = vitrine("validate " + quote(kSource + "/graphs/fxaa_zoneplate.json"));
    EXPECT_EQ(full.status, 0) << full.output;
    EXPECT_NE(full.output.find("ok: 3 passes, 3 textures, 1 output(s)"), std::string::npos) << full.output;

    // The variant removes fxaa through its merge patch: pattern and tonemap remain.
    CliResult variant = vitrine("validate " + quote(kSource + "/graphs/variants/no_fxaa.json"));
    EXPECT_EQ(variant.status, 0) << variant.output;
    EXPECT_NE(variant.output.find("ok: 2 passes, 2 textures, 1 output(s)"), std::string::npos) << variant.output;

    CliResult set = vitrine("validate " + quote(kSource + "/graphs/fxaa_zoneplate.json") +
                            " --set tonemap.params.exposure=1.5 --set frame.width=320");
    EXPECT_EQ(set.status, 0) << set.output;
}

// A base's relative `path` params resolve from the base's own folder, whatever folder the variant is in; the variant's
// own from the variant's.
TEST(GraphCli, VariantsResolveTheBasesPathsFromItsFolder) {
    CliResult shipped = vitrine("validate " + quote(kSource + "/graphs/variants/gltf_reference.json"));
    EXPECT_EQ(shipped.status, 0) << shipped.output;

    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "vitrine_variant_paths" / "a" / "b";
    std::filesystem::create_directories(dir);
    const std::string base = kSource + "/graphs/gltf.json";
    std::ofstream(dir / "deep.json") << R"({"format": "vitrine-graph/1", "extends": ")" + base + R"("})";
    CliResult deep = vitrine("validate " + quote((dir / "deep.json").string()));
    EXPECT_EQ(deep.status, 0) << deep.output;

    std::ofstream(dir / "own.json") << R"({"format": "vitrine-graph/1", "extends": ")" + base +
                                           R"(", "nodes": {"sky": {"params": {"path": "missing.hdr"}}}})";
    CliResult own = vitrine("validate " + quote((dir / "own.json").string()));
    EXPECT_EQ(own.status, 1) << own.output;
    EXPECT_NE(own.output.find((dir / "missing.hdr").string()), std::string::npos) << own.output;
    std::filesystem::remove_all(dir.parent_path().parent_path());
}

TEST(GraphCli, RunWithMissingGraphExitsOne) {
    std::string missing = kSource + "/tests/data/bad_graphs/does_not_exist.json";
    std::string out = testing::TempDir() + "vitrine_graph_cli_run_missing";
    CliResult r = vitrine("run " + quote(missing) + " --out " + quote(out) + " --quiet");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("does_not_exist.json: no such file"), std::string::npos) << r.output;
}

// Only stdout, stderr dropped: for commands whose output is parsed.
CliResult vitrineStdout(const std::string& args) {
    return vitrine(args + " 2>/dev/null");
}

TEST(GraphCli, NodesJsonPrintsTheSchemasToStdout) {
    CliResult r = vitrineStdout("nodes --json");
    ASSERT_EQ(r.status, 0) << r.output;
    nlohmann::json schemas = nlohmann::json::parse(r.output, nullptr, false);
    ASSERT_TRUE(schemas.is_array()) << r.output.substr(0, 200);
    std::set<std::string> types;
    for (const auto& s : schemas)
        types.insert(s.value("type", ""));
    EXPECT_TRUE(types.count("aa.fxaa")) << r.output.substr(0, 200);
    EXPECT_TRUE(types.count("scene.museum")) << r.output.substr(0, 200);
}

TEST(GraphCli, NodesJsonFileWritesTheSchemas) {
    std::string file = testing::TempDir() + "vitrine_nodes_schema.json";
    std::remove(file.c_str());
    CliResult r = vitrine("nodes --json " + quote(file));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output, "");
    std::ifstream in(file);
    nlohmann::json schemas = nlohmann::json::parse(in, nullptr, false);
    EXPECT_TRUE(schemas.is_array() && schemas.size() > 10) << file;
}

// bench --json takes a file (the optional value is only nodes'), and says so before touching the GPU.
TEST(GraphCli, BenchJsonStillNeedsAFile) {
    CliResult r = vitrine("bench " + quote(kSource + "/graphs/fxaa_zoneplate.json") + " --json");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("--json needs a value"), std::string::npos) << r.output;
}

TEST(GraphCli, FramesCountBeforeValidation) {
    CliResult museum =
        vitrine("validate " + quote(kSource + "/graphs/museum.json") + " --frames 24 --set 'frame.write=[0,12,23]'");
    EXPECT_EQ(museum.status, 0) << museum.output;
    EXPECT_NE(museum.output.find("museum.json: ok"), std::string::npos) << museum.output;
    CliResult zero = vitrine("validate " + quote(kSource + "/graphs/fxaa_zoneplate.json") + " --frames 0");
    EXPECT_EQ(zero.status, 1) << zero.output;
    EXPECT_NE(zero.output.find("--frames: expected at least 1"), std::string::npos) << zero.output;
}

TEST(GraphCli, ValidateWithoutAGraphIsAUserError) {
    CliResult r = vitrine("validate");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("expected one GRAPH file argument"), std::string::npos) << r.output;
}

} // namespace
