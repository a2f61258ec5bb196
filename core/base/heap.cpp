#include "core/base/heap.hpp"

#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace vitrine {

HeapPolicy tuneHeapForLargeBlocks(std::size_t reserve) {
    HeapPolicy policy;
    if (const char* v = std::getenv("VITRINE_SYSTEM_HEAP"); v && std::strcmp(v, "1") == 0) {
        policy.note = "VITRINE_SYSTEM_HEAP=1: glibc's default heap";
        return policy;
    }
#if defined(__GLIBC__)
    constexpr std::size_t kHugePage = std::size_t(2) << 20;
    // glibc refuses a threshold above half its per-thread heap size (32 MiB on 64-bit): the largest it takes.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    // Free space at the top of the heap is given back to the kernel only beyond this; it must exceed `reserve`, or the
    // first free() below would trim the reservation away again.
    mallopt(M_TRIM_THRESHOLD, INT_MAX);
    policy.applied = true;
    // At most 1 GiB: M_TOP_PAD is an int, and the trim threshold (INT_MAX) must stay above the reserved free space.
    if (reserve == 0 || reserve > (std::size_t(1) << 30)) return policy;

    // Grow the heap once by `reserve` (M_TOP_PAD pads the next sbrk): one block that the current top cannot hold and
    // that is under the mmap threshold, so it comes from sbrk.
    auto* before = static_cast<char*>(sbrk(0));
    mallopt(M_TOP_PAD, static_cast<int>(reserve));
    // Through a volatile pointer: the compiler may otherwise drop a malloc whose block is only freed.
    void* volatile grow = std::malloc(std::size_t(16) << 20);
    mallopt(M_TOP_PAD, 64 << 20); // later growth, if any, in 64 MiB steps
    auto* after = static_cast<char*>(sbrk(0));
    std::free(grow);
    if (before == reinterpret_cast<char*>(-1) || after == reinterpret_cast<char*>(-1) || after < before + reserve / 2) {
        policy.note = "the heap did not grow by sbrk (it lives in mmap'd memory): no huge pages";
        return policy;
    }
    policy.reserved = static_cast<std::size_t>(after - before);
    const auto first = (reinterpret_cast<std::uintptr_t>(before) + kHugePage - 1) & ~(kHugePage - 1);
    const auto last = reinterpret_cast<std::uintptr_t>(after) & ~(kHugePage - 1);
    if (last > first && madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE) == 0)
        policy.hugePages = true;
    else
        policy.note = std::string("madvise(MADV_HUGEPAGE) failed: ") + std::strerror(errno);
#else
    policy.note = "not glibc: the C library's default heap";
#endif
    return policy;
}

} // namespace vitrine
