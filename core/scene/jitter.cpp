#include "core/scene/jitter.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace vitrine::scene {
namespace {

using Cells = std::array<glm::ivec2, kJitterPatternSamples>;

// The orders below were found by a small simulated-annealing search over permutations of each set, minimising the
// largest star discrepancy of every cyclic run of 2, 4 and 8 samples (tests/unit/scene/test_jitter.cpp checks the
// bounds); the raster order of the same sets has runs of 4 with discrepancy 0.79-0.89.
// clang-format off
constexpr Cells kOrdered = {{{3, 3}, {2, 0}, {3, 2}, {1, 2}, {0, 3}, {1, 1}, {2, 3}, {2, 1},
                             {3, 1}, {0, 0}, {2, 2}, {0, 2}, {3, 0}, {0, 1}, {1, 3}, {1, 0}}};

// The lattice x = 4i + j, y = 4j + 3 - i (i, j in 0..3): basis (4, -1), (1, 4), a square grid rotated by
// atan(1/4) with one sample in each row and column of the 16x16 sub-grid. Edges along its basis vectors see only
// 4 distinct coverage levels.
constexpr Cells kRotated = {{{6, 10}, {14, 8}, {0, 3}, {7, 14}, {9, 5}, {15, 12}, {4, 2}, {10, 9},
                             {2, 11}, {13, 4}, {5, 6}, {3, 15}, {8, 1}, {11, 13}, {1, 7}, {12, 0}}};

// A 16-rooks set chosen by simulated annealing over all permutations to minimise the worst edge error: the largest
// difference, over edge directions (every 0.5 degree) and positions, between an edge's true pixel coverage and the
// fraction of samples it covers (0.117 at the cell centres, against 0.147 for the rotated grid and 0.125 for the
// ordered one; 0.133 / 0.159 / 0.188 at the shifted positions of frames 0-15).
constexpr Cells kImproved = {{{2, 13}, {10, 7}, {12, 4}, {4, 8}, {9, 12}, {1, 3}, {15, 11}, {6, 5},
                              {5, 14}, {8, 9}, {11, 1}, {0, 10}, {13, 15}, {3, 2}, {14, 6}, {7, 0}}};
// clang-format on

// Sub-grid shifts, in cells: a quarter cell off the centre along both diagonals.
constexpr std::array<glm::vec2, kJitterShiftPeriod> kShifts = {
    {{0.25f, 0.25f}, {0.75f, 0.75f}, {0.75f, 0.25f}, {0.25f, 0.75f}}};

float radicalInverse(uint32_t i, uint32_t base) {
    float f = 1.0f, r = 0.0f;
    for (; i > 0; i /= base) {
        f /= static_cast<float>(base);
        r += f * static_cast<float>(i % base);
    }
    return r;
}

const Cells* cellsOf(JitterPattern pattern) {
    switch (pattern) {
    case JitterPattern::Ordered:
        return &kOrdered;
    case JitterPattern::Rotated:
        return &kRotated;
    case JitterPattern::Improved:
        return &kImproved;
    default:
        return nullptr;
    }
}

} // namespace

const std::vector<std::string>& jitterPatternNames() {
    static const std::vector<std::string> names = {"off", "halton", "ordered", "rotated", "improved", "stratified"};
    return names;
}

uint32_t jitterGridFor(uint32_t grid, uint32_t frames) {
    if (grid > 0) return grid;
    uint32_t n = 1;
    while ((n + 1) * (n + 1) <= frames)
        ++n;
    return n;
}

JitterGrid jitterGrid(JitterPattern pattern) {
    const Cells* cells = cellsOf(pattern);
    if (!cells) return {};
    return {pattern == JitterPattern::Ordered ? 4u : 16u, std::vector<glm::ivec2>(cells->begin(), cells->end())};
}

glm::vec2 jitterSample(JitterPattern pattern, uint32_t frame, uint32_t grid) {
    switch (pattern) {
    case JitterPattern::Off:
        return glm::vec2(0.5f);
    case JitterPattern::Halton: {
        const uint32_t i = frame % 256 + 1;
        return {radicalInverse(i, 2), radicalInverse(i, 3)};
    }
    case JitterPattern::Stratified: {
        const uint32_t n = grid == 0 ? 1 : grid;
        const uint32_t k = frame % (n * n);
        return (glm::vec2(static_cast<float>(k % n), static_cast<float>(k / n)) + 0.5f) / static_cast<float>(n);
    }
    default:
        break;
    }
    const Cells& cells = *cellsOf(pattern);
    const float size = pattern == JitterPattern::Ordered ? 4.0f : 16.0f;
    const uint32_t k = frame % kJitterPatternSamples;
    const uint32_t round = frame / kJitterPatternSamples;
    // Each sample moves to the next shift every 16 frames; within a run of 16 every shift is used 4 times.
    const glm::vec2 shift = kShifts[(k + round) % kJitterShiftPeriod];
    return (glm::vec2(cells[k]) + shift) / size;
}

std::string jitterPatternSvg(JitterPattern pattern, uint32_t frames) {
    const float s = 400.0f, m = 20.0f; // pixel size and margin in SVG units
    const std::string name = jitterPatternNames()[static_cast<size_t>(pattern)];
    std::string svg;
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" viewBox=\"0 0 %g %g\">\n",
                  s + 2 * m, s + 2 * m + 24, s + 2 * m, s + 2 * m + 24);
    svg += buf;
    svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    const JitterGrid g = jitterGrid(pattern);
    const uint32_t lines = g.size ? g.size : (pattern == JitterPattern::Stratified ? 16u : 0u);
    for (uint32_t i = 1; i < lines; ++i) {
        const float t = m + s * static_cast<float>(i) / static_cast<float>(lines);
        std::snprintf(buf, sizeof(buf),
                      "<line x1=\"%.2f\" y1=\"%g\" x2=\"%.2f\" y2=\"%g\" stroke=\"#ddd\"/>"
                      "<line x1=\"%g\" y1=\"%.2f\" x2=\"%g\" y2=\"%.2f\" stroke=\"#ddd\"/>\n",
                      t, m, t, m + s, m, t, m + s, t);
        svg += buf;
    }
    std::snprintf(buf, sizeof(buf),
                  "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n", m, m, s, s);
    svg += buf;
    for (uint32_t f = kJitterPatternSamples; f < frames; ++f) {
        const glm::vec2 p = m + s * jitterSample(pattern, f);
        std::snprintf(buf, sizeof(buf), "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"3\" fill=\"#9bd\"/>\n", p.x, p.y);
        svg += buf;
    }
    const uint32_t first = std::min(frames, kJitterPatternSamples);
    for (uint32_t f = 0; f < first; ++f) {
        const glm::vec2 p = m + s * jitterSample(pattern, f);
        std::snprintf(buf, sizeof(buf),
                      "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"9\" fill=\"#c33\"/><text x=\"%.2f\" y=\"%.2f\" "
                      "font-family=\"sans-serif\" font-size=\"10\" fill=\"white\" text-anchor=\"middle\">%u</text>\n",
                      p.x, p.y, p.x, p.y + 3.5f, f);
        svg += buf;
    }
    std::snprintf(buf, sizeof(buf),
                  "<text x=\"%g\" y=\"%g\" font-family=\"sans-serif\" font-size=\"14\">%s: frames 0-%u numbered, "
                  "%u-%u as dots</text>\n</svg>\n",
                  m, s + 2 * m + 12, name.c_str(), first ? first - 1 : 0, first, frames ? frames - 1 : 0);
    svg += buf;
    return svg;
}

} // namespace vitrine::scene
