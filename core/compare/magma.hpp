#pragma once

#include <array>

// Internal to core/compare: the magma colour map (Smith and van der Walt's CC0 map, as shipped by matplotlib), which
// the FLIP paper uses for its error maps.
namespace vitrine::compare::detail {

using Rgb = std::array<float, 3>;

// Entry `index` (0..255, clamped) of the table, sRGB-encoded as published — for HTML/CSS colours.
const Rgb& magmaSrgb(int index);

// The same entry decoded to linear RGB — for Images, which are linear.
const Rgb& magmaLinear(int index);

} // namespace vitrine::compare::detail
