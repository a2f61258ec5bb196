// applySet: the `--set KEY=VALUE` assignments applied to a graph document.
#include "core/base/error.hpp"
#include "core/graph/loader.hpp"

#include <gtest/gtest.h>

namespace vitrine {
namespace {

using nlohmann::json;
using Ptr = json::json_pointer;

json graph() {
    return json::parse(R"({
        "frame": {"width": 640, "height": 360},
        "nodes": {
            "pattern": {"type": "pattern.zoneplate"},
            "tonemap": {"type": "post.tonemap", "params": {"operator": "linear"}, "in": {"color": "pattern.color"}}
        },
        "outputs": {"final": "tonemap.color"}
    })");
}

std::string setError(json& doc, const std::string& assignment) {
    try {
        applySet(doc, assignment);
    } catch (const UserError& e) {
        return e.what();
    }
    return "";
}

TEST(GraphSet, NodeParamBecomesANumber) {
    json doc = graph();
    applySet(doc, "tonemap.params.exposure=1.5");
    const json& v = doc.at(Ptr("/nodes/tonemap/params/exposure"));
    ASSERT_TRUE(v.is_number_float()) << v.dump();
    EXPECT_EQ(v.get<double>(), 1.5);
    EXPECT_EQ(doc.at(Ptr("/nodes/tonemap/params/operator")), "linear") << "other params are kept";
    EXPECT_EQ(doc.at(Ptr("/nodes/tonemap/type")), "post.tonemap");
}

TEST(GraphSet, FrameKeyIsNotANode) {
    json doc = graph();
    applySet(doc, "frame.width=320");
    const json& v = doc.at(Ptr("/frame/width"));
    ASSERT_TRUE(v.is_number_integer()) << v.dump();
    EXPECT_EQ(v.get<int>(), 320);
    EXPECT_EQ(doc.at(Ptr("/frame/height")).get<int>(), 360);
    EXPECT_FALSE(doc["nodes"].contains("frame"));
}

TEST(GraphSet, TextThatIsNotJsonBecomesAString) {
    json doc = graph();
    applySet(doc, "tonemap.params.operator=reinhard");
    EXPECT_EQ(doc.at(Ptr("/nodes/tonemap/params/operator")), json("reinhard"));
    applySet(doc, "outputs.raw=pattern.color");
    EXPECT_EQ(doc.at(Ptr("/outputs/raw")), json("pattern.color"));
    EXPECT_EQ(doc.at(Ptr("/outputs/final")), json("tonemap.color"));
}

TEST(GraphSet, JsonValuesKeepTheirType) {
    json doc = graph();
    applySet(doc, "tonemap.params.inverse=true");
    EXPECT_EQ(doc.at(Ptr("/nodes/tonemap/params/inverse")), json(true));
    applySet(doc, "pattern.params.range=[0.25, 2]");
    EXPECT_EQ(doc.at(Ptr("/nodes/pattern/params/range")), json::parse("[0.25, 2]"));
    applySet(doc, R"(tonemap.params.operator="1.5")");
    EXPECT_EQ(doc.at(Ptr("/nodes/tonemap/params/operator")), json("1.5"));
}

TEST(GraphSet, MissingNodeIsAUserError) {
    json doc = graph();
    const json before = doc;
    std::string message = setError(doc, "nosuch.params.x=1");
    EXPECT_NE(message.find("nosuch.params.x=1"), std::string::npos) << message;
    EXPECT_NE(message.find("no node 'nosuch'"), std::string::npos) << message;
    EXPECT_EQ(doc, before) << "a failed --set must not change the document";
}

TEST(GraphSet, MalformedAssignmentsAreUserErrors) {
    json doc = graph();
    EXPECT_NE(setError(doc, "tonemap.params.exposure"), "");
    EXPECT_NE(setError(doc, "=1"), "");
    EXPECT_NE(setError(doc, "tonemap..exposure=1"), "");
    EXPECT_NE(setError(doc, "tonemap.params.=1"), "");
    EXPECT_EQ(doc, graph());
}

} // namespace
} // namespace vitrine
