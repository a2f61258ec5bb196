#include "tests/gpu/post_test_util.hpp"

#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "nodes/camera/camera_state.hpp"

#include <unistd.h>

#include <cmath>

namespace vitrine::test::post {

std::filesystem::path writeInput(const Image& img, const std::string& name) {
    static const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("vitrine_post_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::filesystem::path path = dir / (name + ".exr");
    writeExr(path, img, ExrPixelType::Float);
    return path;
}

nlohmann::json loadNode(const std::filesystem::path& path) {
    return {{"type", "image.load"}, {"params", {{"path", path.string()}}}};
}

nlohmann::json graph(nlohmann::json nodes, nlohmann::json outputs, int w, int h, int frames) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", w}, {"height", h}, {"frames", frames}, {"write", {frames - 1}}}},
            {"nodes", nodes},
            {"outputs", outputs}};
}

Blob centroid(const Image& img, double x, double y, double r, int c) {
    Blob b;
    double sx = 0.0, sy = 0.0;
    for (int j = std::max(0, int(y - r) - 1); j <= std::min(img.height - 1, int(y + r) + 1); ++j)
        for (int i = std::max(0, int(x - r) - 1); i <= std::min(img.width - 1, int(x + r) + 1); ++i) {
            double px = i + 0.5, py = j + 0.5;
            if ((px - x) * (px - x) + (py - y) * (py - y) > r * r) continue;
            double v = img.at(i, j)[c];
            b.sum += v;
            sx += v * px;
            sy += v * py;
        }
    if (b.sum != 0.0) {
        b.x = sx / b.sum;
        b.y = sy / b.sum;
    }
    return b;
}

namespace {

// test.camera_state: a CameraState from params, for the post nodes' camera_state input.
NodeSchema schema() {
    NodeSchema s;
    s.type = "test.camera_state";
    s.doc = "Test only: a fixed camera state";
    s.pass = PassKind::Transfer;
    OutputPort state;
    state.name = "state";
    state.kind = PortKind::Buffer;
    state.doc = "The state";
    s.outputs = {state};
    s.params = {
        {"shutter", ParamType::Float, 1.0 / 125.0, 0.0, 100.0, {}, ""},
        {"f_number", ParamType::Float, 4.0, 0.5, 64.0, {}, ""},
        {"wide_open", ParamType::Float, 1.8, 0.5, 64.0, {}, ""},
        {"blades", ParamType::Int, 9, 0.0, 32.0, {}, ""},
        {"exposure", ParamType::Float, 1.0, 0.0, 1e9, {}, ""},
        {"k1", ParamType::Float, 0.0, -1.0, 1.0, {}, ""},
        {"focal_length", ParamType::Float, 50.0, 1.0, 2000.0, {}, ""},
        {"mechanical", ParamType::Float, 0.0, 0.0, 2.0, {}, ""},
        {"focus_distance", ParamType::Float, 5.0, 0.01, 1e5, {}, ""},
        {"iso", ParamType::Float, 100.0, 25.0, 409600.0, {}, ""},
    };
    return s;
}

class TestCameraState final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        auto o = std::make_shared<CameraStateObject>();
        o->state.shutterSeconds = p.getFloat("shutter");
        o->state.fNumber = p.getFloat("f_number");
        o->state.wideOpenFNumber = p.getFloat("wide_open");
        o->state.bladeCount = p.getInt("blades");
        o->state.exposure = p.getFloat("exposure");
        o->state.distortionK1 = p.getFloat("k1");
        o->state.focalLengthMm = p.getFloat("focal_length");
        o->state.mechanicalVignetting = p.getFloat("mechanical");
        o->state.focusDistanceM = p.getFloat("focus_distance");
        o->state.iso = p.getFloat("iso");
        ctx.setObject("state", o);
        mState = o;
    }
    // The consumers' shaders read the metering-dependent fields from the GPU buffer: written from the CPU here.
    void execute(ExecuteContext& ctx) override {
        mState->ensureGpu(ctx.gpu());
        mState->writeExposureFromCpu();
        mState->frame = ctx.frameIndex();
    }

private:
    std::shared_ptr<CameraStateObject> mState;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<TestCameraState>(); });

} // namespace
} // namespace vitrine::test::post
