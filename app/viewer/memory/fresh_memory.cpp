#include "app/viewer/memory/fresh_memory.h"

#include <chrono>
#include <exception>

namespace lancer::viewer {

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
        try {
            made_ = making_.get();
        } catch (const std::exception&) {
            made_ = {};  // the allocation failed: nothing prepared, the taker allocates
        }
    }
    return made_.size() == n;
}

bool PreparedBytes::making(size_t n) const {
    return n != 0 && n == size_ && making_.valid() &&
           making_.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
}

std::vector<uint8_t> PreparedBytes::take(size_t n) {
    if (!ready(n)) return {};
    size_ = 0;
    std::vector<uint8_t> taken = std::move(made_);
    made_ = {};
    return taken;
}

}  // namespace lancer::viewer
