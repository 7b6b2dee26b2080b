#include "app/viewer/timing/frame_times.h"

#include <gtest/gtest.h>

namespace lancer::viewer {
namespace {

TEST(FrameTimes, PercentilesByNearestRank) {
    FrameTimes t;
    EXPECT_EQ(t.percentile(95), 0.0);
    EXPECT_EQ(t.summary("still"), "still: no frames");
    // 1..20 ms, added out of order: p50 is the 10th smallest, p95 the 19th, p100 the largest.
    for (int i : {7, 3, 20, 1, 15, 9, 12, 2, 18, 5, 11, 4, 16, 6, 19, 8, 13, 10, 17, 14})
        t.add(double(i), double(i) / 2.0);
    EXPECT_EQ(t.count(), 20u);
    EXPECT_EQ(t.percentile(50), 10.0);
    EXPECT_EQ(t.percentile(95), 19.0);
    EXPECT_EQ(t.percentile(100), 20.0);
    EXPECT_EQ(t.percentile(0), 1.0);
    EXPECT_EQ(t.over(18.0), 2u);
    EXPECT_EQ(t.cpuPercentile(95), 9.5);  // the CPU times kept apart, in their own order
}

TEST(FrameTimes, SummaryCountsFramesOverBudget) {
    FrameTimes t;
    for (int i = 0; i < 99; ++i) t.add(8.0, 6.0);
    t.add(250.0, 40.0);  // one frame kept waiting: the max, not the p95
    EXPECT_EQ(t.summary("turning"),
              "turning: 100 frames, p50 8.0 ms, p95 8.0 ms, max 250.0 ms, 1 over 33 ms, CPU p50 "
              "6.0 ms, p95 6.0 ms, max 40.0 ms");
}

TEST(FramePhases, EachPhaseIsTheTimeSinceTheMarkBeforeAndRepeatsSum) {
    // On a clock the test gives: read right after begin(), the thread's CPU clock had once
    // moved 0.88 ms (a CI run, 2026-12-07).
    FramePhases f;
    const double t0 = 1000.0;
    f.beginAt(t0);
    f.markAt("poll", t0 + 2.0);
    f.markAt("upload", t0 + 32.5);
    f.markAt("draw", t0 + 33.0);
    f.markAt("upload", t0 + 34.0);  // a second upload in the frame joins the first
    EXPECT_DOUBLE_EQ(f.totalMs(), 34.0);
    const std::string s = f.summary();
    EXPECT_EQ(s.substr(s.find(','), std::string::npos), ", upload 31.5, draw 0.5");
    EXPECT_EQ(s.substr(0, 5), "poll ");
    f.begin();
    EXPECT_EQ(f.summary(), "");
}

}  // namespace
}  // namespace lancer::viewer
