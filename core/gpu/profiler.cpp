#include "core/gpu/profiler.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"

namespace vitrine {

GpuProfiler::GpuProfiler(Context& ctx, uint32_t maxScopes) : mCtx(ctx), mMaxScopes(std::max(1u, maxScopes)) {
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = mMaxScopes * 2;
    VK_CHECK(vkCreateQueryPool(ctx.device(), &info, nullptr, &mPool));
    ctx.setName(reinterpret_cast<uint64_t>(mPool), VK_OBJECT_TYPE_QUERY_POOL, "profiler.timestamps");
}

GpuProfiler::~GpuProfiler() {
    Context* ctx = &mCtx;
    VkQueryPool pool = mPool;
    ctx->destroyLater([ctx, pool] { vkDestroyQueryPool(ctx->device(), pool, nullptr); });
}

void GpuProfiler::begin(VkCommandBuffer cmd) { vkCmdResetQueryPool(cmd, mPool, 0, mMaxScopes * 2); }

void GpuProfiler::beginScope(VkCommandBuffer cmd, uint32_t scope) {
    if (scope >= mMaxScopes) throw InternalError("profiler scope " + std::to_string(scope) + " out of range");
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, mPool, scope * 2);
}

void GpuProfiler::endScope(VkCommandBuffer cmd, uint32_t scope) {
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, mPool, scope * 2 + 1);
}

std::vector<double> GpuProfiler::resolve(uint32_t scopeCount) const {
    std::vector<double> ms(scopeCount, 0.0);
    if (scopeCount == 0) return ms;
    std::vector<uint64_t> ticks(scopeCount * 2);
    VK_CHECK(vkGetQueryPoolResults(mCtx.device(), mPool, 0, scopeCount * 2, ticks.size() * sizeof(uint64_t),
                                   ticks.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const double nsPerTick = mCtx.timestampPeriodNs();
    for (uint32_t i = 0; i < scopeCount; ++i)
        ms[i] = static_cast<double>(ticks[2 * i + 1] - ticks[2 * i]) * nsPerTick * 1e-6;
    return ms;
}

} // namespace vitrine
