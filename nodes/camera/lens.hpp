#pragma once
// Lens data for camera.physical: one JSON file per lens type in data/lenses/ (format `vitrine-lens/1`, described
// in data/lenses/README.md), loaded once at graph compile time, and what it says about the lens at a focal length,
// focus distance and aperture. CPU only; unit-tested in tests/unit/camera.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vitrine::camera {

struct Correction {
    enum class Type { None, Profile };
    Type type = Type::None;
    float strength = 0.0f; // Profile: the fraction of the aberration the camera removes (1: all of it)
    float residual() const { return type == Type::None ? 1.0f : 1.0f - strength; }
};

// One row of the per-focal-length aberration table (uncorrected values; linear interpolation between rows).
struct Aberrations {
    float focalMm = 0.0f;
    float k1 = 0.0f, k2 = 0.0f;             // r_d = r (1 + k1 r² + k2 r⁴), r: 1 at the half-diagonal
    float caRed = 1.0f, caBlue = 1.0f;      // radial scale of red / blue relative to green
    float vignettingStops = 0.0f;           // corner light loss wide open, natural cos⁴ included
};

struct LensData {
    std::string file; // for messages
    std::string name;
    float sensorWidthMm = 36.0f, sensorHeightMm = 24.0f; // the format the lens is made for
    float focalMinMm = 50.0f, focalMaxMm = 50.0f;
    std::vector<std::pair<float, float>> maxAperture; // (focal mm, wide-open f-number)
    std::vector<std::pair<float, float>> minAperture; // (focal mm, smallest aperture's f-number)
    float minFocusM = 0.35f;
    int blades = 7;
    float bladeRoundness = 0.5f;
    float focusBreathing = 0.0f; // relative change of the focal length at the closest focus (−0.1: 10 % shorter)
    std::vector<Aberrations> aberrations;
    Correction distortion, ca, vignetting;
};

// Parses a lens file; UserError naming the file, the JSON pointer and what was expected.
LensData loadLens(const std::filesystem::path& path);

// The lens file a `lens` param names: a path ending in .json (relative to graphDir), or the stem of a file in
// dataDir/lenses. UserError listing the shipped lenses when there is no such file.
std::filesystem::path findLens(const std::string& nameOrPath, const std::filesystem::path& graphDir,
                               const std::filesystem::path& dataDir);

// Piecewise-linear in focal length, clamped at the ends.
float interpolate(const std::vector<std::pair<float, float>>& table, float focalMm);

// The lens at one setting, as the post stack sees it (residual aberrations after the camera's correction).
struct LensState {
    float focalLengthMm = 50.0f; // after focus breathing
    float wideOpenFNumber = 1.8f;
    float minFNumber = 22.0f;
    float k1 = 0.0f, k2 = 0.0f;
    float caRed = 1.0f, caBlue = 1.0f;
    float mechanicalVignetting = 0.0f; // fraction of light the corner loses to mechanical vignetting
    float mechanicalWideOpen = 0.0f;   // the same wide open (the GPU fades it with the chosen aperture)
};

// focalMm within the lens's range; focusM ≥ the closest focus (clamped); fNumber the chosen aperture.
// Focus breathing: f' = f (1 + b m / m_min), m = f / (d − f) the thin-lens magnification at focus distance d and
// m_min the magnification at the closest focus. Mechanical vignetting: the part of the wide-open corner loss that
// the natural cos⁴ falloff (from the focal length and the half-diagonal of the format the lens is made for) does not explain, reduced by the
// camera's vignetting correction, and fading out linearly over the first two stops of stopping down.
LensState evaluateLens(const LensData& lens, float focalMm, float focusM, float fNumber);

} // namespace vitrine::camera
