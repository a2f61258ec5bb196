// The program line (nodes/camera/program.cpp) against the curve the README documents ("Physical camera"), for a
// 50 mm f/1.8–22 lens at ISO 100 with a 1/8000–30 s shutter: the expected settings below were worked out by hand
// from the documented rule (knee at f/1.8 and 1/60 s = EV 7.60; above it half a stop of aperture and half a stop of
// shutter per EV; then the limits), not by running the code under test.
#include "nodes/camera/program.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace vitrine::camera {
namespace {

ProgramLimits fiftyMm() {
    ProgramLimits l;
    l.wideOpenFNumber = 1.8f;
    l.minFNumber = 22.0f;
    l.shortestShutter = 1.0f / 8000.0f;
    l.longestShutter = 30.0f;
    l.focalLengthMm = 50.0f;
    l.iso = 100.0f;
    return l;
}

struct Row {
    float ev, shift, fNumber, shutter, ev100;
    const char* what;
};

TEST(Program, TableMatchesTheDocumentedCurve) {
    const Row rows[] = {
        {-5.0f, 0.0f, 1.8f, 30.0f, -3.2109f, "too dark: wide open at the longest shutter, underexposed"},
        {-3.0f, 0.0f, 1.8f, 25.92f, -3.0f, "wide open, 26 s"},
        {3.0f, 0.0f, 1.8f, 0.405f, 3.0f, "wide open, 0.4 s"},
        {7.60288f, 0.0f, 1.8f, 1.0f / 60.0f, 7.60288f, "the knee: wide open at the hand-held 1/60 s"},
        {10.0f, 0.0f, 2.72693f, 0.007261844f, 10.0f, "on the diagonal: f/2.7, 1/138 s"},
        {14.0f, 0.0f, 5.45385f, 0.001815461f, 14.0f, "f/5.5, 1/551 s"},
        {18.0f, 0.0f, 10.90771f, 0.0004538652f, 18.0f, "f/11, 1/2203 s"},
        {21.0f, 0.0f, 18.3445f, 0.0001604656f, 21.0f, "f/18, 1/6232 s"},
        {22.0f, 0.0f, 22.0f, 1.0f / 8000.0f, 21.8846f, "too bright: f/22 at 1/8000 s, overexposed"},
        {14.0f, 2.0f, 10.90771f, 0.007261844f, 14.0f, "shift +2: two stops smaller, two stops longer"},
        {14.0f, -5.0f, 1.8f, 0.0001977539f, 14.0f, "shift -5 stops at the wide-open limit: f/1.8, 1/5057 s"},
        {10.0f, 10.0f, 22.0f, 0.4726563f, 10.0f, "shift +10 stops at the smallest aperture: f/22, 0.47 s"},
    };
    for (const Row& r : rows) {
        const ExposureSettings s = programExposure(r.ev, r.shift, fiftyMm());
        EXPECT_NEAR(s.fNumber / r.fNumber, 1.0, 1e-4) << r.what;
        EXPECT_NEAR(s.shutterSeconds / r.shutter, 1.0, 1e-4) << r.what;
        EXPECT_NEAR(s.ev100, r.ev100, 1e-3) << r.what;
        EXPECT_EQ(s.iso, 100.0f) << r.what;
    }
}

// Auto ISO keeps f/1.8 at 1/60 s below the knee by raising the ISO, up to its ceiling; then the shutter slows.
TEST(Program, AutoIsoRaisesIsoBelowTheKnee) {
    ProgramLimits l = fiftyMm();
    l.autoIso = true;
    l.maxIso = 6400.0f;
    ExposureSettings bright = programExposure(12.0f, 0.0f, l);
    EXPECT_EQ(bright.iso, 100.0f);
    ExposureSettings dim = programExposure(5.0f, 0.0f, l);
    EXPECT_NEAR(dim.iso, 607.5f, 0.5f);
    EXPECT_NEAR(dim.fNumber, 1.8f, 1e-4f);
    EXPECT_NEAR(dim.shutterSeconds * 60.0f, 1.0f, 1e-4f);
    EXPECT_NEAR(dim.ev100, 5.0f, 1e-4f);
    ExposureSettings dark = programExposure(0.0f, 0.0f, l);
    EXPECT_EQ(dark.iso, 6400.0f);
    EXPECT_NEAR(dark.shutterSeconds, 0.050625f, 1e-6f);
    EXPECT_NEAR(dark.ev100, 0.0f, 1e-4f);
}

// The hand-held speed follows the focal length above 60 mm (1/f s): an 85 mm lens's knee is at 1/85 s.
TEST(Program, TelephotoKneeAtOneOverFocalLength) {
    ProgramLimits l = fiftyMm();
    l.wideOpenFNumber = 1.4f;
    l.focalLengthMm = 85.0f;
    const float knee = 2.0f * std::log2(1.4f) + std::log2(85.0f);
    ExposureSettings s = programExposure(knee, 0.0f, l);
    EXPECT_NEAR(s.fNumber, 1.4f, 1e-4f);
    EXPECT_NEAR(s.shutterSeconds * 85.0f, 1.0f, 1e-4f);
}

// Exposure EV and the meter: L = 1000 cd/m² meters at log2(1000 · 100 / 12.5) = 12.966, and the exposure scale
// brings that average luminance to 1 / (1.2 · 8) = 0.104.
TEST(Program, MeterAndExposureScale) {
    EXPECT_NEAR(meteredEv100(1000.0f), 12.9658f, 1e-4f);
    EXPECT_NEAR(meteredEv100(2000.0f) - meteredEv100(1000.0f), 1.0f, 1e-5f);
    EXPECT_NEAR(1000.0f * exposureScale(meteredEv100(1000.0f)), 1.0f / 9.6f, 1e-6f);
    EXPECT_NEAR(ev100Of(16.0f, 1.0f / 100.0f, 100.0f), std::log2(25600.0f), 1e-5f); // sunny 16: EV 14.6
    EXPECT_NEAR(ev100Of(8.0f, 1.0f / 125.0f, 400.0f), std::log2(8000.0f) - 2.0f, 1e-5f);
}

} // namespace
} // namespace vitrine::camera
