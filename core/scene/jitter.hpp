#pragma once
// Sub-pixel camera jitter for temporal anti-aliasing and for accumulated (supersampled) ground truths
// (MUSEUM_SPEC §6). The scene nodes shift their projection by jitterOffset() every frame; pattern nodes use the
// same offsets so a synthetic image and a scene are jittered alike.

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace vitrine::scene {

// In the order of the scene nodes' `jitter` enum.
enum class JitterPattern : uint32_t {
    Off,        // no jitter
    Halton,     // Halton(2, 3), indices 1..256
    Ordered,    // 4x4 ordered grid (weak at near-horizontal and near-vertical edges)
    Rotated,    // 16 samples on a lattice rotated by atan(1/4): N-rooks on the 16x16 sub-grid (weak near 14 and 76 deg)
    Improved,   // 16-rooks set with the smallest worst-direction edge error found by search: no weak direction
    Stratified, // N x N cell centres in raster order, one per frame (aa.accumulate's exact box filter)
};

// The param choices, in enum order: off, halton, ordered, rotated, improved, stratified.
const std::vector<std::string>& jitterPatternNames();

inline constexpr uint32_t kJitterPatternSamples = 16; // samples of each 16-sample pattern
inline constexpr uint32_t kJitterShiftPeriod = 4;     // sub-grid shifts, one per 16 frames

// Where frame `frame` samples the pixel, in pixel units in [0, 1)^2 (x right, y down). The 16-sample grid
// patterns cycle through their samples in an order chosen so any contiguous run is well spread, and every 16
// frames move each sample inside its sub-grid cell (a quarter cell off the centre, four positions; each run of
// 16 uses every position four times, so its mean stays at the pixel centre). `grid`: N of Stratified.
glm::vec2 jitterSample(JitterPattern pattern, uint32_t frame, uint32_t grid = 16);

// The projection shift of that frame in pixels, in (-0.5, 0.5): the jittered image shows at a pixel centre c the
// unjittered image's point c - offset, which is the pixel's corner + jitterSample().
inline glm::vec2 jitterOffset(JitterPattern pattern, uint32_t frame, uint32_t grid = 16) {
    return pattern == JitterPattern::Off ? glm::vec2(0.0f) : glm::vec2(0.5f) - jitterSample(pattern, frame, grid);
}

// N of the stratified pattern: `grid`, or when it is 0 the largest N with N * N <= frames (at least 1).
uint32_t jitterGridFor(uint32_t grid, uint32_t frames);

// Cells of the 16 samples of a grid pattern in order, on its grid (4 for Ordered, 16 for Rotated / Improved).
struct JitterGrid {
    uint32_t size = 0;
    std::vector<glm::ivec2> cells;
};
JitterGrid jitterGrid(JitterPattern pattern);

// An SVG plot of a pattern: the pixel, its sub-grid, the first 16 samples numbered in order, and the positions of
// `frames` frames as dots (the sub-grid shifts).
std::string jitterPatternSvg(JitterPattern pattern, uint32_t frames = 64);

} // namespace vitrine::scene
