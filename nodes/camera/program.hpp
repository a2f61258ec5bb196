#pragma once
// The exposure maths of camera.physical on the CPU (unit-tested in tests/unit/camera): the reflected-light meter's
// calibration, exposure value <-> linear exposure scale, and the program line that picks aperture, shutter and
// (auto) ISO from a metered EV. Thin wrappers of shaders/camera/exposure.h, which the GPU path runs as well (one
// source of truth). The curve is documented in the README ("Physical camera").

namespace vitrine::camera {

// The photographic limits a program works within.
struct ProgramLimits {
    float wideOpenFNumber = 1.8f;  // the lens's maximum aperture at this focal length
    float minFNumber = 22.0f;      // its smallest aperture (largest f-number)
    float shortestShutter = 1.0f / 8000.0f;
    float longestShutter = 30.0f;
    float focalLengthMm = 50.0f;   // sets the hand-held shutter speed 1 / max(60, f) s
    float iso = 100.0f;            // fixed ISO, or the base ISO with autoIso
    bool autoIso = false;
    float maxIso = 6400.0f;        // auto ISO's ceiling
};

// An exposure triangle and the EV100 it amounts to.
struct ExposureSettings {
    float fNumber = 4.0f;
    float shutterSeconds = 1.0f / 125.0f;
    float iso = 100.0f;
    float ev100 = 0.0f; // log2(N² / t) − log2(S / 100): what the settings expose for
};

// Reflected-light meter calibration constant K (ISO 2720; Canon, Nikon and Sekonic use 12.5).
inline constexpr float kMeterCalibration = 12.5f;

// EV100 a meter reads for a scene whose (log-)average luminance is `luminance` cd/m²: log2(L · 100 / K).
float meteredEv100(float luminance);

// EV100 of a set of settings.
float ev100Of(float fNumber, float shutterSeconds, float iso);

// The linear scale post.tonemap multiplies scene radiance (cd/m²) by: 1 / (1.2 · 2^ev100), the saturation-based
// sensitivity's maximum luminance (Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", §5.1).
float exposureScale(float ev100);

// Program mode: settings for a scene that should be exposed at targetEv100 (the metered EV minus exposure
// compensation), moved along the line of equal exposure by `shift` stops (positive: smaller aperture, longer
// shutter). Where the limits cannot reach targetEv100 the result's ev100 differs from it (under/over exposure).
ExposureSettings programExposure(float targetEv100, float shift, const ProgramLimits& limits);

} // namespace vitrine::camera
