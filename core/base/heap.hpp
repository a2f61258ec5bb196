#pragma once

#include <cstddef>
#include <string>

namespace vitrine {

// The CLI's heap policy (README "Warm starts"). A warm `run` of the museum spends most of its time before the first
// pass in page faults, not in arithmetic: building the scene fills ~12 MB of vertices and indices through growing
// vectors, glibc hands every block of 128 KiB or more out as a fresh mmap and gives it back on free, so each doubling
// faults new 4 KiB pages and unmaps the old ones (measured on a 2-core VM, where a fault costs microseconds).
//
// tuneHeapForLargeBlocks() keeps freed memory in the process and backs it with transparent huge pages:
//   - blocks under 32 MiB (glibc's largest threshold) come from the main heap instead of their own mmap;
//   - the heap is not trimmed below 2 GiB of free space, so freed pages are reused without a fault;
//   - the heap is grown once by `reserve` bytes of address space (not memory: nothing is touched) and that range is
//     advised MADV_HUGEPAGE, so a first touch faults 2 MiB at a time where the kernel allows it
//     (/sys/kernel/mm/transparent_hugepage/enabled set to "madvise" or "always").
// Resident memory grows only by what is touched, rounded to 2 MiB pages, and is not returned until exit: right for
// the CLI's short runs, not for a library inside someone else's process (the Python module does not call it).
// VITRINE_SYSTEM_HEAP=1 in the environment leaves glibc's defaults (an A/B switch for the time to first pass).
struct HeapPolicy {
    bool applied = false;     // false: the environment opted out or the C library is not glibc
    bool hugePages = false;   // the reserved range was advised MADV_HUGEPAGE
    std::size_t reserved = 0; // bytes of address space added to the heap up front
    std::string note;         // why something was not done (for --verbose)
};
HeapPolicy tuneHeapForLargeBlocks(std::size_t reserve = std::size_t(1) << 30);

} // namespace vitrine
