// The hash for keys made of bytes or of index lists (FNV-1a, 64-bit): cache keys, pools of
// shared lists. Not for anything that must resist chosen inputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace lancer {

/// FNV-1a's offset basis: the hash of nothing, where a chain of calls starts.
inline constexpr uint64_t kHashStart = 14695981039346656037ull;

/// FNV-1a over `n` bytes, continued from `h`.
inline uint64_t hashBytes(const void* data, size_t n, uint64_t h = kHashStart) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/// FNV-1a's step taken per 32-bit value rather than per byte (a quarter of the multiplies), for
/// keys that are lists of indices; continued from `h`.
inline uint64_t hashWords(std::span<const uint32_t> words, uint64_t h = kHashStart) {
    for (uint32_t w : words) h = (h ^ w) * 1099511628211ull;
    return h;
}

}  // namespace lancer
