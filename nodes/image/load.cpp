// image.load: a PNG/JPEG/HDR/EXR file as a texture, uploaded once.
#include "core/base/error.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "image.load";
    s.doc = "Loads an image file (PNG, JPEG, Radiance HDR, OpenEXR) into a linear texture of the file's size.";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.usage = Usage::TransferDst;
    out.persistent = true;
    out.doc = "The image, scene-linear";
    s.outputs = {out};
    s.params = {
        {"path", ParamType::Path, "", {}, {}, {}, "Image file, relative to the graph file"},
        {"colorspace", ParamType::String, "auto", {}, {}, {},
         "OCIO colour space of the file; auto: sRGB for 8/16-bit files, linear for HDR/EXR"},
        {"layer", ParamType::String, "", {}, {}, {}, "EXR layer to read (empty: the default RGBA layer)"},
        {"format", ParamType::Enum, "rgba32f", {}, {}, {"rgba16f", "rgba32f"}, "Texture format"},
    };
    return s;
}

class Load final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        std::string path = p.getString("path");
        if (path.empty()) ctx.failParam("path", "expected the path of an image file");
        std::filesystem::path file = ctx.resolvePath(path);
        try {
            mImage = p.getString("layer").empty() ? loadImage(file, p.getString("colorspace"))
                                                  : loadExrLayer(file, p.getString("layer"));
        } catch (const UserError& e) {
            ctx.failParam("path", e.what());
        }
        ImageDesc& out = ctx.output("color");
        out.width = static_cast<uint32_t>(mImage.width);
        out.height = static_cast<uint32_t>(mImage.height);
        out.format = p.getString("format") == "rgba16f" ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R32G32B32A32_SFLOAT;
    }
    void execute(ExecuteContext& ctx) override {
        // The output is persistent: one upload serves every frame.
        if (ctx.frameIndex() == 0) ctx.upload("color", mImage);
    }

private:
    Image mImage;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Load>(); });

} // namespace
} // namespace vitrine
