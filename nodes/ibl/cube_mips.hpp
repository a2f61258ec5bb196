#pragma once
// Host-side helpers for the prefiltered cube maps of ibl.capture and ibl.environment: the box-filtered mip chain
// filtered importance sampling reads (shaders/ibl/prefilter.comp's source) and its upload.
#include "core/gpu/resources.hpp"
#include "core/image/image.hpp"

#include <vector>

namespace vitrine {

class Context;

// The 2x2 box-filtered mip chain of each face (faces of a power-of-two size): chain[m][layer].
std::vector<std::vector<Image>> boxMips(std::vector<Image> faces, uint32_t mips);

// Fills every mip and layer of `image` (RGBA32F, just created with TRANSFER_DST and SAMPLED usage) from host data
// and leaves it ready to be sampled by compute shaders. Outside the frame's command buffer: it waits for the GPU.
void uploadCubeMips(Context& ctx, const GpuImage& image, const std::vector<std::vector<Image>>& mips);

} // namespace vitrine
