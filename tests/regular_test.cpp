// The regular subdivision (report, section 3) against brute force, ray for ray: SPD and built-in
// scenes pixel by pixel, random CSG scenes with rays aimed at the grid's corners, edges and faces;
// both walks (exact and push), push's failure modes, sub-tables, mailboxes and refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include "engine/accel/build_guard.h"
#include "engine/accel/eval.h"
#include "engine/accel/regular/directory.h"
#include "engine/accel/structure_dump.h"
#include "engine/accel/structure_view.h"
#include "engine/render/renderer.h"
#include "engine/scene/builtin_scenes.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

BuildParams regular(StepMethod step = StepMethod::Exact) {
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    p.regular.step = step;
    return p;
}

const RegularGrid& gridOf(const Accelerator& a) { return std::get<RegularGrid>(a.impl()); }

/// Walk errors of `accel` over `rays` (compareWithBrute checks the hits, this the walks).
uint64_t walkErrors(const Scene& scene, const Accelerator& accel, const std::vector<Ray>& rays,
                    double tmin = 0.0) {
    return test::traceCounters(scene, accel, rays, tmin).walkErrors;
}

std::string describe(const Scene& s, const std::vector<test::RayMismatch>& m) {
    std::string out;
    for (size_t i = 0; i < std::min<size_t>(m.size(), 3); ++i) out += m[i].toString(s) + "\n";
    return out;
}

/// Points where walks go wrong: corners, edge midpoints and face centres of leaves spread over
/// the grid, plus random points of the finest grid's planes.
std::vector<Vec3> gridPoints(const RegularGrid& g, uint64_t seed, size_t leavesWanted = 150) {
    std::vector<Vec3> pts;
    const auto& leaves = g.leaves();
    size_t stride = std::max<size_t>(1, leaves.size() / leavesWanted);
    for (size_t i = 0; i < leaves.size(); i += stride) {
        const RegularLeaf& L = leaves[i];
        double c[3][3];  // per axis: lo plane, middle, hi plane
        for (int a = 0; a < 3; ++a) {
            c[a][0] = g.plane(a, L.lo[a]);
            c[a][2] = g.plane(a, L.hi[a]);
            c[a][1] = 0.5 * (c[a][0] + c[a][2]);
        }
        for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y)
                for (int z = 0; z < 3; ++z)
                    if (x != 1 || y != 1 || z != 1)
                        pts.push_back(g.frame().toWorld({c[0][x], c[1][y], c[2][z]}));
    }
    std::mt19937_64 rng(seed);
    for (int k = 0; k < 400; ++k) {
        Vec3 p;
        for (int a = 0; a < 3; ++a) p[a] = g.plane(a, uint32_t(rng() % (g.cells(a) + 1)));
        pts.push_back(g.frame().toWorld(p));
    }
    return pts;
}

/// The grid's box in the world (its frame's box when the frame is the world's).
Box3 worldBox(const RegularGrid& g) {
    Box3 b;
    for (int c = 0; c < 8; ++c) b.expand(g.frame().toWorld(boxCorner(g.box(), c)));
    return b;
}

/// Random rays plus rays through the grid's hard points, for one built scheme; in a turned
/// frame also rays along the frame's axes through them, which run along its planes.
std::vector<Ray> hardRays(const Scene& s, const RegularGrid& g, uint64_t seed, int random) {
    std::vector<Ray> rays = test::randomRays(s, seed, random);
    const std::vector<Vec3> pts = gridPoints(g, seed);
    std::vector<Ray> grid = test::raysThroughPoints(pts, worldBox(g), seed + 1);
    rays.insert(rays.end(), grid.begin(), grid.end());
    if (g.frame().turned) {
        const double far = 2.0 * glm::length(worldBox(g).extent());
        for (const Vec3& p : pts)
            for (int a = 0; a < 3; ++a)
                for (double sign : {-1.0, 1.0}) {
                    const Vec3 d = sign * g.frame().axes[a];
                    rays.push_back({p - far * d, d});
                }
    }
    return rays;
}

std::vector<std::string> spdScenes() {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(LANCER_SPD_DIR))
        if (e.path().extension() == ".nff") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    return files;
}

void expectPixelsMatch(const std::string& spec, int size, StepMethod step) {
    Scene s = loadScene(spec);
    auto accel = buildAccelerator(s, regular(step));
    auto rays = test::pixelRays(s, size, size);
    auto bad = test::compareWithBrute(s, *accel, rays);
    EXPECT_TRUE(bad.empty()) << spec << ": " << bad.size() << " pixels differ\n"
                             << describe(s, bad);
    EXPECT_EQ(walkErrors(s, *accel, rays), 0u) << spec;
}

/// Runs `check` on every SPD scene the NFF reader loads; a scene it rejects is reported (the
/// reader is tested elsewhere), but the balls scenes must load.
template <class F>
void forEachSpd(F check) {
    int loaded = 0;
    for (const std::string& f : spdScenes()) {
        try {
            loadScene(f);
        } catch (const SceneError& e) {
            std::printf("note: not tested, the reader rejects it: %s\n", e.what());
            EXPECT_EQ(f.find("balls"), std::string::npos) << e.what();
            continue;
        }
        check(f);
        ++loaded;
    }
    EXPECT_GE(loaded, 4);
}

TEST(RegularExact, EverySpdScenePixelMatchesBrute) {
    forEachSpd([](const std::string& f) {
        expectPixelsMatch(f, f.find("balls4") != std::string::npos ? 32 : 48, StepMethod::Exact);
    });
}

TEST(RegularExact, BuiltinCsgScenesPixelMatchBrute) {
    for (const char* spec : {"builtin:default", "builtin:drilled:4", "builtin:lattice:4"})
        expectPixelsMatch(spec, 48, StepMethod::Exact);
}

TEST(RegularPush, DefaultDeltaPixelMatchesBrute) {
    forEachSpd([](const std::string& f) {
        if (f.find("balls4") == std::string::npos) expectPixelsMatch(f, 40, StepMethod::Push);
    });
    for (const char* spec : {"builtin:default", "builtin:drilled:4", "builtin:lattice:4"})
        expectPixelsMatch(spec, 40, StepMethod::Push);
}

/// Random CSG scenes: plain, with transforms, with surfaces, far from the origin.
std::vector<test::RandomSceneOptions> sceneVariants() {
    std::vector<test::RandomSceneOptions> v(4);
    v[0].transforms = false;
    v[1].transforms = true;
    v[2].surfaces = true;
    v[3].offset = Vec3(1e6, -1e6, 1e6);
    for (auto& o : v) o.primitives = 16;
    return v;
}

// >= 10^5 rays in all: random, from inside and outside, axis-parallel, aimed at and starting on
// cell corners, edge midpoints and face centres; also with tmin > 0 as secondary rays have.
void randomScenesMatchBrute(StepMethod step, int seeds) {
    size_t total = 0;
    for (const auto& opt : sceneVariants()) {
        for (uint64_t seed = 1; seed <= uint64_t(seeds); ++seed) {
            Scene s = test::randomCsgScene(seed * 31 + 7, opt);
            BuildParams p = regular(step);
            p.regular.maxObjects = 1 + int(seed % 3);
            p.regular.maxLevel = 9 + int(seed % 10);
            p.regular.splitAxes = seed % 2 ? SplitAxes::Cycle : SplitAxes::Cost;  // both orders
            // Both stop rules: the report's makes many thin cells, the cost rule fewer.
            p.regular.costStop = seed > uint64_t(seeds) / 2;
            auto accel = buildAccelerator(s, p);
            auto rays = hardRays(s, gridOf(*accel), seed, 2500);
            total += rays.size();
            auto bad = test::compareWithBrute(s, *accel, rays);
            ASSERT_TRUE(bad.empty())
                << s.name << " offset " << toString(opt.offset) << " level " << p.regular.maxLevel
                << " " << splitAxesName(p.regular.splitAxes) << ": " << bad.size()
                << " rays differ\n"
                << describe(s, bad);
            ASSERT_EQ(walkErrors(s, *accel, rays), 0u) << s.name;
            auto secondary = test::compareWithBrute(s, *accel, rays, 1e-3 * s.scale());
            ASSERT_TRUE(secondary.empty()) << s.name << " tmin > 0\n" << describe(s, secondary);
        }
    }
    EXPECT_GE(total, 100000u);
}

