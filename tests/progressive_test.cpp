// The progressive renderer: its passes add up to the full render, coarse passes show as blocks,
// and a new job cancels the one in flight.
#include "engine/render/progressive.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "engine/scene/loader.h"
#include "tests/support/instrumented.h"

namespace lancer {
namespace {

/// Poll `done` until it holds (true) or `seconds` pass (false).
bool waitFor(const std::function<bool()>& done, double seconds) {
    auto start = std::chrono::steady_clock::now();
    while (!done()) {
        if (std::chrono::steady_clock::now() - start > std::chrono::duration<double>(seconds))
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
}

/// Follow job `job` of `pr` snapshot by snapshot into `shown` until it is finished, checking
/// each snapshot against `direct`, the same view rendered at once: only the rows said to have
/// changed change, and every pixel shows its block's corner pixel. Returns the strides seen.
std::vector<int> followJob(ProgressiveRenderer& pr, uint64_t job, const Image& direct, Image& shown,
                           uint64_t& version) {
    std::vector<int> seenStrides;
    const int w = direct.width, h = direct.height;
    auto start = std::chrono::steady_clock::now();
    const auto limit = std::chrono::duration<double>(30.0 * test::kInstrumented);
    for (;;) {
        EXPECT_LT(std::chrono::steady_clock::now() - start, limit);
        if (std::chrono::steady_clock::now() - start > limit) break;
        const bool finished = pr.finished();  // read first: then the snapshot below is the last
        ProgressiveRenderer::Shown what;
        const Image before = shown;
        if (pr.snapshot(version, shown, &what)) {
            seenStrides.push_back(what.stride);
            EXPECT_EQ(what.job, job);
            EXPECT_GT(what.rows, 0);
            // Only the rows said to have changed are copied; they reach the last band's end
            // (further when an earlier pass, whole, was not taken yet).
            EXPECT_LT(what.changedBegin, what.changedEnd);
            EXPECT_GE(what.changedEnd, what.rows);
            for (int y = 0; y < h && before.width == shown.width; ++y) {
                if (y >= what.changedBegin && y < what.changedEnd) continue;
                for (int x = 0; x < w; ++x)
                    if (shown.color[shown.index(x, y)] != before.color[before.index(x, y)]) {
                        ADD_FAILURE() << "row " << y << " outside the changed rows changed";
                        return seenStrides;
                    }
            }
            // Every pixel shows its block's corner pixel of the direct render: at the stride of
            // the pass above its band's end, of the pass before below it.
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const int stride = y < what.rows ? what.stride : what.previousStride;
                    if (stride <= 0) {
                        ADD_FAILURE() << "row " << y << " shown before it was rendered";
                        return seenStrides;
                    }
                    size_t s = direct.index(x - x % stride, y - y % stride), d = shown.index(x, y);
                    if (shown.color[d] != direct.color[s] ||
                        shown.primTests[d] != direct.primTests[s]) {
                        ADD_FAILURE() << x << "," << y << " stride " << stride << " job " << job;
                        return seenStrides;
                    }
                }
        }
        if (finished) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return seenStrides;
}

/// A renderer's onPass (ProgressiveRenderer::setOnPass) that makes its worker wait after each
/// band it shows until the test releases it: the bands come one by one. Declared before the
/// renderer, so it outlives the worker.
class GatedBands {
  public:
    std::function<void()> onPass() {
        return [this] {
            std::unique_lock lock(m_);
            ++bands_;
            cv_.notify_all();
            cv_.wait(lock, [&] { return released_ >= bands_; });
        };
    }
    /// Wait (up to 30 s) until `n` bands were shown; false if they were not.
    bool wait(int n) {
        std::unique_lock lock(m_);
        return cv_.wait_for(lock, std::chrono::seconds(30), [&] { return bands_ >= n; });
    }
    /// Let the worker go on past band `n`.
    void release(int n) {
        std::lock_guard lock(m_);
        released_ = n;
        cv_.notify_all();
    }
    int bands() {
        std::lock_guard lock(m_);
        return bands_;
    }

  private:
    std::mutex m_;
    std::condition_variable cv_;
    int bands_ = 0, released_ = 0;
};

/// `opt` with the camera moved 30% of the way to its target, and its render into `direct`.
RenderOptions movedView(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                        Image& direct) {
    RenderOptions moved = opt;
    Camera cam = scene.camera;
    cam.from += 0.3 * (cam.at - cam.from);
    moved.camera = cam;
    direct = Image(opt.width, opt.height);
    render(scene, accel, moved, direct);
    return moved;
}

/// builtin:default at 64x40 and its render at once.
struct SmallView {
    std::shared_ptr<const Scene> scene =
        std::make_shared<const Scene>(loadScene("builtin:default"));
    std::shared_ptr<const Accelerator> accel = buildAccelerator(*scene, BuildParams{});
    RenderOptions opt = [] {
        RenderOptions o;
        o.width = 64;
        o.height = 40;
        return o;
    }();
    Image direct = [this] {
        Image d(opt.width, opt.height);
        render(*scene, *accel, opt, d);
        return d;
    }();
};

TEST(Progressive, APassComesInPartsOfAtMostMaxRowsUntilTheSnapshotCatchesUp) {
    const SmallView v;
    const auto& [scene, accel, opt, direct] = v;
    // The worker waits after each band until the test has taken it: the bands come one by one.
    GatedBands gate;
    ProgressiveRenderer pr({8, 4, 1});
    pr.setOnPass(gate.onPass());
    auto waitBands = [&](int n) { return gate.wait(n); };
    auto release = [&](int n) { gate.release(n); };
    // Row y of `shown` shows the pass of `stride`: the corner pixel of its block.
    auto rowShows = [&](const Image& shown, int y, int stride) {
        for (int x = 0; x < opt.width; ++x)
            if (shown.color[shown.index(x, y)] !=
                direct.color[direct.index(x - x % stride, y - y % stride)])
                return false;
        return true;
    };
    constexpr int kMax = 5;
    pr.start({scene, accel, opt});
    Image shown;
    uint64_t version = 0;
    ProgressiveRenderer::Shown what;
    ASSERT_TRUE(waitBands(1));
    // Into an image of another size (a new one): whole, whatever the limit.
    ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
    EXPECT_EQ(what.stride, 8);
    EXPECT_FALSE(what.behind);
    EXPECT_EQ(what.changedEnd - what.changedBegin, opt.height);
    release(1);
    ASSERT_TRUE(waitBands(2));  // the pass of stride 4, whole: in parts of kMax rows
    int parts = 0, next = 0;
    for (bool behind = true; behind && parts < 100; ++parts) {
        ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
        EXPECT_EQ(what.stride, 4);
        EXPECT_EQ(what.changedBegin, next);
        EXPECT_LE(what.changedEnd - what.changedBegin, kMax);
        EXPECT_EQ(what.rows, what.changedEnd);
        next = what.changedEnd;
        for (int y = 0; y < opt.height; ++y)
            ASSERT_TRUE(rowShows(shown, y, y < next ? 4 : 8)) << "row " << y << ", part " << parts;
        behind = what.behind;
    }
    EXPECT_EQ(parts, (opt.height + kMax - 1) / kMax);
    EXPECT_EQ(next, opt.height);
    EXPECT_FALSE(pr.snapshot(version, shown, &what, kMax)) << "caught up: nothing new";
    release(1000);
    ASSERT_TRUE(waitFor([&] { return pr.finished(); }, 30.0 * test::kInstrumented));
    while (pr.snapshot(version, shown, &what, kMax))
        EXPECT_LE(what.changedEnd - what.changedBegin, kMax);
    EXPECT_EQ(shown.color, direct.color);
    // A new view into the same image: its first pass comes in parts too, the rows below the
    // part still the old view's, until the snapshot catches up.
    Image direct2;
    const RenderOptions moved = movedView(*scene, *accel, opt, direct2);
    const int before = gate.bands();
    release(before);  // the worker waits after the new job's first band
    pr.start({scene, accel, moved});
    ASSERT_TRUE(waitBands(before + 1));
    ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
    EXPECT_EQ(what.job, 2u);
    EXPECT_EQ(what.stride, 8);
    EXPECT_TRUE(what.behind);
    EXPECT_EQ(what.changedEnd, kMax);
    for (int y = 0; y < opt.height; ++y)
        for (int x = 0; x < opt.width; ++x) {
            const Vec3 want = y < kMax ? direct2.color[direct2.index(x - x % 8, y - y % 8)]
                                       : direct.color[direct.index(x, y)];
            ASSERT_EQ(shown.color[shown.index(x, y)], glm::vec3(want)) << x << "," << y;
        }
    release(1000);
}

TEST(Progressive, AJobBegunInPartsIsFinishedInPartsWhenANewerOneStarts) {
    const SmallView v;
    const auto& [scene, accel, opt, direct] = v;
    Image direct2;
    const RenderOptions moved = movedView(*scene, *accel, opt, direct2);
    // The worker waits after each band until the test has taken it.
    GatedBands gate;
    ProgressiveRenderer pr({8, 4, 1});
    pr.setOnPass(gate.onPass());
    auto waitBands = [&](int n) { return gate.wait(n); };
    auto release = [&](int n) { gate.release(n); };
    // Every row of `shown` shows the first pass (stride 8) of `d`.
    auto showsPass = [&](const Image& shown, const Image& d) {
        for (int y = 0; y < opt.height; ++y)
            for (int x = 0; x < opt.width; ++x)
                if (shown.color[shown.index(x, y)] != d.color[d.index(x - x % 8, y - y % 8)])
                    return false;
        return true;
    };
    constexpr int kMax = 5;
    Image shown(opt.width, opt.height);  // made ahead, as the viewer does: the first pass in parts
    uint64_t version = 0;
    ProgressiveRenderer::Shown what;
    pr.start({scene, accel, opt});
    ASSERT_TRUE(waitBands(1));
    ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
    EXPECT_EQ(what.job, 1u);
    EXPECT_TRUE(what.behind) << "the first image comes in parts into an image made ahead";
    EXPECT_EQ(what.changedEnd, kMax);
    // A newer view renders its first pass; the first is finished in parts all the same.
    pr.start({scene, accel, moved});
    release(1);
    ASSERT_TRUE(waitBands(2));
    EXPECT_EQ(pr.latest().job, 2u);
    int next = kMax, parts = 1;
    do {
        ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
        EXPECT_EQ(what.job, 1u);
        EXPECT_EQ(what.changedBegin, next);
        EXPECT_LE(what.changedEnd - what.changedBegin, kMax);
        next = what.changedEnd;
        ++parts;
    } while (what.behind && parts < 100);
    EXPECT_TRUE(what.stale) << "the newer job waits";
    EXPECT_EQ(next, opt.height);
    EXPECT_EQ(parts, opt.height / kMax);
    EXPECT_TRUE(showsPass(shown, direct)) << "the first view whole, none of the second's rows";
    // Then the newer one, in parts from its first row.
    next = 0;
    do {
        ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
        EXPECT_EQ(what.job, 2u);
        EXPECT_EQ(what.changedBegin, next);
        EXPECT_FALSE(what.stale);
        next = what.changedEnd;
    } while (what.behind && next < opt.height + 1);
    EXPECT_EQ(next, opt.height);
    EXPECT_TRUE(showsPass(shown, direct2));
    EXPECT_FALSE(pr.snapshot(version, shown, &what, kMax)) << "caught up";
    // A job begun in parts and replaced is dropped by a whole snapshot: the newest comes.
    pr.start({scene, accel, opt});
    release(2);
    ASSERT_TRUE(waitBands(3));
    ASSERT_TRUE(pr.snapshot(version, shown, &what, kMax));
    EXPECT_EQ(what.job, 3u);
    EXPECT_TRUE(what.behind);
    pr.start({scene, accel, moved});
    release(3);
    ASSERT_TRUE(waitBands(4));
    ASSERT_TRUE(pr.snapshot(version, shown, &what, 0));
    EXPECT_EQ(what.job, 4u);
    EXPECT_FALSE(what.behind);
    EXPECT_FALSE(what.stale);
    EXPECT_TRUE(showsPass(shown, direct2));
    release(1000);
}

TEST(Progressive, PassesEndInTheFullRenderAndCoarsePassesShowAsBlocks) {
    auto scene = std::make_shared<const Scene>(loadScene("builtin:default"));
    std::shared_ptr<const Accelerator> accel = buildAccelerator(*scene, BuildParams{});
    RenderOptions opt;
    opt.width = 97;  // not a multiple of the strides: partial blocks at the edges
    opt.height = 61;
    Image direct(opt.width, opt.height);
    render(*scene, *accel, opt, direct);

    ProgressiveRenderer pr({8, 4, 2, 1});
    std::atomic<int> shownTimes{0};
    pr.setOnPass([&] { ++shownTimes; });
    pr.start({scene, accel, opt});
    Image shown;
    uint64_t version = 0;
    std::vector<int> seenStrides = followJob(pr, 1, direct, shown, version);
    ASSERT_FALSE(seenStrides.empty());
    EXPECT_EQ(seenStrides.back(), 1);
    // Shown one band at a time: passes 8 and 4 whole, passes 2 and 1 in bands of 8 rows.
    EXPECT_EQ(shownTimes.load(), 1 + 1 + 8 + 8);
    std::vector<PassRecord> passes = pr.passes();
    ASSERT_EQ(passes.size(), 4u);
    uint64_t primary = 0;
    for (const PassRecord& p : passes) primary += p.counters.primaryRays;
    EXPECT_EQ(primary, uint64_t(opt.width) * uint64_t(opt.height))
        << "each pixel is traced once over the passes";
    EXPECT_EQ(shown.color, direct.color);
    // An image of another size (here a new one) is given the whole display.
    Image fresh;
    uint64_t freshVersion = 0;
    ProgressiveRenderer::Shown what;
    ASSERT_TRUE(pr.snapshot(freshVersion, fresh, &what));
    EXPECT_EQ(what.changedBegin, 0);
    EXPECT_EQ(what.changedEnd, opt.height);
    EXPECT_EQ(fresh.color, direct.color);
    EXPECT_EQ(fresh.timeUs, shown.timeUs);

    // A second job of the same size, another view, into the same image: every snapshot is
    // checked as above (an earlier attempt to hand the display over instead of copying it
    // showed stale rows here), and the end is the direct render.
    Image direct2;
    const RenderOptions moved = movedView(*scene, *accel, opt, direct2);
    ASSERT_NE(direct2.color, direct.color);
    pr.start({scene, accel, moved});
    seenStrides = followJob(pr, 2, direct2, shown, version);
    ASSERT_FALSE(seenStrides.empty());
    EXPECT_EQ(seenStrides.back(), 1);
    EXPECT_EQ(shown.color, direct2.color);
    EXPECT_EQ(shown.primTests, direct2.primTests);
}

TEST(Progressive, ANewJobCancelsTheOneInFlight) {
    auto scene = std::make_shared<const Scene>(loadScene("builtin:balls:3"));
    std::shared_ptr<const Accelerator> accel = buildAccelerator(*scene, BuildParams{});
    RenderOptions big;
    big.width = 1600;  // brute force on 800 spheres: minutes if it were not cancelled
    big.height = 1200;
    ProgressiveRenderer pr;
    EXPECT_EQ(pr.job(), 0u);
    pr.start({scene, accel, big});
    EXPECT_EQ(pr.job(), 1u);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    RenderOptions small;
    small.width = 24;
    small.height = 16;
    auto t0 = std::chrono::steady_clock::now();
    pr.start({scene, accel, small});
    // Waiting for the first pass of the new job: it comes, and a job never started does not.
    ASSERT_TRUE(waitFor([&] { return pr.latest().job == 2; }, 20.0 * test::kInstrumented));
    EXPECT_FALSE(waitFor([&] { return pr.latest().job == 3; }, 0.02));
    Image shown;
    uint64_t version = 0;
    ASSERT_TRUE(waitFor([&] { return pr.finished(); }, 20.0 * test::kInstrumented))
        << "the big job was not cancelled";
    double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(ms, 10000.0 * test::kInstrumented);
    EXPECT_EQ(pr.job(), 2u);
    ProgressiveRenderer::Shown what;
    ASSERT_TRUE(pr.snapshot(version, shown, &what));
    EXPECT_EQ(what.job, 2u) << "the display comes from the second job";
    EXPECT_EQ(shown.width, 24);
    EXPECT_EQ(shown.height, 16);
    pr.cancel();
    EXPECT_TRUE(waitFor([&] { return pr.idle(); }, 20.0 * test::kInstrumented));
}

}  // namespace
}  // namespace lancer
