// Focus in the whole viewer (OSMesa): the playback's keys step the picked ray, F frames the
// played region (in the inspector when the mouse is over it, else in the main view, the
// irregular scheme's in the inspector), and "only its regions" (--show visited) narrows the
// overlays and the inspector to the regions the played ray's walk recorded.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "app/viewer/gl/transforms.h"
#include "app/viewer/playback/playback.h"
#include "tests/gl/viewer_harness.h"

namespace lancer::viewer {
namespace {

using testing::ViewerHarness;

constexpr int kW = 1280, kH = 720;

ViewerSettings focusSettings(SchemeKind scheme, bool inspector) {
    ViewerSettings s;
    s.scene = "builtin:balls:2";
    s.build.scheme = scheme;
    s.showInspector = inspector;
    return s;
}

/// Pick the image's centre (a ball of the flake) and wait for its tree.
void pickCentre(ViewerHarness& h) {
    ASSERT_TRUE(h.runUntilSettled());
    const PixelRect a = h.app().state().imageArea();
    h.app().pickPixel((a.x1 - a.x0) / 2, (a.y1 - a.y0) / 2, 0, 0);
    ASSERT_TRUE(h.runUntilSettled());
    ASSERT_FALSE(h.app().rayPlayer().playback().empty()) << h.app().rayPlayer().note();
}

Box3 regionBox(ViewerApp& app, int64_t id) {
    Box3 b;
    for (const Vec3& p : app.overlays().view()->regionCorners(uint32_t(id))) b.expand(p);
    return b;
}

/// A 1280x720 viewer of balls:2 under `scheme`, the image's centre picked and its playback moved
/// by key `k`; `region` is the played (and selected) region then.
struct Played {
    std::unique_ptr<ViewerHarness> h;
    int64_t region = -1;
};
Played playTo(SchemeKind scheme, bool inspector, ImGuiKey k) {
    Played p;
    p.h = std::make_unique<ViewerHarness>(kW, kH, focusSettings(scheme, inspector));
    if (!p.h->ok()) return p;
    pickCentre(*p.h);
    p.h->press(k);
    p.region = p.h->app().selectedRegion();
    return p;
}

/// Type `c` with the mouse at the centre of `r`.
void typeOver(ViewerHarness& h, const Rect& r, char c) {
    h.type(c, 0.5f * (r.x0 + r.x1), 0.5f * (r.y0 + r.y1));
}

/// The box's 8 corners all project inside a w x h image of `cam`, and its projection spans at
/// least a quarter of the image's smaller side: framed, not a speck.
void expectFramed(const Camera& cam, int w, int h, const Box3& box) {
    const gl::ImageProjector proj(cam, w, h);
    glm::dvec2 lo(1e30), hi(-1e30);
    for (int c = 0; c < 8; ++c) {
        const Vec3 p((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                     (c & 4) ? box.hi.z : box.lo.z);
        const std::optional<glm::dvec2> q = proj.toImage(p);
        ASSERT_TRUE(q.has_value());
        EXPECT_GE(q->x, -0.5);
        EXPECT_LE(q->x, w + 0.5);
        EXPECT_GE(q->y, -0.5);
        EXPECT_LE(q->y, h + 0.5);
        lo = glm::min(lo, *q);
        hi = glm::max(hi, *q);
    }
    EXPECT_GE(std::max(hi.x - lo.x, hi.y - lo.y), 0.25 * std::min(w, h));
    const Vec3 c = box.center();
    EXPECT_NEAR(glm::length(cam.at - c), 0.0, 1e-9 * (1.0 + glm::length(c)));
}

TEST(ViewerFocus, PlaybackKeysStepTheRay) {
    ViewerHarness h(kW, kH, focusSettings(SchemeKind::Regular, false));
    ASSERT_TRUE(h.ok());
    pickCentre(h);
    playback::RayPlayback& play = h.app().rayPlayer().playback();
    ASSERT_GE(play.stepCount(), 2) << "the centre ray crosses several leaves";
    ASSERT_GE(play.tree().rays.size(), 2u) << "a hit casts shadow rays";
    EXPECT_EQ(play.state().step, 0);
    h.press(ImGuiKey_RightArrow);
    EXPECT_EQ(play.state().step, 1);
    h.press(ImGuiKey_LeftArrow);
    EXPECT_EQ(play.state().step, 0);
    h.press(ImGuiKey_End);
    EXPECT_EQ(play.state().step, play.stepCount() - 1);
    h.press(ImGuiKey_Home);
    EXPECT_EQ(play.state().step, 0);
    // The selection follows the played step, as with the panel's buttons.
    EXPECT_EQ(h.app().selectedRegion(), int64_t(play.region()->region));
    h.press(ImGuiKey_Space);
    EXPECT_TRUE(play.playing());
    h.press(ImGuiKey_Space);
    EXPECT_FALSE(play.playing());
    h.press(ImGuiKey_DownArrow);
    EXPECT_EQ(play.state().ray, 1);
    h.press(ImGuiKey_UpArrow);
    EXPECT_EQ(play.state().ray, 0);
    h.press(ImGuiKey_UpArrow);  // the first ray stays the first
    EXPECT_EQ(play.state().ray, 0);
}

TEST(ViewerFocus, FOverTheInspectorFramesThePlayedRegionThere) {
    Played p = playTo(SchemeKind::Regular, true, ImGuiKey_RightArrow);
    ASSERT_GE(p.region, 0);
    ViewerHarness& h = *p.h;
    const int64_t id = p.region;
    const Camera main = h.app().camera();
    ASSERT_FALSE(h.app().layout().inspector.empty());
    typeOver(h, h.app().layout().inspector, 'f');
    h.frame();  // the inspector frames at its next update
    const PixelRect v = h.app().inspector().area(kW, kH);
    expectFramed(h.app().inspector().camera(), v.x1 - v.x0, v.y1 - v.y0, regionBox(h.app(), id));
    EXPECT_EQ(h.app().camera().toJson(), main.toJson()) << "the main camera stays";
}

TEST(ViewerFocus, FOverTheImageFramesTheRegionInTheMainView) {
    Played p = playTo(SchemeKind::Regular, true, ImGuiKey_End);
    ASSERT_GE(p.region, 0);
    ViewerHarness& h = *p.h;
    const int64_t id = p.region;
    const Camera inspector = h.app().inspector().camera();
    typeOver(h, h.app().layout().image, 'f');
    expectFramed(h.app().camera(), h.app().state().width(), h.app().state().height(),
                 regionBox(h.app(), id));
    EXPECT_EQ(h.app().inspector().camera().toJson(), inspector.toJson());
    // The regular scheme's leaves do not depend on the camera: the selection stays.
    EXPECT_EQ(h.app().selectedRegion(), id);
}

TEST(ViewerFocus, FFramesAnIrregularRegionInTheInspector) {
    Played p = playTo(SchemeKind::Irregular, false, ImGuiKey_RightArrow);
    ASSERT_GE(p.region, 0);
    ViewerHarness& h = *p.h;
    const Camera main = h.app().camera();
    const Box3 box = regionBox(h.app(), p.region);
    typeOver(h, h.app().layout().image, 'f');
    // Its slabs are cut for the main camera: moving that would rebuild them, so the inspector
    // opens, framed on the slab.
    EXPECT_TRUE(h.app().inspector().shown());
    EXPECT_EQ(h.app().camera().toJson(), main.toJson());
    h.frame();
    const PixelRect v = h.app().inspector().area(kW, kH);
    expectFramed(h.app().inspector().camera(), v.x1 - v.x0, v.y1 - v.y0, box);
}

TEST(ViewerFocus, VisitedDrawsOnlyThePlayedRaysRegions) {
    for (SchemeKind scheme : {SchemeKind::Regular, SchemeKind::Irregular, SchemeKind::Bvh}) {
        SCOPED_TRACE(schemeName(scheme));
        ViewerSettings s = focusSettings(scheme, true);
        s.overlays.leaves = scheme != SchemeKind::Irregular;
        s.overlays.slabs = scheme == SchemeKind::Irregular;
        ViewerHarness h(kW, kH, s);
        ASSERT_TRUE(h.ok());
        pickCentre(h);
        const size_t all = h.app().overlays().geometry().regionsTotal;
        h.app().state().settings().rayRegionsOnly = true;
        ASSERT_TRUE(h.runUntilSettled());
        const std::vector<uint32_t> visited =
            playback::visitedRegions(h.app().rayPlayer().playback());
        ASSERT_FALSE(visited.empty());
        // The layer draws leaves, BVH nodes or projective slabs (not the near region).
        size_t drawable = 0;
        for (uint32_t id : visited) {
            const RegionKind k = h.app().overlays().view()->region(id).kind;
            drawable += k == RegionKind::Leaf || k == RegionKind::BvhLeaf ||
                        k == RegionKind::BvhInner || k == RegionKind::ProjectiveSlab;
        }
        const overlay::OverlayGeometry& g = h.app().overlays().geometry();
        EXPECT_EQ(g.regionsTotal, drawable);
        EXPECT_GT(drawable, 0u);
        EXPECT_LT(g.regionsTotal, all);
        // The inspector keeps only those (the ones its camera sees).
        const std::vector<inspector::RegionView>& drawn = h.app().inspector().model().regions;
        EXPECT_FALSE(drawn.empty());
        for (const inspector::RegionView& r : drawn)
            EXPECT_TRUE(std::binary_search(visited.begin(), visited.end(), r.id)) << r.id;
        // Off: every region again.
        h.app().state().settings().rayRegionsOnly = false;
        ASSERT_TRUE(h.runUntilSettled());
        EXPECT_EQ(h.app().overlays().geometry().regionsTotal, all);
    }
}

}  // namespace
}  // namespace lancer::viewer
