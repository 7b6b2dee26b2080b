// The engine's small helpers: byte counts written for people, the hash, and huge-page advice.
#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "engine/util/format.h"
#include "engine/util/hash.h"
#include "engine/util/huge_pages.h"

namespace lancer {
namespace {

// The unit --memory-budget takes and its messages name: a budget of 4M reads "4.0 MiB".
TEST(FormatBytes, TakesTheLargestUnitReached) {
    EXPECT_EQ(formatBytes(0), "0 B");
    EXPECT_EQ(formatBytes(1023), "1023 B");
    EXPECT_EQ(formatBytes(1024), "1.0 KiB");
    EXPECT_EQ(formatBytes(3'880'000), "3.7 MiB");
    EXPECT_EQ(formatBytes(size_t(512) << 20), "512.0 MiB");
    EXPECT_EQ(formatBytes(size_t(3) << 29), "1.5 GiB");
    EXPECT_EQ(formatBytes(size_t(2) << 40), "2.0 TiB");
    EXPECT_EQ(formatBytes(size_t(4096) << 40), "4096.0 TiB");  // no unit above TiB
}

TEST(FormatBytes, AGivenUnitHoldsForEveryCount) {
    EXPECT_EQ(formatBytes(0, ByteUnit::MiB), "0.0 MiB");
    EXPECT_EQ(formatBytes(3'880'000, ByteUnit::MiB), "3.7 MiB");
    EXPECT_EQ(formatBytes(1536, ByteUnit::KiB), "1.5 KiB");
    EXPECT_EQ(formatBytes(size_t(20) << 20, ByteUnit::B), "20971520 B");
    EXPECT_EQ(formatBytes(size_t(512) << 20, ByteUnit::GiB), "0.5 GiB");
}

TEST(Hash, BytesAreFnv1a64) {
    // The published FNV-1a 64-bit test vectors.
    auto fnv = [](std::string_view s) { return hashBytes(s.data(), s.size()); };
    EXPECT_EQ(fnv(""), 0xcbf29ce484222325ull);
    EXPECT_EQ(fnv("a"), 0xaf63dc4c8601ec8cull);
    EXPECT_EQ(fnv("foobar"), 0x85944171f73967e8ull);
    // A chain of calls hashes the concatenation.
    EXPECT_EQ(hashBytes("bar", 3, hashBytes("foo", 3)), fnv("foobar"));
}

TEST(Hash, WordsTakeOneStepPerValue) {
    const std::vector<uint32_t> a = {1, 2, 3}, b = {3, 2, 1};
    uint64_t h = kHashStart;
    for (uint32_t w : a) h = (h ^ w) * 1099511628211ull;
    EXPECT_EQ(hashWords(a), h);
    EXPECT_NE(hashWords(a), hashWords(b));  // order matters
    EXPECT_EQ(hashWords({}), kHashStart);
}

// The advice is only advice: a large buffer reserved with it keeps what is written to it, and
// ranges too small or not aligned to a huge page are left as they are.
TEST(HugePages, ReservedBufferHoldsWhatIsWrittenAndGrowsAsUsual) {
    std::vector<uint64_t> v;
    const size_t n = kHugePageAdviceBytes / sizeof(uint64_t) + 12345;
    reserveHuge(v, n);
    ASSERT_GE(v.capacity(), n);
    const uint64_t* data = v.data();
    for (size_t i = 0; i < n; ++i) v.push_back(i * 2654435761u);
    EXPECT_EQ(v.data(), data);  // no reallocation within the reserved room
    size_t wrong = 0;
    for (size_t i = 0; i < n; ++i) wrong += v[i] != i * 2654435761u;
    EXPECT_EQ(wrong, 0u);
    std::vector<char> small(100, 'x');
    adviseHugePages(small.data() + 1, 50);
    reserveHuge(small, 10);  // under the capacity: nothing changes
    EXPECT_EQ(small, std::vector<char>(100, 'x'));
}

}  // namespace
}  // namespace lancer
