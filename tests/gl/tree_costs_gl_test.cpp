// Cost on the structure and the tree browser (OSMesa, the whole viewer at 1280x720): once the
// image is complete its region visits and tests are counted by an observer of the render's
// walk, the leaves are coloured by them on the fixed cost scale its key shows, and the
// structure tree lists the structure's nodes with those counts, linked with the selection both
// ways; a table of a million entries lists only the rows in view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include "tests/gl/viewer_harness.h"

namespace lancer::viewer {
namespace {

using testing::ViewerHarness;

uint64_t sum(const std::vector<uint32_t>& v) {
    return std::accumulate(v.begin(), v.end(), uint64_t(0));
}

TEST(ViewerCosts, LeavesByVisitsAreTheRendersCountsOnTheKeysScale) {
    ViewerSettings s;
    s.scene = "builtin:balls:2";
    s.build.scheme = SchemeKind::Regular;
    s.overlays.leaves = true;
    s.overlays.leafColor = overlay::LeafColor::Visits;
    ViewerHarness h(1280, 720, s);
    ASSERT_TRUE(h.ok());
    ASSERT_TRUE(h.runUntilSettled());
    h.frame();
    ViewerState& st = h.app().state();
    ASSERT_TRUE(st.shownComplete());
    const std::shared_ptr<const ImageCosts>& c = st.costs();
    ASSERT_NE(c, nullptr) << st.costsError();
    ASSERT_TRUE(costsFit(c.get(), h.app().overlays().structure(), CostRays::All));
    // The counts are the image's: over every region, the render's per-pixel counters summed
    // (the heat maps' and --stats' region_visits and prim_tests).
    EXPECT_EQ(c->costs.width, st.width());
    EXPECT_EQ(c->costs.totalVisits(), sum(st.shown().regionVisits));
    EXPECT_EQ(c->costs.totalTests(), sum(st.shown().primTests));

    // Each leaf's lines carry the colour of its visits on the fixed scale.
    const overlay::OverlayGeometry& g = h.app().overlays().geometry();
    EXPECT_EQ(g.leafCost, overlay::CostKind::Visits);
    EXPECT_TRUE(g.costsKnown);
    std::set<uint32_t> expected, drawn;
    const StructureView* sv = h.app().overlays().view();
    ASSERT_NE(sv, nullptr);
    for (uint32_t i = 0; i < sv->regionCount(); ++i)
        expected.insert(gl::rgba8(costColor(double(c->costs.visits(i)))));
    for (const gl::BatchVertex& v : g.wires.lines) drawn.insert(v.color);
    EXPECT_EQ(drawn, expected);
    EXPECT_GT(drawn.size(), 2u) << "leaves of several decades";

    // The key: 0 apart, then 1 to 1M+ by decade, each swatch's pixels its colour.
    const KeyReport& r = h.app().keys();
    ASSERT_EQ(r.keys.size(), 1u);
    EXPECT_EQ(r.keys[0].title, "leaves by region visits, all rays (log)");
    const std::vector<KeySwatch>& sw = r.keys[0].swatches;
    ASSERT_EQ(sw.size(), size_t(kCostDecades) + 2);
    EXPECT_EQ(sw[0].label, "0");
    EXPECT_EQ(sw[0].color, kNoCostColor);
    EXPECT_EQ(sw[1].color, costColor(1.0));
    EXPECT_EQ(sw.back().label, "1M+");
    EXPECT_EQ(sw.back().color, costColor(1e6));
    const std::vector<uint8_t> px = h.gl().read();
    for (const KeySwatch& k : sw) {
        const int x = int(k.rect.x0) + 1, y = int(k.rect.y0) + 1;
        const uint8_t* p = &px[4 * (size_t(y) * 1280u + size_t(x))];
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(int(p[ch]), int(std::lround(k.color[ch] * 255.0f)), 1) << k.label;
    }

    // Primary rays alone: counted again, fewer than all rays.
    h.app().overlays().options.costRays = CostRays::Primary;
    ASSERT_TRUE(h.runUntilSettled());
    h.frame();
    ASSERT_TRUE(costsFit(st.costs().get(), h.app().overlays().structure(), CostRays::Primary));
    EXPECT_LT(st.costs()->costs.totalVisits(), sum(st.shown().regionVisits));
    EXPECT_EQ(h.app().keys().keys[0].title, "leaves by region visits, primary rays (log)");
}

TEST(ViewerTree, SelectionOpensItsNodeAndAClickOnANodeSelectsItsRegion) {
    ViewerSettings s;
    s.scene = "builtin:balls:2";
    s.build.scheme = SchemeKind::Regular;
    s.showTree = true;
    ViewerHarness h(1280, 720, s);
    ASSERT_TRUE(h.ok());
    ASSERT_TRUE(h.runUntilSettled());
    const StructureView* sv = h.app().overlays().view();
    ASSERT_NE(sv, nullptr);
    ASSERT_GT(sv->regionCount(), 10u);
    // A region selected elsewhere (as by a Ctrl+click, --select): its path opens and its row
    // is drawn, inside the panel.
    const uint32_t leaf = uint32_t(sv->regionCount() / 2);
    h.app().selectRegion(leaf);
    h.frame();
    h.frame();
    const TreeBrowser& tb = h.app().treeBrowser();
    const std::vector<StructureTree> trees = sv->trees();
    const auto path = sv->treePath(trees[size_t(tb.tree())], leaf);
    ASSERT_TRUE(path);
    for (size_t n = 0; n < path->size(); ++n)
        EXPECT_TRUE(tb.open().count(std::vector<size_t>(path->begin(), path->begin() + n)))
            << "level " << n;
    ASSERT_TRUE(tb.rows().count(leaf));
    const Rect panel = h.app().layout()[PanelId::Tree];
    ASSERT_FALSE(panel.empty());
    const ImVec2 row = tb.rows().at(leaf);
    EXPECT_TRUE(row.x > panel.x0 && row.x < panel.x1 && row.y > panel.y0 && row.y < panel.y1)
        << row.x << " " << row.y << " in " << panel.toString();
    // A click on another region's row selects that region.
    int64_t other = -1;
    for (const auto& [region, at] : tb.rows())
        if (region != leaf && at.y > panel.y0 + 40.0f && at.y < panel.y1 - 10.0f) other = region;
    ASSERT_GE(other, 0);
    const ImVec2 at = tb.rows().at(other);
    h.click(at.x, at.y);
    EXPECT_EQ(h.app().selectedRegion(), other);
    EXPECT_TRUE(h.app().state().settings().showSelection);
}

// A directory of a million entries in one table: opening it lists the rows in view, not the
// table.
TEST(ViewerTree, AMillionEntryTableListsOnlyTheRowsInView) {
    ViewerSettings s;
    s.scene = "builtin:balls:2";
    s.build.scheme = SchemeKind::Regular;
    s.build.regular.fullTable = true;
    s.build.regular.maxObjects = 1;
    s.build.regular.maxLevel = 20;
    s.build.regular.costStop = false;
    s.showTree = true;
    ViewerHarness h(1280, 720, s);
    ASSERT_TRUE(h.ok());
    ASSERT_TRUE(h.runUntilSettled());
    const StructureView* sv = h.app().overlays().view();
    ASSERT_NE(sv, nullptr);
    const std::vector<StructureTree> trees = sv->trees();
    ASSERT_EQ(trees.size(), 2u);
    ASSERT_EQ(trees[1].kind, TreeKind::Directory);
    ASSERT_GE(trees[1].root.children, size_t(1) << 20);
    // The directory shown (its combo), a leaf whose first cell lies far down the table
    // selected: the table opens to its entry.
    h.app().treeBrowser().setTree(1);
    const uint32_t leaf = uint32_t(sv->regionCount() - 1);
    h.app().selectRegion(leaf);
    h.frame();
    h.frame();
    const TreeBrowser& tb = h.app().treeBrowser();
    EXPECT_EQ(tb.tree(), 1);
    EXPECT_TRUE(tb.open().count({})) << "the table is open";
    EXPECT_TRUE(tb.rows().count(leaf)) << "its entry's row is drawn";
    EXPECT_LT(tb.rowsDrawn(), 200u) << "of " << trees[1].root.children << " entries";
}

}  // namespace
}  // namespace lancer::viewer
