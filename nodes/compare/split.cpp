// compare.split: an A/B split view of two images along a movable, rotatable line.
#include "shaders/compare/split.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "compare.split";
    s.doc = "Split view: a on one side of a line, b on the other, with the line and 'A'/'B' markers drawn on top. "
            "Angle 0 is a vertical line with a on the left; 90 is horizontal with a on top.";
    s.inputs = {{"a", PortKind::Texture, {}, false, Usage::Sampled, "Image shown on the negative side of the line"},
                {"b",
                 PortKind::Texture,
                 {},
                 false,
                 Usage::Sampled,
                 "Image shown on the other side (nearest texel at the same relative position when sizes differ)"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "a";
    out.size = SizeRule::ofInput("a");
    out.doc = "The split view, a's size and format";
    s.outputs = {out};
    s.params = {
        {"position",
         ParamType::Float,
         0.5,
         0.0,
         1.0,
         {},
         "Where the line crosses the image along its normal: 0 all b, 1 all a (0.5: through the centre)"},
        {"angle", ParamType::Float, 0.0, -180.0, 180.0, {}, "Rotation of the line in degrees (0: vertical)"},
        {"line_width", ParamType::Float, 2.0, 0.0, 64.0, {}, "Width of the dividing line in pixels (0: none)"},
        {"line_color", ParamType::Vec4, {1.0, 0.65, 0.2, 1.0}, {}, {}, {}, "Linear RGBA of the line (alpha blends)"},
        {"labels",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Draw 5x7 bitmap 'A' and 'B' markers in the image corners deepest on each side of the line"},
    };
    return s;
}

class Split final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("compare/split.comp"); }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        const ImageDesc& out = ctx.output("color").desc();
        const float w = static_cast<float>(out.width), h = static_cast<float>(out.height);
        const float angle = p.getFloat("angle") * std::numbers::pi_v<float> / 180.0f;
        const glm::vec2 normal(std::cos(angle), std::sin(angle));
        // The image's extent along the normal; position 0..1 sweeps the line across all of it.
        const float extent = std::abs(w * normal.x) + std::abs(h * normal.y);
        gpu_types::SplitPush push{};
        push.lineColor = p.getVec4("line_color");
        push.normal = normal;
        push.origin = glm::vec2(0.5f * w, 0.5f * h) + (p.getFloat("position") - 0.5f) * extent * normal;
        push.halfWidth = 0.5f * p.getFloat("line_width");
        push.labels = p.getBool("labels") ? 1u : 0u;
        push.glyphScale = std::max(1u, out.height / 180u);
        placeLabels(push, out.width, out.height);
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    // Each marker goes into the corner farthest into its side of the line; ties go to the top, then the left.
    static void placeLabels(gpu_types::SplitPush& push, uint32_t width, uint32_t height) {
        const int s = static_cast<int>(push.glyphScale), margin = 4 * s, boxW = 7 * s, boxH = 9 * s;
        const int w = static_cast<int>(width), h = static_cast<int>(height);
        const std::array<glm::ivec2, 4> boxes = {glm::ivec2(margin, margin), glm::ivec2(w - margin - boxW, margin),
                                                 glm::ivec2(margin, h - margin - boxH),
                                                 glm::ivec2(w - margin - boxW, h - margin - boxH)};
        size_t minCorner = 0, maxCorner = 1;
        float minD = 0.0f, maxD = 0.0f;
        for (size_t i = 0; i < boxes.size(); ++i) {
            const glm::vec2 centre = glm::vec2(boxes[i]) + 0.5f * glm::vec2(boxW, boxH);
            const float d = glm::dot(centre - push.origin, push.normal);
            if (i == 0 || d < minD) minD = d, minCorner = i;
            if (i == 0 || d > maxD) maxD = d, maxCorner = i;
        }
        push.labelA = boxes[minCorner];
        push.labelB = boxes[maxCorner];
    }

    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Split>(); });

} // namespace
} // namespace vitrine
