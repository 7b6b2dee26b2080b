// The cost of an image on its structure (engine/render/region_costs.h): counted by an observer of
// the render's walk, so its totals are the render's counters, and region by region they are the
// Region and PrimTest events of the pixels' recorded ray trees (lancer trace's walk).
#include "engine/render/region_costs.h"

#include <gtest/gtest.h>

#include "engine/accel/structure_view.h"
#include "engine/render/ray_tree.h"
#include "engine/scene/loader.h"

namespace lancer {
namespace {

struct CostCase {
    const char* scene;
    SchemeKind scheme;
    int bounces;
};

std::vector<CostCase> costCases() {
    std::vector<CostCase> out;
    for (const char* scene : {"builtin:default", "builtin:balls:1", "builtin:drilled:2"})
        for (SchemeKind s :
             {SchemeKind::Brute, SchemeKind::Regular, SchemeKind::Irregular, SchemeKind::Bvh})
            for (int bounces : {0, 2}) out.push_back({scene, s, bounces});
    return out;
}

/// A w x h render on two threads, `bounces` deep.
RenderOptions options(int w, int h, int bounces) {
    RenderOptions ro;
    ro.width = w;
    ro.height = h;
    ro.threads = 2;
    ro.shading.bounces = bounces;
    return ro;
}

// Over the whole image, all rays: the visits and tests counted by region add up to the
// render's region_visits and prim_tests (what `--stats` writes); primary rays alone, to those of
// a render that casts no other ray (no shadows, no bounces).
TEST(RegionCosts, TotalsEqualTheRendersCounters) {
    const int w = 64, h = 40;
    for (const CostCase& c : costCases()) {
        SCOPED_TRACE(std::string(c.scene) + " " + schemeName(c.scheme) + " bounces " +
                     std::to_string(c.bounces));
        Scene scene = loadScene(c.scene);
        BuildParams p;
        p.scheme = c.scheme;
        auto accel = buildAccelerator(scene, p);
        const StructureView sv(scene, *accel);
        const RenderOptions ro = options(w, h, c.bounces);
        Image img(w, h);
        const RenderStats all = render(scene, *accel, ro, img);
        RegionCosts costs;
        ASSERT_TRUE(countRegionCosts(scene, *accel, ro, sv.regionCount(), CostRays::All, costs));
        EXPECT_EQ(costs.regions(), sv.regionCount());
        EXPECT_EQ(costs.totalVisits(), all.counters.regionVisits);
        EXPECT_EQ(costs.totalTests(), all.counters.primTests);
        EXPECT_GT(costs.totalVisits(), 0u);

        RenderOptions primaryOnly = ro;
        primaryOnly.shading.bounces = 0;
        primaryOnly.shading.shadows = false;
        const RenderStats prim = render(scene, *accel, primaryOnly, img);
        RegionCosts pc;
        ASSERT_TRUE(countRegionCosts(scene, *accel, ro, sv.regionCount(), CostRays::Primary, pc));
        EXPECT_EQ(pc.totalVisits(), prim.counters.regionVisits);
        EXPECT_EQ(pc.totalTests(), prim.counters.primTests);
        EXPECT_EQ(pc.rays, CostRays::Primary);
    }
}

// Region by region: the counts are the Region and PrimTest events of every pixel's ray tree as
// tracePixel() records it (the walk `lancer trace` and the viewer's playback show).
TEST(RegionCosts, EachRegionsCountsAreItsRecordedEvents) {
    const int w = 18, h = 12;
    for (const CostCase& c : costCases()) {
        if (c.bounces == 0) continue;
        SCOPED_TRACE(std::string(c.scene) + " " + schemeName(c.scheme));
        Scene scene = loadScene(c.scene);
        BuildParams p;
        p.scheme = c.scheme;
        auto accel = buildAccelerator(scene, p);
        const StructureView sv(scene, *accel);
        const RenderOptions ro = options(w, h, c.bounces);
        for (CostRays rays : {CostRays::All, CostRays::Primary}) {
            std::vector<uint64_t> visits(sv.regionCount()), tests(sv.regionCount());
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const RayTree t =
                        tracePixel(scene, *accel, ro.shading, scene.camera, x, y, w, h);
                    for (const TracedRay& r : t.rays) {
                        if (rays == CostRays::Primary && r.kind != RayKind::Primary) continue;
                        int64_t in = -1;
                        for (const WalkEvent& e : r.events) {
                            if (const walk::Region* reg = e.get<walk::Region>()) {
                                in = reg->region;
                                ++visits[reg->region];
                            } else if (e.kind() == WalkEvent::PrimTest) {
                                ASSERT_GE(in, 0) << "a test before any region";
                                ++tests[size_t(in)];
                            }
                        }
                    }
                }
            RegionCosts costs;
            ASSERT_TRUE(countRegionCosts(scene, *accel, ro, sv.regionCount(), rays, costs));
            EXPECT_EQ(costs.unplacedTests, 0u);
            for (uint32_t r = 0; r < sv.regionCount(); ++r) {
                ASSERT_EQ(costs.visits(r), visits[r]) << "region " << r;
                ASSERT_EQ(costs.tests(r), tests[r]) << "region " << r;
            }
        }
    }
}

// A cancel already set ends the count at once and leaves the result as it was.
TEST(RegionCosts, ACancelLeavesTheResultUnchanged) {
    Scene scene = loadScene("builtin:balls:1");
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    auto accel = buildAccelerator(scene, p);
    RenderOptions ro;
    ro.width = 64;
    ro.height = 40;
    std::atomic<bool> cancel{true};
    RegionCosts costs;
    costs.width = 7;
    EXPECT_FALSE(
        countRegionCosts(scene, *accel, ro, accel->info().regions, CostRays::All, costs, &cancel));
    EXPECT_EQ(costs.width, 7);
    EXPECT_TRUE(costs.visitsBefore.empty());
}

}  // namespace
}  // namespace lancer
