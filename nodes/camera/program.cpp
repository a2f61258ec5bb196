#include "nodes/camera/program.hpp"

#include "shaders/camera/exposure.h"

namespace vitrine::camera {

float meteredEv100(float luminance) { return gpu_types::cameraMeteredEv100(luminance); }

float ev100Of(float fNumber, float shutterSeconds, float iso) { return gpu_types::cameraEv100Of(fNumber, shutterSeconds, iso); }

float exposureScale(float ev100) { return gpu_types::cameraExposureScale(ev100); }

// The program line itself is shaders/camera/exposure.h's cameraProgram, which the GPU runs too.
ExposureSettings programExposure(float targetEv100, float shift, const ProgramLimits& limits) {
    const gpu_types::CameraSettings c = gpu_types::cameraProgram(
        targetEv100, shift, limits.wideOpenFNumber, limits.minFNumber, limits.shortestShutter, limits.longestShutter,
        limits.focalLengthMm, limits.iso, limits.autoIso, limits.maxIso);
    ExposureSettings s;
    s.fNumber = c.fNumber;
    s.shutterSeconds = c.shutterSeconds;
    s.iso = c.iso;
    s.ev100 = c.ev100;
    return s;
}

} // namespace vitrine::camera
