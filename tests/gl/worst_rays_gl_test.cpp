// The Ray panel's "Worst rays" (OSMesa, the whole viewer at 1280x720): once the image is
// complete it lists the 20 costliest pixels of the image on screen, by primitive tests, region
// visits or time, and a click on a row picks that pixel, whose ray tree then plays.
#include <gtest/gtest.h>

#include <algorithm>

#include "app/viewer/playback/worst_rays.h"
#include "tests/gl/viewer_harness.h"

namespace lancer::viewer {
namespace {

using testing::ViewerHarness;

TEST(ViewerWorstRays, ListsTheCostliestPixelsAndPicksOnClick) {
    ViewerSettings s;
    s.scene = "builtin:balls:2";
    s.build.scheme = SchemeKind::Regular;
    s.showRay = true;
    ViewerHarness h(1280, 720, s);
    ASSERT_TRUE(h.ok());
    h.app().state().notes().worstOpen = true;
    ASSERT_TRUE(h.runUntilSettled());
    h.frame();
    ViewerState& st = h.app().state();
    ASSERT_TRUE(st.shownComplete());
    const Image& img = st.shown();
    const std::vector<playback::CostlyPixel>& shown = st.notes().worst;
    ASSERT_EQ(shown.size(), 20u);
    // The list is the image's: its first row holds the most tests of any pixel, each row no
    // fewer than the next, every row's figures those of its pixel.
    EXPECT_EQ(shown[0].tests, *std::max_element(img.primTests.begin(), img.primTests.end()));
    for (size_t i = 0; i < shown.size(); ++i) {
        const size_t k = img.index(shown[i].x, shown[i].y);
        EXPECT_EQ(shown[i].tests, img.primTests[k]) << i;
        EXPECT_EQ(shown[i].visits, img.regionVisits[k]) << i;
        if (i > 0) {
            EXPECT_GE(shown[i - 1].tests, shown[i].tests) << i;
        }
    }
    // Ranked by region visits, the list follows.
    st.notes().worstBy = int(playback::RayCost::Visits);
    h.frame();
    EXPECT_EQ(st.notes().worst[0].visits,
              *std::max_element(img.regionVisits.begin(), img.regionVisits.end()));
    st.notes().worstBy = int(playback::RayCost::Tests);
    h.frame();
    ASSERT_GT(st.notes().worstFirstRow[0], 0.0f);

    // A click on the first row picks its pixel; the traced tree makes the tests the render
    // counted there (the same walk, replayed).
    const playback::CostlyPixel top = st.notes().worst[0];
    h.click(st.notes().worstFirstRow[0], st.notes().worstFirstRow[1]);
    ASSERT_TRUE(h.runUntilSettled());
    const playback::RayPlayback& play = h.app().rayPlayer().playback();
    ASSERT_FALSE(play.empty()) << h.app().rayPlayer().note();
    EXPECT_EQ(play.pixel().x, top.x);
    EXPECT_EQ(play.pixel().y, top.y);
    EXPECT_EQ(play.tree().counters.primTests, top.tests);
}

}  // namespace
}  // namespace lancer::viewer
