#include "app/viewer/memory/fresh_memory.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <thread>
#include <vector>

#include "engine/util/kept_memory.h"

namespace lancer::viewer {
namespace {

/// The share of the whole pages inside [p, p + bytes) that are resident (mincore).
double residentShare(const void* p, size_t bytes) {
    const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
    const uintptr_t b = (uintptr_t(p) + page - 1) & ~(page - 1);
    const uintptr_t e = (uintptr_t(p) + bytes) & ~(page - 1);
    if (e <= b) return 0.0;
    std::vector<unsigned char> in((e - b) / page);
    if (mincore(reinterpret_cast<void*>(b), e - b, in.data()) != 0) return -1.0;
    size_t resident = 0;
    for (unsigned char c : in) resident += c & 1;
    return double(resident) / double(in.size());
}

constexpr size_t kWindowBuffer = size_t(1280) * 720 * 4;

// A fresh mapping is not resident until written: what the prepared bytes spare the UI thread.
TEST(FreshMemory, MincoreTellsPagesNotYetWritten) {
    void* fresh =
        mmap(nullptr, kWindowBuffer, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(fresh, MAP_FAILED);
    EXPECT_EQ(residentShare(fresh, kWindowBuffer), 0.0);
    static_cast<volatile unsigned char*>(fresh)[0] = 1;
    EXPECT_GT(residentShare(fresh, kWindowBuffer), 0.0);
    munmap(fresh, kWindowBuffer);
}

// The bytes come made on a worker: taken here, their pages are mapped before this thread
// writes any.
TEST(FreshMemory, PreparedBytesComeZeroWithTheirPagesMapped) {
    PreparedBytes bytes;
    EXPECT_FALSE(bytes.ready(kWindowBuffer));
    EXPECT_TRUE(bytes.take(kWindowBuffer).empty()) << "nothing prepared";
    bytes.prepare(kWindowBuffer);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!bytes.ready(kWindowBuffer) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ASSERT_TRUE(bytes.ready(kWindowBuffer));
    EXPECT_FALSE(bytes.ready(kWindowBuffer / 2)) << "another size";
    EXPECT_TRUE(bytes.take(kWindowBuffer / 2).empty());
    std::vector<uint8_t> taken = bytes.take(kWindowBuffer);
    ASSERT_EQ(taken.size(), kWindowBuffer);
    EXPECT_EQ(residentShare(taken.data(), taken.size()), 1.0);
    EXPECT_TRUE(std::all_of(taken.begin(), taken.end(), [](uint8_t b) { return b == 0; }));
    EXPECT_FALSE(bytes.ready(kWindowBuffer)) << "taken once";
    // Another size prepared drops nothing taken, and is made in its turn.
    bytes.prepare(kWindowBuffer / 4);
    bytes.prepare(kWindowBuffer / 4);  // the same size: the one being made stays
    while (!bytes.ready(kWindowBuffer / 4) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_EQ(bytes.take(kWindowBuffer / 4).size(), kWindowBuffer / 4);
}

// An allocation the worker cannot make leaves nothing prepared, throws nothing, and is no
// longer being made (a read-back waiting for it then allocates as before).
TEST(FreshMemory, AFailedPreparationLeavesNothingAndThrowsNothing) {
    PreparedBytes bytes;
    const size_t huge = size_t(1) << 62;
    bytes.prepare(huge);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (bytes.making(huge) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_FALSE(bytes.making(huge));
    EXPECT_FALSE(bytes.ready(huge));
    EXPECT_TRUE(bytes.take(huge).empty());
    // A size that can be made is made after it.
    bytes.prepare(kWindowBuffer);
    EXPECT_TRUE(bytes.making(kWindowBuffer) || bytes.ready(kWindowBuffer));
    while (!bytes.ready(kWindowBuffer) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_FALSE(bytes.making(kWindowBuffer));
    EXPECT_EQ(bytes.take(kWindowBuffer).size(), kWindowBuffer);
}

// A block over glibc's first mmap threshold, written and freed, comes back with its pages:
// without keepFreedMemory() (engine/util/kept_memory.h, which `lancer` sets at its start)
// glibc returns it to the system and the next one is mapped afresh.
TEST(FreshMemory, FreedBlocksAreKeptForTheNextAllocation) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's allocator takes no glibc thresholds";
#endif
    ASSERT_TRUE(keepFreedMemory());
    for (const size_t bytes : {kWindowBuffer, size_t(24) << 20}) {
        auto* c = static_cast<volatile unsigned char*>(std::malloc(bytes));
        ASSERT_NE(c, nullptr);
        // Written through volatile: the compiler may not drop an allocation nothing reads.
        for (size_t i = 0; i < bytes; i += 4096) c[i] = 1;
        std::free(const_cast<unsigned char*>(c));
        void* d = std::malloc(bytes);
        ASSERT_NE(d, nullptr);
        EXPECT_EQ(residentShare(d, bytes), 1.0) << bytes << " bytes";
        std::free(d);
    }
}

}  // namespace
}  // namespace lancer::viewer
