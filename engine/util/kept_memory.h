// Freed memory kept in the process's heaps for the next allocation.
//
// glibc returns a freed block over its mmap threshold (128 KiB at first, raised block by block
// up to 32 MiB) to the system, and the heap's top over its trim threshold. The next block of
// that size is fresh memory again, and each of its 4 KiB pages a page fault at its first write:
// in the VM this project is measured in, a fresh 3.5 MiB block written once took 10.5-11.9 ms
// of the writing thread's CPU, written again 0.2 ms (2026-12-07). A bench's repeated builds, a
// viewer's images, batches and textures are such blocks (docs/irregular.md, "Freed memory
// kept"; docs/viewer.md, "Fresh memory").
#pragma once

#include <cstddef>

namespace lancer {

/// The largest block keepFreedMemory() has come from the heaps, and stay there once freed:
/// glibc's largest mmap threshold on 64 bits.
inline constexpr size_t kKeptBlockBytes = size_t(32) << 20;

/// Sets malloc's mmap threshold to kKeptBlockBytes and its trim threshold to `trimBytes` (at
/// most 1 GiB), for the whole process; false where the C library refuses them (a sanitizer's
/// allocator, another C library).
bool keepFreedMemory(size_t trimBytes = size_t(256) << 20);

}  // namespace lancer
