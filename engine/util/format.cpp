#include "engine/util/format.h"

#include <cstdio>

namespace lancer {

std::string formatBytes(size_t bytes, ByteUnit unit) {
    constexpr size_t kKiB = 1024, kMiB = 1024 * 1024;
    if (unit == ByteUnit::Auto)
        unit = bytes < 10 * kKiB ? ByteUnit::B : bytes < 10 * kMiB ? ByteUnit::KiB : ByteUnit::MiB;
    char buf[64];
    if (unit == ByteUnit::B)
        std::snprintf(buf, sizeof buf, "%zu B", bytes);
    else if (unit == ByteUnit::KiB)
        std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / double(kKiB));
    else
        std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(kMiB));
    return buf;
}

}  // namespace lancer
