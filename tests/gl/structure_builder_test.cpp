// The viewer's background builder (app/viewer/structure_builder.h): a newer request cancels the
// build in progress, which returns within 100 ms (the contract of build_guard.h, measured here
// through the builder as the viewer drives it), and the newer request's result is the one seen.
// No GL needed; the builder lives in the viewer library this binary links.
#include "app/viewer/structure_builder.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

#include "engine/scene/loader.h"
#include "tests/support/instrumented.h"

namespace lancer::viewer {
namespace {

using Clock = std::chrono::steady_clock;

/// When each build of a StructureBuilder returned (its onReady calls: superseded builds too).
struct Returns {
    std::mutex m;
    std::condition_variable cv;
    std::vector<Clock::time_point> at;

    void hook(StructureBuilder& b) {
        b.setOnReady([this] {
            {
                std::lock_guard lock(m);
                at.push_back(Clock::now());
            }
            cv.notify_all();
        });
    }
    /// Wait (at most a minute) for the n-th return; its time.
    Clock::time_point wait(size_t n) {
        std::unique_lock lock(m);
        cv.wait_for(lock, std::chrono::seconds(60), [&] { return at.size() >= n; });
        return at.size() >= n ? at[n - 1] : Clock::time_point::max();
    }
    size_t count() {
        std::lock_guard lock(m);
        return at.size();
    }
};

double msBetween(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

/// Builds long enough on balls:5 (66,431 primitives) that a request made a third of their
/// uncancelled time after one starts lands inside it (timed here, not assumed: the regular one
/// split to one primitive a cell down to level 30 took 4 s once and 0.2 s after its builder
/// got faster): the irregular scheme at its defaults, that regular one, the BVH to one
/// primitive a leaf.
struct SlowBuild {
    BuildParams params;
    std::chrono::milliseconds half;  ///< a third of the uncancelled build's time
};

std::vector<SlowBuild> slowBuilds(const Scene& scene) {
    BuildParams irregular;
    irregular.scheme = SchemeKind::Irregular;
    BuildParams regular;
    regular.scheme = SchemeKind::Regular;
    regular.regular.maxObjects = 1;
    regular.regular.maxLevel = 30;
    regular.regular.costStop = false;
    BuildParams bvh;
    bvh.scheme = SchemeKind::Bvh;
    bvh.bvh.maxObjects = 1;
    std::vector<SlowBuild> out;
    for (const BuildParams& p : {irregular, regular, bvh}) {
        const Clock::time_point t0 = Clock::now();
        buildAccelerator(scene, p);
        out.push_back({p, std::chrono::milliseconds(int(msBetween(t0, Clock::now()) / 3))});
    }
    return out;
}

TEST(StructureBuilder, ASupersededBuildIsCancelledWithin100Ms) {
    auto big = std::make_shared<const Scene>(loadScene("builtin:balls:5"));
    auto small = std::make_shared<const Scene>(loadScene("builtin:default"));
    for (const auto& [slow, half] : slowBuilds(*big)) {
        SCOPED_TRACE(schemeName(slow.scheme));
        Returns returns;  // outlives the builder, whose thread calls it
        StructureBuilder builder;
        returns.hook(builder);
        const Clock::time_point started = Clock::now();
        builder.request({"builtin:balls:5", big, slow, {}, {}, {}, {}});
        std::this_thread::sleep_for(half);
        ASSERT_EQ(returns.count(), 0u) << "the build ended within half its own time";
        // The viewer's next request: a slider moved, the same scene at other parameters.
        BuildParams quick;
        quick.scheme = SchemeKind::Regular;
        const Clock::time_point asked = Clock::now();
        const uint64_t id = builder.request({"builtin:default", small, quick, {}, {}, {}, {}});
        const double latency = msBetween(asked, returns.wait(1));
        std::printf("%s build superseded after %.0f ms: returned in %.1f ms\n",
                    schemeName(slow.scheme), msBetween(started, asked), latency);
        // The contract is 100 ms; the builder's thread runs at the lowest priority and this
        // machine's cores are shared, so the bound allows 3 times that (as CancelledBuild does).
        EXPECT_LT(latency, 300.0 * test::kInstrumented);
        returns.wait(2);
        std::optional<BuildResult> r = builder.poll();
        ASSERT_TRUE(r.has_value()) << "no result for the newest request";
        EXPECT_EQ(r->request, id);
        ASSERT_TRUE(r->sceneBuild) << r->error;
        EXPECT_EQ(r->sceneBuild->scene, small);
        EXPECT_EQ(r->sceneBuild->accel->params().scheme, SchemeKind::Regular);
        EXPECT_FALSE(builder.busy());
        EXPECT_FALSE(builder.poll().has_value()) << "the superseded build's result was kept";
    }
}

TEST(StructureBuilder, ClosingCancelsTheBuildInProgress) {
    // Closing the viewer (or reopening a scene) destroys the builder mid-build: it returns
    // within the same bound, not after the build.
    auto big = std::make_shared<const Scene>(loadScene("builtin:balls:5"));
    for (const auto& [slow, half] : slowBuilds(*big)) {
        SCOPED_TRACE(schemeName(slow.scheme));
        Returns returns;
        auto builder = std::make_unique<StructureBuilder>();
        returns.hook(*builder);
        builder->request({"builtin:balls:5", big, slow, {}, {}, {}, {}});
        std::this_thread::sleep_for(half);
        ASSERT_EQ(returns.count(), 0u) << "the build ended within half its own time";
        const Clock::time_point asked = Clock::now();
        builder.reset();
        const double latency = msBetween(asked, Clock::now());
        std::printf("%s builder closed mid-build: returned in %.1f ms\n", schemeName(slow.scheme),
                    latency);
        EXPECT_LT(latency, 300.0 * test::kInstrumented);
    }
}

}  // namespace
}  // namespace lancer::viewer
