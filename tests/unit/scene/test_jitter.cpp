// The camera jitter patterns of core/scene/jitter.hpp against what they promise (MUSEUM_SPEC §6): N-rooks where
// promised, well-spread contiguous runs (star discrepancy), the sub-grid shift, an unbiased mean, and the improved
// grid's lack of a weak edge direction.
#include "core/scene/jitter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

namespace vitrine::scene {
namespace {

const JitterPattern kGridPatterns[] = {JitterPattern::Ordered, JitterPattern::Rotated, JitterPattern::Improved};

std::vector<glm::dvec2> samples(JitterPattern p, uint32_t first, uint32_t count) {
    std::vector<glm::dvec2> s;
    for (uint32_t f = first; f < first + count; ++f)
        s.push_back(glm::dvec2(jitterSample(p, f)));
    return s;
}

// Exact star discrepancy: boxes [0, a) x [0, b) anchored at the origin, corners at the points' coordinates.
double starDiscrepancy(const std::vector<glm::dvec2>& pts) {
    std::vector<double> xs = {1.0}, ys = {1.0};
    for (const auto& p : pts) {
        xs.push_back(p.x);
        ys.push_back(p.y);
    }
    const double n = static_cast<double>(pts.size());
    double worst = 0.0;
    for (double a : xs)
        for (double b : ys) {
            int open = 0, closed = 0;
            for (const auto& p : pts) {
                open += p.x < a && p.y < b;
                closed += p.x <= a && p.y <= b;
            }
            worst = std::max({worst, a * b - open / n, closed / n - a * b});
        }
    return worst;
}

// The worst error of the coverage estimate of a straight edge over the pixel: for every direction (0.25 degree
// steps) and position of the edge, |area of the pixel behind it - fraction of samples behind it|.
double edgeDiscrepancy(const std::vector<glm::dvec2>& pts) {
    // Area of {u cx + v cy < t} in the unit square, cx, cy >= 0: the CDF of a sum of two uniform variables.
    auto area = [](double cx, double cy, double t) {
        if (cx < cy) std::swap(cx, cy);
        if (t <= 0.0) return 0.0;
        if (t >= cx + cy) return 1.0;
        if (cy < 1e-12) return t / cx;
        if (t < cy) return t * t / (2.0 * cx * cy);
        if (t < cx) return (t - 0.5 * cy) / cx;
        return 1.0 - (cx + cy - t) * (cx + cy - t) / (2.0 * cx * cy);
    };
    const double n = static_cast<double>(pts.size());
    double worst = 0.0;
    for (int step = 0; step < 720; ++step) {
        const double theta = step * M_PI / 720.0, c = std::cos(theta), s = std::sin(theta);
        std::vector<double> proj;
        for (const auto& p : pts)
            proj.push_back(std::fabs(c) * (c >= 0 ? p.x : 1 - p.x) + s * p.y);
        std::sort(proj.begin(), proj.end());
        for (size_t k = 0; k < proj.size(); ++k) {
            const double a = area(std::fabs(c), s, proj[k]);
            worst = std::max({worst, std::fabs(a - k / n), std::fabs(a - (k + 1) / n)});
        }
    }
    return worst;
}

TEST(Jitter, SamplesStayInsideThePixel) {
    for (size_t i = 0; i < jitterPatternNames().size(); ++i)
        for (uint32_t f = 0; f < 1024; ++f) {
            glm::vec2 s = jitterSample(static_cast<JitterPattern>(i), f, 16);
            EXPECT_TRUE(s.x > 0.0f && s.x < 1.0f && s.y > 0.0f && s.y < 1.0f) << jitterPatternNames()[i] << " " << f;
            glm::vec2 o = jitterOffset(static_cast<JitterPattern>(i), f, 16);
            // The projection shift moves the sample from the pixel centre to s.
            if (i != 0) {
                EXPECT_NEAR(0.5f - o.x, s.x, 1e-6f);
                EXPECT_NEAR(0.5f - o.y, s.y, 1e-6f);
            }
        }
}

TEST(Jitter, GridPatternsHaveOneSamplePerCellRowOrColumn) {
    for (JitterPattern p : kGridPatterns) {
        const JitterGrid g = jitterGrid(p);
        ASSERT_EQ(g.cells.size(), kJitterPatternSamples);
        for (uint32_t round = 0; round < 2 * kJitterShiftPeriod; ++round) {
            std::set<int> rows, columns;
            std::set<std::pair<int, int>> cells;
            for (const auto& s : samples(p, round * 16, 16)) {
                const int x = static_cast<int>(std::floor(s.x * g.size)),
                          y = static_cast<int>(std::floor(s.y * g.size));
                rows.insert(y);
                columns.insert(x);
                cells.insert({x, y});
            }
            if (p == JitterPattern::Ordered) {
                EXPECT_EQ(cells.size(), 16u) << "ordered 4x4: every cell once, round " << round;
            } else {
                // N-rooks on the 16 x 16 sub-grid, whatever the sub-grid shift.
                EXPECT_EQ(rows.size(), 16u) << jitterPatternNames()[static_cast<size_t>(p)] << " round " << round;
                EXPECT_EQ(columns.size(), 16u) << jitterPatternNames()[static_cast<size_t>(p)] << " round " << round;
            }
        }
    }
}

TEST(Jitter, ContiguousRunsAreWellSpread) {
    // Every run of 4 and of 8 consecutive frames (any start, across the sub-grid shifts) has a star discrepancy below
    // these bounds (measured: ordered 0.54 / 0.38, rotated 0.44 / 0.25, improved 0.45 / 0.29, Halton 0.56 / 0.30);
    // the same grid sets in raster order reach 0.79-0.89 (runs of 4) and 0.55-0.67 (runs of 8).
    for (JitterPattern p :
         {JitterPattern::Ordered, JitterPattern::Rotated, JitterPattern::Improved, JitterPattern::Halton}) {
        double worst4 = 0.0, worst8 = 0.0;
        for (uint32_t start = 0; start < 64; ++start) {
            worst4 = std::max(worst4, starDiscrepancy(samples(p, start, 4)));
            worst8 = std::max(worst8, starDiscrepancy(samples(p, start, 8)));
        }
        const char* name = jitterPatternNames()[static_cast<size_t>(p)].c_str();
        std::printf("%s: worst star discrepancy, runs of 4: %.3f, runs of 8: %.3f\n", name, worst4, worst8);
        EXPECT_LT(worst4, 0.57) << name;
        EXPECT_LT(worst8, 0.40) << name;
    }
}

TEST(Jitter, SubGridShiftGivesMoreThan16PositionsAndKeepsTheMeanCentred) {
    for (JitterPattern p : kGridPatterns) {
        std::set<std::pair<float, float>> distinct;
        for (uint32_t f = 0; f < 64; ++f)
            distinct.insert({jitterSample(p, f).x, jitterSample(p, f).y});
        EXPECT_EQ(distinct.size(), 64u) << jitterPatternNames()[static_cast<size_t>(p)];
        for (uint32_t round = 0; round < 4; ++round) {
            glm::dvec2 mean(0.0);
            for (const auto& s : samples(p, round * 16, 16))
                mean += s / 16.0;
            EXPECT_NEAR(mean.x, 0.5, 1e-6);
            EXPECT_NEAR(mean.y, 0.5, 1e-6);
        }
    }
    std::set<std::pair<float, float>> halton;
    for (uint32_t f = 0; f < 64; ++f)
        halton.insert({jitterSample(JitterPattern::Halton, f).x, jitterSample(JitterPattern::Halton, f).y});
    EXPECT_GT(halton.size(), 16u);
}

TEST(Jitter, ImprovedGridHasNoWeakEdgeDirection) {
    const double ordered = edgeDiscrepancy(samples(JitterPattern::Ordered, 0, 16));
    const double rotated = edgeDiscrepancy(samples(JitterPattern::Rotated, 0, 16));
    const double improved = edgeDiscrepancy(samples(JitterPattern::Improved, 0, 16));
    const double halton = edgeDiscrepancy(samples(JitterPattern::Halton, 0, 16));
    std::printf("worst edge coverage error: ordered %.4f, rotated %.4f, improved %.4f, halton %.4f\n", ordered, rotated,
                improved, halton);
    // Measured: ordered 0.188 (edges near 0 and 90 degrees), rotated 0.159 (near its lattice directions, 14 and 76),
    // improved 0.133, Halton 0.218.
    EXPECT_LT(improved, 0.14);
    EXPECT_LT(improved, rotated - 0.02);
    EXPECT_LT(improved, ordered);
}

TEST(Jitter, StratifiedVisitsEveryCellCentreOnce) {
    for (uint32_t n : {1u, 3u, 4u, 16u}) {
        std::set<std::pair<int, int>> cells;
        for (uint32_t f = 0; f < n * n; ++f) {
            const glm::vec2 s = jitterSample(JitterPattern::Stratified, f, n);
            const glm::vec2 cell = s * static_cast<float>(n) - 0.5f;
            EXPECT_NEAR(cell.x, std::round(cell.x), 1e-4);
            EXPECT_NEAR(cell.y, std::round(cell.y), 1e-4);
            cells.insert({static_cast<int>(std::lround(cell.x)), static_cast<int>(std::lround(cell.y))});
        }
        EXPECT_EQ(cells.size(), static_cast<size_t>(n * n));
    }
}

TEST(Jitter, OffIsTheCentre) {
    for (uint32_t f = 0; f < 8; ++f)
        EXPECT_EQ(jitterOffset(JitterPattern::Off, f), glm::vec2(0.0f));
}

} // namespace
} // namespace vitrine::scene
