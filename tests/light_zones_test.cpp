// The irregular scheme's per-light projective structures (docs/irregular.md, "Projective zones
// for shadow rays"): every shadow ray answered as brute force answers it, with lights outside
// the bounds (walked in their own structure), inside them (the camera-frame walk), far away, just
// beyond a face of the bounds and on a primitive's face plane, and rays along the zones' edges;
// the walk as the observer and `lancer trace` tell it; the budget that skips them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "engine/accel/structure_view.h"
#include "engine/render/ray_tree.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

struct LzShadowRay {
    Ray ray;
    double tmax;
    uint32_t light;
};

const IrregularSubdivision& lzIrregular(const Accelerator& a) {
    return std::get<IrregularSubdivision>(a.impl());
}

std::unique_ptr<Accelerator> lzBuild(const Scene& scene, bool lightBuffer,
                                     size_t memoryBudget = 0) {
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.frame = IrregularFrame::Projective;
    p.lightBuffer = lightBuffer;
    p.memoryBudget = memoryBudget;
    return buildAccelerator(scene, p);
}

/// The ray the tracer casts from `from` toward light l.
LzShadowRay lzToward(const Scene& s, const Vec3& from, uint32_t l) {
    const Vec3 L = s.lights[l].position;
    return {Ray{from, glm::normalize(L - from)}, glm::length(L - from), l};
}

