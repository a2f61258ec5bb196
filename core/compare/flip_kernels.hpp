#pragma once

#include "core/compare/plane.hpp"

#include <array>
#include <vector>

// Internal to core/compare: the filter kernels of LDR-FLIP (HPG 2020), sized from pixels per degree.
namespace vitrine::compare::detail {

// One separable Gaussian of the paper's CSF, with its share of the 2D kernel's unit sum.
struct CsfTerm {
    double weight;
    Kernel kernel; // normalised 1D Gaussian
};

struct FlipKernels {
    std::array<std::vector<CsfTerm>, 3> csf; // Y (achromatic), Cx (red-green), Cz (blue-yellow)
    Kernel featureGauss;                     // normalised 1D Gaussian of the feature detectors
    Kernel edge;                             // first derivative: positive weights sum to 1, negative to -1
    Kernel point;                            // second derivative, normalised the same way
};

// Builds every kernel for one viewing condition; ppd > 0.
FlipKernels makeKernels(double ppd);

} // namespace vitrine::compare::detail
