// Fresh pages are dear where the viewer is measured: in its VM a page's first write costs
// about 3 ms a MiB of the writing thread's time (a 1280x720 RGBA buffer 10-12 ms, against
// 0.2 ms to write the same buffer again; docs/viewer.md, "Fresh memory"). A buffer the UI
// thread needs whole in one frame (the layer's read-back) is therefore made ahead on a worker
// (PreparedBytes); freed blocks are kept for reuse process-wide (engine/util/kept_memory.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <future>
#include <vector>

namespace lancer::viewer {

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
    /// True when `n` bytes are made and not yet taken (false if their allocation failed).
    bool ready(size_t n) const;
    /// True while a worker is still making `n` bytes.
    bool making(size_t n) const;
    /// The `n` bytes made, when ready(n); else an empty vector (nothing is waited for).
    std::vector<uint8_t> take(size_t n);

  private:
    size_t size_ = 0;  ///< the size being made or made (0: none)
    mutable std::future<std::vector<uint8_t>> making_;
    mutable std::vector<uint8_t> made_;
};

}  // namespace lancer::viewer
