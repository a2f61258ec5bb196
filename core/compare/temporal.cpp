#include "core/compare/metrics.hpp"

#include "core/base/error.hpp"
#include "core/compare/plane.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace vitrine::compare {

namespace {

void requireSequence(const std::vector<Image>& frames, const std::string& what) {
    if (frames.size() < 2)
        throw UserError(what + ": expected at least two frames, got " + std::to_string(frames.size()));
    for (size_t i = 1; i < frames.size(); ++i)
        detail::requireSameSize(frames[0], frames[i], what + " (frame 0 and frame " + std::to_string(i) + ")");
}

double meanAbsoluteRgbDifference(const Image& a, const Image& b) {
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels.size(); i += 4)
        for (size_t c = 0; c < 3; ++c)
            sum += std::fabs(static_cast<double>(a.pixels[i + c]) - b.pixels[i + c]);
    return sum / (static_cast<double>(a.width) * a.height * 3.0);
}

} // namespace

double flicker(const std::vector<Image>& frames) {
    requireSequence(frames, "flicker");
    double sum = 0.0;
    for (size_t i = 1; i < frames.size(); ++i)
        sum += meanAbsoluteRgbDifference(frames[i], frames[i - 1]);
    return sum / static_cast<double>(frames.size() - 1);
}

double flickerMotionCompensated(const std::vector<Image>& frames, const std::vector<Image>& velocities) {
    requireSequence(frames, "flickerMotionCompensated");
    if (velocities.size() != frames.size())
        throw UserError("flickerMotionCompensated: expected one velocity image per frame (" +
                        std::to_string(frames.size()) + "), got " + std::to_string(velocities.size()));
    const int w = frames[0].width, h = frames[0].height;
    double pairSum = 0.0;
    int pairs = 0;
    for (size_t i = 1; i < frames.size(); ++i) {
        detail::requireSameSize(frames[i], velocities[i],
                                "flickerMotionCompensated (frame and velocity " + std::to_string(i) + ")");
        const Image& current = frames[i];
        const Image& previous = frames[i - 1];
        double sum = 0.0;
        size_t valid = 0;
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                const float* v = velocities[i].at(x, y);
                const double px = x - static_cast<double>(v[0]);
                const double py = y - static_cast<double>(v[1]);
                // Written as a negated range test so that NaN velocities are skipped too.
                if (!(px >= 0.0 && px <= w - 1 && py >= 0.0 && py <= h - 1)) continue;
                const int x0 = static_cast<int>(std::floor(px)), y0 = static_cast<int>(std::floor(py));
                const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
                const double fx = px - x0, fy = py - y0;
                const float* p00 = previous.at(x0, y0);
                const float* p10 = previous.at(x1, y0);
                const float* p01 = previous.at(x0, y1);
                const float* p11 = previous.at(x1, y1);
                const float* c = current.at(x, y);
                for (int ch = 0; ch < 3; ++ch) {
                    const double top = p00[ch] + fx * (p10[ch] - p00[ch]);
                    const double bottom = p01[ch] + fx * (p11[ch] - p01[ch]);
                    sum += std::fabs(c[ch] - (top + fy * (bottom - top)));
                }
                ++valid;
            }
        }
        if (valid > 0) {
            pairSum += sum / (static_cast<double>(valid) * 3.0);
            ++pairs;
        }
    }
    return pairs > 0 ? pairSum / pairs : 0.0;
}

std::vector<double> errorPerFrame(const std::vector<Image>& frames, const std::vector<Image>& references,
                                  FrameMetric metric) {
    if (frames.size() != references.size())
        throw UserError("errorPerFrame: expected one reference per frame (" + std::to_string(frames.size()) +
                        "), got " + std::to_string(references.size()));
    std::vector<double> errors;
    for (size_t i = 0; i < frames.size(); ++i) {
        detail::requireSameSize(frames[i], references[i], "errorPerFrame (frame " + std::to_string(i) + ")");
        errors.push_back(metric == FrameMetric::Psnr ? psnr(frames[i], references[i])
                                                     : ldrFlip(references[i], frames[i]).mean);
    }
    return errors;
}

std::vector<double> errorPerFrame(const std::vector<Image>& frames, const Image& reference, FrameMetric metric) {
    std::vector<double> errors;
    for (size_t i = 0; i < frames.size(); ++i) {
        detail::requireSameSize(frames[i], reference, "errorPerFrame (frame " + std::to_string(i) + ")");
        errors.push_back(metric == FrameMetric::Psnr ? psnr(frames[i], reference) : ldrFlip(reference, frames[i]).mean);
    }
    return errors;
}

} // namespace vitrine::compare
