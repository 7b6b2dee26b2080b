// What the inspector draws, as data: the level range keeps exactly the leaves of its levels,
// the slice slab exactly the leaves crossing it, the cap bounds what is drawn, and a click
// picks the region under the cursor.
#include "app/viewer/inspector/inspector_model.h"

#include <gtest/gtest.h>

#include <set>

#include "engine/scene/loader.h"

namespace lancer::viewer::inspector {
namespace {

struct Built {
    Scene scene;
    std::unique_ptr<Accelerator> accel;
    std::unique_ptr<StructureView> view;
};

std::unique_ptr<Built> build(const std::string& spec, SchemeKind scheme) {
    auto b = std::make_unique<Built>();
    b->scene = loadScene(spec);
    BuildParams p;
    p.scheme = scheme;
    p.maxLevel = 12;
    p.maxObjects = 2;
    b->accel = buildAccelerator(b->scene, p);
    b->view = std::make_unique<StructureView>(b->scene, *b->accel);
    return b;
}

/// A view of the whole structure from far away (nothing culled).
InspectorView overview(const StructureView& v) {
    return {frameBox(v.worldBounds(), Vec3(1.0, 0.8, -0.6), 40.0), 400, 300};
}

MainView mainView(const Scene& s) { return {s.camera, 64, 48}; }

InspectorOptions everything() {
    InspectorOptions o;
    o.show = true;
    o.frustum = false;
    o.cap = 1 << 30;
    return o;
}

TEST(InspectorModel, LevelRangeKeepsItsLevelsOnly) {
    auto b = build("builtin:balls:2", SchemeKind::Regular);
    const StructureView& v = *b->view;
    InspectorOptions o = everything();
    InspectorModel all = buildModel(v, o, mainView(b->scene), overview(v), -1);
    ASSERT_EQ(all.regions.size(), b->accel->info().regions);
    ASSERT_GE(all.maxLevel, 4);
    o.levelLo = all.maxLevel - 2;
    o.levelHi = all.maxLevel - 1;
    InspectorModel some = buildModel(v, o, mainView(b->scene), overview(v), -1);
    size_t expected = 0;
    for (uint32_t id = 0; id < v.regionCount(); ++id)
        expected += inLevelRange(v.leafLevel(id), o.levelLo, o.levelHi);
    EXPECT_EQ(some.regions.size(), expected);
    EXPECT_GT(expected, 0u);
    EXPECT_LT(expected, all.regions.size());
    for (const RegionView& r : some.regions) {
        EXPECT_GE(r.level, o.levelLo);
        EXPECT_LE(r.level, o.levelHi);
    }
    // Twelve edges a region, nothing else drawn.
    EXPECT_EQ(some.lines.lineCount(), 12 * expected);
}

TEST(InspectorModel, SliceSlabKeepsTheCrossingLeaves) {
    auto b = build("builtin:balls:2", SchemeKind::Regular);
    const StructureView& v = *b->view;
    const Box3 bounds = v.worldBounds();
    InspectorOptions o = everything();
    o.slab.on = true;
    o.slab.axis = 2;
    o.slab.lo = bounds.lo.z + 0.31 * bounds.extent().z;
    o.slab.hi = bounds.lo.z + 0.37 * bounds.extent().z;
    InspectorModel m = buildModel(v, o, mainView(b->scene), overview(v), -1);
    std::set<uint32_t> drawn;
    for (const RegionView& r : m.regions) drawn.insert(r.id);
    size_t crossing = 0;
    for (uint32_t id = 0; id < v.regionCount(); ++id) {
        const Box3 box = cornersBox(v.regionCorners(id));
        const bool crosses = box.lo.z <= o.slab.hi && box.hi.z >= o.slab.lo;
        crossing += crosses;
        EXPECT_EQ(drawn.count(id), crosses ? 1u : 0u) << v.toString(id);
    }
    EXPECT_GT(crossing, 0u);
    EXPECT_LT(crossing, v.regionCount());
}

TEST(InspectorModel, CapBoundsWhatIsDrawn) {
    auto b = build("builtin:balls:2", SchemeKind::Regular);
    const StructureView& v = *b->view;
    InspectorOptions o = everything();
    o.cap = 10;
    InspectorModel m = buildModel(v, o, mainView(b->scene), overview(v), -1);
    EXPECT_EQ(m.regions.size(), 10u);
    EXPECT_GT(m.kept, 10u);  // the panel says the cap was reached
}

TEST(InspectorModel, RegionsOutOfViewAreNotDrawn) {
    auto b = build("builtin:balls:2", SchemeKind::Regular);
    const StructureView& v = *b->view;
    InspectorView away = overview(v);
    // Looking away from the structure.
    away.camera.at = away.camera.from + (away.camera.from - away.camera.at);
    InspectorModel m = buildModel(v, everything(), mainView(b->scene), away, -1);
    EXPECT_TRUE(m.regions.empty());
}

TEST(InspectorModel, ClickPicksTheLeafUnderTheCursor) {
    auto b = build("builtin:balls:2", SchemeKind::Regular);
    const StructureView& v = *b->view;
    const Box3 bounds = v.worldBounds();
    // A thin slab across z, seen from above with an orthographic camera: the drawn leaves tile
    // the slab's section, so the leaf under a pixel is the one holding the point of the slab
    // there.
    InspectorOptions o = everything();
    o.slab.on = true;
    o.slab.axis = 2;
    o.slab.lo = o.slab.hi = bounds.lo.z + 0.4137 * bounds.extent().z;
    InspectorView top;
    top.camera.projection = Projection::Orthographic;
    top.camera.at = bounds.center();
    top.camera.from = bounds.center() + Vec3(0.0, 0.0, 2.0 * bounds.extent().z + 1.0);
    top.camera.up = {0.0, 1.0, 0.0};
    top.camera.orthoHeight = 1.1 * std::max(bounds.extent().x, bounds.extent().y);
    top.width = top.height = 200;
    InspectorModel m = buildModel(v, o, mainView(b->scene), top, -1);
    ASSERT_FALSE(m.regions.empty());
    int checked = 0;
    for (int py = 5; py < 200; py += 17)
        for (int px = 7; px < 200; px += 19) {
            const Ray ray = top.camera.primaryRay(px, py, 200, 200);
            const double t = (o.slab.lo - ray.o.z) / ray.d.z;
            const Vec3 p = ray.at(t);
            if (!bounds.contains(p)) continue;
            const int i = pickRegion(ray, m.regions);
            ASSERT_GE(i, 0);
            EXPECT_EQ(m.regions[size_t(i)].id, v.regionAt(p)) << px << " " << py;
            ++checked;
        }
    EXPECT_GT(checked, 50);
}

TEST(InspectorModel, IrregularSlabsOfTheSelectedZoneOnly) {
    auto b = build("builtin:balls:1", SchemeKind::Irregular);
    const StructureView& v = *b->view;
    InspectorOptions o = everything();
    InspectorModel all = buildModel(v, o, mainView(b->scene), overview(v), -1);
    ASSERT_GT(all.regions.size(), 1u);
    // Select a slab of some zone: only that zone's slabs remain.
    const uint32_t chosen = all.regions[all.regions.size() / 2].id;
    const int64_t zone = v.region(chosen).zone;
    o.zoneSlabsOnly = true;
    InspectorModel one = buildModel(v, o, mainView(b->scene), overview(v), chosen);
    ASSERT_FALSE(one.regions.empty());
    for (const RegionView& r : one.regions) EXPECT_EQ(v.region(r.id).zone, zone);
    EXPECT_LT(one.regions.size(), all.regions.size());
    EXPECT_EQ(one.selection.lineCount(), 12u);
}

}  // namespace
}  // namespace lancer::viewer::inspector
