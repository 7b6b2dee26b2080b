// The parallel build's fragments laid out in the serial build's order: node pairs depth first,
// leaves left to right, each primitive set placed where the serial build first met it
// (docs/regular.md, "How the build runs").
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "engine/accel/regular/regular_builder.h"
#include "engine/util/huge_pages.h"
#include "engine/util/task_fence.h"

namespace lancer {

namespace {

/// The counts of the fragments under `f` added to `to`.
void addFragmentCounts(RegularBuilder::LeafCounts& to, const RegularBuilder::Fragment& f) {
    to.add(f.counts);
    for (const auto& k : f.children) addFragmentCounts(to, *k);
}

/// What the fragments under `f` hold, added to the sizes given.
void addFragmentSizes(const RegularBuilder::Fragment& f, size_t& leaves, size_t& nodes,
                      size_t& trees, size_t& lists, size_t& sets) {
    leaves += f.leafList.size();
    nodes += f.bsp.nodes.size();
    trees += f.pool.trees.nodes.size();
    lists += f.pool.lists.size();
    sets += f.pool.listFirst.size();
    for (const auto& k : f.children) addFragmentSizes(*k, leaves, nodes, trees, lists, sets);
}

}  // namespace

void RegularBuilder::LeafCounts::add(const LeafCounts& o) {
    primRefs += o.primRefs;
    maxPrims = std::max(maxPrims, o.maxPrims);
    emptyLeaves += o.emptyLeaves;
    coveredLeaves += o.coveredLeaves;
    costLeaves += o.costLeaves;
    gainLeaves += o.gainLeaves;
    objectsLeaves += o.objectsLeaves;
    levelLeaves += o.levelLeaves;
    solidCells += o.solidCells;
}

RegularBuilder::Layout RegularBuilder::layOut(Fragment& root) {
    Layout out;
    addFragmentCounts(out.counts, root);
    // One fragment is the serial build's structure as it is; several are laid out in its order.
    if (root.children.empty()) {
        out.bsp = std::move(root.bsp);
        reserveHuge(out.leaves, root.leafList.size());
        for (const uint32_t set : root.leafList)
            out.leaves.push_back(leafOf(root.pool, set, root.pool.roots[set]));
        out.places = std::move(root.places);
        out.pool = std::move(root.pool);
        out.treeNodes = root.treeNodes;
    } else {
        reserve(out, root);
        out.bsp.nodes.resize(1);
        layOut(out, root, 0, 0);
        root.children.clear();  // laid out: their memory is free for what follows
    }
    if (restrictor) makeTrees(out.pool, out.treeNodes);
    return out;
}

void RegularBuilder::layOut(Layout& out, Fragment& f, size_t i, size_t g) {
    const BspNodes::Node n = f.bsp.nodes[i];
    if (n.first == kLinked) return layOut(out, *f.children[n.leaf], 0, g);
    if (n.first >= 0) {
        const size_t first = out.bsp.nodes.size();
        out.bsp.nodes.resize(first + 2);
        out.bsp.nodes[g] = {int32_t(first), 0, n.height};
        layOut(out, f, size_t(n.first), first);
        layOut(out, f, size_t(n.first) + 1, first + 1);
        return;
    }
    if (out.leaves.size() % 4096 == 0) guard.poll();
    // The leaf's set: placed in the layout's pool where the serial build first met it,
    // its tree moved to the end of the layout's trees.
    if (f.placed.empty()) f.placed.assign(f.pool.listFirst.size() - 1, {-1, kUnplaced});
    const uint32_t set = f.leafList[n.leaf];
    if (f.placed[set].list == kUnplaced) {
        const std::span<const uint32_t> prims = f.pool.set(set);
        f.placed[set] = out.pool.share(prims, f.pool.hashes[set], [&](CsgTree& dst) {
            if (restrictor) return reserveTree(prims, out.treeNodes);
            const size_t begin = f.treeStart[set];
            const size_t end =
                set + 1 < f.treeStart.size() ? f.treeStart[set + 1] : f.pool.trees.nodes.size();
            const int shift = int(dst.nodes.size()) - int(begin);
            for (size_t k = begin; k < end; ++k) {
                CsgNode c = f.pool.trees.nodes[k];
                if (c.op != Op::Primitive) c.left += shift, c.right += shift;
                dst.nodes.push_back(c);
            }
            return f.pool.roots[set] < 0 ? -1 : f.pool.roots[set] + shift;
        });
    }
    out.bsp.nodes[g] = {-1, uint32_t(out.leaves.size()), 0};
    out.leaves.push_back(leafOf(out.pool, f.placed[set].list, f.placed[set].root));
    out.places.push_back(f.places[n.leaf]);
}

void RegularBuilder::reserve(Layout& out, const Fragment& root) {
    size_t leaves = 0, nodes = 0, trees = 0, lists = 0, sets = 0;
    addFragmentSizes(root, leaves, nodes, trees, lists, sets);
    reserveHuge(out.leaves, leaves);
    reserveHuge(out.places, leaves);
    reserveHuge(out.bsp.nodes, nodes);
    reserveHuge(out.pool.trees.nodes, trees);
    reserveHuge(out.pool.lists, lists);
    reserveHuge(out.pool.listFirst, sets);
    reserveHuge(out.pool.roots, sets);
    reserveHuge(out.pool.hashes, sets);
}

RegularLeaf RegularBuilder::leafOf(const SetPool& pool, uint32_t list, int root) {
    RegularLeaf leaf;
    leaf.root = root;
    leaf.first = pool.listFirst[list];
    leaf.prims = pool.listFirst[list + 1] - leaf.first;
    if (leaf.prims <= RegularLeaf::kInline)
        std::copy_n(pool.lists.data() + leaf.first, leaf.prims, leaf.inlined);
    return leaf;
}

void RegularBuilder::makeTrees(SetPool& pool, size_t count) {
    std::vector<CsgNode>& nodes = pool.trees.nodes;
    reserveHuge(nodes, count);
    nodes.resize(count);
    const size_t sets = pool.listFirst.size() - 1;
    const uint32_t* lists = pool.lists.data();
    const auto setOf = [&](size_t s) {
        return std::span<const uint32_t>(lists + pool.listFirst[s],
                                         pool.listFirst[s + 1] - pool.listFirst[s]);
    };
    std::vector<size_t> at(sets + 1, 0);
    for (size_t s = 0; s < sets; ++s) at[s + 1] = at[s] + restrictor->unionSize(setOf(s));
    TaskFence fence;
    try {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, sets, 1024), fence.task([&](const auto& r) {
            guard.poll();
            std::vector<int>& scratch = restrictorScratch.local();
            for (size_t s = r.begin(); s != r.end(); ++s)
                if (at[s + 1] > at[s])
                    restrictor->restrictUnions(setOf(s), nodes.data() + at[s], int(at[s]), scratch);
        }));
    } catch (...) {
        fence.acquire();
        throw;
    }
    fence.acquire();
}

void RegularBuilder::placeLeaves(Layout& out) const {
    const AxisSchedule& schedule = grid.schedule_;
    const int finest = out.bsp.nodes[0].height;
    int depth[3];
    const double* planes[3];  // held locally: the stores to the leaves could alias the vectors
    for (int a = 0; a < 3; ++a)
        depth[a] = schedule.cuts(finest, a), planes[a] = grid.planes_[a].data();
    for (size_t i = 0; i < out.leaves.size(); ++i) {
        const LeafPlace& pl = out.places[i];
        RegularLeaf& L = out.leaves[i];
        for (int a = 0; a < 3; ++a) {
            const int shift = depth[a] - schedule.cuts(pl.level, a);
            L.lo[a] = pl.pos[a] << shift;
            L.hi[a] = (pl.pos[a] + 1) << shift;
            L.plane[a] = planes[a][L.lo[a]];
            L.plane[3 + a] = planes[a][L.hi[a]];
        }
    }
}

}  // namespace lancer
