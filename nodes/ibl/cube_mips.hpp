#pragma once
// Host-side helpers for the prefiltered cube maps of ibl.capture and ibl.environment: the box-filtered mip chain
// filtered importance sampling reads (shaders/ibl/prefilter.comp's source) and its upload.
#include "core/gpu/descriptors.hpp"
#include "core/gpu/resources.hpp"
#include "core/image/image.hpp"

#include <string>

#include <vector>

namespace vitrine {

class Context;

// The 2x2 box-filtered mip chain of each face (faces of a power-of-two size): chain[m][layer].
std::vector<std::vector<Image>> boxMips(std::vector<Image> faces, uint32_t mips);

// Fills every mip and layer of `image` (RGBA32F, just created with TRANSFER_DST and SAMPLED usage) from host data
// and leaves it ready to be sampled by compute shaders. Outside the frame's command buffer: it waits for the GPU.
void uploadCubeMips(Context& ctx, const GpuImage& image, const std::vector<std::vector<Image>>& mips);

// The node sets of shaders/ibl/prefilter.comp and copy_mip.comp (binding 0 the source, sampled linearly between
// mips; binding 1 one mip of the target): made on first use (a pool of 16 sets, one per mip), emptied on later ones.
void resetPrefilterSets(Context& gpu, DescriptorSets& sets, const std::string& name);
// A set of `sets` reading `source` and writing `target` (a mip's view, in GENERAL layout).
VkDescriptorSet prefilterMipSet(Context& gpu, DescriptorSets& sets, VkImageView source, VkImageView target);

} // namespace vitrine
