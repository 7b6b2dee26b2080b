#include "engine/util/format.h"

#include <cstdio>

namespace lancer {

std::string formatBytes(size_t bytes, ByteUnit unit) {
    static const char* const kNames[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    int u = int(unit) - int(ByteUnit::B);
    double v = double(bytes);
    if (unit == ByteUnit::Auto) {
        for (u = 0; v >= 1024.0 && u < 4; ++u) v /= 1024.0;
    } else {
        for (int i = 0; i < u; ++i) v /= 1024.0;
    }
    char buf[64];
    if (u == 0)
        std::snprintf(buf, sizeof buf, "%zu B", bytes);
    else
        std::snprintf(buf, sizeof buf, "%.1f %s", v, kNames[u]);
    return buf;
}

}  // namespace lancer
