// The BVH against brute force, ray for ray: SPD and built-in scenes pixel by pixel (perspective
// and orthographic, secondary rays from the surfaces), random CSG scenes with rays aimed at the
// nodes' corners, edges and faces, both stop rules; its structure (every leaf lists each
// primitive meeting its box, children inside their parent); the observed walk; refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "engine/accel/build_guard.h"
#include "engine/accel/structure_view.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

using test::expectSame;

/// maxObjects -1: automatic (the cost stop with kAutoBvhObjects).
BuildParams bvhParams(int maxObjects = -1, bool costStop = true, int maxLevel = 0) {
    BuildParams p;
    p.scheme = SchemeKind::Bvh;
    p.bvh.maxObjects = maxObjects;
    p.bvh.costStop = costStop;
    p.bvh.maxLevel = maxLevel;
    return p;
}

const Bvh& bvhOf(const Accelerator& a) { return std::get<Bvh>(a.impl()); }

/// Corners, edge midpoints and face centres of some nodes' boxes: where a box test rounds.
std::vector<Vec3> nodePoints(const Bvh& b, size_t count, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<Vec3> pts;
    for (size_t k = 0; k < count && !b.nodes().empty(); ++k) {
        const Box3 box = b.nodes()[rng() % b.nodes().size()].box();
        for (int i = 0; i < 27; i += 2) {
            Vec3 c;
            for (int a = 0, j = i; a < 3; ++a, j /= 3)
                c[a] = j % 3 == 0 ? box.lo[a] : (j % 3 == 1 ? box.center()[a] : box.hi[a]);
            pts.push_back(c);
        }
    }
    return pts;
}

TEST(Bvh, SpdScenesPixelForPixel) {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(LANCER_SPD_DIR))
        if (e.path().extension() == ".nff") files.push_back(e.path());
    ASSERT_GE(files.size(), 10u);
    std::sort(files.begin(), files.end());
    for (const auto& path : files) {
        Scene scene = loadScene(path.string());
        const int n = path.filename() == "balls4.nff" ? 24 : 40;
        for (int ortho = 0; ortho < 2; ++ortho) {
            if (ortho) test::makeOrthographic(scene);
            auto accel = buildAccelerator(scene, bvhParams());
            const std::string what =
                path.filename().string() + (ortho ? " orthographic" : " perspective");
            test::expectSamePixelsAndSecondaries(scene, *accel, n, 7, what);
        }
    }
}

TEST(Bvh, BuiltinCsgScenesPixelForPixel) {
    for (const char* spec : {"builtin:default", "builtin:drilled:4", "builtin:lattice:4"}) {
        Scene scene = loadScene(spec);
        for (int ortho = 0; ortho < 2; ++ortho) {
            if (ortho) test::makeOrthographic(scene);
            for (const BuildParams& p : {bvhParams(), bvhParams(1), bvhParams(4, true, 6)}) {
                auto accel = buildAccelerator(scene, p);
                const std::string what = std::string(spec) + (ortho ? " orthographic " : " ") +
                                         toString(accel->params());
                test::expectSamePixelsAndSecondaries(scene, *accel, 48, 3, what);
            }
        }
    }
}

// 24 random scenes x (3000 random + node-corner + pixel rays), both stop rules: over 10^5 rays.
TEST(Bvh, RandomScenesAndHardRays) {
    size_t total = 0;
    for (uint64_t seed = 1; seed <= 24; ++seed) {
        test::RandomSceneOptions opt;
        opt.transforms = seed % 2 == 0;
        opt.surfaces = seed % 3 == 0;
        opt.primitives = 8 + int(seed % 4) * 6;
        opt.groups = seed % 4 == 1 ? 3 : 1;
        if (seed % 5 == 0) opt.offset = Vec3(1e6, -1e6, 5e5);
        Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        const BuildParams p = bvhParams(seed % 2 == 1 ? -1 : 1 + int(seed % 3));
        auto accel = buildAccelerator(scene, p);
        const std::string what = "seed " + std::to_string(seed) + " " + toString(p);
        std::vector<Ray> rays = test::randomRays(scene, seed, 3000);
        const std::vector<Ray> corner =
            test::raysThroughPoints(nodePoints(bvhOf(*accel), 60, seed), scene.bounds, seed);
        rays.insert(rays.end(), corner.begin(), corner.end());
        const std::vector<Ray> pix = test::pixelRays(scene, 16, 16);
        rays.insert(rays.end(), pix.begin(), pix.end());
        expectSame(scene, *accel, rays, what);
        // Rays starting on node boundaries, with a tmin as the tracer's secondary rays have.
        std::vector<Ray> onBoundary;
        for (size_t i = 0; i < corner.size(); i += 4) onBoundary.push_back(corner[i + 1]);
        expectSame(scene, *accel, onBoundary, what + " tmin", 1e-9 * scene.scale());
        total += rays.size() + onBoundary.size();
    }
    EXPECT_GE(total, 100000u);
}