// A grid in a turned frame walks the mapped ray and tests the world one: every hit equal to
// brute force's, on random rays, rays through its cells' corners, edges and faces and rays
// along its own axes (which run along its planes), for both step methods and stop rules.
TEST(RegularFrame, RandomTurnedSubtreesRayForRay) {
    int turned = 0;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        Scene s = test::turnedBars(seed * 13 + 5, 24);
        for (StepMethod step : {StepMethod::Exact, StepMethod::Push}) {
            BuildParams p = regular(step);
            if (seed % 2) {
                p.regular.maxObjects = 1 + int(seed % 3);
                p.regular.maxLevel = 10 + int(seed % 6);
            }
            auto accel = buildAccelerator(s, p);
            const RegularGrid& g = gridOf(*accel);
            turned += g.frame().turned;
            auto rays = hardRays(s, g, seed, 2000);
            auto bad = test::compareWithBrute(s, *accel, rays);
            ASSERT_TRUE(bad.empty()) << s.name << " " << stepName(step) << ": " << bad.size()
                                     << " of " << rays.size() << " rays differ\n"
                                     << describe(s, bad);
            ASSERT_EQ(walkErrors(s, *accel, rays), 0u) << s.name;
            auto secondary = test::compareWithBrute(s, *accel, rays, 1e-3 * s.scale());
            ASSERT_TRUE(secondary.empty()) << s.name << " tmin > 0\n" << describe(s, secondary);
        }
    }
    // Bars turned off the axes: the frame is the turn's in most of them.
    EXPECT_GE(turned, 12);
}

// builtin:sponge (OpenSCAD's example024): the grid follows the sponge's frame, its axes those of
// the turn; every pixel and secondary ray hits as brute force, with a fifth of the tests per ray
// of brute force and of the same build along the world's axes (one region of 221 primitives).
TEST(RegularFrame, TurnedSpongeIsBuiltInItsOwnFrame) {
    Scene s = makeBuiltin("sponge", 3);
    auto accel = buildAccelerator(s, regular());
    const RegularGrid& g = gridOf(*accel);
    ASSERT_TRUE(g.frame().turned);
    // Every frame axis is one of the turned cube's edges.
    const Mat3 turn = Mat3(s.prims[s.tree.primitives().front()].xf.m);
    for (int a = 0; a < 3; ++a) {
        double best = 0.0;
        for (int b = 0; b < 3; ++b)
            best = std::max(best, std::abs(glm::dot(g.frame().axes[a], glm::normalize(turn[b]))));
        EXPECT_GT(best, 1.0 - 1e-9) << "axis " << a;
    }
    test::expectSamePixelsAndSecondaries(s, *accel, 96, 7, "sponge, turned frame");
    BuildParams world = regular();
    world.regular.turnedFrame = false;
    auto flat = buildAccelerator(s, world);
    EXPECT_FALSE(gridOf(*flat).frame().turned);
    const std::vector<Ray> rays = test::pixelRays(s, 96, 96);
    const RayCounters own = test::traceCounters(s, *accel, rays);
    const RayCounters axes = test::traceCounters(s, *flat, rays);
    const RayCounters brute = test::traceCounters(s, *buildAccelerator(s, {}), rays);
    EXPECT_LT(5 * own.primTests, brute.primTests)
        << own.primTests << " against " << brute.primTests;
    EXPECT_LT(5 * own.primTests, axes.primTests) << own.primTests << " against " << axes.primTests;
    // The structure's description is in the world: a leaf's corners are its frame box's.
    const StructureView view(s, *accel);
    for (uint32_t id = 0; id < view.regionCount(); id += 7) {
        const RegionInfo r = view.region(id);
        const std::array<Vec3, 8> c = view.regionCorners(id);
        const Vec3 lo = g.frame().toFrame(c[0]), hi = g.frame().toFrame(c[7]);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(lo[a], r.frameBox.lo[a], 1e-12);
            EXPECT_NEAR(hi[a], r.frameBox.hi[a], 1e-12);
        }
        EXPECT_EQ(view.regionAt(0.5 * (c[0] + c[7])), id);
    }
    // `lancer structure` names the frame: its axes, as the grid holds them.
    std::ostringstream dump;
    writeStructureJson(view, {.width = 64, .height = 64}, dump);
    const nlohmann::json j = nlohmann::json::parse(dump.str());
    ASSERT_TRUE(j["regular"].contains("axes"));
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            EXPECT_DOUBLE_EQ(j["regular"]["axes"][a][k].get<double>(), g.frame().axes[a][k]);
    std::ostringstream flatDump;
    writeStructureJson(StructureView(s, *flat), {.width = 64, .height = 64}, flatDump);
    EXPECT_FALSE(nlohmann::json::parse(flatDump.str())["regular"].contains("axes"));
}

// A primitive flattened by a scale of 1e-300 beside turned bars: every box of the frame is
// finite (or empty), and every hit is brute force's.
TEST(RegularFrame, NearlySingularTransformKeepsFiniteBoxes) {
    Scene s = test::turnedBars(5, 16, 40.0);
    const Primitive& p0 = s.prims[0];
    s.prims[0] = makePrimitive(p0.shape, p0.xf * Transform::scale({1e-300, 1.0, 1.0}), 0);
    s.prepare();
    auto accel = buildAccelerator(s, regular());
    const RegularGrid& g = gridOf(*accel);
    for (const Box3& b : g.boxes()) {
        if (b.isEmpty()) continue;
        for (int a = 0; a < 3; ++a)
            EXPECT_TRUE(std::isfinite(b.lo[a]) && std::isfinite(b.hi[a])) << b.toString();
    }
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(std::isfinite(g.box().lo[a] + g.box().hi[a]));
    test::expectSame(s, *accel, hardRays(s, g, 5, 2000), "flattened primitive");
}

// Scenes with no turned primitive, and a turn too small to pay, keep the world's axes.
TEST(RegularFrame, WorldAxesKeptWhereNoTurnPays) {
    for (const char* name : {"default", "lattice", "drilled"}) {
        Scene s = makeBuiltin(name, -1);
        auto accel = buildAccelerator(s, regular());
        EXPECT_FALSE(gridOf(*accel).frame().turned) << name;
    }
    // Bars turned by two degrees: their boxes grow by a third, short of what a frame needs.
    Scene s = test::turnedBars(3, 16, 2.0);
    EXPECT_FALSE(gridOf(*buildAccelerator(s, regular())).frame().turned);
    EXPECT_TRUE(gridOf(*buildAccelerator(test::turnedBars(3, 16, 40.0), regular())).frame().turned);
}

TEST(RegularExact, RandomCsgScenesRayForRay) { randomScenesMatchBrute(StepMethod::Exact, 6); }
TEST(RegularPush, RandomCsgScenesRayForRayAtDefaultDelta) {
    randomScenesMatchBrute(StepMethod::Push, 6);
}

// A union-only scene's leaves are evaluated by merging their primitives' spans (flatUnion), not
// by walking their trees: the same spans as the tree of unions, the same hits as brute force.
TEST(RegularUnion, FlatUnionIsTheTreeOfUnions) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    for (int trial = 0; trial < 3000; ++trial) {
        const int n = 1 + int(rng() % 24);
        SpanList tree, flat, next;
        for (int p = 0; p < n; ++p) {
            // A primitive's spans: sorted and disjoint, a surface's of zero length.
            const int count = int(rng() % 3);
            std::vector<double> t(size_t(2 * count));
            for (double& x : t) x = u(rng);
            std::sort(t.begin(), t.end());
            SpanList spans;
            for (int k = 0; k < count; ++k) {
                const bool surface = rng() % 5 == 0;
                const double out = surface ? t[size_t(2 * k)] : t[size_t(2 * k + 1)];
                spans.push_back(
                    {{t[size_t(2 * k)], uint32_t(p), 0, false}, {out, uint32_t(p), 1, false}});
            }
            spanUnion(tree, spans, next);
            tree.swap(next);
            flat.insert(flat.end(), spans.begin(), spans.end());
        }
        SpanList merged;
        flatUnion(flat, merged);
        ASSERT_EQ(merged, tree) << "trial " << trial << ": " << toString(merged) << " against "
                                << toString(tree);
    }
}

