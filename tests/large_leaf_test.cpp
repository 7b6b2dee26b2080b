// Leaves whose tree lists more than kLazyLeafPrims primitives evaluate it lazily, as brute force
// does (eval.h): the regular and irregular schemes and the BVH with such leaves against brute
// force ray for ray, with and without mailboxes, and no more primitive tests per ray than brute
// force makes.
#include <gtest/gtest.h>

#include "engine/accel/accelerator.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

/// Schemes whose leaves hold many primitives: explicit max-objects above kLazyLeafPrims, a
/// shallow regular BSP (every leaf lazy) and a deeper one (lazy and small leaves along one ray:
/// a primitive tested lazily in one leaf is taken from its mailbox in the next, whose pending
/// check must not trust boundaries it was never given).
std::vector<BuildParams> largeLeafBuilds(bool mailboxes) {
    std::vector<BuildParams> out;
    for (auto [objects, level] : {std::pair{64, 1}, std::pair{20, 8}}) {
        BuildParams regular;
        regular.scheme = SchemeKind::Regular;
        regular.regular.maxObjects = objects;
        regular.regular.maxLevel = level;
        out.push_back(regular);
    }
    BuildParams irregular;
    irregular.scheme = SchemeKind::Irregular;
    irregular.irregular.maxObjects = 64;
    out.push_back(irregular);
    BuildParams bvh;
    bvh.scheme = SchemeKind::Bvh;
    bvh.bvh.maxObjects = 64;
    out.push_back(bvh);
    for (BuildParams& p : out) p.mailboxes = mailboxes;
    return out;
}

TEST(LargeLeaves, LazyTreesGiveBruteForcesHits) {
    size_t lazyLeaves = 0;
    for (uint64_t seed = 1; seed <= 12; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 60;
        opt.spread = 2.0;  // crowded: leaves overlap many boxes
        const Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        const std::vector<Ray> rays = test::randomRays(scene, seed * 31, 600);
        for (bool mailboxes : {true, false})
            for (const BuildParams& p : largeLeafBuilds(mailboxes)) {
                auto accel = buildAccelerator(scene, p);
                if (p.scheme == SchemeKind::Regular && mailboxes)
                    for (const auto& leaf : std::get<RegularGrid>(accel->impl()).leaves())
                        lazyLeaves += leaf.prims > kLazyLeafPrims;
                test::expectSame(scene, *accel, rays,
                                 "seed " + std::to_string(seed) + " " + toString(p));
            }
    }
    EXPECT_GE(lazyLeaves, 4u) << "the scenes gave too few leaves over kLazyLeafPrims";
}

TEST(LargeLeaves, NoMoreTestsPerRayThanBruteForce) {
    // One leaf over every primitive of a crowded difference-heavy scene: its lazy evaluation
    // skips what brute force skips.
    for (uint64_t seed = 1; seed <= 6; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 40;
        opt.spread = 1.0;
        const Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        const std::vector<Ray> rays = test::randomRays(scene, seed, 400);
        BuildParams one;
        one.scheme = SchemeKind::Regular;
        one.regular.maxObjects = 1000;  // never split: one leaf
        const auto brute =
            test::traceCounters(scene, *buildAccelerator(scene, BuildParams{}), rays);
        const auto leaf = test::traceCounters(scene, *buildAccelerator(scene, one), rays);
        EXPECT_LE(leaf.primTests, brute.primTests) << "seed " << seed;
    }
}

}  // namespace
}  // namespace lancer