// Without mailboxes every leaf tests its primitives again: the same hits, more tests.
// A turned scene: the BVH is built along the turn's axes (the rule of the regular grid,
// grid_frame.h) and walks the ray mapped into them; every hit is brute force's, on random turned
// trees and on the sponge, where it visits a quarter of the nodes of the world-axes build.
TEST(Bvh, TurnedScenesAreBuiltInTheirFrame) {
    for (uint64_t seed = 1; seed <= 6; ++seed) {
        Scene s = test::turnedBars(seed * 7 + 2, 24);
        std::vector<Ray> rays = test::randomRays(s, seed, 3000);
        auto a = buildAccelerator(s, bvhParams());
        test::expectSame(s, *a, rays, s.name);
        test::expectSame(s, *a, rays, s.name + ", tmin > 0", 1e-3 * s.scale());
    }
    Scene s = loadScene("builtin:sponge:3");
    auto own = buildAccelerator(s, bvhParams());
    const Bvh& b = std::get<Bvh>(own->impl());
    ASSERT_TRUE(b.frame().turned);
    test::expectSamePixelsAndSecondaries(s, *own, 64, 5, "sponge, bvh");
    BuildParams world = bvhParams();
    world.bvh.turnedFrame = false;
    auto flat = buildAccelerator(s, world);
    EXPECT_FALSE(std::get<Bvh>(flat->impl()).frame().turned);
    const std::vector<Ray> rays = test::pixelRays(s, 64, 64);
    const RayCounters c = test::traceCounters(s, *own, rays);
    const RayCounters w = test::traceCounters(s, *flat, rays);
    EXPECT_LT(2 * c.regionVisits, w.regionVisits)
        << c.regionVisits << " against " << w.regionVisits;
    // Its nodes' corners are the world's: each node's centre is picked back.
    const StructureView view(s, *own);
    for (uint32_t id = 0; id < view.regionCount(); ++id) {
        if (!b.nodes()[id].leaf) continue;
        const std::array<Vec3, 8> k = view.regionCorners(id);
        const Vec3 lo = b.frame().toFrame(k[0]), hi = b.frame().toFrame(k[7]);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(lo[a], b.nodes()[id].box().lo[a], 1e-12);
            EXPECT_NEAR(hi[a], b.nodes()[id].box().hi[a], 1e-12);
        }
    }
}

/// How many of `rays` Bvh::occluded answers as brute force's intersect does, each with
/// t in (tmin, tmax] for tmax a quarter, a half and the whole of brute force's hit distance (or
/// the scene's size past it), the rays' ends landing before, at and after their hits. Counts the
/// blocked answers in `blocked`.
size_t occludedAsBrute(const Scene& scene, const Accelerator& accel, const std::vector<Ray>& rays,
                       double tmin, const std::string& what, size_t& blocked) {
    auto brute = buildAccelerator(scene, BuildParams{});
    const Bvh& bvh = bvhOf(accel);
    TraceContext cb(scene.prims.size(), scene.tree.depth()),
        ca(scene.prims.size(), scene.tree.depth());
    ca.useMailboxes = accel.usesMailboxes();
    NullObserver obs;
    size_t same = 0, failures = 0;
    for (const Ray& r : rays) {
        Hit near;
        cb.beginRay();
        const double reach = brute->intersect(r, tmin, kInf, cb, obs, near)
                                 ? near.t
                                 : glm::length(scene.bounds.extent()) + 1.0;
        for (double f : {0.25, 0.5, 1.0, 1.5}) {
            const double tmax = std::max(tmin, f * reach);
            Hit hb, ha;
            cb.beginRay();
            ca.beginRay();
            const bool fb = brute->intersect(r, tmin, tmax, cb, obs, hb);
            const bool fa = bvh.occluded(r, tmin, tmax, ca, obs, ha);
            blocked += fa;
            // A blocked answer's boundary is one of the scene's: inside (tmin, tmax].
            const bool inside = !fa || (ha.t > tmin && ha.t <= tmax);
            if (fa == fb && inside)
                ++same;
            else if (failures++ < 3)
                ADD_FAILURE() << what << ": " << r.toString() << " on (" << tmin << ", " << tmax
                              << "]: occluded " << fa << " at t = " << ha.t << ", brute force "
                              << fb << " at t = " << hb.t;
        }
    }
    return same;
}

