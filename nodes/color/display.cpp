// color.display: the OpenColorIO display/view transform on the GPU (display-encoded output).
#include "core/base/error.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/color.hpp"
#include "core/shader/compiler.hpp"

#include <fstream>
#include <sstream>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "color.display";
    s.doc = "OpenColorIO display transform (config data/ocio/config.ocio or $VITRINE_OCIO) evaluated on the GPU "
            "from the GLSL OCIO generates: the same transform `vitrine run` applies to PNGs on the CPU.";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Colour in the `source` colour space"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "Display-encoded colour (e.g. sRGB-encoded values in [0, 1])";
    s.outputs = {out};
    s.params = {
        {"source", ParamType::String, "scene_linear", {}, {}, {}, "OCIO colour space (or role) of the input"},
        {"display", ParamType::String, "sRGB", {}, {}, {}, "OCIO display"},
        {"view", ParamType::String, "Standard", {}, {}, {}, "OCIO view of that display"},
    };
    return s;
}

class Display final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        const ColorConfig& config = ColorConfig::builtin();
        if (!config.hasColorSpace(p.getString("source")))
            ctx.failParam("source", "no colour space '" + p.getString("source") + "' in " + config.file().string());
        std::string glsl;
        try {
            glsl = config.displayShaderGlsl(p.getString("source"), p.getString("display"), p.getString("view"), "OCIODisplay");
        } catch (const UserError& e) {
            ctx.failParam("display", e.what());
        }
        std::filesystem::path body = defaultShaderDir() / "color/display.comp.in";
        std::ifstream in(body);
        if (!in) throw InternalError(body.string() + ": cannot read the color.display shader body");
        std::stringstream ss;
        ss << in.rdbuf();
        mPipeline = ctx.computePipelineSource("color/display.comp (OCIO " + p.getString("display") + "/" +
                                                  p.getString("view") + ")",
                                              "#version 460\n" + glsl + "\n" + ss.str());
    }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Display>(); });

} // namespace
} // namespace vitrine
