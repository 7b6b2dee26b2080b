#include "app/viewer/timing/frame_budget.h"

#include <gtest/gtest.h>

namespace lancer::viewer {
namespace {

TEST(FrameBudget, StepsDrawFromOneBudgetAndStopOnceItIsSpentLessTheirReserve) {
    double now = 100.0;
    FrameBudget b(33.0, [&] { return now; });
    const unsigned long first = b.frame();
    b.begin();
    EXPECT_EQ(b.frame(), first + 1);
    EXPECT_EQ(b.spentMs(), 0.0);
    now += 20.0;  // a new view's parts and the layer
    EXPECT_EQ(b.spentMs(), 20.0);
    EXPECT_EQ(b.leftMs(), 13.0);
    EXPECT_TRUE(b.allows(5.0)) << "8 ms left beyond a reserve of 5";
    EXPECT_FALSE(b.allows(13.0)) << "nothing left beyond a reserve of 13";
    EXPECT_EQ(b.deferred(), 1);
    now += 14.0;  // over the frame's budget: every optional step stops
    EXPECT_LT(b.leftMs(), 0.0);
    EXPECT_FALSE(b.allows());
    EXPECT_EQ(b.deferred(), 2);
    // The next frame starts with the whole budget again.
    b.begin();
    EXPECT_EQ(b.frame(), first + 2);
    EXPECT_EQ(b.deferred(), 0);
    EXPECT_TRUE(b.allows(32.0));
    EXPECT_EQ(b.budgetMs(), 33.0);
}

TEST(FrameBudget, ByDefaultTheUiThreadsCpuTime) {
    FrameBudget b(33.0);
    b.begin();
    volatile double sink = 0.0;  // CPU work on this thread: the clock moves
    for (int i = 0; i < 2000000; ++i) sink = sink + double(i) * 0.5;
    EXPECT_GT(b.spentMs(), 0.0);
    EXPECT_LT(b.spentMs(), 10000.0);
}

}  // namespace
}  // namespace lancer::viewer
