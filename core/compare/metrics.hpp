#pragma once

#include "core/image/image.hpp"

#include <numbers>
#include <vector>

// Image-comparison metrics for `vitrine compare`, the image tests and the benchmarks. All of them run on the CPU
// on vitrine::Image (linear float RGBA, top row first). Every function that takes two or more images throws
// vitrine::UserError naming both sizes when they differ, and when an image is empty.
//
// Scalar results that are images (SSIM map, FLIP error map, exposure map) store the value in R, G and B and 1 in A,
// so that they can be written as grey images or passed to falseColor()/flipColorMap().
namespace vitrine::compare {

// Peak signal-to-noise ratio in dB over R, G and B (alpha ignored): 10·log10(peak² / MSE). Values are not clamped,
// so HDR images can be compared with a matching `peak`. Returns +infinity for identical images.
double psnr(const Image& a, const Image& b, double peak = 1.0);

struct SsimResult {
    double mean = 0.0; // mean of `map` over every pixel
    Image map;         // per-pixel SSIM
};

// SSIM of Wang, Bovik, Sheikh and Simoncelli 2004 with the paper's constants: 11×11 Gaussian window (σ = 1.5),
// K1 = 0.01, K2 = 0.03, L = 1. It runs on one channel: the Rec.709 luminance of the linear RGB values, each clamped
// to [0,1] first. We chose linear luminance (not sRGB-encoded values) because renders are compared in the same
// linear space the renderer writes; note that this weighs errors in dark regions less than SSIM on 8-bit display
// values does. Unlike Wang's ssim_index.m, which crops the 5-pixel border, the map covers every pixel: the window
// reads clamped-to-edge samples outside the image, so SSIM(x, x) is exactly 1 everywhere.
SsimResult ssim(const Image& a, const Image& b);

// The viewing condition of the FLIP paper's default setup: a 0.7 m wide 4K (3840 px) monitor seen from 0.7 m,
// i.e. 0.7 · 3840 / 0.7 · π / 180 ≈ 67.0206 pixels per degree of visual angle (the paper rounds it to 67).
inline constexpr double kDefaultPixelsPerDegree = 0.7 * 3840.0 / 0.7 * std::numbers::pi / 180.0;

// Summary of a FLIP error map, as the FLIP tool reports it. The weighted median and quartiles are those of the
// paper's weighted histogram, where each pixel counts with a weight equal to its error: the weighted p-quantile is
// the smallest error e such that the errors up to and including e add up to more than p times the sum of all
// errors. We compute it exactly from the sorted errors (the limit of infinitely narrow histogram buckets), so it
// does not depend on a bucket count. All are 0 for an all-zero map.
struct FlipStatistics {
    double mean = 0.0;
    double weightedMedian = 0.0;
    double q1 = 0.0; // weighted first quartile
    double q3 = 0.0; // weighted third quartile
    double minimum = 0.0;
    double maximum = 0.0;
};

struct FlipResult : FlipStatistics {
    Image errorMap; // per-pixel FLIP error in [0,1]
};

// Computes the statistics of an error map (value read from R) and keeps the map. Used by ldrFlip()/hdrFlip(), and
// public so callers can pool error maps they combined themselves.
FlipResult summarizeFlip(Image errorMap);

// LDR-FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG 2020).
// Inputs are LINEAR RGB that is display-referred: the caller has already tone-mapped, and values are clamped to
// [0,1] here (NaN counts as 0). The paper's first step, sRGB decoding, is therefore the identity: an Image is
// already what the paper obtains after decoding its sRGB input. Symmetric in its arguments; the order follows
// the paper. Throws UserError for pixelsPerDegree <= 0.
FlipResult ldrFlip(const Image& reference, const Image& test, double pixelsPerDegree = kDefaultPixelsPerDegree);

struct HdrFlipOptions {
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    // Exposure range in stops. When `automaticExposures` is true they are computed from the reference as the
    // paper does, and the fields here are ignored.
    bool automaticExposures = true;
    double startExposure = 0.0;
    double stopExposure = 0.0;
    // 0: the paper's choice, max(2, ceil(stop − start)).
    int exposureCount = 0;
};

struct HdrFlipResult : FlipResult {
    // Per pixel, which exposure gave the maximum error, as i / (count − 1) in [0,1] (0 when count is 1).
    Image exposureMap;
    double startExposure = 0.0;
    double stopExposure = 0.0;
    int exposureCount = 0;
};

// HDR-FLIP (Andersson et al., "Visualizing Errors in Rendered High Dynamic Range Images", EG 2021). Inputs are
// linear scene-referred RGB (negative values count as 0). For each of `exposureCount` exposures evenly spaced in
// [start, stop], both images are scaled by 2^exposure and tone-mapped with the paper's fit of the ACES curve, then
// compared with LDR-FLIP; the result is the per-pixel maximum. Automatic exposures: start maps the reference's
// maximum luminance, stop its median luminance, to 0.85 after tone mapping.
HdrFlipResult hdrFlip(const Image& reference, const Image& test, const HdrFlipOptions& options = {});

// The magma colour map the FLIP paper uses for error maps: error e in [0,1] → entry round(255·e) of the 256-entry
// table. The table is sRGB-encoded; the returned Image holds its LINEAR values, so that whatever writes the image
// (PNG encoders apply the sRGB transfer) shows the paper's colours.
Image flipColorMap(const Image& errorMap);

// Per-channel |a − b| for R, G and B; alpha is 1.
Image absoluteDifference(const Image& a, const Image& b);

// Heat map of an image: v = scale · max(R, G, B), clamped to [0,1], through the same magma map as FLIP (so every
// heat map in a report reads the same way). Taking the largest channel lets an RGB difference image be passed
// directly. NaN shows as 1, so broken pixels stand out.
Image falseColor(const Image& scalar, double scale);

// Mean absolute difference between consecutive frames, over R, G and B, averaged over pixels and then over the
// frame pairs. Throws UserError for fewer than two frames.
double flicker(const std::vector<Image>& frames);

// Flicker after motion compensation. velocities.size() must equal frames.size(); velocities[0] is not read.
// velocities[i] holds, in .r and .g, the screen-space motion IN PIXELS (x right, y down) of the surface seen at each
// pixel of frame i since frame i−1: that surface was at (x − v.r, y − v.g) in frame i−1 (current minus previous
// position, the usual G-buffer velocity convention, but in pixels rather than UV units). Frame i−1 is fetched there
// bilinearly (pixel centres at integer coordinates); pixels whose fetch lands outside frame i−1 are skipped. Each
// pair's mean is over its valid pixels; pairs with no valid pixel are left out of the average.
double flickerMotionCompensated(const std::vector<Image>& frames, const std::vector<Image>& velocities);

enum class FrameMetric {
    Psnr,     // dB, higher is better
    FlipMean, // mean LDR-FLIP at the default viewing condition, lower is better
};

// The metric of each frame against one reference (a still camera), or against its own reference frame.
std::vector<double> errorPerFrame(const std::vector<Image>& frames, const Image& reference, FrameMetric metric);
std::vector<double> errorPerFrame(const std::vector<Image>& frames, const std::vector<Image>& references,
                                  FrameMetric metric);

} // namespace vitrine::compare