// hitInUnionLeaf (the walk's leaf of a union-only scene, without an active observer) against
// the merge it stands for: random primitives' spans in a region, random windows [t0, t1] and
// tmin (starting before, inside and after spans, on their ends), the same hit (t, primitive,
// part) as flatUnion then firstBoundary, or none; each primitive tested once, then taken from
// its mailbox.
TEST(RegularUnion, UnionLeafIsFlatUnion) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    struct Table {
        const std::vector<SpanList>* spans;
        uint32_t prim(uint32_t k) const { return k; }
        void prefetch(uint32_t) const {}
        int operator()(uint32_t k, Span* out) const {
            std::copy((*spans)[k].begin(), (*spans)[k].end(), out);
            return int((*spans)[k].size());
        }
    };
    size_t hits = 0, inside = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const int n = 1 + int(rng() % 12);
        std::vector<SpanList> spans(static_cast<size_t>(n));
        std::vector<double> ends;
        for (int p = 0; p < n; ++p) {
            const int count = int(rng() % 3);
            std::vector<double> t(size_t(2 * count));
            for (double& x : t) x = rng() % 4 == 0 ? double(int(u(rng))) : u(rng);  // ties
            std::sort(t.begin(), t.end());
            for (int k = 0; k < count; ++k) {
                const bool surface = rng() % 5 == 0;
                const double in = t[size_t(2 * k)], out = surface ? in : t[size_t(2 * k + 1)];
                if (k > 0 && !(in > spans[size_t(p)].back().out.t)) continue;  // disjoint
                spans[size_t(p)].push_back(
                    {{in, uint32_t(p), 0, false}, {out, uint32_t(p), 1, false}});
                ends.push_back(in);
                ends.push_back(out);
            }
        }
        auto pick = [&] {
            return !ends.empty() && rng() % 3 == 0 ? ends[rng() % ends.size()] : u(rng);
        };
        double t0 = pick(), t1 = pick(), tmin = rng() % 2 ? pick() : -kInf;
        if (t0 > t1) std::swap(t0, t1);
        SpanList merged;
        std::vector<uint32_t> keys(static_cast<size_t>(n));
        for (int p = 0; p < n; ++p) keys[size_t(p)] = uint32_t(p);
        std::shuffle(keys.begin(), keys.end(), rng);  // the leaf's order is any
        // The tie rule is the leaf's order: flatUnion's stable sort over the spans listed so.
        SpanList listed;
        for (uint32_t k : keys) listed.insert(listed.end(), spans[k].begin(), spans[k].end());
        flatUnion(listed, merged);
        const Boundary* want = firstBoundary(merged, tmin, t0, t1);
        TraceContext ctx(size_t(n), 1);
        ctx.beginRay();
        NullObserver obs;
        Hit hit;
        const Table table{&spans};
        const bool got =
            hitInUnionLeaf(keys.data(), uint32_t(n), table, tmin, t0, t1, ctx, obs, hit);
        ASSERT_EQ(got, want != nullptr) << "trial " << trial;
        if (want) {
            ASSERT_EQ(hit.t, want->t) << "trial " << trial;
            ASSERT_EQ(hit.prim, want->prim) << "trial " << trial;
            ASSERT_EQ(hit.part, want->part) << "trial " << trial;
            ++hits;
        }
        for (const Span& sp : merged) inside += sp.in.t < t0 && sp.out.t > t1;
        ASSERT_EQ(ctx.counters.primTests, uint64_t(n));
        ASSERT_EQ(ctx.counters.mailboxHits, 0u);
        // The same region again for the same ray: every primitive from its mailbox.
        Hit again;
        ASSERT_EQ(hitInUnionLeaf(keys.data(), uint32_t(n), table, tmin, t0, t1, ctx, obs, again),
                  got);
        if (got) {
            ASSERT_EQ(again.t, hit.t);
        }
        ASSERT_EQ(ctx.counters.primTests, uint64_t(n));
        ASSERT_EQ(ctx.counters.mailboxHits, uint64_t(n));
    }
    EXPECT_GT(hits, 5000u);
    EXPECT_GT(inside, 500u);  // windows inside a merged span: the merge's way
}

// A sphereflake on a floor rendered with shadows and mirror bounces (shadow rays on the light
// buffer's stretches, reflected rays from surfaces): the regular scheme's image, pixel for pixel,
// is brute force's, and its walk makes the same tests, mailbox hits and visits as the walk seen
// by an observer (which evaluates every leaf's tree of unions).
TEST(RegularUnion, SphereflakeRenderEqualsBruteForce) {
    Scene s = loadScene("builtin:balls:3");
    s.prepare();
    ASSERT_TRUE(s.tree.unionOnly());
    auto accel = buildAccelerator(s, regular());
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto brute = buildAccelerator(s, bp);
    for (int bounces : {0, 2}) {
        RenderOptions ro;
        ro.width = ro.height = 96;
        ro.threads = 1;
        ro.shading.bounces = bounces;
        Image a(ro.width, ro.height), b(ro.width, ro.height);
        const RenderStats sa = render(s, *accel, ro, a);
        render(s, *brute, ro, b);
        ASSERT_GT(sa.counters.shadowRays, 0u);
        for (size_t i = 0; i < a.color.size(); ++i) {
            ASSERT_EQ(a.hitPrim[i], b.hitPrim[i]) << "pixel " << i << ", bounces " << bounces;
            ASSERT_EQ(a.color[i], b.color[i]) << "pixel " << i << ", bounces " << bounces;
        }
    }
    auto rays = test::pixelRays(s, 48, 48);
    const RayCounters fast = test::traceCounters(s, *accel, rays);
    TraceContext ctx(s.prims.size(), s.tree.depth());
    for (const Ray& r : rays) test::recordWalk(*accel, r, ctx);
    EXPECT_EQ(fast.primTests, ctx.counters.primTests);
    EXPECT_EQ(fast.mailboxHits, ctx.counters.mailboxHits);
    EXPECT_EQ(fast.regionVisits, ctx.counters.regionVisits);
    EXPECT_GT(fast.primTests, rays.size());
}

/// A union of spheres of sizes 1 to 1/1000 of the scene, far from the origin, with exact
/// duplicates (ties between spheres sharing their boundary) and spheres touching, over a floor
/// polygon (a primitive the sphere quads cannot reject); and rays that graze spheres (at the
/// radius, a hair inside and outside it), start inside them, or are aimed at their centres.
struct QuadScene {
    Scene scene;
    std::vector<Ray> rays;
};

QuadScene quadScene(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    QuadScene q;
    Scene& s = q.scene;
    const Vec3 offset(1e4, -3e3, 2e3);
    std::vector<int> leaves;
    std::vector<Sphere> spheres;
    for (int i = 0; i < 400; ++i) {
        Sphere sp;
        sp.r = 10.0 * std::pow(1e-3, u(rng));
        sp.c = offset + Vec3(u(rng), u(rng), u(rng)) * 100.0;
        if (i % 10 == 1) sp = spheres.back();  // a duplicate: the same spans
        if (i % 10 == 2) {                     // touching the previous one
            const Sphere& o = spheres.back();
            const Vec3 dir = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
            sp.c = o.c + dir * (o.r + sp.r);
        }
        spheres.push_back(sp);
        s.prims.push_back(makePrimitive(sp, Transform{}));
        leaves.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
    }
    Polygon floor;
    makePolygon({offset + Vec3(-10, -10, -1), offset + Vec3(110, -10, -1),
                 offset + Vec3(110, 110, -1), offset + Vec3(-10, 110, -1)},
                floor);
    s.prims.push_back(makePrimitive(floor, Transform{}));
    leaves.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
    s.tree.root = s.tree.balanced(Op::Union, leaves);
    s.prepare();
    const auto unit = [&] {
        return glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) + 1e-9);
    };
    for (size_t i = 0; i < spheres.size(); ++i) {
        const Sphere& sp = spheres[i];
        const Vec3 d = unit();
        // Perpendicular to d: the line passes at distance `at` from the centre.
        const Vec3 side = glm::normalize(glm::cross(d, unit()));
        for (double at : {0.0, 1.0, 1.0 - 1e-12, 1.0 + 1e-12, 1.0 - 1e-7, 1.0 + 1e-7}) {
            const Vec3 p = sp.c + side * (at * sp.r);
            q.rays.push_back({p - d * 300.0, d});                      // from outside the scene
            q.rays.push_back({p - d * (0.5 * sp.r), d * 1e-3});        // near it, a short d
            q.rays.push_back({sp.c + unit() * (0.5 * sp.r), unit()});  // from inside it
        }
    }
    std::vector<Ray> random = test::randomRays(s, seed, 3000);
    q.rays.insert(q.rays.end(), random.begin(), random.end());
    return q;
}

