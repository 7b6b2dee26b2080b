// Fresh pages are dear where the viewer is measured: in its VM a page's first write costs
// about 3 ms a MiB of the writing thread's time (a 1280x720 RGBA buffer 10-12 ms, against
// 0.2 ms to write the same buffer again; docs/viewer.md, "Fresh memory"). A buffer the UI
// thread needs whole in one frame (the layer's read-back) is therefore made ahead on a worker
// (PreparedBytes), and freed blocks stay in the process's heaps for reuse (keepFreedMemory()):
// glibc returns a freed block over its mmap threshold (128 KiB at first) to the system, so
// each new image, batch or llvmpipe texture of a size freed before paid for its pages again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <future>
#include <vector>

namespace lancer::viewer {

/// The largest block keepFreedMemory() has come from the heaps (and stay there once freed):
/// glibc's largest mmap threshold on 64 bits.
inline constexpr size_t kKeptBlockBytes = size_t(32) << 20;

/// Sets malloc's mmap threshold to kKeptBlockBytes and its trim threshold to `trimBytes`, for
/// the whole process; false where the C library refuses them (a sanitizer's allocator).
bool keepFreedMemory(size_t trimBytes = size_t(256) << 20);

/// Bytes of a size known ahead, allocated and written on a worker thread, so that the thread
/// taking them finds their pages mapped.
class PreparedBytes {
  public:
    PreparedBytes() = default;
    /// Waits for a worker still writing.
    ~PreparedBytes();
    PreparedBytes(const PreparedBytes&) = delete;
    PreparedBytes& operator=(const PreparedBytes&) = delete;

    /// Starts making `n` zero bytes on a worker, unless `n` are ready or being made already
    /// (bytes of another size are dropped).
    void prepare(size_t n);
    /// True when `n` bytes are made and not yet taken.
    bool ready(size_t n) const;
    /// The `n` bytes made, when ready(n); else an empty vector (nothing is waited for).
    std::vector<uint8_t> take(size_t n);

  private:
    size_t size_ = 0;  ///< the size being made or made (0: none)
    mutable std::future<std::vector<uint8_t>> making_;
    mutable std::vector<uint8_t> made_;
};

}  // namespace lancer::viewer
