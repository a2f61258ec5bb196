#include "core/compare/flip_kernels.hpp"

#include <cmath>
#include <numbers>

namespace vitrine::compare::detail {

namespace {

// Peak-to-trough width of the human edge detector in degrees, i.e. 2 standard deviations (HPG 2020, section 4.2).
constexpr double kFeatureWidth = 0.082;

// The CSFs are sums of Gaussians in frequency, a·exp(−b·f²); in space each term is a·sqrt(π/b)·exp(−π²·d²/b) with
// d in degrees. Every channel uses the radius of the widest term so that the three share one support, as in the
// paper's reference code. A 2D kernel of Gaussian terms is a sum of separable kernels, so we filter each term
// separably and weigh it by its share of the 2D sum — the same result as the paper's normalised 2D kernel.
std::vector<CsfTerm> csfTerms(const std::vector<std::array<double, 2>>& ab, double ppd, int radius) {
    std::vector<CsfTerm> terms;
    double total = 0.0;
    for (const auto& [a, b] : ab) {
        std::vector<double> g(2 * radius + 1);
        double sum = 0.0;
        for (int i = -radius; i <= radius; ++i) {
            const double d = i / ppd;
            g[i + radius] = std::exp(-std::numbers::pi * std::numbers::pi * d * d / b);
            sum += g[i + radius];
        }
        CsfTerm term{a * std::sqrt(std::numbers::pi / b) * sum * sum, {}};
        for (double v : g)
            term.kernel.push_back(v / sum);
        total += term.weight;
        terms.push_back(std::move(term));
    }
    for (CsfTerm& t : terms)
        t.weight /= total;
    return terms;
}

Kernel normaliseSigned(const Kernel& k) {
    double positive = 0.0, negative = 0.0;
    for (double v : k)
        (v > 0.0 ? positive : negative) += v;
    Kernel out;
    // A sum that underflowed to 0 (tiny ppd) leaves its weights at 0 instead of dividing by zero.
    for (double v : k)
        out.push_back(v > 0.0 ? (positive > 0.0 ? v / positive : 0.0) : (negative < 0.0 ? -v / negative : 0.0));
    return out;
}

} // namespace

FlipKernels makeKernels(double ppd) {
    FlipKernels k;
    // (a, b) of the achromatic, red-green and blue-yellow CSFs (HPG 2020, section 4.1).
    const std::vector<std::array<double, 2>> kA = {{1.0, 0.0047}};
    const std::vector<std::array<double, 2>> kRg = {{1.0, 0.0053}};
    const std::vector<std::array<double, 2>> kBy = {{34.1, 0.04}, {13.5, 0.025}};
    constexpr double kMaxB = 0.04;
    const int csfRadius =
        static_cast<int>(std::ceil(3.0 * std::sqrt(kMaxB / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
    k.csf = {csfTerms(kA, ppd, csfRadius), csfTerms(kRg, ppd, csfRadius), csfTerms(kBy, ppd, csfRadius)};

    const double sd = 0.5 * kFeatureWidth * ppd;
    const int radius = static_cast<int>(std::ceil(3.0 * sd));
    Kernel gauss, edge, point;
    double gaussSum = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        const double g = std::exp(-(i * i) / (2.0 * sd * sd));
        gauss.push_back(g);
        gaussSum += g;
        edge.push_back(-i * g);
        point.push_back((i * i / (sd * sd) - 1.0) * g);
    }
    for (double g : gauss)
        k.featureGauss.push_back(g / gaussSum);
    k.edge = normaliseSigned(edge);
    k.point = normaliseSigned(point);
    return k;
}

} // namespace vitrine::compare::detail