/// The tracer's shadow rays from the first hits of pixel rays (offset off the surface, one per
/// light the surface faces), rays from random points of the bounds to each light, and rays from
/// the corners and edge midpoints of random zones of each light's structure, at its slabs'
/// boundary depths: their (u, v) lies on the zones' edges, their origin on a slab's face.
std::vector<LzShadowRay> lzShadowRays(const Scene& s, const IrregularSubdivision& irr,
                                      uint64_t seed) {
    auto brute = buildAccelerator(s, BuildParams{});
    Tracer tracer(s, *brute, ShadingOptions{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    std::vector<LzShadowRay> out;
    for (const Ray& r : test::pixelRays(s, 24, 24)) {
        Hit hit;
        if (!tracer.nearest(r, 0.0, kInf, ctx, obs, hit)) continue;
        SurfacePoint p = tracer.surface(r, hit);
        const Vec3 above = p.p + tracer.offset(p.p) * p.facing;
        for (uint32_t l = 0; l < s.lights.size(); ++l)
            if (glm::dot(p.facing, s.lights[l].position - p.p) > 0.0)
                out.push_back(lzToward(s, above, l));
    }
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 300; ++k) {
        const Vec3 p = s.bounds.lo + Vec3(u(rng), u(rng), u(rng)) * s.bounds.extent();
        out.push_back(lzToward(s, p, uint32_t(k % s.lights.size())));
    }
    for (uint32_t l = 0; l < irr.lights().size(); ++l) {
        const ProjectiveZones& lz = irr.lights()[l];
        if (lz.zoneCount() == 0) continue;
        const ScreenBsp& bsp = lz.screen();
        for (int k = 0; k < 60; ++k) {
            const uint32_t z = uint32_t(rng() % lz.zoneCount());
            const uint32_t first = lz.zoneFirst()[z], last = lz.zoneFirst()[z + 1];
            const double depth = lz.slabLo(first + uint32_t(rng() % (last - first)));
            for (int j = 0; j < 9; ++j) {
                const glm::dvec2 lo = bsp.zoneLo[z], hi = bsp.zoneHi[z];
                const double a = j % 3 == 0 ? lo.x : j % 3 == 1 ? 0.5 * (lo.x + hi.x) : hi.x;
                const double b = j / 3 == 0 ? lo.y : j / 3 == 1 ? 0.5 * (lo.y + hi.y) : hi.y;
                out.push_back(lzToward(s, lz.frame().toWorld({a * depth, b * depth, depth}), l));
            }
        }
    }
    return out;
}

struct LzTally {
    size_t rays = 0, blocked = 0, inLightZones = 0;
};

/// Each shadow ray against brute force: the irregular walk toward its light finds brute force's
/// nearest hit (prim and t), and occluded() (with the light buffer's stretches, and without)
/// answers as brute force does.
LzTally lzCheck(const std::string& name, const Scene& s) {
    auto brute = buildAccelerator(s, BuildParams{});
    auto withBuffer = lzBuild(s, true);
    auto without = lzBuild(s, false);
    const IrregularSubdivision& irr = lzIrregular(*without);
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    LzTally tally;
    size_t failures = 0;
    for (const LzShadowRay& sr : lzShadowRays(s, irr, 17)) {
        ++tally.rays;
        Hit want, got;
        ctx.beginRay();
        const bool blocked = brute->intersect(sr.ray, 0.0, sr.tmax, ctx, obs, want);
        tally.blocked += blocked;
        if (sr.light < irr.lights().size()) {
            double u, v;
            const ProjectiveZones& lz = irr.lights()[sr.light];
            tally.inLightZones += lz.coversFromCentre(lz.frame().ray(sr.ray), u, v);
        }
        ctx.beginRay();
        const bool found = irr.intersectTowardLight(sr.ray, sr.light, 0.0, sr.tmax, ctx, obs, got);
        if ((found != blocked || (found && (got.prim != want.prim || got.t != want.t))) &&
            failures++ < 5)
            ADD_FAILURE() << name << ": " << sr.ray.toString() << " toward light " << sr.light
                          << ": irregular " << found << " p" << got.prim << " t " << got.t
                          << ", brute force " << blocked << " p" << want.prim << " t " << want.t;
        for (const Accelerator* a : {withBuffer.get(), without.get()}) {
            ctx.beginRay();
            if (a->occluded(sr.ray, sr.tmax, sr.light, ctx, obs) != blocked && failures++ < 5)
                ADD_FAILURE() << name << ": occluded() " << sr.ray.toString() << " toward light "
                              << sr.light << " differs from brute force's " << blocked;
        }
    }
    EXPECT_EQ(ctx.counters.walkErrors, 0u) << name;
    EXPECT_EQ(failures, 0u) << name;
    return tally;
}

/// The scene's lights replaced by: one inside the bounds, one just beyond a face of them, one
/// far away, and one on the plane of the top face of the highest primitive's box (beyond the
/// bounds along x, so its structure's depth axis is x and that plane passes through it).
void lzPlaceLights(Scene& s) {
    const Box3 b = s.bounds;
    const Vec3 c = b.center(), e = b.extent();
    double top = -kInf;
    for (uint32_t p : s.livePrimitives()) top = std::max(top, s.minBox[p].hi.z);
    s.lights = {Light{c + 0.1 * e, Vec3(0.5)},
                Light{Vec3(c.x, c.y, b.hi.z + 1e-6 * glm::length(e)), Vec3(0.5)},
                Light{c + 1e4 * glm::length(e) * glm::normalize(Vec3(0.3, -0.5, 0.8)), Vec3(0.5)},
                Light{Vec3(b.hi.x + 0.5 * e.x, c.y + 0.1 * e.y, top), Vec3(0.5)}};
}

TEST(LightZones, SpdScenesShadowRaysAsBruteForce) {
    for (const char* f : {"balls1.nff", "gears1.nff", "tetra3.nff", "rings2.nff", "balls2.nff"}) {
        Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/" + f);
        auto accel = lzBuild(s, false);
        const nlohmann::json& x = accel->info().extra;
        // The SPD lights stand outside the scenes' bounds: each gets its structure.
        EXPECT_EQ(x["light_structures"].get<size_t>(), s.lights.size()) << f;
        EXPECT_EQ(x["lights_inside"].get<size_t>(), 0u) << f;
        EXPECT_GT(x["light_zones"].get<size_t>(), 0u) << f;
        const LzTally t = lzCheck(f, s);
        std::printf("%s: %zu shadow rays, %zu blocked, %zu in a light's zones\n", f, t.rays,
                    t.blocked, t.inLightZones);
        EXPECT_GT(t.blocked, 0u) << f;
        EXPECT_GT(t.inLightZones, t.rays / 2) << f;
    }
}

TEST(LightZones, LightsInsideOutsideFarAndOnAFacePlane) {
    for (const char* spec : {"builtin:default", "builtin:drilled:4", "builtin:lattice:4"}) {
        Scene s = loadScene(spec);
        lzPlaceLights(s);
        auto accel = lzBuild(s, false);
        const IrregularSubdivision& irr = lzIrregular(*accel);
        const nlohmann::json& x = accel->info().extra;
        // The light inside the bounds has none: its shadow rays walk the camera frame.
        EXPECT_EQ(x["lights_inside"].get<size_t>(), 1u) << spec;
        EXPECT_EQ(irr.lights()[0].zoneCount(), 0u) << spec;
        EXPECT_EQ(x["light_structures"].get<size_t>(), 3u) << spec;
        const LzTally t = lzCheck(spec, s);
        std::printf("%s: %zu shadow rays, %zu blocked, %zu in a light's zones\n", spec, t.rays,
                    t.blocked, t.inLightZones);
        EXPECT_GT(t.blocked, 0u) << spec;
        EXPECT_GT(t.inLightZones, 0u) << spec;
    }
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        test::RandomSceneOptions opt;
        opt.transforms = seed % 2 == 0;
        opt.surfaces = seed % 3 == 0;
        if (seed >= 7) opt.offset = Vec3(3e5, -2e5, 1e5);  // far from the origin
        Scene s = test::randomCsgScene(seed, opt);
        if (s.bounds.isEmpty()) continue;
        lzPlaceLights(s);
        const LzTally t = lzCheck("random " + std::to_string(seed), s);
        EXPECT_GT(t.inLightZones, 0u) << seed;
    }
}