// The quads' first look at a leaf's spheres (RegularGrid::quadMisses) rejects only spheres
// whose exact test finds no span, at every point of the ray the walk may take it from (near
// each leaf), and rejects most of a leaf's spheres that the ray misses.
TEST(RegularUnion, SphereQuadsRejectOnlyMisses) {
    size_t rejected = 0, missed = 0, grazing = 0;
    for (uint64_t seed : {3u, 4u}) {
        QuadScene q = quadScene(seed);
        const Scene& s = q.scene;
        auto accel = buildAccelerator(s, regular());
        const RegularGrid& g = gridOf(*accel);
        ASSERT_FALSE(g.sphereQuads().empty());
        const std::vector<uint32_t>& list = g.primList();
        for (const Ray& ray : q.rays) {
            RegularGrid::QuadRay qr = g.quadRay(ray);
            double tA, tB;
            if (!clipLine(ray, g.box(), tA, tB)) continue;
            for (double f : {0.0, 0.3, 1.0}) {
                qr.at(ray.at(tA + f * (tB - tA)));
                for (size_t k = 0; k < g.sphereQuads().size(); ++k) {
                    const uint32_t misses = RegularGrid::quadMisses(g.sphereQuads()[k], qr);
                    for (size_t j = 0; j < 4 && 4 * k + j < list.size(); ++j) {
                        Span spans[2];
                        const uint32_t p = list[4 * k + j];
                        const int n = s.primSpans(p, ray, spans, Precision::Double);
                        if (misses >> j & 1) {
                            ASSERT_EQ(n, 0) << "sphere " << p << " rejected, but the ray "
                                            << ray.toString() << " meets it";
                            ++rejected;
                        } else if (n > 0 && (spans[0].out.t - spans[0].in.t) * glm::length(ray.d) <
                                                2e-3 * s.packedSpheres[p].r) {
                            ++grazing;  // kept, as it must be: the ray barely meets it
                        }
                        missed += n == 0;
                    }
                }
            }
        }
    }
    EXPECT_GT(rejected, missed * 9 / 10) << "the quads should reject most missed spheres";
    EXPECT_GT(grazing, 100u);
}

// The walk with the sphere quads (no active observer) against the walk an observer sees (the
// same walk, told to the observer) and against brute force: the same hits, and the same tests (a
// sphere the quads reject is a test each time a leaf lists it), mailbox hits and leaf visits, on
// rays that graze spheres, start inside them, start at tmin > 0, and on the floor the quads
// cannot reject. Without the mailboxes too.
TEST(RegularUnion, SphereQuadWalkEqualsObservedWalkAndBruteForce) {
    for (uint64_t seed : {5u, 6u}) {
        QuadScene q = quadScene(seed);
        const Scene& s = q.scene;
        for (bool mailboxes : {true, false}) {
            BuildParams p = regular();
            p.mailboxes = mailboxes;
            auto accel = buildAccelerator(s, p);
            ASSERT_FALSE(gridOf(*accel).sphereQuads().empty());
            auto bad = test::compareWithBrute(s, *accel, q.rays);
            ASSERT_TRUE(bad.empty()) << bad.size() << " rays differ\n" << describe(s, bad);
            auto later = test::compareWithBrute(s, *accel, q.rays, 1e-4 * s.scale());
            ASSERT_TRUE(later.empty()) << "tmin > 0\n" << describe(s, later);
            const RayCounters fast = test::traceCounters(s, *accel, q.rays);
            TraceContext ctx(s.prims.size(), s.tree.depth());
            ctx.useMailboxes = accel->usesMailboxes();
            for (const Ray& r : q.rays) test::recordWalk(*accel, r, ctx);
            EXPECT_EQ(fast.primTests, ctx.counters.primTests);
            EXPECT_EQ(fast.mailboxHits, ctx.counters.mailboxHits);
            EXPECT_EQ(fast.regionVisits, ctx.counters.regionVisits);
            EXPECT_GT(fast.primTests, 2 * q.rays.size());
            if (mailboxes) {
                EXPECT_GT(fast.mailboxHits, 0u);
            }
        }
    }
}

TEST(RegularUnion, UnionOnlyScenesRayForRay) {
    size_t total = 0;
    for (uint64_t seed = 1; seed <= 6; ++seed) {
        // Random solids, densely overlapping, under one union.
        test::RandomSceneOptions opt;
        opt.primitives = 24;
        opt.spread = 2.0;
        opt.surfaces = seed % 2 == 0;
        Scene s = test::randomCsgScene(seed * 13 + 5, opt);
        std::vector<int> leaves;
        CsgTree t;
        for (uint32_t p = 0; p < s.prims.size(); ++p) leaves.push_back(t.leaf(p));
        t.root = t.balanced(Op::Union, leaves);
        s.tree = std::move(t);
        s.prepare();
        BuildParams p = regular();
        p.regular.maxObjects = 1 + int(seed % 3);
        p.regular.costStop = seed > 3;
        auto accel = buildAccelerator(s, p);
        auto rays = hardRays(s, gridOf(*accel), seed, 2500);
        total += rays.size();
        auto bad = test::compareWithBrute(s, *accel, rays);
        ASSERT_TRUE(bad.empty()) << s.name << ": " << bad.size() << " rays differ\n"
                                 << describe(s, bad);
        auto secondary = test::compareWithBrute(s, *accel, rays, 1e-3 * s.scale());
        ASSERT_TRUE(secondary.empty()) << s.name << " tmin > 0\n" << describe(s, secondary);
    }
    EXPECT_GE(total, 20000u);
}

// The report's push has an error: a delta larger than a thin cell jumps over it (wrong hits);
// a delta below the coordinates' rounding does not leave the cell (stalls, counted errors).
// Exact stepping is right on the same rays.
TEST(RegularPush, WrongForDeltaTooLargeOrTooSmallWhereExactIsRight) {
    size_t skipped = 0, stalledOrWrong = 0;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 20;
        Scene s = test::randomCsgScene(seed * 11, opt);
        BuildParams p = regular(StepMethod::Exact);
        p.regular.maxLevel = 18;  // cells 1/64 of the box
        p.regular.maxObjects = 1;
        p.regular.costStop = false;  // the report's rule: thin cells, where push goes wrong
        auto exact = buildAccelerator(s, p);
        auto rays = hardRays(s, gridOf(*exact), seed, 3000);
        ASSERT_TRUE(test::compareWithBrute(s, *exact, rays).empty());
        ASSERT_EQ(walkErrors(s, *exact, rays), 0u);

        p.regular.step = StepMethod::Push;
        p.regular.delta = 0.05;  // wider than the finest cells
        auto large = buildAccelerator(s, p);
        skipped += test::compareWithBrute(s, *large, rays, 0.0, 1e-9, SIZE_MAX).size();

        p.regular.delta = 1e-19;  // below the rounding of the coordinates
        auto tiny = buildAccelerator(s, p);
        stalledOrWrong += walkErrors(s, *tiny, rays) +
                          test::compareWithBrute(s, *tiny, rays, 0.0, 1e-9, SIZE_MAX).size();
    }
    std::printf(
        "push, delta 0.05: %zu wrong hits; delta 1e-19: %zu walk errors + wrong hits "
        "(exact: none)\n",
        skipped, stalledOrWrong);
    EXPECT_GT(skipped, 0u) << "a push larger than the cells should skip some";
    EXPECT_GT(stalledOrWrong, 0u) << "a push below rounding should stall";
}

TEST(RegularWalk, RegionsAreContiguousAndInRayOrder) {
    Scene s = test::randomCsgScene(5);
    auto accel = buildAccelerator(s, regular());
    const RegularGrid& g = gridOf(*accel);
    TraceContext ctx(s.prims.size(), s.tree.depth());
    int walks = 0;
    for (const Ray& r : test::randomRays(s, 3, 400)) {
        RecordingObserver obs = test::recordWalk(*accel, r, ctx);
        double prev = -kInf;
        bool first = true;
        for (const WalkEvent& e : obs.events) {
            const walk::Region* w = e.get<walk::Region>();
            if (!w) continue;
            ASSERT_LT(w->region, g.regionCount());
            ASSERT_LE(w->t0, w->t1);
            if (!first) {
                ASSERT_EQ(w->t0, prev) << r.toString();
            }
            // The cell contains the ray's points of its interval (up to rounding).
            const RegularLeaf& L = g.leaves()[w->region];
            Vec3 mid = r.at(0.5 * (w->t0 + w->t1));
            for (int a = 0; a < 3; ++a) {
                double slack = 1e-9 * g.box().extent()[a];
                ASSERT_GE(mid[a], g.plane(a, L.lo[a]) - slack)
                    << r.toString() << g.describeLeaf(w->region);
                ASSERT_LE(mid[a], g.plane(a, L.hi[a]) + slack)
                    << r.toString() << g.describeLeaf(w->region);
            }
            prev = w->t1;
            first = false;
        }
        walks += !first;
    }
    EXPECT_GT(walks, 100);
    EXPECT_NE(g.describeLeaf(0).find("leaf 0 cells ["), std::string::npos) << g.describeLeaf(0);
}

