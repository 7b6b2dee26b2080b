// Numbers written for people: byte counts in B, KiB or MiB.
#pragma once

#include <cstddef>
#include <string>

namespace lancer {

enum class ByteUnit { Auto, B, KiB, MiB };

/// `bytes` as "812 B", "37.5 KiB" or "3.7 MiB". Auto takes the largest unit of which there are
/// at least 10 (below 10 KiB, bytes), so 2 to 4 significant digits show; a table column passes
/// one unit for all its rows.
std::string formatBytes(size_t bytes, ByteUnit unit = ByteUnit::Auto);

}  // namespace lancer
