// Numbers written for people: byte counts in binary units, B to TiB.
#pragma once

#include <cstddef>
#include <string>

namespace lancer {

enum class ByteUnit { Auto, B, KiB, MiB, GiB, TiB };

/// `bytes` as "812 B", "37.5 KiB", "3.7 MiB" or "1.5 GiB": the units --memory-budget takes.
/// Auto takes the largest unit of which there is at least one (up to TiB); a table column passes
/// one unit for all its rows.
std::string formatBytes(size_t bytes, ByteUnit unit = ByteUnit::Auto);

}  // namespace lancer