TEST(RegularMailbox, SameHitsFewerTestsThanWithout) {
    Scene s = loadScene("builtin:lattice:4");
    BuildParams with = regular(), without = regular();
    without.mailboxes = false;
    auto a = buildAccelerator(s, with), b = buildAccelerator(s, without);
    EXPECT_TRUE(a->usesMailboxes());
    EXPECT_FALSE(b->usesMailboxes());
    auto rays = test::pixelRays(s, 40, 40);
    EXPECT_TRUE(test::compareWithBrute(s, *b, rays).empty());
    RayCounters ca = test::traceCounters(s, *a, rays), cb = test::traceCounters(s, *b, rays);
    EXPECT_GT(ca.mailboxHits, 0u);
    EXPECT_EQ(cb.mailboxHits, 0u);
    EXPECT_LT(ca.primTests, cb.primTests);
    EXPECT_EQ(ca.primTests + ca.mailboxHits, cb.primTests);  // every saved test is a mailbox hit
}

// Shadow, reflection and refraction rays go through the subdivision: whole renders with bounces
// give the same image as brute force.
TEST(RegularRender, ImageWithBouncesEqualsBrute) {
    Scene s = loadScene("builtin:default");
    RenderOptions opt;
    opt.width = opt.height = 40;
    opt.threads = 2;
    opt.shading.bounces = 4;
    BuildParams bp;
    auto brute = buildAccelerator(s, bp);
    auto reg = buildAccelerator(s, regular());
    Image ib(40, 40), ir(40, 40);
    RenderStats sb = render(s, *brute, opt, ib);
    RenderStats sr = render(s, *reg, opt, ir);
    EXPECT_EQ(sb.counters.rays, sr.counters.rays);
    EXPECT_GT(sr.counters.rays, sr.counters.primaryRays);
    EXPECT_EQ(sr.counters.walkErrors, 0u);
    EXPECT_EQ(ib.hitPrim, ir.hitPrim);
    for (size_t i = 0; i < ib.color.size(); ++i)
        ASSERT_EQ(ib.color[i], ir.color[i]) << "pixel " << i;
}

// Sub-tables name the same leaf as the full table for every point, in less memory.
TEST(RegularSubTables, SameLeafAsFullTableInLessMemory) {
    // Scenes whose subdivision is deep in places and shallow elsewhere (in a uniformly deep
    // one, such as drilled:4 at max-objects 1, sub-tables cost about as much as the full table).
    for (std::string spec :
         {std::string(LANCER_SPD_DIR) + "/balls2.nff", std::string("builtin:default")}) {
        Scene s = loadScene(spec);
        BuildParams pf = regular();
        pf.regular.maxLevel = 18;  // deeper than the top table, so sub-tables appear
        pf.regular.maxObjects = 1;
        pf.regular.costStop = false;  // the report's rule: deep where boxes meet
        BuildParams ps = pf;
        pf.regular.fullTable = true;
        auto full = buildAccelerator(s, pf), sub = buildAccelerator(s, ps);
        const RegularGrid &gf = gridOf(*full), &gs = gridOf(*sub);
        ASSERT_EQ(gf.regionCount(), gs.regionCount());
        EXPECT_EQ(full->info().extra["directory"], "full");
        EXPECT_EQ(sub->info().extra["directory"], "sub-tables");
        EXPECT_EQ(size_t(sub->info().extra["full_table_bytes"]), gf.directory().memoryBytes());
        EXPECT_LT(gs.directory().memoryBytes(), gf.directory().memoryBytes()) << spec;
        EXPECT_LT(sub->info().memoryBytes, full->info().memoryBytes) << spec;
        // Every finest cell when the grid is small, else a dense random sample.
        uint64_t cells = uint64_t(gf.cells(0)) * gf.cells(1) * gf.cells(2);
        std::mt19937_64 rng(1);
        uint64_t samples = std::min<uint64_t>(cells, 1u << 20);
        for (uint64_t n = 0; n < samples; ++n) {
            uint64_t c = cells == samples ? n : rng() % cells;
            uint32_t i = uint32_t(c % gf.cells(0)), j = uint32_t(c / gf.cells(0) % gf.cells(1)),
                     k = uint32_t(c / gf.cells(0) / gf.cells(1));
            uint32_t leaf = gf.directory().lookup(i, j, k);
            ASSERT_EQ(leaf, gs.directory().lookup(i, j, k))
                << spec << " cell " << i << " " << j << " " << k;
            const RegularLeaf& L = gf.leaves()[leaf];
            ASSERT_TRUE(L.lo[0] <= i && i < L.hi[0] && L.lo[1] <= j && j < L.hi[1] &&
                        L.lo[2] <= k && k < L.hi[2]);
        }
    }
}

// The directory's fill polls the build's guard: a cancelled build stops there too (a full table
// of 2^18 entries for one leaf is written by that leaf alone).
TEST(RegularDirectory, FillStopsWhenTheBuildIsCancelled) {
    BspNodes bsp;
    bsp.nodes.resize(1);
    std::stop_source stop;
    stop.request_stop();
    const BuildGuard cancelled(0, {stop.get_token(), {}});
    Directory d;
    EXPECT_THROW(d.build(bsp, AxisSchedule(), 18, true, &cancelled), BuildCancelled);
    const BuildGuard running;
    d.build(bsp, AxisSchedule(), 18, true, &running);
    EXPECT_EQ(d.entryCount(), size_t(1) << 18);
    EXPECT_EQ(d.lookup(5, 17, 63), 0u);
}

// A rope is a cached directory lookup: for every face of every leaf, each finest cell just
// across it lies in the rope's leaf; a face marked split really has several leaves across it.
TEST(RegularRopes, EveryRopeIsTheLeafTheDirectoryGivesAcrossTheFace) {
    for (std::string spec : {std::string(LANCER_SPD_DIR) + "/balls2.nff",
                             std::string("builtin:drilled:3"), std::string("builtin:default")}) {
        Scene s = loadScene(spec);
        BuildParams p = regular();
        p.regular.maxLevel = 15;
        p.regular.maxObjects = 1;
        p.regular.costStop = false;  // the report's rule: leaves of many sizes, split faces
        auto accel = buildAccelerator(s, p);
        const RegularGrid& g = gridOf(*accel);
        size_t roped = 0, split = 0, border = 0;
        for (uint32_t id = 0; id < g.regionCount(); ++id) {
            const RegularLeaf& L = g.leaves()[id];
            for (int a = 0; a < 3; ++a)
                for (int side = 0; side < 2; ++side) {
                    const uint32_t rope = L.rope[2 * a + side];
                    if (side ? L.hi[a] == g.cells(a) : L.lo[a] == 0) {
                        ASSERT_EQ(rope, kBorder) << spec << " leaf " << id;
                        ++border;
                        continue;
                    }
                    const int b = (a + 1) % 3, c = (a + 2) % 3;
                    std::set<uint32_t> across;
                    for (uint32_t i = L.lo[b]; i < L.hi[b]; ++i)
                        for (uint32_t j = L.lo[c]; j < L.hi[c]; ++j) {
                            uint32_t cell[3];
                            cell[a] = side ? L.hi[a] : L.lo[a] - 1;
                            cell[b] = i;
                            cell[c] = j;
                            across.insert(g.directory().lookup(cell[0], cell[1], cell[2]));
                        }
                    if (rope == kSplitFace) {
                        EXPECT_GT(across.size(), 1u) << spec << " leaf " << id;
                        ++split;
                    } else {
                        ASSERT_EQ(across, std::set<uint32_t>{rope}) << spec << " leaf " << id;
                        ++roped;
                    }
                }
        }
        EXPECT_GT(roped, 0u) << spec;
        EXPECT_GT(split, 0u) << spec;
        EXPECT_GT(border, 0u) << spec;
    }
}

