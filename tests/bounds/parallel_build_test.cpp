// The regular build in parallel: cells of RegularGrid::kTaskPrims primitives or more build their
// halves as tasks, and the structure must be the serial build's whatever the number of threads
// (the same leaves in the same order, the same trees, lists, directory and figures).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "engine/accel/regular/regular_grid.h"
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