// Shadow rays take Bvh::occluded, which stops at the first boundary it is sure of: on union-only
// scenes (rays that begin outside every primitive, inside one, and on a surface) and on random
// CSG scenes, it answers as brute force's nearest hit does, for ends before, at and past the hit.
TEST(Bvh, OccludedAnswersAsTheNearestHit) {
    size_t rays = 0, same = 0, blocked = 0;
    for (const char* f : {"balls2.nff", "rings2.nff", "gears1.nff", "tetra3.nff"}) {
        Scene scene = loadScene(std::string(LANCER_SPD_DIR) + "/" + f);
        auto accel = buildAccelerator(scene, bvhParams());
        std::vector<Ray> r = test::pixelRays(scene, 24, 24);
        const std::vector<Ray> sec = test::secondaryRays(scene, r, 3);
        const std::vector<Ray> rnd = test::randomRays(scene, 5, 400);
        r.insert(r.end(), rnd.begin(), rnd.end());
        same += occludedAsBrute(scene, *accel, r, 0.0, f, blocked);
        same += occludedAsBrute(scene, *accel, sec, 1e-9 * scene.scale(), f, blocked);
        rays += 4 * (r.size() + sec.size());
    }
    for (uint64_t seed = 1; seed <= 12; ++seed) {
        test::RandomSceneOptions opt;
        opt.groups = seed % 3 == 0 ? 3 : 1;
        Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        auto accel = buildAccelerator(scene, bvhParams(seed % 2 ? -1 : 1));
        const std::vector<Ray> r = test::randomRays(scene, seed, 500);
        same += occludedAsBrute(scene, *accel, r, 0.0, "seed " + std::to_string(seed), blocked);
        rays += 4 * r.size();
    }
    EXPECT_EQ(same, rays);
    EXPECT_GT(blocked, rays / 8);
    EXPECT_LT(blocked, rays);
}

// The render's union-only walks are made once per octant of the ray's direction (the faces'
// offsets constants): each of the eight gives brute force's nearest hit and occlusion, on
// rays through node corners, edges and faces and random ones, from tmin 0 and a secondary
// ray's, on spheres with a floor polygon and on spheres with open cylinders.
TEST(Bvh, UnionWalksOfEveryOctantAgreeWithBruteForce) {
    for (const char* spec : {"builtin:balls:3", "builtin:rings:3"}) {
        Scene scene = loadScene(spec);
        ASSERT_TRUE(scene.tree.unionOnly());
        for (int maxObjects : {-1, 3}) {
            auto accel = buildAccelerator(scene, bvhParams(maxObjects));
            const Bvh& b = bvhOf(*accel);
            std::vector<Ray> rays = test::randomRays(scene, 11, 2000);
            const std::vector<Ray> hard =
                test::raysThroughPoints(nodePoints(b, 80, 12), scene.bounds, 13);
            rays.insert(rays.end(), hard.begin(), hard.end());
            size_t octants[8] = {};
            for (const Ray& r : rays)
                if (!hasFlatAxis(r))
                    ++octants[WideBoxes<false>(&b.top(), b.wides().data(), r, b.anchor()).octant];
            for (int k = 0; k < 8; ++k) EXPECT_GE(octants[k], 100u) << spec << " octant " << k;
            const std::string what = std::string(spec) + " " + toString(bvhParams(maxObjects));
            expectSame(scene, *accel, rays, what);
            expectSame(scene, *accel, rays, what + " tmin", 1e-9 * scene.scale());
            size_t blocked = 0;
            EXPECT_EQ(occludedAsBrute(scene, *accel, rays, 0.0, what, blocked), 4 * rays.size());
            EXPECT_GT(blocked, rays.size() / 4);
        }
    }
}

