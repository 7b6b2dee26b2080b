// Bounded and cancellable builds: a build over its memory budget stops subdividing (irregular)
// or is refused naming the budget (regular), and its peak heap, measured here by a counting
// operator new, stays within the budget; a cancelled build returns within 100 ms.
#include <gtest/gtest.h>
#include <malloc.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>

#include "engine/accel/accelerator.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"
#include "tests/support/instrumented.h"

namespace {

std::atomic<size_t> gLive{0}, gPeak{0};

void counted(void* p) {
    const size_t now = gLive.fetch_add(malloc_usable_size(p)) + malloc_usable_size(p);
    size_t peak = gPeak.load();
    while (now > peak && !gPeak.compare_exchange_weak(peak, now)) {
    }
}

void* allocate(size_t n, size_t align) {
    void* p = align > alignof(std::max_align_t)
                  ? std::aligned_alloc(align, (std::max<size_t>(n, 1) + align - 1) / align * align)
                  : std::malloc(std::max<size_t>(n, 1));
    if (!p) throw std::bad_alloc();
    counted(p);
    return p;
}

void release(void* p) {
    if (!p) return;
    gLive.fetch_sub(malloc_usable_size(p));
    std::free(p);
}

}  // namespace

void* operator new(size_t n) { return allocate(n, 0); }
void* operator new[](size_t n) { return allocate(n, 0); }
void* operator new(size_t n, std::align_val_t a) { return allocate(n, size_t(a)); }
void* operator new[](size_t n, std::align_val_t a) { return allocate(n, size_t(a)); }
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, size_t) noexcept { release(p); }
void operator delete[](void* p, size_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, size_t, std::align_val_t) noexcept { release(p); }
// The nothrow forms too (std::stable_sort's buffer): libstdc++'s call the forms above, but a
// sanitizer's runtime replaces them with its own, whose blocks the release above would free.
void* operator new(size_t n, const std::nothrow_t&) noexcept {
    try {
        return allocate(n, 0);
    } catch (const std::bad_alloc&) {
        return nullptr;
    }
}
void* operator new[](size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void* operator new(size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    try {
        return allocate(n, size_t(a));
    } catch (const std::bad_alloc&) {
        return nullptr;
    }
}
void* operator new[](size_t n, std::align_val_t a, const std::nothrow_t& t) noexcept {
    return operator new(n, a, t);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }

namespace lancer {
namespace {

/// The heap a call takes at its peak, above what was live before it.
template <class F>
size_t peakOf(F&& f) {
    const size_t before = gLive.load();
    gPeak.store(before);
    f();
    return gPeak.load() - before;
}

/// A build under its budget: the accelerator (null when refused), the refusal's message and
/// the heap the build took at its peak.
struct BoundedResult {
    std::unique_ptr<Accelerator> accel;
    std::string refusal;
    size_t peak = 0;
};

BoundedResult buildBounded(const Scene& scene, const BuildParams& p) {
    BoundedResult r;
    r.peak = peakOf([&] {
        try {
            r.accel = buildAccelerator(scene, p);
        } catch (const std::invalid_argument& e) {
            r.refusal = e.what();
        }
    });
    return r;
}

Scene sponge() { return loadScene(std::string(LANCER_SOURCE_DIR) + "/assets/openscad/sponge.csg"); }

TEST(BoundedBuild, IrregularOverItsBudgetStopsWithinIt) {
    Scene scene = sponge();
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.lightBuffer = false;  // built beside the structure, outside its budget
    for (IrregularFrame frame : {IrregularFrame::Camera, IrregularFrame::Projective}) {
        p.irregular.frame = frame;
        p.memoryBudget = 0;
        const size_t free = buildAccelerator(scene, p)->info().memoryBytes;
        p.memoryBudget = free / 4;  // a quarter of what it takes unbounded
        std::unique_ptr<Accelerator> bounded;
        const size_t peak = peakOf([&] { bounded = buildAccelerator(scene, p); });
        SCOPED_TRACE(irregularFrameName(frame));
        EXPECT_LE(peak, p.memoryBudget)
            << "unbounded structure " << free << ", bounded " << bounded->info().memoryBytes << " "
            << bounded->info().extra.dump();
        EXPECT_LE(bounded->info().memoryBytes, p.memoryBudget);
        const nlohmann::json& x = bounded->info().extra;
        EXPECT_TRUE(x["bsp_stopped"].get<bool>() || x["merged_zones"].get<size_t>() > 0 ||
                    x["coarse_zones"].get<size_t>() > 0)
            << x.dump();
        // Fewer regions, the same picture.
        auto bad = test::compareWithBrute(scene, *bounded, test::pixelRays(scene, 48, 48));
        EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
        bad = test::compareWithBrute(scene, *bounded, test::randomRays(scene, 7, 2000));
        EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
    }
}

TEST(BoundedBuild, IrregularRuleFitsTheMeasuredPeak) {
    // The rule charges each zone the slabs it makes (not the worst case of its primitive count):
    // a budget a few times the heap an unbounded build peaks at lets the build run unbounded,
    // and half that peak stops it within the budget, with brute force's hits either way.
    Scene scene = loadScene("builtin:balls:3");
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.lightBuffer = false;
    p.memoryBudget = size_t(64) << 30;  // no stop
    std::unique_ptr<Accelerator> free;
    const size_t peak = peakOf([&] { free = buildAccelerator(scene, p); });
    const nlohmann::json& fx = free->info().extra;
    ASSERT_FALSE(fx["bsp_stopped"].get<bool>()) << fx.dump();
    ASSERT_EQ(fx["merged_zones"].get<size_t>(), 0u) << fx.dump();
    std::printf("unbounded: peak heap %zu bytes, structure %zu, %zu regions\n", peak,
                free->info().memoryBytes, free->info().regions);
    // 16 x the peak: the projective frame's pre-pass (do all zones fit?) has its threshold on
    // this scene at 3.95 x the peak glibc's malloc_usable_size counts, and at 4.002 x the one
    // the sanitizers' allocators count (the size requested): docs/irregular.md. Each light's
    // structure makes its hulls within a sixteenth of its share of the budget (shared equally by
    // the two frames and the lights), which 8 x the peak left short of them.
    for (size_t budget : {16 * peak, peak / 2}) {
        SCOPED_TRACE(budget);
        p.memoryBudget = budget;
        std::unique_ptr<Accelerator> b;
        const size_t used = peakOf([&] { b = buildAccelerator(scene, p); });
        const nlohmann::json& x = b->info().extra;
        const bool stopped = x["bsp_stopped"].get<bool>() || x["merged_zones"].get<size_t>() > 0 ||
                             x.value("projective_merged_zones", size_t(0)) > 0 ||
                             x.value("coarse_zones", size_t(0)) > 0 ||
                             x.value("projective_coarse_zones", size_t(0)) > 0 ||
                             x.value("projective_bsp_stopped", false);
        std::printf("budget %zu: peak heap %zu, %zu regions%s\n", budget, used, b->info().regions,
                    stopped ? " (stopped)" : "");
        EXPECT_LE(used, budget);
        if (budget > peak) {
            EXPECT_FALSE(stopped) << x.dump();
            EXPECT_EQ(b->info().regions, free->info().regions);
        } else {
            EXPECT_TRUE(stopped) << x.dump();
        }
        auto bad = test::compareWithBrute(scene, *b, test::pixelRays(scene, 32, 32));
        EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
        bad = test::compareWithBrute(scene, *b, test::randomRays(scene, 11, 1000));
        EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
    }
}

TEST(BoundedBuild, IrregularUnderItsLeastStructureIsRefusedWithinIt) {
    // Budgets from a byte up: each one either refuses, naming --memory-budget, or builds within
    // it (peak heap and structure), with brute force's hits. A budget limit of 0 bytes once
    // meant "no limit" (a 1-byte budget built the unbounded 2.3 MB structure), and budgets
    // under the least structure built it anyway, over them.
    Scene scene = sponge();
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.lightBuffer = false;
    for (IrregularFrame frame : {IrregularFrame::Camera, IrregularFrame::Projective}) {
        p.irregular.frame = frame;
        SCOPED_TRACE(irregularFrameName(frame));
        int refused = 0, built = 0;
        for (size_t budget :
             {size_t(1), size_t(17), size_t(1) << 10, size_t(16) << 10, size_t(32) << 10,
              size_t(48) << 10, size_t(64) << 10, size_t(256) << 10}) {
            SCOPED_TRACE(budget);
            p.memoryBudget = budget;
            const auto [a, what, peak] = buildBounded(scene, p);
            if (!a) {
                EXPECT_EQ(what.rfind("--memory-budget ", 0), 0u) << what;
                EXPECT_NE(what.find("raise --memory-budget"), std::string::npos) << what;
                EXPECT_LE(peak, 4096u);  // the primitives' list and the message, nothing built
                ++refused;
                continue;
            }
            EXPECT_LE(peak, budget);
            ++built;
            EXPECT_LE(a->info().memoryBytes, budget);
            auto bad = test::compareWithBrute(scene, *a, test::pixelRays(scene, 24, 24));
            EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
        }
        EXPECT_GE(refused, 3);  // 1 B, 17 B and 1 KiB hold no structure of 221 primitives
        EXPECT_GE(built, 1);    // 256 KiB holds a coarse one
    }
}

TEST(BoundedBuild, RegularOverItsBudgetIsRefusedWithinIt) {
    Scene scene = sponge();
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    p.lightBuffer = false;
    p.regular.maxLevel = 30;
    p.regular.maxObjects = 1;
    p.regular.costStop = false;  // the report's rule: cells crossed by bars split to level 30
    p.memoryBudget = size_t(4) << 20;
    const size_t peak = peakOf([&] {
        try {
            buildAccelerator(scene, p);
            ADD_FAILURE() << "a build over its budget was accepted";
        } catch (const std::invalid_argument& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("--memory-budget 4.0 MiB"), std::string::npos) << what;
            EXPECT_NE(what.find("--max-level 30"), std::string::npos) << what;
        }
    });
    EXPECT_LE(peak, p.memoryBudget);
}

TEST(BoundedBuild, TheLightBufferIsHeldWithinTheBudget) {
    // At the defaults the light buffer is built beside the structure and held with it: its
    // bytes come out of the budget, and when they would pass a quarter of it the buffer is left
    // out. Either way the whole build (structure and buffer, both threads) stays within the
    // budget, or is refused within it, with brute force's hits.
    Scene scene = sponge();
    ASSERT_GT(scene.lights.size(), 0u);
    const size_t light = LightBuffer::bytesAtMost(scene.lights.size());
    for (SchemeKind scheme : {SchemeKind::Regular, SchemeKind::Irregular}) {
        for (size_t budget : {5 * light, light}) {  // the buffer held; left out
            SCOPED_TRACE(std::string(schemeName(scheme)) + " under " + std::to_string(budget));
            BuildParams p;
            p.scheme = scheme;
            p.memoryBudget = budget;
            const auto [a, what, peak] = buildBounded(scene, p);
            if (!a) {
                EXPECT_NE(what.find("--memory-budget"), std::string::npos) << what;
            }
            std::printf("%s, budget %zu (light buffer at most %zu): peak heap %zu%s\n",
                        schemeName(scheme), budget, light, peak, a ? "" : " (refused)");
            EXPECT_LE(peak, budget);
            if (!a) continue;
            const nlohmann::json& x = a->info().extra;
            EXPECT_LE(a->info().memoryBytes, budget) << x.dump();
            if (light <= budget / 4) {
                EXPECT_GT(x.value("light_buffer_bytes", size_t(0)), 0u) << x.dump();
                EXPECT_LE(x.value("light_buffer_bytes", size_t(0)), light);
            } else {
                EXPECT_FALSE(x.contains("light_buffer_bytes")) << x.dump();
                EXPECT_NE(x.value("light_buffer_left_out", std::string()).find("over a quarter"),
                          std::string::npos)
                    << x.dump();
            }
            auto bad = test::compareWithBrute(scene, *a, test::pixelRays(scene, 32, 32));
            EXPECT_TRUE(bad.empty()) << bad.size() << " rays differ from brute force";
        }
    }
}

TEST(BoundedBuild, BudgetOptionValues) {
    EXPECT_EQ(parseMemoryBudget("512M"), size_t(512) << 20);
    EXPECT_EQ(parseMemoryBudget("2GiB"), size_t(2) << 30);
    EXPECT_EQ(parseMemoryBudget("1.5g"), size_t(3) << 29);
    EXPECT_EQ(parseMemoryBudget("4096"), size_t(4096));
    EXPECT_THROW(parseMemoryBudget("lots"), std::invalid_argument);
    EXPECT_THROW(parseMemoryBudget("0"), std::invalid_argument);
    EXPECT_THROW(parseMemoryBudget("3X"), std::invalid_argument);
    EXPECT_GE(defaultMemoryBudget(), size_t(256) << 20);
}

/// Start a build on another thread, cancel it once it has run `after`, and return the time from
/// the cancel request to the build's return; `cancelled` tells whether it ended by the request.
double cancelAfter(const Scene& scene, const BuildParams& p, std::chrono::milliseconds after,
                   bool& cancelled) {
    std::stop_source stop;
    std::atomic<bool> done{false};
    std::chrono::steady_clock::time_point returned;
    cancelled = false;
    std::thread t([&] {
        try {
            buildAccelerator(scene, p, {stop.get_token(), {}});
        } catch (const BuildCancelled&) {
            cancelled = true;
        }
        returned = std::chrono::steady_clock::now();
        done = true;
    });
    std::this_thread::sleep_for(after);
    const auto asked = std::chrono::steady_clock::now();
    stop.request_stop();
    t.join();
    return std::chrono::duration<double, std::milli>(returned - asked).count();
}

TEST(CancelledBuild, ReturnsWithin100Ms) {
    // balls:5, 66,430 spheres: each scheme builds for seconds here, so the cancel lands inside.
    Scene scene = loadScene("builtin:balls:5");
    for (SchemeKind scheme : {SchemeKind::Regular, SchemeKind::Irregular}) {
        SCOPED_TRACE(schemeName(scheme));
        BuildParams p;
        p.scheme = scheme;
        std::vector<int> cancelAt = {20, 150};
        if (scheme == SchemeKind::Regular) {
            p.regular.maxObjects = 1;  // a deep BSP: a long build
            // On an idle machine this build takes about 150 ms: the late cancel lands at half
            // of an uncancelled build's time, so it always falls inside the build.
            const auto t0 = std::chrono::steady_clock::now();
            buildAccelerator(scene, p);
            const double whole =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
            cancelAt = {std::max(1, int(whole / 8)), std::max(2, int(whole / 2))};
        }
        for (int ms : cancelAt) {
            bool cancelled = false;
            const double latency = cancelAfter(scene, p, std::chrono::milliseconds(ms), cancelled);
            EXPECT_TRUE(cancelled) << "the build finished before the cancel at " << ms << " ms";
            // The contract is 100 ms (measured 1-70 ms under a load of 18 on two cores); a
            // loaded machine gets 3 times that.
            EXPECT_LT(latency, 300.0 * test::kInstrumented) << "cancelled at " << ms << " ms";
            std::printf("%s cancelled after %d ms: returned in %.1f ms\n", schemeName(scheme), ms,
                        latency);
        }
    }
    // A build cancelled before it starts does nothing.
    std::stop_source stop;
    stop.request_stop();
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    EXPECT_THROW(buildAccelerator(scene, p, {stop.get_token(), {}}), BuildCancelled);
}

TEST(BuildProgress, ALongBuildReportsOnceASecond) {
    Scene scene = sponge();
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.frame = IrregularFrame::Camera;
    std::vector<BuildProgress> seen;
    BuildControl c;
    c.progress = [&](const BuildProgress& b) { seen.push_back(b); };
    const auto start = std::chrono::steady_clock::now();
    buildAccelerator(scene, p, c);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // At most one report a second, none in the first second, and some when the build is long
    // (polls come often enough).
    EXPECT_LE(double(seen.size()), secs);
    if (secs > 3.0) {
        EXPECT_GE(seen.size(), 1u) << secs << " s";
    }
    for (const BuildProgress& b : seen) {
        EXPECT_GE(b.seconds, 1.0);
        EXPECT_TRUE(BuildGuard::fits(b.bytes, b.budget)) << b.bytes << " of " << b.budget;
    }
}

}  // namespace
}  // namespace lancer
