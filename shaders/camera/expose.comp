#version 460
#extension GL_GOOGLE_include_directive : require
#define EXPOSE_SHADER
#include "camera/meter.h"
#include "camera/exposure.h"
#include "post/aperture.glsl"

// camera.physical's exposure on the GPU, one workgroup after the metering reduction: the histogram's trimmed mean
// of log2 luminance (the twin of nodes/camera/metering.cpp's histogramMeanLog2), eye adaptation with its state kept
// in the buffer across frames, the program line (shaders/camera/exposure.h, shared with the CPU) and what follows
// from the chosen f-number, written to the CameraExposure the post nodes read.
layout(local_size_x = EXPOSE_GROUP) in;
layout(set = 1, binding = 1) readonly buffer Histogram { vec2 bins[]; };
layout(std430, set = 1, binding = 2) buffer Exposure { CameraExposure camera; };

shared float sArea[EXPOSE_GROUP];
shared float sRoundness;

// x: mean log2 Y over the weight between the fractions low and high of the total; y: 1 when there was any weight.
vec2 histogramMeanLog2(float low, float high) {
    float total = 0.0;
    for (int i = 0; i < METER_BINS; ++i) total += bins[i].x;
    if (!(total > 0.0)) return vec2(0.0);
    float lo = low * total, hi = high * total;
    float below = 0.0, weight = 0.0, sum = 0.0;
    for (int i = 0; i < METER_BINS; ++i) {
        vec2 b = bins[i];
        if (b.x <= 0.0) continue;
        float from = max(below, lo), to = min(below + b.x, hi);
        if (to > from) {
            float part = (to - from) / b.x;
            weight += part * b.x;
            sum += part * b.y;
        }
        below += b.x;
    }
    return weight > 0.0 ? vec2(sum / weight, 1.0) : vec2(0.0);
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid == 0u) {
        bool valid = (pc.flags & EXPOSE_RESET) == 0u && camera.adaptValid != 0u;
        float adapted = camera.adaptedEv100, last = camera.lastMeteredEv100;
        bool metered = false;
        float m = 0.0;
        if ((pc.flags & EXPOSE_METERED) != 0u) {
            vec2 mean = histogramMeanLog2(pc.meterLow, pc.meterHigh);
            if (mean.y > 0.0) {
                metered = true;
                m = cameraMeteredEv100(exp2(mean.x));
                last = m;
            }
        }
        if (!valid) {
            // Converged at once: the first metering (or the initial EV) is taken as it is.
            adapted = metered ? m : pc.initialEv100;
            if (!metered) last = adapted;
        } else {
            adapted = cameraAdapt(adapted, last, pc.dt, pc.tau);
        }

        CameraSettings s;
        if ((pc.flags & EXPOSE_MANUAL) != 0u) {
            s.fNumber = pc.manualFNumber;
            s.shutterSeconds = pc.manualShutter;
            s.iso = pc.iso;
            s.ev100 = cameraEv100Of(s.fNumber, s.shutterSeconds, s.iso);
        } else {
            s = cameraProgram(adapted - pc.compensation, pc.shift, pc.wideOpenFNumber, pc.minFNumber,
                              pc.shortestShutter, pc.longestShutter, pc.focalLengthMm, pc.iso,
                              (pc.flags & EXPOSE_AUTO_ISO) != 0u, pc.maxIso);
        }
        float stops = cameraStopsDown(s.fNumber, pc.wideOpenFNumber);
        camera.ev100 = s.ev100;
        camera.exposure = cameraExposureScale(s.ev100);
        camera.fNumber = s.fNumber;
        camera.shutterSeconds = s.shutterSeconds;
        camera.iso = s.iso;
        camera.meteredEv100 = adapted;
        camera.stopsDown = stops;
        camera.apertureRoundness = cameraApertureRoundness(stops, pc.bladeRoundness);
        camera.mechanicalVignetting = cameraMechanicalVignetting(pc.mechanicalWideOpen, stops);
        camera.adaptedEv100 = adapted;
        camera.lastMeteredEv100 = last;
        camera.adaptValid = 1u;
        sRoundness = camera.apertureRoundness;
    }
    barrier();
    // The aperture's area, 0.5 ∮ r(θ)² dθ by the midpoint rule over 4096 directions (core/scene/aperture.cpp's
    // apertureArea), spread over the group.
    const int kSteps = 4096;
    float sum = 0.0;
    for (int i = int(lid); i < kSteps; i += EXPOSE_GROUP) {
        float r = apertureBoundary(pc.blades, sRoundness, pc.bladeRotation, 6.28318530718 * (float(i) + 0.5) / float(kSteps));
        sum += 0.5 * r * r;
    }
    sArea[lid] = sum;
    barrier();
    for (uint k = EXPOSE_GROUP / 2; k > 0u; k >>= 1) {
        if (lid < k) sArea[lid] += sArea[lid + k];
        barrier();
    }
    if (lid == 0u) camera.apertureArea = sArea[0] * 6.28318530718 / float(kSteps);
}