TEST(Bvh, MailboxesSpareRepeatedTestsOnly) {
    Scene scene = loadScene("builtin:lattice:4");
    BuildParams with = bvhParams(), without = bvhParams();
    without.mailboxes = false;
    auto a = buildAccelerator(scene, with), b = buildAccelerator(scene, without);
    const std::vector<Ray> rays = test::pixelRays(scene, 32, 32);
    expectSame(scene, *a, rays, "mailboxes");
    expectSame(scene, *b, rays, "no mailboxes");
    const RayCounters ca = test::traceCounters(scene, *a, rays);
    const RayCounters cb = test::traceCounters(scene, *b, rays);
    EXPECT_GT(ca.mailboxHits, 0u);
    EXPECT_EQ(cb.mailboxHits, 0u);
    EXPECT_EQ(ca.primTests + ca.mailboxHits, cb.primTests);
    EXPECT_EQ(ca.regionVisits, cb.regionVisits);
}

// Each leaf lists exactly the live primitives whose minimized box meets its box, sorted (its
// restricted tree then holds there); every live primitive is listed by some leaf; a child's box
// lies inside its parent's; the depth limit holds.
TEST(Bvh, LeavesListEveryPrimitiveMeetingTheirBox) {
    for (uint64_t seed = 40; seed <= 45; ++seed) {
        test::RandomSceneOptions opt;
        opt.transforms = true;
        opt.primitives = 30;
        opt.groups = 3;
        Scene scene = test::randomCsgScene(seed, opt);
        auto accel = buildAccelerator(scene, bvhParams(1, seed % 2 == 0, seed == 45 ? 3 : 0));
        const Bvh& b = bvhOf(*accel);
        std::vector<char> listed(scene.prims.size(), 0);
        const std::vector<uint32_t> live = scene.livePrimitives();
        for (uint32_t id = 0; id < b.nodes().size(); ++id) {
            const BvhNode& n = b.nodes()[id];
            if (seed == 45) {
                EXPECT_LE(n.depth, 3);
            }
            if (!n.leaf) {
                for (uint32_t c : {n.first, n.first + 1}) {
                    EXPECT_EQ(b.parent(c), id);
                    const Box3 cb = b.nodes()[c].box(), pb = n.box();
                    EXPECT_TRUE(glm::all(glm::greaterThanEqual(cb.lo, pb.lo)) &&
                                glm::all(glm::lessThanEqual(cb.hi, pb.hi)))
                        << "seed " << seed << " node " << c;
                }
                continue;
            }
            const std::vector<uint32_t> got(b.primList().begin() + n.first,
                                            b.primList().begin() + n.first + n.count);
            EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
            std::vector<uint32_t> want;
            for (uint32_t p : live) {
                if (scene.minBox[p].isEmpty()) continue;
                Box3 grown = scene.minBox[p];
                grown.lo -= Vec3(1e-9 * scene.scale());
                grown.hi += Vec3(1e-9 * scene.scale());
                if (grown.overlaps(n.box())) want.push_back(p);
            }
            std::sort(want.begin(), want.end());
            EXPECT_EQ(got, want) << "seed " << seed << " leaf " << id;
            for (uint32_t p : got) listed[p] = 1;
        }
        for (uint32_t p : live) {
            if (!scene.minBox[p].isEmpty()) {
                EXPECT_TRUE(listed[p]) << "seed " << seed << " p" << p;
            }
        }
    }
}