// A BSP deep in one spot only: the full table (2^level entries) would not fit, sub-tables do,
// and the walk is still exact.
TEST(RegularSubTables, DeepLevelBuiltWhereTheFullTableWouldNotFit) {
    Scene s;
    s.prims.push_back(makePrimitive(Sphere{{0, 0, 0}, 1.0}, Transform()));
    s.prims.push_back(makePrimitive(Sphere{{2.0 + 1e-7, 0, 0}, 1.0}, Transform()));  // near touch
    s.prims.push_back(makePrimitive(Sphere{{100, 100, 100}, 1.0}, Transform()));
    std::vector<int> leaves{s.tree.leaf(0), s.tree.leaf(1), s.tree.leaf(2)};
    s.tree.root = s.tree.balanced(Op::Union, leaves);
    s.prepare();
    s.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
    BuildParams p = regular();
    p.regular.maxLevel = 40;
    p.regular.maxObjects = 1;
    p.regular.costStop = false;  // the report's rule splits the gap down to level 40
    auto accel = buildAccelerator(s, p);
    const RegularGrid& g = gridOf(*accel);
    int finest = accel->info().extra["finest_level"];
    EXPECT_GE(finest, 36);
    EXPECT_GT(double(std::ldexp(4.0, finest)), double(defaultMemoryBudget()));
    // The cells along the near-touching pair's gap: tens of thousands of leaves, a few MiB.
    EXPECT_LT(accel->info().memoryBytes, size_t(16) << 20);
    p.regular.fullTable = true;
    EXPECT_THROW(buildAccelerator(s, p), std::invalid_argument);
    // Rays at the near-touching pair and through its grid points.
    std::vector<Ray> rays = test::raysThroughPoints(gridPoints(g, 3, 400), g.box(), 9);
    for (int k = 0; k < 2000; ++k) {
        double y = (k % 100 - 50) * 2e-3, z = (k / 100 - 10) * 5e-2;
        rays.push_back({{1.0 + 5e-8, y - 5, z}, glm::normalize(Vec3(1e-9 * (k % 7), 1, 0.01))});
    }
    auto bad = test::compareWithBrute(s, *accel, rays);
    EXPECT_TRUE(bad.empty()) << describe(s, bad);
    EXPECT_EQ(walkErrors(s, *accel, rays), 0u);
}

/// Whether the sphere `c`, `r` holds the box `b` of the grid's frame, grown by `m`.
bool sphereHoldsCell(const RegularGrid& g, const RegularLeaf& L, Vec3 c, double r, double m) {
    for (int k = 0; k < 8; ++k) {
        Vec3 f;
        for (int a = 0; a < 3; ++a)
            f[a] = (k >> a) & 1 ? g.plane(a, L.hi[a]) + m : g.plane(a, L.lo[a]) - m;
        if (!(glm::length(g.frame().toWorld(f) - c) < r)) return false;
    }
    return true;
}

// A cell that a subtrahend fills (inside a cavity) or that the whole solid fills lists nothing:
// no boundary of the solid lies there. A turned block less a sphere, split fine by the report's
// rule: every leaf inside the cavity is empty, the build counts them (`solid_cells`), and every
// ray, through the leaves' corners and faces too, hits as brute force, both step methods.
TEST(RegularSolidCells, CellsInsideACavityOrTheSolidListNothing) {
    for (double turn : {0.0, 30.0}) {
        Scene s;
        const Transform xf = Transform::rotate(turn, glm::normalize(Vec3(1, 2, 3)));
        s.prims.push_back(makePrimitive(Block{Vec3(-2.0), Vec3(2.0)}, xf));
        s.prims.push_back(makePrimitive(Sphere{Vec3(0.0), 1.5}, Transform()));
        s.prims.push_back(makePrimitive(Block{{-3, -3, -3}, {3, 3, -1}}, Transform()));  // a cut
        s.tree.root = s.tree.combine(Op::Difference,
                                     s.tree.combine(Op::Difference, s.tree.leaf(0), s.tree.leaf(1)),
                                     s.tree.leaf(2));
        s.prepare();
        s.frameCamera({-1.0, 2.0, -1.5}, {0, 0, 1});
        for (StepMethod step : {StepMethod::Exact, StepMethod::Push}) {
            BuildParams p = regular(step);
            p.regular.maxLevel = 12;
            p.regular.maxObjects = 1;
            p.regular.costStop = false;
            auto accel = buildAccelerator(s, p);
            const RegularGrid& g = gridOf(*accel);
            size_t inCavity = 0;
            const double m = 1e-4 * s.scale();
            for (const RegularLeaf& L : g.leaves())
                if (sphereHoldsCell(g, L, Vec3(0.0), 1.5, m)) {
                    ++inCavity;
                    EXPECT_EQ(L.prims, 0u) << "a leaf inside the cavity lists primitives";
                }
            EXPECT_GT(inCavity, 20u) << turn;
            EXPECT_GT(accel->info().extra["solid_cells"].get<size_t>(), inCavity / 8) << turn;
            auto rays = hardRays(s, g, 7, 3000);
            const auto pixels = test::pixelRays(s, 48, 48);
            rays.insert(rays.end(), pixels.begin(), pixels.end());
            auto bad = test::compareWithBrute(s, *accel, rays);
            EXPECT_TRUE(bad.empty()) << turn << " " << stepName(step) << ": " << bad.size()
                                     << " of " << rays.size() << " rays differ\n"
                                     << describe(s, bad);
            EXPECT_EQ(walkErrors(s, *accel, rays), 0u);
            auto secondary = test::compareWithBrute(s, *accel, rays, 1e-3 * s.scale());
            EXPECT_TRUE(secondary.empty()) << turn << " tmin > 0\n" << describe(s, secondary);
        }
    }
}

TEST(RegularRefusal, AbsurdLevelAndObjectsAreRefusedWithAMessage) {
    // Overlapping boxes: with max-objects 1 every cell of the overlap splits down to max-level.
    Scene s;
    s.prims.push_back(makePrimitive(Sphere{{0, 0, 0}, 1.0}, Transform()));
    s.prims.push_back(makePrimitive(Sphere{{0.5, 0, 0}, 1.0}, Transform()));
    s.tree.root = s.tree.combine(Op::Union, s.tree.leaf(0), s.tree.leaf(1));
    s.prepare();
    BuildParams p = regular();
    p.regular.maxLevel = 48;
    p.regular.maxObjects = 1;
    p.regular.costStop = false;  // the cost rule stops these cells (RegularCost below)
    try {
        buildAccelerator(s, p);
        FAIL() << "not refused";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--max-level 48"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--max-objects 1"), std::string::npos) << e.what();
    }
    p.regular.maxLevel = 49;
    EXPECT_THROW(buildAccelerator(s, p), std::invalid_argument);
    p.regular.maxLevel = 10;
    p.regular.maxObjects = 0;
    EXPECT_THROW(buildAccelerator(s, p), std::invalid_argument);
}

TEST(RegularAxes, ScheduleCountsTheCutsOfEachAxis) {
    const AxisSchedule report;  // x, y, z in turn
    for (int level = 0; level < 48; ++level) {
        EXPECT_EQ(report.axis(level), level % 3);
        for (int a = 0; a < 3; ++a) ASSERT_EQ(report.cuts(level, a), (level - a + 2) / 3);
    }
    const AxisSchedule flat({0, 1, 0, 1, 2});
    EXPECT_EQ(flat.toString(8), "xyxyzzxy");  // then axis level % 3 from level 5
    EXPECT_EQ(flat.cuts(5, 0), 2);
    EXPECT_EQ(flat.cuts(5, 1), 2);
    EXPECT_EQ(flat.cuts(5, 2), 1);
    EXPECT_EQ(flat.cuts(8, 0), 3);
    EXPECT_EQ(flat.cuts(8, 2), 2);
    EXPECT_THROW(AxisSchedule({0, 3}), std::invalid_argument);
}

