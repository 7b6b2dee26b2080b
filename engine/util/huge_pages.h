// Large buffers a build fills once, backed by huge pages where the kernel offers them.
//
// A build's large arrays (a tree pool, leaves, sphere quads) are fresh memory, and every 4 KiB
// page of it is a page fault at its first touch: on the machines measured, 64 MiB touched page
// by page took 180 ms of CPU time in the kernel, and 4 ms once advised to huge pages (a fault
// per 2 MiB). The advice changes no byte of what is built.
#pragma once

#include <cstddef>
#include <vector>

namespace lancer {

/// Buffers from this size on are advised (smaller ones hold at most a few huge pages).
inline constexpr size_t kHugePageAdviceBytes = size_t(4) << 20;

/// Ask the kernel to back the whole 2 MiB pages inside [p, p + bytes) with huge pages when they
/// are first touched (madvise MADV_HUGEPAGE, Linux); nothing elsewhere or when refused.
void adviseHugePages(void* p, size_t bytes);

/// `v` with room for `n` elements, its buffer advised to huge pages when it is large: to call
/// before the elements are first written.
template <class T, class A>
void reserveHuge(std::vector<T, A>& v, size_t n) {
    v.reserve(n);
    if (v.capacity() * sizeof(T) >= kHugePageAdviceBytes)
        adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace lancer
