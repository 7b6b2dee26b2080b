// The depth strip of a zone (overlay_geometry.h): the projective slabs that the image cannot
// show apart, laid along depth, with the slab under the cursor or selected marked.
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer/overlay/overlay_geometry.h"
#include "engine/accel/accelerator.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"

namespace lancer::viewer::overlay {
namespace {

TEST(DepthStrip, TheSlabPickedUnderAPixelIsTheStripsCurrentOneAndHoldsTheHitsDepth) {
    Scene scene = loadScene("builtin:balls:2");
    scene.prepare();
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    const std::unique_ptr<Accelerator> accel = buildAccelerator(scene, p);
    const StructureView view(scene, *accel);
    const ZoneFrameView* fr = overlayFrame(view, true);
    ASSERT_NE(fr, nullptr);
    ASSERT_EQ(fr->kind(), ZoneFrameKind::Projective);
    constexpr int kW = 48, kH = 36;
    RenderOptions opt;
    opt.width = kW;
    opt.height = kH;
    opt.camera = scene.camera;
    Image img(kW, kH);
    render(scene, *accel, opt, img);
    size_t checked = 0, inner = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const float depth = img.depth[img.index(x, y)];
            const auto picked = pick(view, scene.camera, kW, kH, x + 0.5, y + 0.5, depth, true);
            if (!picked || picked->zone < 0 || !std::isfinite(depth)) continue;
            ASSERT_TRUE(picked->frameDepth.has_value());
            const DepthStrip s = depthStrip(*fr, uint32_t(picked->zone), picked->frameDepth);
            const std::vector<SlabInfo> slabs = fr->slabs(uint32_t(picked->zone));
            ASSERT_EQ(s.slabs.size(), slabs.size());
            // The slabs in depth order, each beginning where the one before ends.
            for (size_t k = 1; k < s.slabs.size(); ++k) ASSERT_EQ(s.slabs[k].z0, s.slabs[k - 1].z1);
            ASSERT_GE(s.current, 0) << "pixel " << x << "," << y;
            const DepthStrip::Slab& c = s.slabs[size_t(s.current)];
            EXPECT_EQ(c.region, picked->region);
            EXPECT_GE(*picked->frameDepth, c.z0);
            EXPECT_LE(*picked->frameDepth, c.z1);
            EXPECT_EQ(c.prims, slabs[size_t(s.current)].prims.size());
            // The same slab when asked by region (the selection), and its place on the bar.
            EXPECT_EQ(depthStrip(*fr, uint32_t(picked->zone), std::nullopt, c.region).current,
                      s.current);
            const double a = s.at(*picked->frameDepth);
            EXPECT_GE(a, s.at(c.z0));
            EXPECT_LE(a, s.at(c.z1));
            inner += s.current > 0;
            ++checked;
        }
    EXPECT_GT(checked, size_t(kW));
    EXPECT_GT(inner, 0u) << "some hits lie beyond a zone's first slab";
}

TEST(DepthStrip, EachSlabTakesAnEqualShareOfTheBarInDepthOrder) {
    DepthStrip s;
    s.slabs = {{7, 2.0, 3.0, 1}, {8, 3.0, 11.0, 2}, {9, 11.0, 100.0, 1}};
    EXPECT_EQ(s.z0(), 2.0);
    EXPECT_EQ(s.z1(), 100.0);
    EXPECT_EQ(s.at(2.0), 0.0);
    EXPECT_NEAR(s.at(2.5), 0.5 / 3.0, 1e-15);
    EXPECT_NEAR(s.at(3.0), 1.0 / 3.0, 1e-15);
    EXPECT_NEAR(s.at(7.0), 1.5 / 3.0, 1e-15);
    EXPECT_NEAR(s.at(11.0), 2.0 / 3.0, 1e-15);
    EXPECT_EQ(s.at(100.0), 1.0);
    EXPECT_EQ(s.at(1.0), 0.0);
    EXPECT_EQ(s.at(1e9), 1.0);
    EXPECT_EQ(DepthStrip{}.at(1.0), 0.0);
}

}  // namespace
}  // namespace lancer::viewer::overlay
