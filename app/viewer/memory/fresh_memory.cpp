#include "app/viewer/memory/fresh_memory.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>

namespace lancer::viewer {

bool keepFreedMemory(size_t trimBytes) {
    // A fixed mmap threshold also stops glibc from moving it block by block.
    return mallopt(M_MMAP_THRESHOLD, int(kKeptBlockBytes)) == 1 &&
           mallopt(M_TRIM_THRESHOLD, int(std::min<size_t>(trimBytes, size_t(1) << 30))) == 1;
}

PreparedBytes::~PreparedBytes() {
    if (making_.valid()) making_.wait();
}

void PreparedBytes::prepare(size_t n) {
    if (n == size_) return;
    if (making_.valid()) making_.wait();  // a size changed while one was made: rare
    making_ = {};
    made_ = {};
    size_ = n;
    if (n == 0) return;
    // Value-initialised: every page written on the worker.
    making_ = std::async(std::launch::async, [n] { return std::vector<uint8_t>(n); });
}

bool PreparedBytes::ready(size_t n) const {
    if (n == 0 || n != size_) return false;
    if (making_.valid()) {
        if (making_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
        made_ = making_.get();
    }
    return made_.size() == n;
}

std::vector<uint8_t> PreparedBytes::take(size_t n) {
    if (!ready(n)) return {};
    size_ = 0;
    std::vector<uint8_t> taken = std::move(made_);
    made_ = {};
    return taken;
}

}  // namespace lancer::viewer
