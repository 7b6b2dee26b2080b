// costliestPixels: the n costliest pixels by tests, visits or time, costliest first, ties in
// reading order, at most the image's pixels; nothing for an image without counters.
#include "app/viewer/playback/worst_rays.h"

#include <gtest/gtest.h>

namespace lancer::viewer::playback {
namespace {

TEST(WorstRays, RanksPixelsByEachCost) {
    Image img(3, 2);
    const uint32_t tests[6] = {5, 9, 1, 9, 0, 7};
    const uint32_t visits[6] = {1, 2, 8, 3, 4, 5};
    const float us[6] = {0.5f, 0.1f, 0.2f, 3.0f, 0.4f, 0.3f};
    for (size_t i = 0; i < 6; ++i) {
        img.primTests[i] = tests[i];
        img.regionVisits[i] = visits[i];
        img.timeUs[i] = us[i];
    }
    const std::vector<CostlyPixel> t = costliestPixels(img, RayCost::Tests, 3);
    ASSERT_EQ(t.size(), 3u);
    // Two pixels of 9 tests: (1, 0) before (0, 1), in reading order; then 7 at (2, 1).
    EXPECT_EQ(t[0].x, 1);
    EXPECT_EQ(t[0].y, 0);
    EXPECT_EQ(t[1].x, 0);
    EXPECT_EQ(t[1].y, 1);
    EXPECT_EQ(t[2].tests, 7u);
    EXPECT_EQ(t[2].visits, 5u);
    EXPECT_FLOAT_EQ(t[2].us, 0.3f);
    const std::vector<CostlyPixel> v = costliestPixels(img, RayCost::Visits, 1);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v[0].x, 2);
    EXPECT_EQ(v[0].y, 0);
    const std::vector<CostlyPixel> s = costliestPixels(img, RayCost::Time, 20);
    ASSERT_EQ(s.size(), 6u);  // no more than the image has
    EXPECT_EQ(s[0].x, 0);
    EXPECT_EQ(s[0].y, 1);
    EXPECT_EQ(s[5].tests, 9u);  // 0.1 us, the cheapest
    EXPECT_TRUE(costliestPixels(Image{}, RayCost::Tests, 20).empty());
}

}  // namespace
}  // namespace lancer::viewer::playback
