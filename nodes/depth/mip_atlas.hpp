#pragma once

// The mip-chain atlas of shaders/common/mip_atlas.glsl on the C++ side: depth.hiz and color.pyramid size their
// outputs with it and record their reduction with recordMipChain().
#include "core/graph/node.hpp"
#include "shaders/depth/hiz.h"

#include <algorithm>
#include <cstdint>

namespace vitrine {

// Levels down to 1x1 of a level-0 image of w x h.
inline uint32_t mipAtlasLevels(uint32_t w, uint32_t h) {
    uint32_t levels = 1;
    while ((std::max(w, h) >> levels) > 0) ++levels;
    return levels;
}

// The atlas of all levels of a w x h image: level 0, then levels 1.. in a row below it.
inline uint32_t mipAtlasWidth(uint32_t w, uint32_t h) {
    uint32_t levels = mipAtlasLevels(w, h), row = 0;
    for (uint32_t k = 1; k < levels; ++k) row += std::max(w >> k, 1u);
    return std::max(w, row);
}
inline uint32_t mipAtlasHeight(uint32_t w, uint32_t h) {
    return h + (mipAtlasLevels(w, h) > 1 ? std::max(h >> 1, 1u) : 0u);
}
inline void sizeMipAtlas(ImageDesc& out, uint32_t w, uint32_t h) {
    out.width = mipAtlasWidth(w, h);
    out.height = mipAtlasHeight(w, h);
}

// Levels written per dispatch: each texel reads at most (2^kMipLevelsPerDispatch + 1)^2 source texels.
inline constexpr int kMipLevelsPerDispatch = 3;

// The whole chain in ceil(levels / 3) dispatches, each reading the last level of the one before; the first also
// writes zeros to every atlas texel outside the levels.
inline void recordMipChain(ExecuteContext& ctx, PipelineId pipeline, uint32_t w, uint32_t h, int fallback = 0) {
    const int levels = static_cast<int>(mipAtlasLevels(w, h));
    gpu_types::MipChainPush push{};
    push.size = {static_cast<int>(w), static_cast<int>(h)};
    push.fallback = fallback;
    for (int first = 0; first < levels; first += kMipLevelsPerDispatch) {
        push.source = first - 1;
        push.first = first;
        push.count = std::min(kMipLevelsPerDispatch, levels - first);
        if (first > 0) ctx.computeBarrier();
        // The first dispatch spans the atlas's width: it also zeroes the padding between and beside the levels
        // (never left as whatever the memory held: bilinear lookups at a level's edge touch it).
        ctx.dispatch(pipeline, push, first == 0 ? mipAtlasWidth(w, h) : std::max(w >> first, 1u),
                     std::max(h >> first, 1u));
    }
}

} // namespace vitrine
