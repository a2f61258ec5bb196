// The CLI's heap policy (core/base/heap.hpp): large blocks come from the heap, whose reserved range is advised huge
// pages, and freed pages stay in the process. Each case runs in a child process (EXPECT_EXIT), since the policy is
// process-wide and the other tests of this binary keep glibc's defaults.
#include "core/base/heap.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace vitrine {
namespace {

#if defined(__GLIBC__)

// The VmFlags of the mapping that holds `address`, from /proc/self/smaps ("" when none does).
std::string vmFlagsAt(const void* address) {
    const auto at = reinterpret_cast<std::uintptr_t>(address);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t lo = 0, hi = 0;
        if (std::sscanf(line.c_str(), "%lx-%lx ", &lo, &hi) == 2) {
            inside = lo <= at && at < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line.substr(8);
    }
    return "";
}

// Exits 0 when every check holds, else prints the first failure and exits 1.
[[noreturn]] void fail(const std::string& what) {
    std::fprintf(stderr, "%s\n", what.c_str());
    std::exit(1);
}

void checkTunedHeap() {
    const HeapPolicy policy = tuneHeapForLargeBlocks(std::size_t(256) << 20);
    if (!policy.applied) fail("not applied: " + policy.note);
    if (policy.reserved < (std::size_t(256) << 20)) fail("reserved " + std::to_string(policy.reserved));
    if (!policy.hugePages) fail("no huge pages: " + policy.note);

    // A 24 MiB block (glibc's default would mmap it on its own) comes from the heap, in the advised range.
    const struct mallinfo2 before = mallinfo2();
    void* volatile block = std::malloc(std::size_t(24) << 20);
    static_cast<volatile char*>(block)[0] = 1;
    if (mallinfo2().hblks != before.hblks) fail("a 24 MiB block was given its own mmap");
    // Huge pages cover whole aligned 2 MiB ranges: the block's second aligned one is in the advised range (its first
    // bytes may lie in the heap's free space from before the reservation).
    constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
    const std::uintptr_t inside = ((reinterpret_cast<std::uintptr_t>(block) + kHuge - 1) & ~(kHuge - 1)) + kHuge;
    const std::string flags = vmFlagsAt(reinterpret_cast<const void*>(inside));
    if (flags.find(" hg") == std::string::npos) fail("the block's pages are not advised huge pages: " + flags);

    // Freed, its pages stay: the heap does not shrink, and the same size comes back at the same address.
    void* const first = block;
    std::free(block);
    if (mallinfo2().arena < before.arena) fail("the heap was trimmed after a free");
    void* volatile again = std::malloc(std::size_t(24) << 20);
    if (again != first) fail("a freed 24 MiB block was not reused");
    std::free(again);
    std::exit(0);
}

void checkSystemHeap() {
    setenv("VITRINE_SYSTEM_HEAP", "1", 1);
    const HeapPolicy policy = tuneHeapForLargeBlocks();
    if (policy.applied || policy.hugePages || policy.reserved != 0) fail("VITRINE_SYSTEM_HEAP=1 did not opt out");
    const struct mallinfo2 before = mallinfo2();
    // 48 MiB: above the largest threshold glibc's defaults ever move to, so it gets its own mmap.
    void* volatile block = std::malloc(std::size_t(48) << 20);
    if (mallinfo2().hblks != before.hblks + 1) fail("glibc's default no longer mmaps a 48 MiB block");
    std::free(block);
    std::exit(0);
}

TEST(Heap, LargeBlocksComeFromTheHugePageHeapAndFreedPagesAreKept) {
    EXPECT_EXIT(checkTunedHeap(), testing::ExitedWithCode(0), "");
}

TEST(Heap, SystemHeapSwitchKeepsGlibcsDefaults) {
    EXPECT_EXIT(checkSystemHeap(), testing::ExitedWithCode(0), "");
}

#endif

} // namespace
} // namespace vitrine
