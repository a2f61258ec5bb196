#include "nodes/camera/camera_state.hpp"

#include "core/scene/aperture.hpp"

#include <algorithm>
#include <cstring>

namespace vitrine {

gpu_types::CameraExposure exposureOf(const CameraState& s) {
    gpu_types::CameraExposure e{};
    e.ev100 = s.ev100;
    e.exposure = s.exposure;
    e.fNumber = s.fNumber;
    e.shutterSeconds = s.shutterSeconds;
    e.iso = s.iso;
    e.meteredEv100 = s.meteredEv100;
    e.stopsDown = gpu_types::cameraStopsDown(s.fNumber, s.wideOpenFNumber);
    const scene::ApertureShape shape =
        scene::apertureAt(static_cast<uint32_t>(std::max(0, s.bladeCount)), s.bladeRoundness, s.bladeRotation,
                          s.fNumber, s.wideOpenFNumber);
    e.apertureRoundness = shape.roundness;
    e.apertureArea = scene::apertureArea(shape);
    e.mechanicalVignetting = s.mechanicalVignetting;
    return e;
}

void CameraStateObject::ensureGpu(Context& gpu) {
    if (mBuffer) return;
    mBuffer = GpuBuffer(gpu, sizeof(gpu_types::CameraExposure), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                        "camera_state.exposure");
    std::memset(mBuffer.mapped(), 0, sizeof(gpu_types::CameraExposure));
    const std::array<VkBuffer, 1> buffers = {mBuffer.buffer()};
    mSet = StorageBufferSet(gpu, buffers, VK_SHADER_STAGE_COMPUTE_BIT, "camera_state.exposure");
}

void CameraStateObject::writeExposureFromCpu() {
    gpu_types::CameraExposure e = exposureOf(state);
    const gpu_types::CameraExposure old = gpuExposure();
    e.adaptedEv100 = old.adaptedEv100;
    e.lastMeteredEv100 = old.lastMeteredEv100;
    e.adaptValid = old.adaptValid;
    std::memcpy(mBuffer.mapped(), &e, sizeof e);
}

gpu_types::CameraExposure CameraStateObject::gpuExposure() const {
    gpu_types::CameraExposure e{};
    if (mBuffer) std::memcpy(&e, mBuffer.mapped(), sizeof e);
    return e;
}

CameraState CameraStateObject::resolved() const {
    CameraState s = state;
    if (cpuExposure || !mBuffer) return s;
    const gpu_types::CameraExposure e = gpuExposure();
    s.ev100 = e.ev100;
    s.exposure = e.exposure;
    s.fNumber = e.fNumber;
    s.shutterSeconds = e.shutterSeconds;
    s.iso = e.iso;
    s.meteredEv100 = e.meteredEv100;
    s.mechanicalVignetting = e.mechanicalVignetting;
    return s;
}

void CameraStateObject::releaseGpu() {
    mSet = StorageBufferSet();
    mBuffer = GpuBuffer();
}

} // namespace vitrine
