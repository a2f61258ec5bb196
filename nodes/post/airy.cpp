// post.airy: diffraction at the aperture (MUSEUM_SPEC §7): the image convolved with the Airy pattern of the lens's
// f-number, per wavelength, so stopping down softens the image and spreads bright points into rings.
#include "shaders/post/airy.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/camera/camera_state.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace vitrine {
namespace {

// The kernel reaches the fifth dark ring of the widest channel (x = 16.47, 4.3 first-zero radii): 96 % of the
// pattern's energy lies inside it.
constexpr float kRingsReach = 16.4706f / AIRY_FIRST_ZERO;

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.airy";
    s.doc = "Diffraction at a small aperture: the colour convolved, per channel, with the Airy pattern (2 J1(x) / x)^2 "
            "of a circular aperture whose first dark ring lies at 1.22 lambda N on the sensor (lambda per channel), "
            "in pixels from the sensor height; integrated over each pixel and normalised so energy is kept. Grows "
            "with the f-number: invisible wide open, a softening and rings around bright points stopped down.";
    s.inputs = {
        {"color", PortKind::Texture, {}, false, Usage::Sampled, "Linear HDR colour"},
        {"camera", PortKind::Camera, {}, true, Usage::Sampled,
         "The scene camera: its lens's f-number and sensor height when the params are 0"},
        {"camera_state", PortKind::Buffer, {}, true, Usage::Sampled,
         "camera.physical's state: its f-number and sensor height replace the params"},
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "The diffracted colour";
    OutputPort psf;
    psf.name = "psf";
    psf.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    psf.size = SizeRule::absolute(1, 1); // (2 max_radius + 1)^2, set in setup()
    psf.usage = Usage::StorageReadWrite;
    psf.doc = "The kernel (rgb per channel, unnormalised, centred; zero beyond this frame's radius)";
    s.outputs = {color, psf};
    s.params = {
        {"f_number", ParamType::Float, 0.0, 0.0, 256.0, {}, "f-number N. 0: the camera's (camera_state or camera)"},
        {"sensor_height", ParamType::Float, 0.0, 0.0, 1000.0, {},
         "Sensor height in mm (the image's height on it gives the pixel pitch). 0: the camera's"},
        {"wavelengths", ParamType::Vec3, nlohmann::json::array({630.0, 532.0, 465.0}), {}, {}, {},
         "Wavelength of R, G and B in nm"},
        {"scale", ParamType::Float, 1.0, 0.0, 1000.0, {}, "Multiplies the pattern's size (1: physical)"},
        {"max_radius", ParamType::Int, 8, 1.0, 32.0, {}, "Largest kernel half-size in pixels (cost: (2r + 1)^2 taps)"},
        {"supersample", ParamType::Int, 4, 1.0, 16.0, {}, "Points per axis integrating the pattern over a pixel"},
    };
    return s;
}

class Airy final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        if (ctx.hasInput("camera")) mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.hasInput("camera_state")) mState = ctx.objectAs<CameraStateObject>("camera_state");
        if (!mCamera && !mState && p.getFloat("f_number") <= 0.0f)
            ctx.failParam("f_number", "is 0 (the camera's) but neither camera nor camera_state is connected");
        if (!mCamera && !mState && p.getFloat("sensor_height") <= 0.0f)
            ctx.failParam("sensor_height", "is 0 (the camera's) but neither camera nor camera_state is connected");
        const glm::vec3 lambda = p.getVec3("wavelengths");
        if (glm::any(glm::lessThan(lambda, glm::vec3(300.0f))) || glm::any(glm::greaterThan(lambda, glm::vec3(1000.0f))))
            ctx.failParam("wavelengths", "expected three wavelengths in nm between 300 and 1000");
        const int maxRadius = p.getInt("max_radius");
        ImageDesc& psf = ctx.output("psf");
        psf.width = psf.height = static_cast<uint32_t>(2 * maxRadius + 1);
        // The camera's f-number is read on the GPU, by both passes.
        mGpuFNumber = mState && p.getFloat("f_number") <= 0.0f;
        const ShaderDefines defines = cameraExposureDefines(mGpuFNumber);
        mPsf = ctx.computePipeline("post/airy_psf.comp", defines, mGpuFNumber ? 1 : 0);
        mConvolve = ctx.computePipeline("post/airy.comp", defines, mGpuFNumber ? 1 : 0);
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        float fNumber = p.getFloat("f_number"), sensorMm = p.getFloat("sensor_height");
        if (mState) {
            fNumber = fNumber > 0.0f ? fNumber : 1.0f; // mGpuFNumber: per unit f-number, the shader multiplies
            sensorMm = sensorMm > 0.0f ? sensorMm : mState->state.sensorHeightMm;
        }
        if (mCamera) {
            fNumber = fNumber > 0.0f ? fNumber : mCamera->current.state.lens.fNumber;
            sensorMm = sensorMm > 0.0f ? sensorMm : mCamera->current.state.lens.sensorHeightMm;
        }
        const ImageDesc& out = ctx.output("color").desc();
        const float pitchNm = sensorMm * 1e6f / static_cast<float>(out.height);
        const glm::vec3 lambda = p.getVec3("wavelengths");
        gpu_types::AiryPush push{};
        push.firstZero = glm::vec4(1.21967f * lambda * fNumber / pitchNm * p.getFloat("scale"), 0.0f);
        push.maxRadius = p.getInt("max_radius");
        const float widest = std::max({push.firstZero.x, push.firstZero.y, push.firstZero.z});
        push.radius = mGpuFNumber ? push.maxRadius
                                  : std::clamp(static_cast<int>(std::ceil(kRingsReach * widest)), 1, push.maxRadius);
        push.supersample = static_cast<uint32_t>(p.getInt("supersample"));
        const uint32_t side = static_cast<uint32_t>(2 * push.maxRadius + 1);
        const CameraStateObject* camera = mGpuFNumber ? mState.get() : nullptr;
        dispatchWithCamera(ctx, camera, mPsf, push, side, side);
        ctx.computeBarrier();
        dispatchWithCamera(ctx, camera, mConvolve, push, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<CameraStateObject> mState;
    bool mGpuFNumber = false;
    PipelineId mPsf = 0, mConvolve = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Airy>(); });

} // namespace
} // namespace vitrine
