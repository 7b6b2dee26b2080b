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

TEST(FrameBudget, APartStartsOnlyWhenItsLearnedCostFitsInWhatIsLeft) {
    double now = 0.0;
    FrameBudget b(33.0, [&] { return now; });
    b.begin();
    now += 20.0;
    // 13 ms left, 5 kept for later steps: a part of 8 ms fits, one of 8.5 does not.
    EXPECT_TRUE(b.fits(8.0, 5.0));
    EXPECT_FALSE(b.fits(8.5, 5.0));
    EXPECT_EQ(b.deferred(), 1);
    // allows() would let the 8.5 ms part start (some budget is left) and overrun by 0.5 ms.
    EXPECT_TRUE(b.allows(5.0));

    StepCost band(1.0);  // 1 ms a row until measured
    EXPECT_EQ(band.estimateMs(30), 30.0);
    EXPECT_EQ(band.unitsIn(7.5), 7.0);
    EXPECT_EQ(band.unitsIn(0.0), 0.0);
    EXPECT_EQ(band.unitsIn(-2.0), 0.0);
    band.record(30, 6.0);  // measured 0.2 ms a row: a quarter of the way from 1.0
    EXPECT_DOUBLE_EQ(band.msPerUnit(), 0.8);
    for (int i = 0; i < 40; ++i) band.record(30, 6.0);
    EXPECT_NEAR(band.msPerUnit(), 0.2, 1e-4) << "a lasting cost is followed";
    EXPECT_NEAR(band.unitsIn(8.0), 40.0, 1.0);
    band.record(30, 30.0);  // one slow part (the machine's load) moves it only partly
    EXPECT_NEAR(band.msPerUnit(), 0.4, 1e-3);
    band.record(0, 5.0);  // nothing done: nothing learned
    EXPECT_NEAR(band.msPerUnit(), 0.4, 1e-3);
    // A step asks its part's estimate: with 5 ms left beyond its reserve, 12 rows at 0.4 ms.
    now = 28.0;
    EXPECT_TRUE(b.fits(band.estimateMs(10), 0.0));
    EXPECT_FALSE(b.fits(band.estimateMs(13), 0.0));
}

TEST(FrameBudget, AStepThatWaitedItsPatienceStartsItsFirstPartWhateverTheBudget) {
    // Every frame spent before the step: a part never fits, yet the step starts one after
    // kPatienceFrames frames of waiting, the first of its frame only, and waits again after.
    double now = 0.0;
    FrameBudget b(33.0, [&] { return now; });
    Patience p;
    int started = 0, frames = 0;
    for (; frames < 3 * int(kPatienceFrames + 1); ++frames) {
        b.begin();
        now += 40.0;
        if (b.fits(5.0, 0.0, p)) {
            ++started;
            EXPECT_EQ(frames % int(kPatienceFrames + 1), int(kPatienceFrames)) << frames;
            EXPECT_EQ(b.forced(), 1);
            EXPECT_EQ(b.deferred(), 0) << "let in over the budget: not deferred";
            EXPECT_EQ(p.waited(), 0u);
            EXPECT_FALSE(b.fits(5.0, 0.0, p)) << "a second part of the frame waits";
            EXPECT_EQ(p.waited(), 0u) << "the step made progress in this frame";
        } else {
            EXPECT_EQ(b.forced(), 0);
            EXPECT_EQ(b.deferred(), 1);
            EXPECT_FALSE(b.fits(5.0, 0.0, p)) << "asked again in the frame";
            EXPECT_EQ(p.waited(), unsigned(frames % int(kPatienceFrames + 1)) + 1)
                << "a frame counted once";
        }
    }
    EXPECT_EQ(started, 3);
    // A part that fits starts and resets the count, as one let in over the budget does.
    b.begin();
    now += 40.0;
    EXPECT_FALSE(b.fits(5.0, 0.0, p));
    EXPECT_EQ(p.waited(), 1u);
    b.begin();
    EXPECT_TRUE(b.fits(5.0, 0.0, p));
    EXPECT_EQ(b.forced(), 0);
    EXPECT_EQ(p.waited(), 0u);
    // Each step has its own count: one that waited does not let in another.
    Patience other;
    for (unsigned i = 0; i < kPatienceFrames; ++i) {
        b.begin();
        now += 40.0;
        EXPECT_FALSE(b.fits(5.0, 0.0, p));
    }
    b.begin();
    now += 40.0;
    EXPECT_FALSE(b.fits(5.0, 0.0, other)) << "its first frame of waiting";
    EXPECT_TRUE(b.fits(5.0, 0.0, p)) << "its patience spent";
    EXPECT_EQ(b.forced(), 1);
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
