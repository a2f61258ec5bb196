#include "nodes/camera/program.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::camera {

float meteredEv100(float luminance) { return std::log2(std::max(luminance, 1e-9f) * 100.0f / kMeterCalibration); }

float ev100Of(float fNumber, float shutterSeconds, float iso) {
    return std::log2(fNumber * fNumber / shutterSeconds) - std::log2(iso / 100.0f);
}

float exposureScale(float ev100) { return 1.0f / (1.2f * std::exp2(ev100)); }

// In APEX terms (Av = 2 log2 N, Tv = −log2 t, E = Av + Tv = the EV at the chosen ISO):
//   1. auto ISO raises the ISO above its base only as far as keeps the shutter at the hand-held speed
//      Tv_h = log2(max(60, f)) with the lens wide open, up to maxIso;
//   2. E ≤ Av_open + Tv_h: wide open, the shutter takes the rest (down to the longest shutter);
//   3. above that knee the line climbs diagonally, half a stop of aperture and half a stop of shutter per EV,
//      until the smallest aperture; then the shutter alone (up to the shortest shutter), then overexposure;
//   4. a program shift P moves (Av, Tv) to (Av + P, Tv − P), clamped so that both stay within their limits.
ExposureSettings programExposure(float targetEv100, float shift, const ProgramLimits& limits) {
    const float avOpen = 2.0f * std::log2(limits.wideOpenFNumber);
    const float avMin = std::max(avOpen, 2.0f * std::log2(limits.minFNumber));
    const float tvLo = -std::log2(limits.longestShutter);
    const float tvHi = -std::log2(limits.shortestShutter);
    const float tvHand = std::clamp(std::log2(std::max(60.0f, limits.focalLengthMm)), tvLo, tvHi);
    const float knee = avOpen + tvHand;

    float iso = limits.iso;
    if (limits.autoIso) {
        const float atBase = targetEv100 + std::log2(limits.iso / 100.0f);
        if (atBase < knee) iso = std::min(limits.maxIso, limits.iso * std::exp2(knee - atBase));
    }
    const float e = targetEv100 + std::log2(iso / 100.0f);

    float av = avOpen, tv = e - avOpen;
    if (e > knee) {
        av = avOpen + 0.5f * (e - knee);
        tv = tvHand + 0.5f * (e - knee);
        if (av > avMin) av = avMin, tv = e - avMin;
        if (tv > tvHi) tv = tvHi, av = std::min(e - tvHi, avMin);
    }
    tv = std::clamp(tv, tvLo, tvHi);

    // The shift keeps the exposure: only within the range where both aperture and shutter can follow.
    const float lo = std::max(avOpen, av + tv - tvHi), hi = std::min(avMin, av + tv - tvLo);
    if (shift != 0.0f && lo <= hi) {
        const float shifted = std::clamp(av + shift, lo, hi);
        tv -= shifted - av;
        av = shifted;
    }

    ExposureSettings s;
    s.fNumber = std::exp2(0.5f * av);
    s.shutterSeconds = std::exp2(-tv);
    s.iso = iso;
    s.ev100 = av + tv - std::log2(iso / 100.0f);
    return s;
}

} // namespace vitrine::camera