// The knobs change the structure as a user expects: more leaves at max-objects 1 than at 8
// without the cost stop, a shallower tree under a lower max-level.
// A union-only scene's entries are primList's primitives in its order, each leaf's last one
// marked (the walks stop there), with the scene's packed sphere or none: on the sphereflake (a
// floor polygon among spheres), the rings (open cylinders among spheres) at several leaf sizes.
TEST(Bvh, UnionEntriesAreTheLeavesPrimitives) {
    for (const char* spec : {"builtin:balls:3", "builtin:rings:3"}) {
        for (int maxObjects : {-1, 1, 5}) {
            Scene scene = loadScene(spec);
            ASSERT_TRUE(scene.tree.unionOnly());
            auto accel = buildAccelerator(scene, bvhParams(maxObjects));
            const Bvh& b = bvhOf(*accel);
            const std::vector<BvhUnionEntry>& x = b.unionEntries();
            ASSERT_EQ(x.size(), b.primList().size());
            std::vector<char> ends(x.size(), 0);
            size_t spheres = 0, others = 0;
            for (const BvhNode& n : b.nodes()) {
                if (!n.leaf) continue;
                ASSERT_GT(n.count, 0u);
                ends[n.first + n.count - 1] = 1;
            }
            for (size_t i = 0; i < x.size(); ++i) {
                const uint32_t p = b.primList()[i];
                EXPECT_EQ(x[i].prim, p) << spec << " entry " << i;
                EXPECT_EQ(x[i].last, uint32_t(ends[i])) << spec << " entry " << i;
                const bool packed = scene.packedSpheres[p].r >= 0.0;
                EXPECT_EQ(x[i].r >= 0.0, packed) << spec << " entry " << i;
                if (packed) {
                    EXPECT_EQ(x[i].c, scene.packedSpheres[p].c);
                    EXPECT_EQ(x[i].r, scene.packedSpheres[p].r);
                }
                ++(packed ? spheres : others);
            }
            EXPECT_GT(spheres, 0u) << spec;
            EXPECT_GT(others, 0u) << spec;
        }
    }
    // A CSG scene's leaves read their binary node: no entries.
    Scene csg = loadScene("builtin:drilled:3");
    EXPECT_TRUE(bvhOf(*buildAccelerator(csg, bvhParams())).unionEntries().empty());
}

TEST(Bvh, KnobsChangeTheStructure) {
    Scene scene = loadScene("builtin:lattice:4");
    auto fine = buildAccelerator(scene, bvhParams(1, false));
    auto coarse = buildAccelerator(scene, bvhParams(8, false));
    auto shallow = buildAccelerator(scene, bvhParams(1, false, 3));
    EXPECT_GT(fine->info().regions, coarse->info().regions);
    EXPECT_LE(bvhOf(*shallow).depth(), 3);
    EXPECT_GT(bvhOf(*fine).depth(), 3);
    EXPECT_EQ(fine->info().regions, bvhOf(*fine).nodes().size());
    const nlohmann::json& x = fine->info().extra;
    EXPECT_EQ(x.at("leaves").get<size_t>(),
              x.at("stop_reasons").at("max_objects").get<size_t>() +
                  x.at("stop_reasons").at("max_level").get<size_t>() +
                  x.at("stop_reasons").at("cost").get<size_t>() +
                  x.at("stop_reasons").at("unsplittable").get<size_t>());
}

// The wide nodes the walks read stand for the binary tree: every slot's float box, put back by
// the anchor, holds its binary node's double box; a wide node's slots are descendants of its
// binary node; every leaf is in exactly one slot, every unused slot is empty. Random
// scenes, some far from the origin (where a float cannot hold a coordinate's digits).
TEST(Bvh, WideNodesHoldTheirChildrensBoxes) {
    int checked = 0;
    for (uint64_t seed = 60; seed <= 71; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 40;
        opt.groups = seed % 2 ? 4 : 2;
        opt.surfaces = seed % 3 == 0;
        if (seed % 4 == 0) opt.offset = Vec3(1e6, -1e6, 5e5);
        Scene scene = test::randomCsgScene(seed, opt);
        auto accel = buildAccelerator(scene, bvhParams(1));
        const Bvh& b = bvhOf(*accel);
        const std::vector<BvhNode>& nodes = b.nodes();
        if (nodes.empty() || nodes[0].leaf) continue;  // what the intersections left is small
        ++checked;
        std::vector<int> inSlots(nodes.size(), 0);
        // The walks start at the root, slot 0 of top(), the others unused.
        EXPECT_EQ(b.top().node[0], 0u);
        EXPECT_EQ(b.top().wide[0], 0u);
        for (int k = 1; k < kBvhWidth; ++k) EXPECT_EQ(b.top().node[k], kNoNode);
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(double(b.top().lo[a][0]) + b.anchor()[a], nodes[0].lo[a]);
            EXPECT_GE(double(b.top().hi[a][0]) + b.anchor()[a], nodes[0].hi[a]);
        }
        // Walk the wide tree from its root, which stands for binary node 0.
        std::vector<std::pair<uint32_t, uint32_t>> todo{{0u, 0u}};  // wide, binary
        size_t seen = 0;
        while (!todo.empty()) {
            const auto [w, bin] = todo.back();
            todo.pop_back();
            ++seen;
            const BvhWideNode& wn = b.wides()[w];
            for (int k = 0; k < kBvhWidth; ++k) {
                if (wn.node[k] == kNoNode) {
                    EXPECT_EQ(wn.wide[k], kNoWide);
                    for (int a = 0; a < 3; ++a) EXPECT_GT(wn.lo[a][k], wn.hi[a][k]);
                    continue;
                }
                const uint32_t id = wn.node[k];
                ASSERT_LT(id, nodes.size());
                ++inSlots[id];
                // A descendant of `bin`: each expansion of a slot goes one level further, and
                // there are at most kBvhWidth - 2 of them.
                uint32_t up = b.parent(id);
                for (int i = 0; i < kBvhWidth - 2 && up != bin && up != kNoNode; ++i)
                    up = b.parent(up);
                EXPECT_EQ(up, bin) << "seed " << seed << " slot node " << id;
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(double(wn.lo[a][k]) + b.anchor()[a], nodes[id].lo[a])
                        << "seed " << seed << " node " << id << " axis " << a;
                    EXPECT_GE(double(wn.hi[a][k]) + b.anchor()[a], nodes[id].hi[a])
                        << "seed " << seed << " node " << id << " axis " << a;
                }
                // A leaf's slot names its first entry, which the union-only walks read.
                EXPECT_EQ(bool(wn.wide[k] & kWideLeaf), bool(nodes[id].leaf));
                if (nodes[id].leaf) {
                    EXPECT_EQ(wn.wide[k] & ~kWideLeaf, nodes[id].first);
                }
                if (!(wn.wide[k] & kWideLeaf)) todo.push_back({wn.wide[k], id});
            }
        }
        EXPECT_EQ(seen, b.wides().size());
        for (uint32_t id = 0; id < nodes.size(); ++id)
            if (nodes[id].leaf) {
                EXPECT_EQ(inSlots[id], 1) << "seed " << seed << " leaf " << id;
            }
    }
    EXPECT_GE(checked, 6);
}

