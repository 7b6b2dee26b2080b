// The regular build in parallel: cells of RegularGrid::kTaskPrims primitives or more build their
// halves as tasks, and the structure must be the serial build's whatever the number of threads
// (the same leaves in the same order, the same trees, lists, directory and figures).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>
#include <set>

#include "engine/accel/regular/regular_grid.h"
#include "engine/model/restriction.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

/// Everything a regular build makes, in plain arrays.
struct Built {
    std::vector<RegularLeaf> leaves;
    std::vector<CsgNode> pool;
    std::vector<uint32_t> primList;
    std::vector<uint32_t> directory;  ///< every entry: its block, kind, value, table and depth
    std::string extra;
};

Built buildWith(const Scene& scene, int threads) {
    const tbb::global_control only(tbb::global_control::max_allowed_parallelism, size_t(threads));
    nlohmann::json extra;
    const RegularGrid g = RegularGrid::build(scene, RegularConfig{}, extra);
    Built b{g.leaves(), g.treePool().nodes, g.primList(), {}, extra.dump()};
    g.directory().forEachEntry([&](const uint32_t* lo, const uint32_t* hi, bool sub, uint32_t value,
                                   uint32_t table, int depth) {
        b.directory.insert(b.directory.end(), {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                                               uint32_t(sub), value, table, uint32_t(depth)});
    });
    return b;
}

void expectSameStructure(const Scene& scene) {
    ASSERT_GE(scene.tree.primitives().size(), RegularGrid::kTaskPrims)
        << "too small for the build to make tasks";
    const Built one = buildWith(scene, 1);
    for (int threads : {2}) {
        SCOPED_TRACE(std::to_string(threads) + " threads");
        const Built many = buildWith(scene, threads);
        EXPECT_EQ(one.extra, many.extra);
        ASSERT_EQ(one.leaves.size(), many.leaves.size());
        size_t leavesDiffering = 0;
        for (size_t i = 0; i < one.leaves.size(); ++i)
            leavesDiffering +=
                std::memcmp(&one.leaves[i], &many.leaves[i], sizeof(RegularLeaf)) != 0;
        EXPECT_EQ(leavesDiffering, 0u);
        ASSERT_EQ(one.pool.size(), many.pool.size());
        size_t nodesDiffering = 0;
        for (size_t i = 0; i < one.pool.size(); ++i) {
            const CsgNode &a = one.pool[i], &b = many.pool[i];
            nodesDiffering +=
                a.op != b.op || a.left != b.left || a.right != b.right || a.prim != b.prim;
        }
        EXPECT_EQ(nodesDiffering, 0u);
        EXPECT_EQ(one.primList, many.primList);
        EXPECT_EQ(one.directory, many.directory);
    }
}

TEST(ParallelBuild, SameStructureWhateverTheThreadsOnASphereflake) {
    // balls:4: 7,382 primitives under one union, its leaves restricting the scene's tree.
    expectSameStructure(loadScene("builtin:balls:4"));
}

TEST(ParallelBuild, EachLeafsTreeIsTheScenesRestrictedToItsPrimitivesStoredOnceInOrder) {
    // A union's leaves get their trees after the layout, each written at a place reserved for
    // it (RegularBuilder::makeTrees): every leaf's tree must be the scene's tree restricted to
    // its primitives, each distinct set's tree stored once, in the order the leaves first meet
    // them, and nothing else in the pool.
    const Scene scene = loadScene("builtin:balls:4");
    const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    nlohmann::json extra;
    const RegularGrid g = RegularGrid::build(scene, RegularConfig{}, extra);
    CsgTree view = g.treePool();
    std::vector<char> marks(scene.prims.size(), 0);
    std::set<int> seen;
    size_t nodes = 0;
    int lastNew = -1;
    size_t differing = 0, outOfOrder = 0;
    for (const RegularLeaf& L : g.leaves()) {
        const uint32_t* p = L.primitives(g.primList().data());
        const std::vector<uint32_t> prims(p, p + L.prims);
        CsgTree expected;
        expected.root = restrictTreeTo(scene.tree, prims, marks, expected);
        view.root = L.root;
        differing += view.toString() != expected.toString();
        if (L.root >= 0 && seen.insert(L.root).second) {
            nodes += expected.nodes.size();
            outOfOrder += L.root < lastNew;
            lastNew = L.root;
        }
    }
    EXPECT_EQ(differing, 0u);
    EXPECT_EQ(outOfOrder, 0u);
    EXPECT_EQ(g.treePool().nodes.size(), nodes);
    EXPECT_EQ(size_t(extra["distinct_trees"]), seen.size());
}

TEST(ParallelBuild, SameStructureWhateverTheThreadsOnARandomCsgScene) {
    // 1,500 random CSG trees of 4 solids (unions, intersections, differences) under one union,
    // and open surfaces: each cell restricts its own tree.
    test::RandomSceneOptions opt;
    opt.primitives = 6000;
    opt.groups = 1500;
    opt.spread = 30.0;
    opt.surfaces = true;
    expectSameStructure(test::randomCsgScene(18, opt));
}

}  // namespace
}  // namespace lancer
