// The structure's trees (StructureView::trees, treeChild, treePath), which the viewer's tree
// browser lists: every region of the scheme is one node of its tree, with the region's
// primitives; the inner nodes are the structure's (the BSP's cut planes, the directory's
// entries and sub-tables, the screen BSP's cuts); a node's region range holds exactly the
// regions below it; and the path to a region leads to its node.
#include <gtest/gtest.h>

#include <map>

#include "engine/accel/structure_view.h"
#include "engine/scene/loader.h"

namespace lancer {
namespace {

struct Walked {
    size_t nodes = 0;
    std::map<TreeNodeKind, size_t> byKind;
    std::vector<int64_t> regionNodes;  ///< per region: how many nodes are it
};

/// Walk the whole tree, checking each node against the structure as it goes; returns the
/// regions below `n` (itself included), sorted.
std::vector<uint32_t> walkTree(const StructureView& sv, const TreeNode& n, Walked& w) {
    ++w.nodes;
    ++w.byKind[n.kind];
    std::vector<uint32_t> below;
    if (n.region >= 0) {
        EXPECT_LT(uint64_t(n.region), sv.regionCount());
        ++w.regionNodes[size_t(n.region)];
        below.push_back(uint32_t(n.region));
        if (n.prims >= 0) {
            EXPECT_EQ(size_t(n.prims), sv.region(uint32_t(n.region)).prims.size());
        }
    }
    for (size_t i = 0; i < n.children; ++i) {
        const TreeNode c = sv.treeChild(n, i);
        EXPECT_EQ(c.depth, n.depth + 1);
        std::vector<uint32_t> sub = walkTree(sv, c, w);
        below.insert(below.end(), sub.begin(), sub.end());
    }
    std::sort(below.begin(), below.end());
    below.erase(std::unique(below.begin(), below.end()), below.end());
    if (n.ranged) {
        // The range is exactly the regions below (the directory's entries name leaves that
        // other entries name too, so a table's range is the leaves its entries name).
        EXPECT_EQ(below.size(), size_t(n.regionHi - n.regionLo)) << sv.describe(n);
        if (!below.empty()) {
            EXPECT_EQ(below.front(), n.regionLo) << sv.describe(n);
            EXPECT_EQ(below.back() + 1, n.regionHi) << sv.describe(n);
        }
    }
    return below;
}

TEST(StructureTree, EveryRegionIsOneNodeAndTheInnerNodesAreTheStructures) {
    for (const char* scene : {"builtin:default", "builtin:balls:1", "builtin:drilled:2"})
        for (SchemeKind scheme :
             {SchemeKind::Brute, SchemeKind::Regular, SchemeKind::Irregular, SchemeKind::Bvh}) {
            SCOPED_TRACE(std::string(scene) + " " + schemeName(scheme));
            Scene sc = loadScene(scene);
            BuildParams p;
            p.scheme = scheme;
            p.regular.maxObjects = 1;
            auto accel = buildAccelerator(sc, p);
            const StructureView sv(sc, *accel);
            const std::vector<StructureTree> trees = sv.trees();
            switch (scheme) {
                case SchemeKind::Brute:
                    EXPECT_TRUE(trees.empty());
                    break;
                case SchemeKind::Regular:
                    ASSERT_EQ(trees.size(), 2u);
                    break;
                case SchemeKind::Irregular:
                    ASSERT_EQ(trees.size(), sv.frames().size());
                    break;
                case SchemeKind::Bvh:
                    ASSERT_EQ(trees.size(), 1u);
                    break;
            }
            for (const StructureTree& t : trees) {
                SCOPED_TRACE(t.name);
                Walked w;
                w.regionNodes.assign(sv.regionCount(), 0);
                walkTree(sv, t.root, w);
                switch (t.kind) {
                    case TreeKind::RegularBsp:
                        EXPECT_EQ(w.byKind[TreeNodeKind::Cell], sv.cutPlanes().size());
                        EXPECT_EQ(w.byKind[TreeNodeKind::Leaf], sv.regionCount());
                        for (int64_t k : w.regionNodes) EXPECT_EQ(k, 1);
                        break;
                    case TreeKind::Directory:
                        // Every entry and sub-table once, as the overlays' grid draws them.
                        EXPECT_EQ(w.nodes - 1, sv.directoryBlocks().size());
                        for (int64_t k : w.regionNodes) EXPECT_GE(k, 1);
                        break;
                    case TreeKind::ScreenBsp: {
                        const ZoneFrameView& f = *sv.frame(t.frame);
                        EXPECT_EQ(w.byKind[TreeNodeKind::Cut], f.cuts().size());
                        EXPECT_EQ(w.byKind[TreeNodeKind::Zone], f.zoneCount());
                        EXPECT_EQ(w.byKind[TreeNodeKind::Slab], f.slabCount());
                        break;
                    }
                    case TreeKind::Bvh:
                        EXPECT_EQ(w.nodes, sv.regionCount());
                        for (int64_t k : w.regionNodes) EXPECT_EQ(k, 1);
                        break;
                }
                // The path to each region the tree holds leads to a node that is that region.
                for (uint32_t id = 0; id < sv.regionCount(); ++id) {
                    const auto path = sv.treePath(t, id);
                    if (w.regionNodes[id] == 0) {
                        EXPECT_FALSE(path) << "region " << id;
                        continue;
                    }
                    ASSERT_TRUE(path) << "region " << id;
                    TreeNode n = t.root;
                    for (size_t i : *path) n = sv.treeChild(n, i);
                    EXPECT_EQ(n.region, int64_t(id));
                }
            }
        }
}

}  // namespace
}  // namespace lancer