// The float test of a wide node's four boxes meets every box the double test meets, on an
// interval holding the double one: random rays, rays through node corners, edges and faces
// (axis-parallel ones among them), from near and far, with tmin 0 and a secondary ray's.
TEST(Bvh, WideBoxTestHoldsTheDoubleOne) {
    size_t met = 0;
    for (uint64_t seed = 70; seed <= 75; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 30;
        opt.groups = 3;
        opt.transforms = seed % 2 == 0;
        if (seed % 3 == 0) opt.offset = Vec3(-3e5, 2e6, 1e4);
        Scene scene = test::randomCsgScene(seed, opt);
        auto accel = buildAccelerator(scene, bvhParams(1));
        const Bvh& b = bvhOf(*accel);
        std::vector<Ray> rays = test::randomRays(scene, seed, 300);
        const std::vector<Ray> hard =
            test::raysThroughPoints(nodePoints(b, 40, seed), scene.bounds, seed);
        rays.insert(rays.end(), hard.begin(), hard.end());
        for (const Ray& world : rays) {
            const Ray r = b.frame().turned ? b.frame().toFrame(world) : world;
            for (double tmin : {0.0, 1e-9 * scene.scale()}) {
                const SlabRay slab(r);
                auto check = [&](const auto& boxes) {
                    // The wide nodes, and the root's one slot (w == wides().size()).
                    for (uint32_t w = 0; w <= b.wides().size(); ++w) {
                        const bool top = w == b.wides().size();
                        const BvhWideNode& wn = top ? b.top() : b.wides()[w];
                        BvhEntry c[kBvhWidth];
                        const __m128 lo = _mm_set1_ps(floatDown(tmin)), hi = _mm_set1_ps(INFINITY);
                        const int n = top ? boxes.root(lo, hi, c[0])
                                          : boxes.children({kNoNode, w, 0.0f, 0.0f}, lo, hi, c);
                        for (int k = 0; k < kBvhWidth; ++k) {
                            if (wn.node[k] == kNoNode) continue;
                            double t0, t1;
                            if (!slab.clip(b.nodes()[wn.node[k]], tmin, kInf, t0, t1)) continue;
                            ++met;
                            const BvhEntry* e = std::find_if(
                                c, c + n, [&](const BvhEntry& x) { return x.node == wn.node[k]; });
                            ASSERT_NE(e, c + n) << "seed " << seed << " node " << wn.node[k]
                                                << " ray " << world.toString();
                            EXPECT_LE(double(e->t0), t0);
                            EXPECT_GE(double(e->t1), t1);
                        }
                    }
                };
                if (hasFlatAxis(r))
                    check(WideBoxes<true>(&b.top(), b.wides().data(), r, b.anchor()));
                else
                    check(WideBoxes<false>(&b.top(), b.wides().data(), r, b.anchor()));
            }
        }
    }
    EXPECT_GT(met, 10000u);
}