TEST(LightZones, TraceTellsTheWalkInTheLightsStructure) {
    Scene scene = loadScene(std::string(LANCER_SPD_DIR) + "/balls1.nff");
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.lightBuffer = false;  // whole shadow rays, one walk each
    auto accel = buildAccelerator(scene, p);
    const IrregularSubdivision& irr = lzIrregular(*accel);
    ASSERT_FALSE(irr.lightFirstRegion().empty());
    const uint32_t firstLightId = irr.lightFirstRegion().front();
    StructureView view(scene, *accel);
    ShadingOptions sh;
    sh.bounces = 0;
    size_t walks = 0, exits = 0;
    for (int y = 0; y < 16; y += 3)
        for (int x = 0; x < 16; x += 3) {
            const RayTree t = tracePixel(scene, *accel, sh, scene.camera, x, y, 16, 16);
            for (const TracedRay& r : t.rays) {
                if (r.kind != RayKind::Shadow) continue;
                const std::vector<size_t> steps = r.regionSteps();
                if (steps.empty()) continue;
                const uint32_t first = r.events[steps[0]].as<walk::Region>().region;
                if (first < firstLightId) continue;
                ++walks;
                const RegionInfo info = view.region(first);
                ASSERT_EQ(info.light, r.light);
                const std::vector<StepReason> why = explainSteps(r, view, &scene);
                ASSERT_EQ(why.size(), steps.size());
                // Located once in the light's structure, then slab after slab toward the light.
                EXPECT_NE(why[0].text.find("in the zone of its light's projective structure"),
                          std::string::npos)
                    << why[0].text;
                EXPECT_NE(why[0].text.find("light " + std::to_string(r.light) + "'s "),
                          std::string::npos)
                    << why[0].text;
                double lastDepth = kInf;
                for (size_t k = 0; k < steps.size(); ++k) {
                    const RegionInfo ri = view.region(r.events[steps[k]].as<walk::Region>().region);
                    EXPECT_EQ(ri.light, r.light);
                    EXPECT_LE(ri.frameBox.hi.z, lastDepth);
                    lastDepth = ri.frameBox.lo.z;
                    if (k + 1 < steps.size()) {
                        EXPECT_NE(why[k].text.find("through its near depth plane"),
                                  std::string::npos)
                            << why[k].text;
                        ++exits;
                    }
                }
                for (const WalkEvent& e : r.events) {
                    EXPECT_EQ(e.get<walk::Pointer>(), nullptr);  // no corner pointer
                    if (const auto* ex = e.get<walk::Exit>()) {
                        EXPECT_EQ(ex->axis, 2);
                        // The exit point lies on the line from the origin to the light.
                        const Vec3 q = r.origin + ex->t * r.direction;
                        EXPECT_LT(glm::length(q - ex->point), 1e-9 * scene.scale());
                    }
                }
            }
        }
    EXPECT_GT(walks, 10u);
    EXPECT_GT(exits, 10u);
}

/// `s`'s camera turned about its up vector by `degrees` around the point it looks at.
void lzTurnCamera(Scene& s, double degrees) {
    const Vec3 k = glm::normalize(s.camera.up), d = s.camera.from - s.camera.at;
    const double a = degrees * 3.14159265358979323846 / 180.0;
    s.camera.from = s.camera.at + d * std::cos(a) + glm::cross(k, d) * std::sin(a) +
                    k * glm::dot(k, d) * (1.0 - std::cos(a));
}