/// `n` x `n` x `layers` spheres on a lattice of spacing 1 (flat when layers < n), in a union.
Scene sphereLattice(int n, int layers) {
    Scene s;
    int root = -1;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < layers; ++k) {
                s.prims.push_back(makePrimitive(Sphere{{i + 0.5, j + 0.5, k + 0.5}, 0.3}, {}));
                int leaf = s.tree.leaf(uint32_t(s.prims.size() - 1));
                root = root < 0 ? leaf : s.tree.combine(Op::Union, root, leaf);
            }
    s.tree.root = root;
    s.prepare();
    return s;
}

TEST(RegularAxes, CostOrderIsTheReportsOnACubeAndCubicCellsOnAFlatScene) {
    BuildParams cost = regular(), cycle = regular();
    cycle.regular.splitAxes = SplitAxes::Cycle;
    cost.regular.maxObjects = cycle.regular.maxObjects = 1;
    {  // a cube of evenly spread spheres: the planner's ties give the report's order
        Scene s = sphereLattice(8, 8);
        auto a = buildAccelerator(s, cost);
        const RegularGrid& g = gridOf(*a);
        EXPECT_EQ(g.schedule().toString(12), AxisSchedule().toString(12));
        EXPECT_EQ(a->info().extra["split_axes"], "cost");
    }
    // 16 x 16 x 1 spheres: cutting x and y first keeps the cells about cubic; the report's order
    // cuts z (the short axis) every third level, and rays walk through more, flatter cells.
    Scene s = sphereLattice(16, 1);
    auto byCost = buildAccelerator(s, cost), byCycle = buildAccelerator(s, cycle);
    const RegularGrid &gc = gridOf(*byCost), &gr = gridOf(*byCycle);
    EXPECT_EQ(gc.schedule().toString(8).find('z'), std::string::npos) << gc.schedule().toString(8);
    EXPECT_EQ(byCycle->info().extra["axis_schedule"],
              gr.schedule().toString(64).substr(0, size_t(byCycle->info().extra["finest_level"])));
    EXPECT_LT(gc.cells(2), gr.cells(2)) << "fewer cuts across the flat axis";
    std::vector<Ray> rays = test::randomRays(s, 5, 4000);
    const auto pts = gridPoints(gc, 5);
    const auto more = test::raysThroughPoints(pts, s.bounds, 6);
    rays.insert(rays.end(), more.begin(), more.end());
    for (const Accelerator* a : {byCost.get(), byCycle.get()}) {
        auto bad = test::compareWithBrute(s, *a, rays);
        ASSERT_TRUE(bad.empty()) << describe(s, bad);
        EXPECT_EQ(walkErrors(s, *a, rays), 0u);
    }
    const RayCounters c = test::traceCounters(s, *byCost, rays),
                      r = test::traceCounters(s, *byCycle, rays);
    EXPECT_LT(double(c.regionVisits), 0.8 * double(r.regionVisits));
    EXPECT_LE(c.primTests, r.primTests);
}

/// Spheres of radius `r` at `n` random centres in the unit cube, in a union.
Scene randomSpheres(int n, double r, uint64_t seed) {
    Scene s;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int root = -1;
    for (int i = 0; i < n; ++i) {
        s.prims.push_back(makePrimitive(Sphere{{u(rng), u(rng), u(rng)}, r}, {}));
        int leaf = s.tree.leaf(uint32_t(i));
        root = root < 0 ? leaf : s.tree.combine(Op::Union, root, leaf);
    }
    s.tree.root = root;
    s.prepare();
    return s;
}

TEST(RegularCost, CellOfOverlappingPrimitivesIsNotSplitAtTheDefaults) {
    // Eight unit spheres whose centres are 0.2 apart: every half, quarter and eighth of the
    // scene box overlaps all eight boxes, though no cell lies inside all of them, so no split
    // lowers the cost. The report's rule alone (max-objects 1, or 4 with --no-cost-stop)
    // splits down to max-level.
    Scene s;
    int root = -1;
    for (int i = 0; i < 8; ++i) {
        const Vec3 c{i & 1 ? 0.1 : -0.1, i & 2 ? 0.1 : -0.1, i & 4 ? 0.1 : -0.1};
        s.prims.push_back(makePrimitive(Sphere{c, 1.0}, {}));
        int leaf = s.tree.leaf(uint32_t(i));
        root = root < 0 ? leaf : s.tree.combine(Op::Union, root, leaf);
    }
    s.tree.root = root;
    s.prepare();
    BuildParams p = regular();
    auto a = buildAccelerator(s, p);
    EXPECT_EQ(a->info().regions, 1u);
    EXPECT_EQ(int(a->info().extra["cost_leaves"]), 1);
    EXPECT_EQ(int(a->info().extra["stop_reasons"]["cost"]), 1);
    auto bad = test::compareWithBrute(s, *a, test::randomRays(s, 3, 2000));
    EXPECT_TRUE(bad.empty()) << describe(s, bad);
    // An explicit knob asks for the report's rule.
    p.regular.maxLevel = 12;
    p.regular.maxObjects = 1;
    EXPECT_GT(buildAccelerator(s, p)->info().regions, 1000u);
    p.regular.maxLevel = 30;
    EXPECT_THROW(buildAccelerator(s, p), std::invalid_argument);  // more than 4M BSP nodes
    p = regular();
    p.regular.costStop = false;
    EXPECT_GT(buildAccelerator(s, p)->info().regions, 1000u);
}

TEST(RegularCost, ManySmallSeparatedPrimitivesAreSplitDeeply) {
    // 200 spheres of radius 0.002 in a unit cube, about 0.17 apart: 3 cuts per axis (level 9)
    // separate most of them. At the defaults the cost rule splits while a cell holds more than
    // 4; the report's rule at max-objects 1 keeps splitting around the closest ones, whose cells
    // are cut 5 times per axis and more.
    Scene s = randomSpheres(200, 0.002, 11);
    BuildParams p = regular();
    auto automatic = buildAccelerator(s, p);
    const auto& xa = automatic->info().extra;
    EXPECT_EQ(int(xa["effective_max_level"]), automaticMaxLevel(200) + kGainDepth);
    EXPECT_LE(int(xa["max_prims_per_leaf"]), kAutoObjectsCount);
    p.regular.maxObjects = 1;
    auto a = buildAccelerator(s, p);
    const auto& x = a->info().extra;
    EXPECT_EQ(int(x["effective_max_level"]), automaticMaxLevel(200));
    EXPECT_GE(int(x["finest_level"]), 15);
    EXPECT_LE(int(x["max_prims_per_leaf"]), 2);
    EXPECT_LT(double(x["prims_per_leaf"]), 1.0);  // empty space cut away: more leaves than spheres
    for (const Accelerator* g : {automatic.get(), a.get()}) {
        std::vector<Ray> rays = test::randomRays(s, 4, 3000);
        const auto more = test::raysThroughPoints(gridPoints(gridOf(*g), 4), s.bounds, 5);
        rays.insert(rays.end(), more.begin(), more.end());
        auto bad = test::compareWithBrute(s, *g, rays);
        EXPECT_TRUE(bad.empty()) << describe(s, bad);
        EXPECT_EQ(walkErrors(s, *g, rays), 0u);
    }
    // An explicit max-level is a cap the build keeps.
    p.regular.maxLevel = 9;
    EXPECT_EQ(int(buildAccelerator(s, p)->info().extra["finest_level"]), 9);
    p.regular.maxObjects = kAutoObjects;
    EXPECT_EQ(int(buildAccelerator(s, p)->info().extra["finest_level"]), 9);
}

TEST(RegularCost, AutomaticMaxLevelGrowsWithThePrimitiveCount) {
    EXPECT_EQ(automaticMaxLevel(0), 16);
    EXPECT_EQ(automaticMaxLevel(1), 16);
    EXPECT_EQ(automaticMaxLevel(221), 21);     // the sponge
    EXPECT_EQ(automaticMaxLevel(7382), 24);    // balls4
    EXPECT_EQ(automaticMaxLevel(597871), 28);  // balls:6
    EXPECT_EQ(automaticMaxLevel(size_t(1) << 62), 48);
    // The automatic depth goes kGainDepth levels below the base level where the gain floor
    // lets a split through.
    RegularConfig c;
    EXPECT_EQ(effectiveMaxLevel(c, 7382), 24 + kGainDepth);
    EXPECT_EQ(gainLevel(c, 7382), 24);
    // Without the cost stop nothing bounds the depth but the cap: the base level.
    c.costStop = false;
    EXPECT_EQ(effectiveMaxLevel(c, 7382), 24);
    EXPECT_EQ(gainLevel(c, 7382), std::numeric_limits<int>::max());
    // An explicit max-level is a cap kept as it is, with no gain floor.
    c.costStop = true;
    c.maxLevel = 7;
    EXPECT_EQ(effectiveMaxLevel(c, 7382), 7);
    EXPECT_EQ(gainLevel(c, 7382), std::numeric_limits<int>::max());
}