// The observer sees the walk the render makes: the same hit and counts; every region event
// names a node whose box holds the event's stretch (to the float test's rounding); children events
// name the visited nodes.
TEST(Bvh, ObservedWalkEqualsTheRender) {
    Scene scene = loadScene("builtin:drilled:4");
    auto accel = buildAccelerator(scene, bvhParams());
    const Bvh& b = bvhOf(*accel);
    const std::vector<Ray> rays = test::pixelRays(scene, 24, 24);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    RayCounters observed;
    for (const Ray& r : rays) {
        const RayCounters before = ctx.counters;
        const RecordingObserver rec = test::recordWalk(*accel, r, ctx);
        observed += ctx.counters - before;
        for (const WalkEvent& e : rec.events) {
            const walk::Region* g = e.get<walk::Region>();
            if (!g) continue;
            ASSERT_LT(g->region, b.nodes().size());
            if (std::isfinite(g->t0) && g->t0 <= g->t1) {
                // Inner nodes' intervals are the float test's, widened by 2^-21 of t.
                Box3 box = b.nodes()[g->region].box();
                const Vec3 pad(1e-6 * scene.scale() + 2e-6 * g->t1 * glm::length(r.d));
                box.lo -= pad;
                box.hi += pad;
                EXPECT_TRUE(box.contains(r.at(0.5 * (g->t0 + g->t1))))
                    << "node " << g->region << " t " << g->t0 << " " << g->t1 << " box "
                    << b.nodes()[g->region].box().toString() << " ray " << r.toString();
            }
        }
    }
    const RayCounters rendered = test::traceCounters(scene, *accel, rays);
    EXPECT_EQ(observed.primTests, rendered.primTests);
    EXPECT_EQ(observed.mailboxHits, rendered.mailboxHits);
    EXPECT_EQ(observed.regionVisits, rendered.regionVisits);
    EXPECT_GT(rendered.regionVisits, rays.size());
}

// The structure view describes nodes as regions: leaves with their list and tree, inner nodes
// without; a point inside a leaf's box picks a leaf containing it.
TEST(Bvh, StructureViewDescribesNodes) {
    Scene scene = loadScene("builtin:default");
    auto accel = buildAccelerator(scene, bvhParams(1, false));
    const StructureView view(scene, *accel);
    ASSERT_EQ(view.regionCount(), bvhOf(*accel).nodes().size());
    size_t leaves = 0;
    for (uint32_t id = 0; id < view.regionCount(); ++id) {
        const RegionInfo r = view.region(id);
        const BvhNode& n = bvhOf(*accel).nodes()[id];
        EXPECT_EQ(r.level, n.depth);
        EXPECT_EQ(r.frameBox, n.box());
        if (r.kind == RegionKind::BvhLeaf) {
            ++leaves;
            EXPECT_EQ(r.prims.size(), n.count);
            EXPECT_GE(r.root, 0);
            const Vec3 c = n.box().center();
            EXPECT_TRUE(view.region(view.regionAt(c)).frameBox.contains(c));
        } else {
            EXPECT_EQ(r.kind, RegionKind::BvhInner);
            EXPECT_TRUE(r.prims.empty());
        }
    }
    EXPECT_GT(leaves, 1u);
    EXPECT_EQ(view.structureCorners()[0], bvhOf(*accel).box().lo);
}

TEST(Bvh, RefusesBadParametersAndBudgets) {
    Scene scene = loadScene("builtin:default");
    for (int bad : {0, -3}) {
        try {
            buildAccelerator(scene, bvhParams(bad));
            ADD_FAILURE() << "--max-objects " << bad << " accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("--max-objects"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(buildAccelerator(scene, bvhParams(-1, true, 65)), std::invalid_argument);
    Scene big = loadScene("builtin:lattice:8");
    BuildParams p = bvhParams(1, false);
    p.memoryBudget = 16 * 1024;
    try {
        buildAccelerator(big, p);
        ADD_FAILURE() << "a 16 KiB budget accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--memory-budget"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace lancer
