#pragma once

#include "core/shading/sh.hpp"

#include <glm/glm.hpp>

#include <array>
#include <vector>

// An equirectangular HDR environment turned into what the sky nodes output (sky.hdri's CPU
// half): cube-map faces, SH9 of the environment without the sun, and the sun found in it.
//
// Equirect convention (Y up, the sky nodes' azimuth): column u in [0, 1] maps to azimuth
// 2 pi u - pi measured from -Z toward +X (the image centre looks down -Z, +X is at 3/4 of
// the width); row v (0 at the top) maps to elevation pi/2 - pi v.
namespace vitrine::shading {

glm::dvec3 equirectDirection(double u, double v);

struct SunEstimate {
    bool found = false;
    glm::dvec3 direction{0.0, 1.0, 0.0}; // toward the sun; the brightest pixel when not found
    glm::dvec3 illuminance{0.0};         // on a surface facing the sun; zero when not found
    double solidAngle = 0.0;             // of the pixels taken as the sun
};

struct EnvironmentBake {
    int size = 0;
    std::array<std::vector<float>, 6> faces; // RGBA, size x size, top row first, layer order +X -X +Y -Y +Z -Z
    Sh9 sh;                                  // radiance coefficients without the sun
    SunEstimate sun;
};

// The sun is the set of pixels connected (4-neighbours, wrapping in azimuth) to the brightest
// one whose luminance exceeds both kSunRegionFraction of the maximum and kSunMinContrast times
// the median; none is found when the maximum itself is not kSunMinContrast times the median
// (overcast skies, or HDRIs whose sun is clipped). Its illuminance is the integral of
// (L - L_ring) cos(angle to the sun) dw over those pixels, where L_ring is the mean radiance of
// the pixels bordering the region; for the SH the region is filled with L_ring, so the sky
// behind the sun is kept and nothing is counted twice.
inline constexpr double kSunRegionFraction = 0.01;
inline constexpr double kSunMinContrast = 100.0;

SunEstimate findSun(const float* rgba, int width, int height, std::vector<float>* withoutSun = nullptr);

// rgba: width x height linear RGBA, top row first, multiplied by `intensity`. The cube faces
// keep the sun unless sunInCubemap is false (then they are made from the sun-free image too).
EnvironmentBake bakeEquirect(const float* rgba, int width, int height, int faceSize, double intensity,
                             bool sunInCubemap);

} // namespace vitrine::shading
