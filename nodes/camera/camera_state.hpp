#pragma once
// The physical camera's state for one frame: what `camera.physical` hands the post stack on its `state`
// port (a Buffer-kind object, like shadow.directional's `cascades`). Consumers (post.tonemap, post.dof,
// post.airy, post.lens, post.streaks, post.flare, post.grain, post.motion_blur) take an optional `camera_state`
// input; connected, its values replace the node's own lens/exposure params, so that changing the light
// changes aperture, bokeh shape and streaks by itself (MUSEUM_SPEC §7).
// Two halves: the metering-independent fields (lens, sensor, aperture shape) are filled on the CPU in the
// producer's execute() and read by consumers in theirs (push constants); the metering-dependent ones (EV, exposure,
// f-number, shutter, ISO and what follows from the f-number) live in a small GPU buffer
// (shaders/camera/exposure.h's CameraExposure) that camera.physical writes on the GPU after metering and that
// the consumers' shaders read (bound at set 1, compiled with CAMERA_EXPOSURE), so no frame waits for a readback.
#include "core/gpu/buffer_set.hpp"
#include "core/gpu/resources.hpp"
#include "core/graph/node.hpp"
#include "shaders/camera/exposure.h"

#include <array>

namespace vitrine {

struct CameraState {
    // Exposure. ev100: the exposure value at ISO 100 the camera settled on (metered scene EV after
    // compensation and eye adaptation). exposure: the linear scale post.tonemap multiplies HDR radiance
    // (cd/m²) by before its curve, 1 / (1.2 · 2^ev100) (saturation-based sensitivity, Lagarde & de Rousiers 2014).
    float ev100 = 13.0f;
    float exposure = 1.0f / (1.2f * 8192.0f);
    // The exposure triangle chosen (program mode) or set (manual mode).
    float fNumber = 4.0f;
    float shutterSeconds = 1.0f / 125.0f;
    float iso = 100.0f;
    // Optics. focalLengthMm: after focus breathing. sensor: the film back (mm); the vertical field of view
    // the scene camera renders with is the consumer's business (it comes from the camera port).
    float focalLengthMm = 50.0f;
    float focusDistanceM = 5.0f;
    float sensorWidthMm = 36.0f;
    float sensorHeightMm = 24.0f;
    // Aperture shape: bladeCount blades (0: a circle), bladeRoundness 0 (straight blades: a polygon) .. 1
    // (a circle); rotation of the first blade in radians. wideOpenFNumber: the lens's maximum aperture at this
    // focal length; at fNumber == wideOpenFNumber the aperture is round (the blades are out of the way).
    int bladeCount = 9;
    float bladeRoundness = 0.5f;
    float bladeRotation = 0.0f;
    float wideOpenFNumber = 1.8f;
    float minFNumber = 22.0f; // the smallest aperture (largest f-number) the lens stops down to
    // Residual lens aberrations after the lens's own correction (data/lenses/*.json), for post.lens:
    // radial distortion r_d = r (1 + k1 r² + k2 r⁴), r normalised to the half-diagonal; lateral chromatic
    // aberration as the red and blue channels' radial scale relative to green (1 = none).
    float distortionK1 = 0.0f;
    float distortionK2 = 0.0f;
    float caRedScale = 1.0f;
    float caBlueScale = 1.0f;
    // Mechanical vignetting strength of this lens at this aperture (0: none); natural cos⁴ falloff follows
    // from the focal length and sensor.
    float mechanicalVignetting = 0.0f;
    // Appended by camera.physical: the scene's EV100 as metered and eye-adapted, before exposure compensation
    // (ev100 above is what the chosen settings expose for; the two differ by the compensation, by manual settings,
    // or where the program ran out of aperture/shutter/ISO range).
    float meteredEv100 = 13.0f;
};

class CameraStateObject final : public PortObject {
public:
    // The metering-independent fields always; the metering-dependent ones only where the producer computed them on
    // the CPU (cpuExposure: test.camera_state, camera.physical's manual mode or `readback` debug modes). Otherwise
    // resolved() reads them back from the GPU buffer once the frame has completed (tests, logs).
    CameraState state;
    uint32_t frame = 0; // the frame state was last written for
    bool cpuExposure = true;

    // Called by the producer in its execute(): creates the exposure buffer (host-visible, 64 bytes) and its set.
    void ensureGpu(Context& gpu);
    // Writes the metering-dependent fields of `state` (and what follows from them) into the buffer from the CPU.
    // Only while the GPU is not using it: the graph runs one frame in flight and records before it submits.
    void writeExposureFromCpu();
    // `state` with the metering-dependent fields of the buffer (valid after the frame completed).
    CameraState resolved() const;
    gpu_types::CameraExposure gpuExposure() const;

    // For consumers: the buffer's set (binding 0, compute) to bind at set 1 with ExecuteContext::dispatchWithSets.
    std::array<VkDescriptorSetLayout, 1> layouts() const { return {mSet.layout()}; }
    std::array<VkDescriptorSet, 1> sets() const { return {mSet.set()}; }
    VkBuffer buffer() const { return mBuffer.buffer(); }

    void releaseGpu() override;

private:
    GpuBuffer mBuffer;
    StorageBufferSet mSet;
};

// The CameraExposure a CameraState amounts to (stopsDown, roundness, aperture area and mechanical vignetting
// derived from its f-number); eye adaptation's fields zero.
gpu_types::CameraExposure exposureOf(const CameraState& s);

// For consumers: the shader define that makes a shader read the camera's buffer (shaders/camera/exposure.glsl).
inline ShaderDefines cameraExposureDefines(bool connected) {
    return connected ? ShaderDefines{{"CAMERA_EXPOSURE", "1"}} : ShaderDefines{};
}

// For consumers: dispatches `pipeline` (made with cameraExposureDefines(camera != nullptr) and nodeSets 1 when
// camera is set) with the camera's exposure buffer at set 1, or plainly without a camera.
template <typename T>
void dispatchWithCamera(ExecuteContext& ctx, const CameraStateObject* camera, PipelineId pipeline, const T& push,
                        uint32_t width, uint32_t height) {
    if (!camera) return ctx.dispatch(pipeline, push, width, height);
    const auto layouts = camera->layouts();
    const auto sets = camera->sets();
    ctx.dispatchWithSets(pipeline, &push, static_cast<uint32_t>(sizeof(T)), width, height, layouts, sets);
}

} // namespace vitrine
