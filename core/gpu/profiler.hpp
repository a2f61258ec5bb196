#pragma once

#include "core/gpu/vk_check.hpp"

#include <cstdint>
#include <vector>

namespace vitrine {

class Context;

// Timestamp queries around scopes (one scope per render-graph pass). Record begin()/
// beginScope()/endScope() into one command buffer; after it completed, resolve() gives the
// milliseconds of each scope in the order they were opened.
class GpuProfiler {
public:
    GpuProfiler(Context& ctx, uint32_t maxScopes);
    ~GpuProfiler();
    GpuProfiler(const GpuProfiler&) = delete;
    GpuProfiler& operator=(const GpuProfiler&) = delete;

    void begin(VkCommandBuffer cmd);
    void beginScope(VkCommandBuffer cmd, uint32_t scope);
    void endScope(VkCommandBuffer cmd, uint32_t scope);
    std::vector<double> resolve(uint32_t scopeCount) const;

private:
    Context& mCtx;
    VkQueryPool mPool = VK_NULL_HANDLE;
    uint32_t mMaxScopes;
};

} // namespace vitrine