TEST(RegularCost, GainFloorSplitsTheDenseCellsOfASphereflakeDeeper) {
    // balls:4: the sphereflake's smallest spheres, 1/81 of the largest, cluster around their
    // parents. With a uniform depth (every cell stopped at the base level) the cells holding the
    // clusters stop at the cap, many spheres each; the gain floor takes those deeper, and only
    // those: a few more leaves, fewer tests, and every hit is brute force's.
    Scene s = loadScene("builtin:balls:4");
    s.prepare();
    const size_t n = s.tree.primitives().size();
    BuildParams p = regular();
    // A lower floor than the default's 8, which lets balls:6's clusters (of 9^6 spheres) go
    // deeper but not balls:4's.
    p.regular.minGain = 2.0;
    auto floor = buildAccelerator(s, p);
    // An infinite floor stops every cell at the base level: the cost stop capped there (an
    // explicit --max-level would build by the report's rule instead).
    p.regular.minGain = std::numeric_limits<double>::infinity();
    auto uniform = buildAccelerator(s, p);
    const auto &xf = floor->info().extra, &xu = uniform->info().extra;
    EXPECT_GT(size_t(xf["gain_leaves"]), 0u);
    EXPECT_EQ(int(xu["finest_level"]), automaticMaxLevel(n));
    EXPECT_EQ(int(xf["gain_level"]), automaticMaxLevel(n));
    EXPECT_GT(int(xf["finest_level"]), automaticMaxLevel(n));
    std::vector<Ray> rays = test::pixelRays(s, 64, 64);
    const auto more = test::randomRays(s, 7, 3000);
    rays.insert(rays.end(), more.begin(), more.end());
    auto bad = test::compareWithBrute(s, *floor, rays);
    EXPECT_TRUE(bad.empty()) << describe(s, bad);
    EXPECT_EQ(walkErrors(s, *floor, rays), 0u);
    const RayCounters f = test::traceCounters(s, *floor, rays),
                      u = test::traceCounters(s, *uniform, rays);
    EXPECT_LT(f.primTests, u.primTests);
    EXPECT_LT(double(floor->info().regions), 1.05 * double(uniform->info().regions));
    EXPECT_GT(floor->info().regions, uniform->info().regions);
}

TEST(RegularBuild, LeavesHoldTheirOverlappingPrimitivesAndShareTrees) {
    Scene s = loadScene("builtin:lattice:4");
    // At the defaults the cost rule leaves 32 leaves with 32 distinct sets; the report's rule
    // alone makes many leaves with the same set, which must share one tree.
    for (bool costStop : {true, false}) {
        SCOPED_TRACE(costStop ? "cost stop" : "report's rule");
        BuildParams p = regular();
        p.regular.costStop = costStop;
        auto accel = buildAccelerator(s, p);
        const RegularGrid& g = gridOf(*accel);
        const auto& x = accel->info().extra;
        EXPECT_EQ(size_t(x["leaves"]), g.regionCount());
        if (!costStop) {
            EXPECT_LT(size_t(x["distinct_trees"]), g.regionCount());  // shared
        }
        EXPECT_LE(size_t(x["distinct_trees"]), g.regionCount());
        EXPECT_LE(int(x["finest_level"]), int(x["effective_max_level"]));
        CsgTree t = g.treePool();
        for (const RegularLeaf& L : g.leaves()) {
            Box3 cell;
            for (int a = 0; a < 3; ++a)
                cell.lo[a] = g.plane(a, L.lo[a]), cell.hi[a] = g.plane(a, L.hi[a]);
            t.root = L.root;
            std::vector<uint32_t> ps = L.root < 0 ? std::vector<uint32_t>{} : t.primitives();
            EXPECT_EQ(ps.size(), L.prims);
            for (uint32_t p : ps) ASSERT_TRUE(s.minBox[p].overlaps(cell));
        }
    }
}

/// The stop reasons of a regular build, checked to add up to its leaves.
size_t stopSum(const Accelerator& a) {
    const nlohmann::json& r = a.info().extra["stop_reasons"];
    EXPECT_EQ(r.size(), 4u);
    size_t sum = 0;
    for (const char* k : {"max_objects", "max_level", "cost", "memory"}) {
        EXPECT_TRUE(r.contains(k)) << k;
        sum += r.value(k, size_t(0));
    }
    EXPECT_EQ(sum, a.info().regions);
    EXPECT_EQ(size_t(a.info().extra["leaves"]), a.info().regions);
    return sum;
}

TEST(RegularKnobs, ExplicitMaxLevelAndMaxObjectsChangeTheStructure) {
    // builtin:default at the defaults: the cost stop splits down to max-objects (6 leaves, each
    // of 4 primitives or fewer). An explicit knob builds by the report's rule (docs/regular.md,
    // "Explicit knobs").
    Scene s = loadScene("builtin:default");
    BuildParams p = regular();
    auto automatic = buildAccelerator(s, p);
    EXPECT_EQ(automatic->info().regions, 6u);
    EXPECT_EQ(automatic->info().extra["cost_stop"], true);
    EXPECT_EQ(size_t(automatic->info().extra["stop_reasons"]["max_objects"]), 6u);
    stopSum(*automatic);
    p.regular.maxObjects = 1;
    size_t last = 0;
    for (int level : {4, 8, 12}) {
        SCOPED_TRACE("max-level " + std::to_string(level));
        p.regular.maxLevel = level;
        auto a = buildAccelerator(s, p);
        EXPECT_EQ(a->info().extra["cost_stop"], false);
        EXPECT_EQ(int(a->info().extra["finest_level"]), level);
        EXPECT_GT(a->info().regions, last);
        EXPECT_GT(size_t(a->info().extra["stop_reasons"]["max_level"]), 0u);
        last = a->info().regions;
        stopSum(*a);
        auto bad = test::compareWithBrute(s, *a, test::pixelRays(s, 24, 16));
        EXPECT_TRUE(bad.empty()) << describe(s, bad);
    }
    // Either knob alone: max-objects at the automatic depth's base level, max-level at
    // max-objects 4.
    p = regular();
    p.regular.maxObjects = 1;
    auto objects = buildAccelerator(s, p);
    EXPECT_GT(objects->info().regions, automatic->info().regions);
    EXPECT_EQ(int(objects->info().extra["effective_max_level"]), automaticMaxLevel(s.prims.size()));
    stopSum(*objects);
    p = regular();
    p.regular.maxLevel = 8;
    auto level = buildAccelerator(s, p);
    EXPECT_GT(level->info().regions, 2u);
    p.regular.maxObjects = 1;
    EXPECT_GT(buildAccelerator(s, p)->info().regions, level->info().regions);
    EXPECT_GT(size_t(level->info().extra["stop_reasons"]["max_objects"]), 0u);
    stopSum(*level);
    // auto is the default; kAutoObjectsCount is what the cells stop at.
    RegularConfig c;
    EXPECT_TRUE(c.automatic());
    EXPECT_TRUE(c.usesCostStop());
    EXPECT_EQ(c.objects(), kAutoObjectsCount);
    c.maxObjects = 4;
    EXPECT_FALSE(c.usesCostStop());
}

TEST(RegularKnobs, StopReasonsAddUpToTheLeaves) {
    // Covered cells (inside all their primitives' boxes) and the cost estimate's stops count
    // as cost; cells of at most max-objects primitives as max_objects; the cap as max_level.
    for (const char* spec : {"builtin:lattice:4", "builtin:balls:2", "builtin:drilled"}) {
        SCOPED_TRACE(spec);
        Scene s = loadScene(spec);
        for (bool costStop : {true, false}) {
            BuildParams p = regular();
            p.regular.costStop = costStop;
            auto a = buildAccelerator(s, p);
            stopSum(*a);
            const auto& x = a->info().extra;
            EXPECT_EQ(size_t(x["stop_reasons"]["cost"]),
                      size_t(x["cost_leaves"]) + size_t(x["covered_leaves"]));
            EXPECT_EQ(size_t(x["stop_reasons"]["memory"]), 0u);
        }
    }
}

}  // namespace
}  // namespace lancer