TEST(LightZones, ABuildForAnotherViewTakesTheLightsStructuresOfThePrevious) {
    auto scene = std::make_unique<Scene>(loadScene(std::string(LANCER_SPD_DIR) + "/balls2.nff"));
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.frame = IrregularFrame::Projective;
    auto first = buildAccelerator(*scene, p);
    // Another view of the same prepared scene (the viewer's rebuild after a camera move).
    Scene turned = *scene;
    lzTurnCamera(turned, 35.0);
    auto lent = buildAccelerator(turned, p, {{}, {}, first.get()});
    auto fresh = buildAccelerator(turned, p);
    const nlohmann::json &xl = lent->info().extra, &xf = fresh->info().extra;
    EXPECT_TRUE(xl["lights_lent"].get<bool>());
    EXPECT_TRUE(xl["light_buffer_lent"].get<bool>());
    EXPECT_FALSE(xf["lights_lent"].get<bool>());
    EXPECT_FALSE(xf["light_buffer_lent"].get<bool>());
    EXPECT_EQ(xl["light_ms"].get<double>(), 0.0);
    // What is lent is what the build would have made: the same structures and light buffer.
    for (const char* k :
         {"light_structures", "light_zones", "light_slabs", "light_empty_slabs", "light_regions",
          "light_bytes", "light_buffer_bytes", "zones", "projective_zones"})
        EXPECT_EQ(xl[k], xf[k]) << k;
    EXPECT_EQ(lent->info().regions, fresh->info().regions);
    EXPECT_EQ(lent->info().memoryBytes, fresh->info().memoryBytes);
    // Changed knobs, or a scene prepared again, lend nothing.
    BuildParams other = p;
    other.irregular.maxObjects = 2;
    EXPECT_FALSE(buildAccelerator(turned, other, {{}, {}, first.get()})
                     ->info()
                     .extra["lights_lent"]
                     .get<bool>());
    Scene again = loadScene(std::string(LANCER_SPD_DIR) + "/balls2.nff");
    lzTurnCamera(again, 35.0);
    auto notLent = buildAccelerator(again, p, {{}, {}, first.get()});
    EXPECT_FALSE(notLent->info().extra["lights_lent"].get<bool>());
    EXPECT_FALSE(notLent->info().extra["light_buffer_lent"].get<bool>());
    // The lent structures refer to the new scene, not the one they were built over: with the
    // first build and its scene gone, every shadow ray and pixel is still brute force's.
    first.reset();
    scene.reset();
    const IrregularSubdivision& irr = lzIrregular(*lent);
    TraceContext ctx(turned.prims.size(), turned.tree.depth());
    NullObserver obs;
    size_t failures = 0, inLightZones = 0;
    for (const LzShadowRay& sr : lzShadowRays(turned, irr, 3)) {
        Hit want, got;
        const bool blocked = test::bruteHit(turned, sr.ray, want) && want.t <= sr.tmax;
        double u, v;
        const ProjectiveZones& lz = irr.lights()[sr.light];
        inLightZones += lz.coversFromCentre(lz.frame().ray(sr.ray), u, v);
        ctx.beginRay();
        const bool found = irr.intersectTowardLight(sr.ray, sr.light, 0.0, sr.tmax, ctx, obs, got);
        ctx.beginRay();
        failures += found != blocked || (found && got.prim != want.prim) ||
                    lent->occluded(sr.ray, sr.tmax, sr.light, ctx, obs) != blocked;
    }
    EXPECT_GT(inLightZones, 0u);
    EXPECT_EQ(failures, 0u);
    test::expectSamePixelsAndSecondaries(turned, *lent, 24, 11, "lent lights' structures");
}

TEST(LightZones, BudgetLeftByTheEyeSkipsThemCounted) {
    Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/gears1.nff");
    auto unbounded = lzBuild(s, false);
    ASSERT_GT(unbounded->info().extra["light_bytes"].get<size_t>(), 0u);
    // Shrinking budgets: the lights' structures share what the camera frame and the eye's zones
    // leave; each build keeps within its budget, every light is built or counted as skipped,
    // and the answers stay brute force's.
    auto brute = buildAccelerator(s, BuildParams{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    size_t skipped = 0, failures = 0;
    double budget = double(unbounded->info().memoryBytes);
    for (int k = 0; k < 16; ++k) {
        budget *= 0.8;
        std::unique_ptr<Accelerator> bounded;
        try {
            bounded = lzBuild(s, false, size_t(budget));
        } catch (const std::invalid_argument&) {
            break;  // below what the camera frame needs at its coarsest
        }
        const nlohmann::json& x = bounded->info().extra;
        EXPECT_LE(bounded->info().memoryBytes, size_t(budget));
        const size_t over = x["lights_over_budget"].get<size_t>();
        EXPECT_EQ(over + x["light_structures"].get<size_t>(), s.lights.size());
        if (over == 0 || skipped > 0) continue;
        skipped = over;
        for (const LzShadowRay& sr : lzShadowRays(s, lzIrregular(*bounded), 5)) {
            Hit h;
            ctx.beginRay();
            const bool want = brute->intersect(sr.ray, 0.0, sr.tmax, ctx, obs, h);
            ctx.beginRay();
            failures += bounded->occluded(sr.ray, sr.tmax, sr.light, ctx, obs) != want;
        }
    }
    EXPECT_GT(skipped, 0u);
    EXPECT_EQ(failures, 0u);
}

}  // namespace
}  // namespace lancer
