#pragma once

#include <array>
#include <cmath>
#include <vector>

// A float64 model of LDR-FLIP's colour pipeline (Andersson et al., "FLIP: A Difference Evaluator for Alternating
// Images", HPG 2020, section 4.1), written from the paper for the tests of core/compare (test_flip_colour.cpp) and of
// the compare.flip node (tests/gpu/compare_nodes_test.cpp). It does not call vitrine's code.
//
// It is exact for one case only: two UNIFORM images. There, every CSF filter (each has unit sum) returns the YCxCz
// values it was given, so converting back to linear RGB gives the input colour again and the clamp to [0,1] leaves it.
// The edge and point detectors (positive weights sum to 1, negative to -1) see no features, so ΔE_f = 0 and
// FLIP = ΔE_c^(1 - 0) = ΔE_c at every pixel. What is left is: linear RGB -> XYZ -> L*a*b* -> Hunt adjustment ->
// HyAB^q_c -> the paper's redistribution with p_c, p_t and c_max. The YCxCz round trip is not modelled on purpose:
// for a uniform image it must be the identity, so an error in it (a wrong inverse) is a difference from this model.
namespace vitrine::compare::testing {

using Rgb = std::array<double, 3>;
using Matrix3 = std::array<std::array<double, 3>, 3>;

inline double determinant(const Matrix3& m) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Linear sRGB to CIE XYZ, built from the chromaticities: the Rec. 709 primaries R (0.64, 0.33), G (0.30, 0.60),
// B (0.15, 0.06) and the D65 white point (0.31271, 0.32902), scaled so that RGB (1,1,1) is the white with Y = 1.
// These five-digit D65 coordinates are the ones behind the matrix of FLIP's reference code; with sRGB's rounded
// (0.3127, 0.3290) the FLIP values of the test pairs move by less than 3e-5.
inline Matrix3 rgbToXyzMatrix() {
    const double xy[4][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.31271, 0.32902}};
    auto xyzOf = [&](int i) { return Rgb{xy[i][0] / xy[i][1], 1.0, (1.0 - xy[i][0] - xy[i][1]) / xy[i][1]}; };
    Matrix3 primaries{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            primaries[r][c] = xyzOf(c)[r];
    // Scales s with primaries · s = white, by Cramer's rule.
    const Rgb white = xyzOf(3);
    Matrix3 m{};
    for (int c = 0; c < 3; ++c) {
        Matrix3 replaced = primaries;
        for (int r = 0; r < 3; ++r)
            replaced[r][c] = white[r];
        const double scale = determinant(replaced) / determinant(primaries);
        for (int r = 0; r < 3; ++r)
            m[r][c] = primaries[r][c] * scale;
    }
    return m;
}

inline Rgb toXyz(const Rgb& rgb) {
    const Matrix3 m = rgbToXyzMatrix();
    Rgb xyz{};
    for (int r = 0; r < 3; ++r)
        xyz[r] = m[r][0] * rgb[0] + m[r][1] * rgb[1] + m[r][2] * rgb[2];
    return xyz;
}

// Relative luminance Y of a linear sRGB colour (white = 1).
inline double luminance(const Rgb& rgb) {
    return toXyz(rgb)[1];
}

struct Lab {
    double l, a, b;
};

// CIE 1976 L*a*b* relative to the white RGB (1,1,1), then the Hunt adjustment of the paper: a* and b* scaled by
// 0.01·L*, because colour differences are harder to see in the dark.
inline Lab huntLab(const Rgb& rgb) {
    const Rgb xyz = toXyz(rgb), white = toXyz({1.0, 1.0, 1.0});
    auto f = [](double t) {
        const double delta = 6.0 / 29.0;
        return t > delta * delta * delta ? std::cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
    };
    const double fx = f(xyz[0] / white[0]), fy = f(xyz[1] / white[1]), fz = f(xyz[2] / white[2]);
    const double l = 116.0 * fy - 16.0;
    return {l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)};
}

// HyAB (Abasi et al. 2020): city-block distance in lightness plus Euclidean distance in the chroma plane.
inline double hyab(const Lab& p, const Lab& q) {
    return std::abs(p.l - q.l) + std::hypot(p.a - q.a, p.b - q.b);
}

// ΔE_c of the paper: HyAB^q_c (q_c = 0.7) redistributed so that [0, p_c·c_max) maps linearly onto [0, p_t) and
// [p_c·c_max, c_max] onto [p_t, 1], with p_c = 0.4, p_t = 0.95 and c_max = HyAB(green, blue)^q_c, the largest
// difference the paper considers.
inline double colourError(double hyabDistance) {
    const double qc = 0.7, pc = 0.4, pt = 0.95;
    const double cmax = std::pow(hyab(huntLab({0.0, 1.0, 0.0}), huntLab({0.0, 0.0, 1.0})), qc);
    const double e = std::pow(hyabDistance, qc);
    return e < pc * cmax ? pt / (pc * cmax) * e : pt + (e - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt);
}

// LDR-FLIP at any pixel of a uniform `reference` image against a uniform `test` image (colours in [0,1]).
inline double uniformPairFlip(const Rgb& reference, const Rgb& test) {
    return colourError(hyab(huntLab(reference), huntLab(test)));
}

// Coloured pairs for the tests: what each exercises is in its name. Colours with "equal luminance" have the same Y
// under the matrix above, so they differ in chroma only (|ΔL*| = 0) and a grey-only pipeline cannot tell them apart.
struct ColourPair {
    const char* name;
    Rgb reference, test;
};

inline std::vector<ColourPair> colourPairs() {
    const Matrix3 m = rgbToXyzMatrix();
    const double greenOfRedLuminance = 0.6 * m[1][0] / m[1][1];
    const double yellowOfBlueLuminance = (0.2 * (m[1][0] + m[1][1]) + m[1][2]) / (m[1][0] + m[1][1]);
    const double greyOfPinkLuminance = luminance({0.8, 0.3, 0.4});
    return {
        {"red_vs_green_equal_luminance", {0.6, 0.0, 0.0}, {0.0, greenOfRedLuminance, 0.0}},
        {"blue_vs_yellow_equal_luminance", {0.2, 0.2, 1.0}, {yellowOfBlueLuminance, yellowOfBlueLuminance, 0.0}},
        {"pink_vs_grey_equal_luminance",
         {0.8, 0.3, 0.4},
         {greyOfPinkLuminance, greyOfPinkLuminance, greyOfPinkLuminance}},
        {"orange_vs_teal", {0.9, 0.4, 0.1}, {0.1, 0.5, 0.6}},
        {"magenta_vs_dark_grey", {0.7, 0.2, 0.7}, {0.3, 0.3, 0.3}},
        {"small_warm_shift", {0.5, 0.4, 0.3}, {0.45, 0.42, 0.3}},
    };
}

} // namespace vitrine::compare::testing
