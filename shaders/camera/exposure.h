// camera.physical's exposure, shared by C++ (nodes/camera/) and GLSL (shaders/camera/expose.comp and the post
// nodes that read it): the buffer the camera writes on the GPU every frame (the metering-dependent half of
// nodes/camera/camera_state.hpp's CameraState) and the exposure maths, written once in the common subset of C++
// and GLSL so that the CPU (tests, `readback` debug modes) and the GPU compute the same thing.
#ifndef CAMERA_EXPOSURE_H
#define CAMERA_EXPOSURE_H
#include "../common/shared.h"

#ifdef __cplusplus
#include <glm/glm.hpp>
#define CAMERA_FN inline
namespace vitrine::gpu_types {
using glm::clamp;
using glm::exp;
using glm::exp2;
using glm::log2;
using glm::max;
using glm::min;
#else
#define CAMERA_FN
#endif

// std430, scalars only (C++ and GLSL agree). Binding 0 of the set consumers bind at set 1.
struct CameraExposure {
    float ev100;          // what the chosen settings expose for
    float exposure;       // 1 / (1.2 · 2^ev100): post.tonemap's scale of radiance (cd/m²)
    float fNumber;
    float shutterSeconds;
    float iso;
    float meteredEv100;   // the scene's EV100 as metered and eye-adapted, before compensation
    float stopsDown;      // log2(fNumber / wide-open f-number) ≥ 0 (half the stops of light): how far the blades are in
    float apertureRoundness; // core/scene/aperture.cpp's apertureAt(...).roundness at fNumber
    float apertureArea;   // area of that unit-circumradius aperture shape (post.dof's normalisation)
    float mechanicalVignetting; // nodes/camera/lens.cpp's mechanical vignetting at fNumber
    // Eye adaptation's state across frames (camera.physical's GPU path): the adapted EV, the last metering, and
    // 1 once either holds a value.
    float adaptedEv100;
    float lastMeteredEv100;
    uint adaptValid;
    uint pad0;
    uint pad1;
    uint pad2;
};

// Reflected-light meter calibration K (ISO 2720; Canon, Nikon and Sekonic use 12.5).
#define CAMERA_METER_CALIBRATION 12.5f

// EV100 a meter reads for a scene of (log-)average luminance `luminance` cd/m²: log2(L · 100 / K).
CAMERA_FN float cameraMeteredEv100(float luminance) {
    return log2(max(luminance, 1e-9f) * 100.0f / CAMERA_METER_CALIBRATION);
}

// EV100 of a set of settings.
CAMERA_FN float cameraEv100Of(float fNumber, float shutterSeconds, float iso) {
    return log2(fNumber * fNumber / shutterSeconds) - log2(iso / 100.0f);
}

// 1 / (1.2 · 2^ev100), the saturation-based sensitivity's maximum luminance (Lagarde & de Rousiers 2014, §5.1).
CAMERA_FN float cameraExposureScale(float ev100) { return 1.0f / (1.2f * exp2(ev100)); }

// Eye adaptation over one frame of dt seconds with time constant tau: the EV moves 1 − exp(−dt/τ) of the way
// from `adapted` to `metered` (tau 0: at once).
CAMERA_FN float cameraAdapt(float adapted, float metered, float dt, float tau) {
    float keep = tau > 0.0f ? exp(-dt / tau) : 0.0f;
    return metered + (adapted - metered) * keep;
}

struct CameraSettings {
    float fNumber;
    float shutterSeconds;
    float iso;
    float ev100; // log2(N² / t) − log2(S / 100): what the settings expose for
};

// Program mode (README "Physical camera"). In APEX terms (Av = 2 log2 N, Tv = −log2 t, E = Av + Tv):
//   1. auto ISO raises the ISO above its base only as far as keeps the shutter at the hand-held speed
//      Tv_h = log2(max(60, f)) with the lens wide open, up to maxIso;
//   2. E ≤ Av_open + Tv_h: wide open, the shutter takes the rest (down to the longest shutter);
//   3. above that knee the line climbs diagonally, half a stop of aperture and half a stop of shutter per EV,
//      until the smallest aperture; then the shutter alone (up to the shortest shutter), then overexposure;
//   4. a program shift P moves (Av, Tv) to (Av + P, Tv − P), clamped so that both stay within their limits.
CAMERA_FN CameraSettings cameraProgram(float targetEv100, float shift, float wideOpenFNumber, float minFNumber,
                                       float shortestShutter, float longestShutter, float focalLengthMm, float baseIso,
                                       bool autoIso, float maxIso) {
    float avOpen = 2.0f * log2(wideOpenFNumber);
    float avMin = max(avOpen, 2.0f * log2(minFNumber));
    float tvLo = -log2(longestShutter);
    float tvHi = -log2(shortestShutter);
    float tvHand = clamp(log2(max(60.0f, focalLengthMm)), tvLo, tvHi);
    float knee = avOpen + tvHand;

    float iso = baseIso;
    if (autoIso) {
        float atBase = targetEv100 + log2(baseIso / 100.0f);
        if (atBase < knee) iso = min(maxIso, baseIso * exp2(knee - atBase));
    }
    float e = targetEv100 + log2(iso / 100.0f);

    float av = avOpen;
    float tv = e - avOpen;
    if (e > knee) {
        av = avOpen + 0.5f * (e - knee);
        tv = tvHand + 0.5f * (e - knee);
        if (av > avMin) {
            av = avMin;
            tv = e - avMin;
        }
        if (tv > tvHi) {
            tv = tvHi;
            av = min(e - tvHi, avMin);
        }
    }
    tv = clamp(tv, tvLo, tvHi);

    // The shift keeps the exposure: only within the range where both aperture and shutter can follow.
    float lo = max(avOpen, av + tv - tvHi);
    float hi = min(avMin, av + tv - tvLo);
    if (shift != 0.0f && lo <= hi) {
        float shifted = clamp(av + shift, lo, hi);
        tv -= shifted - av;
        av = shifted;
    }

    CameraSettings s;
    s.fNumber = exp2(0.5f * av);
    s.shutterSeconds = exp2(-tv);
    s.iso = iso;
    s.ev100 = av + tv - log2(iso / 100.0f);
    return s;
}

// log2(N / N_open), clamped at 0: how far the aperture is closed from wide open, in the unit of
// core/scene/aperture.cpp's apertureAt (one unit = two stops of light).
CAMERA_FN float cameraStopsDown(float fNumber, float wideOpenFNumber) {
    return max(0.0f, log2(max(fNumber, 1e-3f) / max(wideOpenFNumber, 1e-3f)));
}

// Blade roundness at an aperture: round wide open, the lens's bladeRoundness from one stop down on
// (core/scene/aperture.cpp's apertureAt).
CAMERA_FN float cameraApertureRoundness(float stopsDown, float bladeRoundness) {
    return 1.0f - clamp(stopsDown, 0.0f, 1.0f) * (1.0f - clamp(bladeRoundness, 0.0f, 1.0f));
}

// Mechanical vignetting at an aperture: the wide-open value fading out linearly over the first two stops
// (nodes/camera/lens.cpp's evaluateLens).
CAMERA_FN float cameraMechanicalVignetting(float wideOpenValue, float stopsDown) {
    return wideOpenValue * clamp(1.0f - stopsDown, 0.0f, 1.0f);
}

#ifdef __cplusplus
static_assert(sizeof(CameraExposure) == 64);
} // namespace vitrine::gpu_types
#endif
#undef CAMERA_FN
#endif
