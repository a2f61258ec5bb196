// Phases 2-4 (validate, order/cull, compile) on graphs of test-only node types registered in a
// local NodeRegistry. The nodes do nothing, so no GPU is involved. Every expected order,
// lifetime and size below is worked out by hand from the graph in the test.
#include "core/base/error.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <set>

namespace vitrine {
namespace {

using nlohmann::json;

class NoopNode final : public Node {
public:
    void execute(ExecuteContext&) override {}
};

OutputPort output(const std::string& name, SizeRule size = SizeRule::frame()) {
    OutputPort out;
    out.name = name;
    out.size = std::move(size);
    return out;
}

InputPort input(const std::string& name, bool optional = false) {
    InputPort in;
    in.name = name;
    in.optional = optional;
    return in;
}

NodeRegistry buildRegistry() {
    NodeRegistry r;
    auto add = [&](NodeSchema s) { r.add(std::move(s), [] { return std::make_unique<NoopNode>(); }); };

    NodeSchema source;
    source.type = "test.source";
    source.outputs = {output("out")}; // rgba16f, frame-sized
    add(source);

    NodeSchema filter;
    filter.type = "test.filter";
    filter.inputs = {input("in")};
    filter.outputs = {output("out", SizeRule::ofInput("in"))};
    filter.outputs[0].formatFrom = "in";
    add(filter);

    NodeSchema half;
    half.type = "test.half";
    half.inputs = {input("in")};
    half.outputs = {output("out", SizeRule::ofInput("in", 0.5f))};
    half.outputs[0].format = VK_FORMAT_R8G8B8A8_UNORM;
    add(half);

    NodeSchema merge;
    merge.type = "test.merge";
    merge.inputs = {input("a"), input("b")};
    merge.outputs = {output("out", SizeRule::ofInput("a"))};
    merge.outputs[0].formatFrom = "a";
    add(merge);

    NodeSchema feedback;
    feedback.type = "test.feedback";
    feedback.inputs = {input("in"), input("history", true)};
    feedback.outputs = {output("out")};
    add(feedback);

    NodeSchema rgba8Only;
    rgba8Only.type = "test.rgba8_only";
    rgba8Only.inputs = {input("in")};
    rgba8Only.inputs[0].formats = {VK_FORMAT_R8G8B8A8_UNORM};
    rgba8Only.outputs = {output("out")};
    add(rgba8Only);

    NodeSchema buffer;
    buffer.type = "test.buffer";
    buffer.outputs = {output("data")};
    buffer.outputs[0].kind = PortKind::Buffer;
    add(buffer);
    return r;
}

// Local to these tests: the global registry (and the real nodes) are not linked into test_graph.
const NodeRegistry& testRegistry() {
    static const NodeRegistry registry = buildRegistry();
    return registry;
}

CompiledGraph compile(const json& doc) {
    return compileGraph(validateGraph(doc, "test.json", testRegistry()), testRegistry());
}

// The UserError message of compiling `doc`, or "" when it compiled.
std::string compileError(const json& doc) {
    try {
        compile(doc);
    } catch (const UserError& e) {
        return e.what();
    }
    return "";
}

std::vector<std::string> passIds(const CompiledGraph& g) {
    std::vector<std::string> ids;
    for (const auto& p : g.passes)
        ids.push_back(p.id);
    return ids;
}

const GraphResource& resource(const CompiledGraph& g, const std::string& name) {
    int r = g.findResource(name);
    if (r < 0) throw std::runtime_error("no resource " + name);
    return g.resources[r];
}

// source feeds left and right, which merge reads; orphan reads source but no output needs it.
json diamond(const std::string& left = "left") {
    return json{{"frame", {{"width", 64}, {"height", 32}}},
                {"nodes",
                 {{"merge", {{"type", "test.merge"}, {"in", {{"a", left + ".out"}, {"b", "right.out"}}}}},
                  {left, {{"type", "test.filter"}, {"in", {{"in", "source.out"}}}}},
                  {"right", {{"type", "test.filter"}, {"in", {{"in", "source.out"}}}}},
                  {"source", {{"type", "test.source"}}},
                  {"orphan", {{"type", "test.filter"}, {"in", {{"in", "source.out"}}}}}}},
                {"outputs", {{"final", "merge.out"}}}};
}

TEST(GraphCompile, DiamondRunsProducersBeforeConsumers) {
    CompiledGraph g = compile(diamond());
    // source is the only node without inputs; left and right both become ready after it and
    // tie, broken by declaration order (nodes are keyed by id, so "left" < "right").
    EXPECT_EQ(passIds(g), (std::vector<std::string>{"source", "left", "right", "merge"}));
    ASSERT_EQ(g.outputs.size(), 1u);
    EXPECT_EQ(g.outputs[0].first, "final");
    EXPECT_EQ(g.resources[g.outputs[0].second].name, "merge.out");
}

TEST(GraphCompile, TiesAreBrokenByDeclarationOrder) {
    // Renaming left to zleft puts it after right in declaration order, so right runs first.
    CompiledGraph g = compile(diamond("zleft"));
    EXPECT_EQ(passIds(g), (std::vector<std::string>{"source", "right", "zleft", "merge"}));
    CompiledGraph again = compile(diamond("zleft"));
    EXPECT_EQ(passIds(again), passIds(g));
}

TEST(GraphCompile, CullsNodesNoOutputNeeds) {
    CompiledGraph g = compile(diamond());
    EXPECT_EQ(g.culled, std::vector<std::string>{"orphan"});
    EXPECT_EQ(g.findPass("orphan"), nullptr);
    EXPECT_EQ(g.findResource("orphan.out"), -1);
    EXPECT_NE(g.findPass("left"), nullptr);
}

TEST(GraphCompile, CullsWholeBranchWhenOutputMoves) {
    json doc = diamond();
    doc["outputs"]["final"] = "left.out";
    CompiledGraph g = compile(doc);
    EXPECT_EQ(passIds(g), (std::vector<std::string>{"source", "left"}));
    EXPECT_EQ(g.culled, (std::vector<std::string>{"merge", "orphan", "right"}));
}

TEST(GraphCompile, MergeReadsEachInputFromItsProducer) {
    CompiledGraph g = compile(diamond());
    const CompiledPass* merge = g.findPass("merge");
    ASSERT_NE(merge, nullptr);
    std::map<std::string, std::string> read;
    for (const auto& u : merge->uses)
        if (!u.output) read[u.port] = g.resources[u.resource].name;
    EXPECT_EQ(read, (std::map<std::string, std::string>{{"a", "left.out"}, {"b", "right.out"}}));
}

// src -> f1 -> f2 (half size, rgba8) -> m, and m also reads src: passes 0..3 are src, f1, f2, m.
json chain() {
    return json{{"frame", {{"width", 64}, {"height", 32}}},
                {"nodes",
                 {{"src", {{"type", "test.source"}}},
                  {"f1", {{"type", "test.filter"}, {"in", {{"in", "src.out"}}}}},
                  {"f2", {{"type", "test.half"}, {"in", {{"in", "f1.out"}}}}},
                  {"m", {{"type", "test.merge"}, {"in", {{"a", "f2.out"}, {"b", "src.out"}}}}}}},
                {"outputs", {{"final", "m.out"}}}};
}

TEST(GraphCompile, ChainLifetimesSpanFirstWriteToLastRead) {
    CompiledGraph g = compile(chain());
    ASSERT_EQ(passIds(g), (std::vector<std::string>{"src", "f1", "f2", "m"}));
    EXPECT_TRUE(g.culled.empty());

    const GraphResource& src = resource(g, "src.out");
    EXPECT_EQ(src.firstPass, 0u); // written by src
    EXPECT_EQ(src.lastPass, 3u);  // last read by m
    const GraphResource& f1 = resource(g, "f1.out");
    EXPECT_EQ(f1.firstPass, 1u);
    EXPECT_EQ(f1.lastPass, 2u);
    const GraphResource& f2 = resource(g, "f2.out");
    EXPECT_EQ(f2.firstPass, 2u);
    EXPECT_EQ(f2.lastPass, 3u);
    EXPECT_TRUE(src.transient() && f1.transient() && f2.transient());

    // A graph output is read back after the frame: alive through every pass, never aliased.
    const GraphResource& m = resource(g, "m.out");
    EXPECT_TRUE(m.extracted);
    EXPECT_FALSE(m.transient());
    EXPECT_EQ(m.firstPass, 0u);
    EXPECT_EQ(m.lastPass, 3u);
    EXPECT_NE(m.desc.usage & VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 0u);
}

TEST(GraphCompile, SizeAndFormatRulesFollowTheInputs) {
    CompiledGraph g = compile(chain());
    const ImageDesc& src = resource(g, "src.out").desc;
    EXPECT_EQ(src.width, 64u);
    EXPECT_EQ(src.height, 32u);
    EXPECT_EQ(src.format, VK_FORMAT_R16G16B16A16_SFLOAT);
    const ImageDesc& f1 = resource(g, "f1.out").desc; // same as its input
    EXPECT_EQ(f1.width, 64u);
    EXPECT_EQ(f1.height, 32u);
    EXPECT_EQ(f1.format, VK_FORMAT_R16G16B16A16_SFLOAT);
    const ImageDesc& f2 = resource(g, "f2.out").desc; // half of 64x32, declared rgba8
    EXPECT_EQ(f2.width, 32u);
    EXPECT_EQ(f2.height, 16u);
    EXPECT_EQ(f2.format, VK_FORMAT_R8G8B8A8_UNORM);
    const ImageDesc& m = resource(g, "m.out").desc; // size and format of input a (f2.out)
    EXPECT_EQ(m.width, 32u);
    EXPECT_EQ(m.height, 16u);
    EXPECT_EQ(m.format, VK_FORMAT_R8G8B8A8_UNORM);
    // src.out is written as storage and sampled by f1 and m.
    EXPECT_EQ(src.usage & (VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT),
              static_cast<VkImageUsageFlags>(VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT));
}

// Splits "x -> y -> z -> x" into its names.
std::vector<std::string> splitArrows(const std::string& text) {
    std::vector<std::string> names;
    for (size_t start = 0;;) {
        size_t arrow = text.find(" -> ", start);
        names.push_back(text.substr(start, arrow - start));
        if (arrow == std::string::npos) break;
        start = arrow + 4;
    }
    return names;
}

TEST(GraphCompile, CycleErrorNamesEveryNodeOnItAndThePointer) {
    // a -> b -> c -> a is a cycle (each reads the previous one's output); d hangs off it.
    json doc{{"nodes",
              {{"a", {{"type", "test.filter"}, {"in", {{"in", "c.out"}}}}},
               {"b", {{"type", "test.filter"}, {"in", {{"in", "a.out"}}}}},
               {"c", {{"type", "test.filter"}, {"in", {{"in", "b.out"}}}}},
               {"d", {{"type", "test.filter"}, {"in", {{"in", "c.out"}}}}}}},
             {"outputs", {{"final", "d.out"}}}};
    std::string message = compileError(doc);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(message, m,
                                  std::regex(R"(^test\.json: /nodes/(\w+)/in/in: the graph has a cycle: ([\w >-]+))")))
        << message;
    const std::set<std::pair<std::string, std::string>> edges = {
        {"a", "b"}, {"b", "c"}, {"c", "a"}}; // producer, consumer
    std::vector<std::string> cycle = splitArrows(m[2].str().substr(0, m[2].str().find_last_not_of(' ') + 1));
    ASSERT_EQ(cycle.size(), 4u) << message;
    EXPECT_EQ(cycle.front(), cycle.back()) << message;
    EXPECT_EQ(std::set<std::string>(cycle.begin(), cycle.end()), (std::set<std::string>{"a", "b", "c"})) << message;
    for (size_t i = 0; i + 1 < cycle.size(); ++i)
        EXPECT_TRUE(edges.count({cycle[i], cycle[i + 1]})) << cycle[i] << " -> " << cycle[i + 1] << " is not an edge";
    EXPECT_TRUE(m[1] == "a" || m[1] == "b" || m[1] == "c") << message;
    EXPECT_NE(message.find("@prev"), std::string::npos) << "the message should say how to read last frame";
}

TEST(GraphCompile, CyclePointerNamesTheInputOnTheCycle) {
    // x.b reads y and y.in reads x; x.a reads src, which is not on the cycle.
    json doc{{"nodes",
              {{"src", {{"type", "test.source"}}},
               {"x", {{"type", "test.merge"}, {"in", {{"a", "src.out"}, {"b", "y.out"}}}}},
               {"y", {{"type", "test.filter"}, {"in", {{"in", "x.out"}}}}}}},
             {"outputs", {{"final", "y.out"}}}};
    std::string message = compileError(doc);
    bool onCycle =
        message.rfind("test.json: /nodes/x/in/b: ", 0) == 0 || message.rfind("test.json: /nodes/y/in/in: ", 0) == 0;
    EXPECT_TRUE(onCycle) << message;
    EXPECT_EQ(message.find("src"), std::string::npos) << message;
}

TEST(GraphCompile, ReadingOwnOutputWithoutPrevIsRejected) {
    json doc{{"nodes",
              {{"src", {{"type", "test.source"}}},
               {"fb", {{"type", "test.feedback"}, {"in", {{"in", "src.out"}, {"history", "fb.out"}}}}}}},
             {"outputs", {{"final", "fb.out"}}}};
    std::string message = compileError(doc);
    EXPECT_EQ(message.rfind("test.json: /nodes/fb/in/history: ", 0), 0u) << message;
    EXPECT_NE(message.find("fb.out@prev"), std::string::npos) << message;
}

TEST(GraphCompile, PrevSelfLoopIsTemporalFeedbackNotACycle) {
    json doc{{"frame", {{"width", 64}, {"height", 32}}},
             {"nodes",
              {{"src", {{"type", "test.source"}}},
               {"fb", {{"type", "test.feedback"}, {"in", {{"in", "src.out"}, {"history", "fb.out@prev"}}}}}}},
             {"outputs", {{"final", "fb.out"}}}};
    CompiledGraph g;
    ASSERT_NO_THROW(g = compile(doc));
    EXPECT_EQ(passIds(g), (std::vector<std::string>{"src", "fb"}));
    const GraphResource& fb = resource(g, "fb.out");
    EXPECT_TRUE(fb.history);
    EXPECT_FALSE(fb.transient());
    EXPECT_EQ(fb.firstPass, 0u);
    EXPECT_EQ(fb.lastPass, 1u);
    EXPECT_FALSE(resource(g, "src.out").history);

    const CompiledPass* pass = g.findPass("fb");
    ASSERT_NE(pass, nullptr);
    auto use = std::find_if(pass->uses.begin(), pass->uses.end(), [](const PassUse& u) { return u.port == "history"; });
    ASSERT_NE(use, pass->uses.end());
    EXPECT_TRUE(use->previous);
    EXPECT_FALSE(use->output);
    EXPECT_EQ(g.resources[use->resource].name, "fb.out");
}

TEST(GraphCompile, PrevKeepsItsProducerAliveButOrdersItAfterTheReader) {
    // acc reads blur's last-frame value, blur reads acc's current one; only acc is an output.
    json doc{{"nodes",
              {{"src", {{"type", "test.source"}}},
               {"acc", {{"type", "test.feedback"}, {"in", {{"in", "src.out"}, {"history", "blur.out@prev"}}}}},
               {"blur", {{"type", "test.filter"}, {"in", {{"in", "acc.out"}}}}}}},
             {"outputs", {{"final", "acc.out"}}}};
    CompiledGraph g = compile(doc);
    EXPECT_EQ(passIds(g), (std::vector<std::string>{"src", "acc", "blur"}));
    EXPECT_TRUE(g.culled.empty());
    EXPECT_TRUE(resource(g, "blur.out").history);
    EXPECT_FALSE(resource(g, "acc.out").history);
    EXPECT_TRUE(resource(g, "acc.out").extracted);
}

TEST(GraphCompile, KindMismatchIsAUserErrorAtTheInput) {
    json doc{
        {"nodes", {{"buf", {{"type", "test.buffer"}}}, {"f", {{"type", "test.filter"}, {"in", {{"in", "buf.data"}}}}}}},
        {"outputs", {{"final", "f.out"}}}};
    std::string message = compileError(doc);
    EXPECT_EQ(message.rfind("test.json: /nodes/f/in/in: ", 0), 0u) << message;
    EXPECT_NE(message.find("takes a texture"), std::string::npos) << message;
    EXPECT_NE(message.find("buf.data is a buffer"), std::string::npos) << message;

    json bufferOut{{"nodes", {{"buf", {{"type", "test.buffer"}}}}}, {"outputs", {{"final", "buf.data"}}}};
    message = compileError(bufferOut);
    EXPECT_EQ(message.rfind("test.json: /outputs/final: ", 0), 0u) << message;
    EXPECT_NE(message.find("must be textures"), std::string::npos) << message;
}

TEST(GraphCompile, InputFormatRestrictionIsChecked) {
    json bad{
        {"nodes",
         {{"src", {{"type", "test.source"}}}, {"only", {{"type", "test.rgba8_only"}, {"in", {{"in", "src.out"}}}}}}},
        {"outputs", {{"final", "only.out"}}}};
    std::string message = compileError(bad);
    EXPECT_EQ(message.rfind("test.json: /nodes/only/in/in: ", 0), 0u) << message;
    EXPECT_NE(message.find("takes rgba8"), std::string::npos) << message;
    EXPECT_NE(message.find("src.out is rgba16f"), std::string::npos) << message;

    json good = bad;
    good["nodes"]["half"] = {{"type", "test.half"}, {"in", {{"in", "src.out"}}}};
    good["nodes"]["only"]["in"]["in"] = "half.out";
    EXPECT_EQ(compileError(good), "");
}

TEST(GraphCompile, RegistryRejectsBadDefaultsAndDuplicates) {
    NodeRegistry r;
    NodeSchema s;
    s.type = "test.p";
    s.params = {{"gain", ParamType::Float, 2.0, 0.0, 1.0, {}, "out of its own range"}};
    EXPECT_THROW(r.add(s, [] { return std::make_unique<NoopNode>(); }), InternalError);
    s.params[0].defaultValue = 0.5;
    EXPECT_NO_THROW(r.add(s, [] { return std::make_unique<NoopNode>(); }));
    EXPECT_THROW(r.add(s, [] { return std::make_unique<NoopNode>(); }), InternalError);
    EXPECT_EQ(r.find("test.p"), r.all().front());
    EXPECT_EQ(testRegistry().find("test.p"), nullptr);
}

// validateGraphErrors (what `vitrine serve` answers /api/validate with): every independent error at once, each naming
// its own pointer, and nothing reported twice for a node whose declaration failed.
TEST(GraphValidate, EveryErrorIsReportedWithItsOwnPointer) {
    json doc = {{"nodes",
                 {{"a", {{"type", "test.source"}, {"colour", 1}}},
                  {"b", {{"type", "test.filter"}, {"in", {{"in", "a.nope"}}}}},
                  {"c", {{"type", "test.merge"}, {"in", {{"a", "a.out"}, {"b", "ghost.out"}, {"x", "a.out"}}}}},
                  {"d", {{"type", "test.nosuch"}}},
                  {"e", {{"type", "test.filter"}, {"in", {{"in", "d.out"}}}}}}},
                {"outputs", {{"final", "c.out"}, {"bad", "a.missing"}}}};
    std::vector<std::string> errors = validateGraphErrors(doc, "test.json", testRegistry());
    std::set<std::string> pointers;
    for (const std::string& e : errors) {
        std::smatch m;
        ASSERT_TRUE(std::regex_search(e, m, std::regex("^test\\.json: (/[^:]*): "))) << e;
        pointers.insert(m[1]);
    }
    EXPECT_EQ(pointers, (std::set<std::string>{"/nodes/a/colour", "/nodes/b/in/in", "/nodes/c/in/b", "/nodes/c/in/x",
                                               "/nodes/d/type", "/outputs/bad"}));
    EXPECT_EQ(errors.size(), pointers.size()) << "an error reported twice";

    // The first of them is the one validateGraph throws.
    try {
        validateGraph(doc, "test.json", testRegistry());
        ADD_FAILURE() << "validateGraph accepted the graph";
    } catch (const UserError& e) {
        EXPECT_EQ(errors.front(), e.what());
    }
    EXPECT_TRUE(validateGraphErrors(diamond(), "test.json", testRegistry()).empty());
    // A structural error after which nothing else can be checked is the only one.
    EXPECT_EQ(validateGraphErrors(json{{"nodes", 3}}, "test.json", testRegistry()).size(), 1u);
}

} // namespace
} // namespace vitrine
