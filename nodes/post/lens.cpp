// post.lens: radial distortion, lateral chromatic aberration, natural and mechanical vignetting.
#include "shaders/post/lens.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.lens";
    s.doc = "Lens imperfections, each on/off: radial distortion r_d = r (1 + k1 r^2 + k2 r^4) with r normalised to "
            "the half-diagonal (k1 < 0 barrel, > 0 pincushion); lateral chromatic aberration (the red and blue images "
            "scaled radially by ca_red / ca_blue relative to green); natural vignetting cos^4(field angle), "
            "tan = distance on the sensor / focal length; mechanical vignetting: the entrance pupil (radius "
            "wide-open f-number / f-number of the barrel's opening) clipped by that opening, offset by "
            "mechanical_vignetting opening radii at the frame corner (stops down away). camera_state, when "
            "connected, supplies k1, k2, the CA scales, focal length, sensor, f-numbers and the mechanical strength.";
    s.inputs = {
        {"color", PortKind::Texture, {}, false, Usage::Sampled, "Linear HDR colour"},
        {"camera_state",
         PortKind::Buffer,
         {},
         true,
         Usage::Sampled,
         "camera.physical's state: replaces the lens params (distortion, CA, focal length, sensor, aperture)"},
    };
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "The colour as the sensor sees it through the lens";
    s.outputs = {out};
    s.params = {
        {"distortion", ParamType::Bool, true, {}, {}, {}, "Apply radial distortion"},
        {"k1", ParamType::Float, -0.03, -1.0, 1.0, {}, "Radial distortion r^2 coefficient (negative: barrel)"},
        {"k2", ParamType::Float, 0.0, -1.0, 1.0, {}, "Radial distortion r^4 coefficient"},
        {"chromatic_aberration", ParamType::Bool, true, {}, {}, {}, "Apply lateral chromatic aberration"},
        {"ca_red", ParamType::Float, 1.001, 0.9, 1.1, {}, "Red image's radial scale relative to green"},
        {"ca_blue", ParamType::Float, 0.999, 0.9, 1.1, {}, "Blue image's radial scale relative to green"},
        {"vignetting", ParamType::Bool, true, {}, {}, {}, "Natural vignetting: cos^4 of the field angle"},
        {"focal_length", ParamType::Float, 35.0, 1.0, 2000.0, {}, "Focal length in mm (natural vignetting)"},
        {"sensor_width", ParamType::Float, 36.0, 1.0, 200.0, {}, "Sensor width in mm; it spans the image's width"},
        {"mechanical_vignetting",
         ParamType::Float,
         0.6,
         0.0,
         2.0,
         {},
         "Offset of the barrel's opening at the frame corner, in its radii (0: off)"},
        {"f_number", ParamType::Float, 2.8, 0.5, 64.0, {}, "Aperture (mechanical vignetting)"},
        {"wide_open",
         ParamType::Float,
         1.8,
         0.5,
         64.0,
         {},
         "The lens's maximum aperture: its pupil fills the barrel's opening (mechanical vignetting)"},
    };
    return s;
}

class Lens final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        if (p.getFloat("f_number") < p.getFloat("wide_open"))
            ctx.failParam("f_number", "must be >= wide_open (" + std::to_string(p.getFloat("wide_open")) +
                                          "): a lens does not open wider than its maximum aperture");
        // The distortion must be invertible over the frame (and a little beyond, for the CA scales): r_d(r) increasing.
        const float k1 = p.getFloat("k1"), k2 = p.getFloat("k2");
        for (float r = 0.0f; r <= 1.2f; r += 0.01f)
            if (1.0f + 3.0f * k1 * r * r + 5.0f * k2 * r * r * r * r <= 0.0f)
                ctx.failParam("k1",
                              "k1 = " + std::to_string(k1) + ", k2 = " + std::to_string(k2) +
                                  " fold the image over itself (r (1 + k1 r^2 + k2 r^4) stops increasing at r = " +
                                  std::to_string(r) + " half-diagonals); expected a monotonic distortion");
        if (ctx.hasInput("camera_state")) mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        mPipeline = ctx.computePipeline("post/lens.comp", cameraExposureDefines(mCamera != nullptr), mCamera ? 1 : 0);
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        const ImageDesc& out = ctx.output("color").desc();
        gpu_types::LensPush push{};
        push.centre = glm::vec2(0.5f * out.width, 0.5f * out.height);
        push.halfDiagonal = 0.5f * std::hypot(static_cast<float>(out.width), static_cast<float>(out.height));
        push.k1 = p.getFloat("k1");
        push.k2 = p.getFloat("k2");
        push.caRed = p.getFloat("ca_red");
        push.caBlue = p.getFloat("ca_blue");
        float focal = p.getFloat("focal_length"), sensor = p.getFloat("sensor_width");
        float fNumber = p.getFloat("f_number"), wideOpen = p.getFloat("wide_open");
        push.mechanical = p.getFloat("mechanical_vignetting");
        if (mCamera) {
            const CameraState& s = mCamera->state;
            push.k1 = s.distortionK1;
            push.k2 = s.distortionK2;
            push.caRed = s.caRedScale;
            push.caBlue = s.caBlueScale;
            focal = s.focalLengthMm;
            sensor = s.sensorWidthMm;
            // The f-number and the mechanical vignetting at it are the camera's, which the shader reads on the GPU.
            fNumber = 1.0f;
            wideOpen = s.wideOpenFNumber;
            push.mechanical = 1.0f;
        }
        push.mmPerPixel = sensor / static_cast<float>(out.width);
        push.focalMm = focal;
        push.pupil = mCamera ? wideOpen : std::clamp(wideOpen / std::max(fNumber, 1e-3f), 1e-3f, 1.0f);
        push.flags = (p.getBool("distortion") ? LENS_DISTORTION : 0u) |
                     (p.getBool("chromatic_aberration") ? LENS_CA : 0u) |
                     (p.getBool("vignetting") ? LENS_NATURAL_VIGNETTING : 0u) |
                     (push.mechanical > 0.0f ? LENS_MECHANICAL_VIGNETTING : 0u);
        dispatchWithCamera(ctx, mCamera.get(), mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    std::shared_ptr<CameraStateObject> mCamera;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Lens>(); });

} // namespace
} // namespace vitrine
