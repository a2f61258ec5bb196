// Lens files (nodes/camera/lens.cpp): the shipped ones load with their spec-sheet numbers, bad files are refused
// naming the file and the JSON pointer, and the derived quantities follow the formulas lens.hpp documents
// (worked out here by hand).
#include "nodes/camera/lens.hpp"

#include "core/base/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <unistd.h>

namespace vitrine::camera {
namespace {

namespace fs = std::filesystem;
const fs::path kData = fs::path(VITRINE_SOURCE_DIR) / "data";

LensData shipped(const std::string& name) { return loadLens(findLens(name, ".", kData)); }

TEST(Lens, ShippedLensesLoadWithTheirSpecSheetNumbers) {
    int count = 0;
    for (const auto& e : fs::directory_iterator(kData / "lenses"))
        if (e.path().extension() == ".json") {
            EXPECT_NO_THROW(loadLens(e.path())) << e.path();
            ++count;
        }
    EXPECT_GE(count, 3);
    EXPECT_LE(count, 5);

    LensData kit = shipped("canon_ef-s_18-55mm_f3.5-5.6_is_stm");
    EXPECT_EQ(kit.focalMinMm, 18.0f);
    EXPECT_EQ(kit.focalMaxMm, 55.0f);
    EXPECT_EQ(kit.blades, 7);
    EXPECT_FLOAT_EQ(interpolate(kit.maxAperture, 18.0f), 3.5f);
    EXPECT_FLOAT_EQ(interpolate(kit.maxAperture, 55.0f), 5.6f);
    EXPECT_NEAR(interpolate(kit.maxAperture, 30.0f), 4.0f + 0.5f * 6.0f / 11.0f, 1e-5f); // between 24 and 35 mm
    EXPECT_FLOAT_EQ(interpolate(kit.maxAperture, 10.0f), 3.5f);                         // clamped
    EXPECT_FLOAT_EQ(interpolate(kit.minAperture, 55.0f), 36.0f);

    LensData fifty = shipped("canon_ef_50mm_f1.8_stm");
    EXPECT_FLOAT_EQ(interpolate(fifty.maxAperture, 50.0f), 1.8f);
    EXPECT_FLOAT_EQ(interpolate(fifty.minAperture, 50.0f), 22.0f);
    EXPECT_FLOAT_EQ(fifty.minFocusM, 0.35f);
    EXPECT_EQ(shipped("canon_ef_85mm_f1.4l_is").blades, 9);
    EXPECT_EQ(shipped("canon_ef_24-70mm_f2.8l_ii").blades, 9);
}

// Focus breathing f' = f (1 + b m / m_min): the 24-70 (b = −0.08) at 70 mm is 8 % shorter at its closest focus,
// unchanged at infinity, and in between follows the magnification.
TEST(Lens, FocusBreathingFollowsMagnification) {
    LensData zoom = shipped("canon_ef_24-70mm_f2.8l_ii");
    EXPECT_NEAR(evaluateLens(zoom, 70.0f, 0.38f, 2.8f).focalLengthMm, 70.0f * 0.92f, 1e-3f);
    EXPECT_NEAR(evaluateLens(zoom, 70.0f, 0.1f, 2.8f).focalLengthMm, 70.0f * 0.92f, 1e-3f); // clamped to 0.38 m
    EXPECT_NEAR(evaluateLens(zoom, 70.0f, 1e6f, 2.8f).focalLengthMm, 70.0f, 1e-3f);
    const double m = 0.07 / (2.0 - 0.07), mMin = 0.07 / (0.38 - 0.07);
    EXPECT_NEAR(evaluateLens(zoom, 70.0f, 2.0f, 2.8f).focalLengthMm, 70.0 * (1.0 - 0.08 * m / mMin), 1e-3);
}

// The 50 mm's 1.7 stops of corner falloff wide open on full frame, less cos⁴ of the corner's angle
// (atan(21.633 / 50): 0.4951 stops), leave 1.2049 stops mechanical = 56.6 % of the light; the camera's profile
// corrects half (residual 0.5); one stop down it is halved again, two stops down gone.
TEST(Lens, MechanicalVignettingAndResidualAberrations) {
    LensData fifty = shipped("canon_ef_50mm_f1.8_stm");
    const double lost = 1.0 - std::exp2(-(1.7 - (-std::log2(std::pow(50.0 / std::hypot(50.0, 21.6333), 4.0)))));
    EXPECT_NEAR(evaluateLens(fifty, 50.0f, 5.0f, 1.8f).mechanicalVignetting, 0.5 * lost, 1e-4);
    EXPECT_NEAR(evaluateLens(fifty, 50.0f, 5.0f, 1.8f * std::sqrt(2.0f)).mechanicalVignetting, 0.25 * lost, 1e-4);
    EXPECT_NEAR(evaluateLens(fifty, 50.0f, 5.0f, 3.6f).mechanicalVignetting, 0.0, 1e-6);
    LensState s = evaluateLens(shipped("canon_ef-s_18-55mm_f3.5-5.6_is_stm"), 18.0f, 5.0f, 5.6f);
    EXPECT_FLOAT_EQ(s.k1, -0.04f);   // distortion uncorrected ("none")
    EXPECT_FLOAT_EQ(s.caRed, 1.0f);  // CA corrected fully by the profile
    EXPECT_FLOAT_EQ(s.caBlue, 1.0f);
    EXPECT_FLOAT_EQ(s.wideOpenFNumber, 3.5f);
}

void expectRefused(const std::string& text, const std::string& pointer) {
    const fs::path p = fs::temp_directory_path() / ("vitrine_lens_test_" + std::to_string(::getpid()) + ".json");
    std::ofstream(p) << text;
    try {
        loadLens(p);
        ADD_FAILURE() << "accepted a lens file with a bad " << pointer;
    } catch (const UserError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(p.string()), std::string::npos) << what;
        EXPECT_NE(what.find(pointer + ":"), std::string::npos) << what;
    }
    fs::remove(p);
}

TEST(Lens, BadFilesNameFileAndPointer) {
    std::ifstream in(kData / "lenses" / "canon_ef_50mm_f1.8_stm.json");
    const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto replaced = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        const size_t at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    expectRefused(replaced("\"blades\": 7", "\"blades\": 2"), "/blades");
    expectRefused(replaced("\"blades\": 7,", ""), "/blades");
    expectRefused(replaced("\"type\": \"profile\", \"strength\": 1.0", "\"type\": \"magic\", \"strength\": 1.0"),
                  "/correction/ca/type");
    expectRefused(replaced("[[50.0, 1.8]]", "[[50.0, \"fast\"]]"), "/max_aperture/0/1");
    expectRefused(replaced("\"min_aperture\": [[50.0, 22.0]]", "\"min_aperture\": [[50.0, 1.2]]"), "/min_aperture");
    expectRefused(replaced("vitrine-lens/1", "vitrine-lens/9"), "/format");
    expectRefused(replaced("\"distortion_k1\": -0.010", "\"distortion_k1\": 3"), "/aberrations/0/distortion_k1");
}

TEST(Lens, UnknownNameListsTheShippedLenses) {
    try {
        findLens("canon_ef_50mm_f0.95", ".", kData);
        ADD_FAILURE() << "found a lens that does not exist";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("canon_ef_50mm_f1.8_stm"), std::string::npos) << e.what();
    }
    EXPECT_THROW(findLens("no/such/lens.json", ".", kData), UserError);
}

} // namespace
} // namespace vitrine::camera
