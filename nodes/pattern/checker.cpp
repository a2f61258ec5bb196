// pattern.checker: a rotated checkerboard with a supersampled ground truth.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "shaders/pattern/checker.h"

#include <glm/gtc/constants.hpp>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "pattern.checker";
    s.doc = "Rotated checkerboard (long slanted edges); supersample > 1 box-filters N x N samples per pixel.";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.doc = "Checkerboard of color_a and color_b";
    s.outputs = {out};
    s.params = {
        {"cell_size", ParamType::Float, 16.0, 0.5, 4096.0, {}, "Cell edge in pixels"},
        {"angle", ParamType::Float, 7.0, -360.0, 360.0, {}, "Rotation in degrees"},
        {"supersample", ParamType::Int, 1, 1.0, 32.0, {}, "N: N x N stratified samples per pixel"},
        {"color_a", ParamType::Vec4, {0.05, 0.05, 0.05, 1.0}, {}, {}, {}, "Linear RGBA of the even cells"},
        {"color_b", ParamType::Vec4, {0.9, 0.9, 0.9, 1.0}, {}, {}, {}, "Linear RGBA of the odd cells"},
    };
    return s;
}

class Checker final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("pattern/checker.comp"); }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::CheckerPush push{};
        push.colorA = p.getVec4("color_a");
        push.colorB = p.getVec4("color_b");
        push.cellSize = p.getFloat("cell_size");
        push.angle = glm::radians(p.getFloat("angle"));
        push.supersample = static_cast<uint32_t>(p.getInt("supersample"));
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Checker>(); });

} // namespace
} // namespace vitrine
