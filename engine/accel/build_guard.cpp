#include "engine/accel/build_guard.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "engine/util/format.h"

namespace lancer {

size_t physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? size_t(pages) * size_t(page) : 0;
}

size_t defaultMemoryBudget() {
    const size_t phys = physicalMemoryBytes();
    if (phys == 0) return size_t(1) << 30;
    return std::max(phys / 8, size_t(256) << 20);
}

size_t parseMemoryBudget(const std::string& text) {
    auto bad = [&] {
        return std::invalid_argument("--memory-budget " + text +
                                     ": expected a size such as 512M, 2G or 1.5GiB");
    };
    size_t pos = 0;
    double v;
    try {
        v = std::stod(text, &pos);
    } catch (const std::exception&) {
        throw bad();
    }
    std::string unit = text.substr(pos);
    for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
    if (unit.size() > 1 && unit.back() == 'B') unit.pop_back();
    if (unit.size() > 1 && unit.back() == 'I') unit.pop_back();
    double scale = 1.0;
    if (unit == "K")
        scale = 1024.0;
    else if (unit == "M")
        scale = 1024.0 * 1024.0;
    else if (unit == "G")
        scale = 1024.0 * 1024.0 * 1024.0;
    else if (unit == "T")
        scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
    else if (!unit.empty() && unit != "B")
        throw bad();
    v *= scale;
    if (!(v >= 1.0 && v < 1.8e19)) throw bad();
    return size_t(v);
}

BuildGuard::BuildGuard(size_t budget, BuildControl control, size_t held)
    : given_(budget ? budget : defaultMemoryBudget()),
      budget_(given_ - std::min(held, given_)),
      control_(std::move(control)),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

std::string BuildGuard::describe() const {
    if (budget_ == given_) return formatBytes(given_);
    return formatBytes(given_) + " (" + formatBytes(given_ - budget_) +
           " of it held by the light buffer)";
}

void BuildGuard::report(const char* stage, size_t bytes, size_t items) {
    const std::unique_lock lock(reporting_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    const auto now = std::chrono::steady_clock::now();
    const double secs = std::chrono::duration<double>(now - start_).count();
    if (secs < 1.0 || now - last_ < std::chrono::seconds(1)) return;
    last_ = now;
    control_.progress({stage, secs, bytes, budget_, items});
}

}  // namespace lancer
