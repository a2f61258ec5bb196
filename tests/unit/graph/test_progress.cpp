// Progress observers (what `vitrine serve` forwards to the editor as a node's progress): who hears of long work, with
// which node id, and how often.
#include "core/base/log.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace vitrine {
namespace {

struct Heard {
    std::string node, label;
    size_t done, total;
};

ProgressObserver recorder(std::vector<Heard>& heard) {
    return [&heard](const std::string& node, const std::string& label, size_t done, size_t total) {
        heard.push_back({node, label, done, total});
    };
}

TEST(Progress, ObserverHearsStartAndEndWithTheOutermostNode) {
    std::vector<Heard> heard;
    const std::string outer = "capture", inner = "gbuffer";
    {
        ScopedProgressObserver observer(recorder(heard));
        ScopedProgressNode a(outer);
        ScopedProgressNode b(inner); // a node of the graph `capture` runs inside itself
        Progress p("capturing probes", 1000);
        for (int i = 0; i < 1000; ++i) p.advance(); // far faster than 100 ms apart: throttled
    }
    ASSERT_GE(heard.size(), 2u);
    EXPECT_LE(heard.size(), 4u) << "advances closer than 100 ms apart are not all forwarded";
    EXPECT_EQ(heard.front().done, 0u);
    EXPECT_EQ(heard.back().done, 1000u);
    for (const Heard& h : heard) {
        EXPECT_EQ(h.node, "capture");
        EXPECT_EQ(h.label, "capturing probes");
        EXPECT_EQ(h.total, 1000u);
    }

    // Once the observer's scope ended, nothing more is heard; outside any node the id is empty.
    const size_t before = heard.size();
    { Progress quiet("later", 3); quiet.advance(3); }
    EXPECT_EQ(heard.size(), before);
    {
        ScopedProgressObserver observer(recorder(heard));
        Progress p("outside", 2);
    }
    ASSERT_GT(heard.size(), before);
    EXPECT_EQ(heard.back().node, "");
    EXPECT_EQ(heard.back().done, 2u) << "finish() reports the end";
}

// advanceTo: work that reports the fraction it has done moves the bar forward only, and never past the end.
TEST(Progress, AdvanceToMovesForwardToTheFraction) {
    Progress p("fraction", 100);
    p.advanceTo(0.5);
    EXPECT_EQ(p.done(), 50u);
    p.advanceTo(0.25);
    EXPECT_EQ(p.done(), 50u);
    p.advanceTo(0.999);
    EXPECT_EQ(p.done(), 99u);
    p.advanceTo(2.0);
    EXPECT_EQ(p.done(), 100u);
}

TEST(Progress, ObserversArePerThread) {
    std::vector<Heard> heard, other;
    ScopedProgressObserver observer(recorder(heard));
    std::thread([&] {
        ScopedProgressObserver mine(recorder(other));
        Progress p("elsewhere", 2);
    }).join();
    EXPECT_TRUE(heard.empty());
    EXPECT_FALSE(other.empty());
}

// The compiler marks the node whose setup runs, so a bake in setup() reports under its id.
class SlowSetupNode final : public Node {
public:
    void setup(SetupContext& ctx) override {
        ctx.output("out");
        Progress p("baking", 4);
        p.advance(4);
    }
    void execute(ExecuteContext&) override {}
};

TEST(Progress, CompilerNamesTheNodeWhoseSetupWorks) {
    NodeRegistry registry;
    NodeSchema slow;
    slow.type = "test.slow";
    OutputPort out;
    out.name = "out";
    slow.outputs = {out};
    registry.add(slow, [] { return std::make_unique<SlowSetupNode>(); });
    nlohmann::json doc = {{"frame", {{"width", 8}, {"height", 8}}},
                          {"nodes", {{"lightmap", {{"type", "test.slow"}}}}},
                          {"outputs", {{"final", "lightmap.out"}}}};
    std::vector<Heard> heard;
    ScopedProgressObserver observer(recorder(heard));
    compileGraph(validateGraph(doc, "progress.json", registry), registry);
    ASSERT_FALSE(heard.empty());
    EXPECT_EQ(heard.back().node, "lightmap");
    EXPECT_EQ(heard.back().label, "baking");
    EXPECT_EQ(heard.back().done, 4u);
}

} // namespace
} // namespace vitrine
